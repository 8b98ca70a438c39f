"""The paper on the built-in A465: plan the perturbed passes at the Table 2 operating point,
simulate them, identify the local model, and compare D* with M(q*) and the paper's Table 3.

    python examples/paper_a465.py            # about 2 s
"""

import json
import pathlib

import numpy as np

import perturbid_rs as pr

HERE = pathlib.Path(__file__).parent


def main() -> None:
    robot = pr.robots.a465()
    op_json = json.loads((HERE / "op.json").read_text())
    op = pr.OperatingPoint(op_json["q"], op_json["qd"], op_json["qdd"])
    plan = pr.plan_experiments(robot, op, design="orthogonal")
    # the paper's simulation: gravity and friction excluded, a little torque noise
    recordings = pr.simulate(robot, plan, gravity=False, friction=None, torque_noise=[0.005] * robot.n)
    model = pr.identify_local(plan, recordings)
    truth = robot.linearize(op.q, op.qd, op.qdd, gravity=False)
    np.set_printoptions(precision=3, suppress=True)
    print("first column of D (Table 3)")
    print("  identified D*:", model.D[:, 0])
    print("  actual M(q*): ", truth.D[:, 0])
    print("  paper:        ", np.array([9.95, 0.0, 0.0, -1.37, 0.0, -0.27]))
    err = np.abs(model.D - truth.D).max()
    print(f"largest error in D*: {err:.2e} (standard errors up to {model.stderr['D'].max():.2e})")
    assert err < 0.05, "the local model should reproduce M(q*)"


if __name__ == "__main__":
    main()
