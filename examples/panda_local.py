"""A real arm from its URDF, start to finish, with the local method: the Franka Emika Panda at a
drilling pose. Plan the perturbed passes, rehearse them on a "true robot" (a 1.2 kg drill the
URDF does not know, joint friction, torque noise and encoder quantisation: examples/
panda_true_robot.json), identify the local model, and validate it on states near the pose
against the true robot.

    python examples/panda_local.py [--quick] [--out DIR]

The Panda's URDF comes from example-robot-data (`pip install example-robot-data`); its finger
joints are locked. With a real robot, replace `pr.simulate(...)` by what it logs running the
plan's trajectories (`plan.experiments[i].t`, `.q`, `.qd`, `.qdd`; `pr.Recording` takes t, q, tau).
"""

import argparse
import json
import pathlib
import sysconfig

import numpy as np

import perturbid_rs as pr

HERE = pathlib.Path(__file__).parent


def panda_urdf() -> pathlib.Path:
    root = pathlib.Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
    path = root / "panda_description/urdf/panda.urdf"
    if not path.is_file():
        raise SystemExit(f"the Panda URDF is not at {path}: pip install example-robot-data")
    return path


def main() -> None:
    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--quick", action="store_true", help="a smaller plan (for CI)")
    args.add_argument("--out", type=pathlib.Path, default=pathlib.Path("panda_local"))
    a = args.parse_args()
    robot = pr.Robot.from_urdf(panda_urdf(), lock={"panda_finger_joint1": 0.02})
    spec = json.loads((HERE / "panda_drilling_op.json").read_text())
    op = pr.OperatingPoint(spec["q"], spec["qd"], spec["qdd"])
    true_robot = pr.TrueRobot.load(HERE / "panda_true_robot.json")
    # perturbations that keep every joint turning one way: Coulomb friction then cancels
    plan = pr.plan_experiments(
        robot, op, design="orthogonal", keep_velocity_sign=True, rate=500.0 if a.quick else 1000.0
    )
    print(f"plan: {len(plan.experiments)} experiments, {sum(e.duration for e in plan.experiments):.0f} s of motion")
    recordings = pr.simulate(robot, plan, true_robot=true_robot)
    model = pr.identify_local(plan, recordings)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "local_model.json").write_text(model.to_json())
    # validation: states near the pose, within the perturbation sizes, on the true robot
    rng = np.random.default_rng(0)
    k = 50
    q = op.q + rng.uniform(-0.01, 0.01, (k, robot.n))
    qd = op.qd + rng.uniform(-0.02, 0.02, (k, robot.n))
    qdd = op.qdd + rng.uniform(-0.1, 0.1, (k, robot.n))
    # what the true robot logs at those states (its sensors' noise included)
    t = np.arange(k) * 1e-3
    measured = pr.simulate(robot, (t, q, qd, qdd), true_robot=true_robot).tau
    nominal = robot.rnea(q, qd, qdd)
    predicted = model.predict(q, qd, qdd)
    rms = lambda e: np.sqrt(np.mean(e**2, axis=0))  # noqa: E731
    np.set_printoptions(precision=3, suppress=True)
    print("torque error near the pose, RMS per joint (N m)")
    print("  the URDF alone:   ", rms(nominal - measured))
    print("  the local model:  ", rms(predicted - measured))
    assert rms(predicted - measured).max() < 0.2 * rms(nominal - measured).max(), "the local model should beat the URDF"
    print(f"wrote {a.out / 'local_model.json'}")


if __name__ == "__main__":
    main()
