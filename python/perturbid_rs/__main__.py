"""``python -m perturbid_rs``: the paper's experiment on the built-in A465 (with arguments,
the ``perturbid`` command line: ``python -m perturbid_rs paper --out DIR``). The robot passes the
operating point of Kinsheel & Taha (2010), Table 2, in the planned nominal, G, H and D
experiments; the simulated recordings (gravity and friction excluded, as in the paper) give the
local model by the separated regressions, shown beside the paper's Table 2 (nominal torques)
and Table 3 (first column of D). A second run adds torque noise to show the uncertainty."""

from __future__ import annotations

import sys

import numpy as np

from . import OperatingPoint, identify_local, plan_experiments, robots, simulate

# Kinsheel & Taha (ICARCV 2010), Table 2 and Table 3.
Q = np.array([0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0])
QD = np.array([0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140])
QDD = np.array([-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710])
TN = np.array([-1.1883, -3.4797, -1.7304, -0.1377, -0.4466, 0.0539])
D1_ACTUAL = np.array([9.956, 0.0, 0.0, -1.37, 0.0, -0.27])
D1_PERTURBATION = np.array([9.95, 0.0, 0.0, -1.37, 0.0, -0.27])


def num(x, fmt: str) -> str:
    """`x` formatted; a number that rounds to zero prints without a sign (no `-0.000`)."""
    s = f"{x:{fmt}}"
    return s.replace("-", " ") if isinstance(x, (float, np.floating)) and float(s) == 0 else s


def row(label: str, values, fmt: str = "8.3f") -> str:
    return f"{label:<22}" + " ".join(num(x, fmt) for x in values)


def main(argv: list[str] | None = None) -> int:
    if argv:
        from ._cli import run

        return run(argv)
    robot = robots.a465("kinsheel2010")
    op = OperatingPoint(Q, QD, QDD)
    plan = plan_experiments(robot, op, design="random", seed=0)
    model = identify_local(plan, simulate(robot, plan, gravity=False, friction=None))
    noisy = identify_local(plan, simulate(robot, plan, gravity=False, friction=None, torque_noise=0.05, seed=1))
    actual = robot.mass_matrix(Q)
    assert model.D is not None and noisy.D is not None, "the plan has a D experiment"

    print("CRS A465 (kinsheel2010) at the operating point of Kinsheel & Taha (2010), Table 2")
    print("local model identified from simulated perturbation experiments; gravity and friction")
    print(f"excluded, as in the paper; {plan.experiment('D').deltas.shape[0]} crossings per experiment\n")
    print(f"{'joint':>5} {'q*':>8} {'qd*':>8} {'qdd*':>8} {'T* identified':>14} {'Tn paper':>10} {'diff':>8}")
    for i in range(robot.n):
        t = model.torque[i]
        cells = [num(Q[i], ">8.4f"), num(QD[i], ">8.4f"), num(QDD[i], ">8.4f"), num(t, ">14.4f"), num(TN[i], ">10.4f"), num(t - TN[i], ">8.4f")]
        print(f"{i + 1:>5} " + " ".join(cells))
    print("\nTable 3, first column of D:")
    print(row("", [f"D{i + 1}1" for i in range(6)], ">8"))
    print(row("actual M(q*)", actual[:, 0]))
    print(row("paper, actual", D1_ACTUAL))
    print(row("perturbation method", model.D[:, 0]))
    print(row("paper, perturbation", D1_PERTURBATION))
    print(row("  with 0.05 N m noise", noisy.D[:, 0]))
    print(row("  standard error", noisy.stderr["D"][:, 0]))
    print("\ncond(X): " + ", ".join(f"{k} {v:.2f}" for k, v in model.cond.items()))
    worst_t = np.abs(model.torque - TN).max()
    worst_d = np.abs(model.D - actual).max() / np.abs(actual).max()
    print(f"largest difference: T* vs paper {worst_t:.4f} N m; identified D* vs M(q*) {worst_d:.1e} (relative)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
