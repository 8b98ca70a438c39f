"""``python -m perturbid_rs``: the built-in A465 at the paper's operating point, beside the
paper's Table 2 (nominal torques) and Table 3 (first column of D, "actual" row)."""

from __future__ import annotations

import sys

import numpy as np

from . import robots

# Kinsheel & Taha (ICARCV 2010), Table 2 and Table 3.
Q = np.array([0.7854, 0.3927, -0.5236, 0.0, 1.0472, 0.0])
QD = np.array([0.0890, -0.1060, 0.0220, 0.0560, 0.0110, 0.0140])
QDD = np.array([-0.1550, -0.5000, 0.0340, -0.2910, -0.0080, 0.1710])
TN = np.array([-1.1883, -3.4797, -1.7304, -0.1377, -0.4466, 0.0539])
D1 = np.array([9.956, 0.0, 0.0, -1.37, 0.0, -0.27])


def main(argv: list[str] | None = None) -> int:
    robot = robots.a465("kinsheel2010")
    lin = robot.linearize(Q, QD, QDD, gravity=False)
    print("CRS A465 (kinsheel2010) at the operating point of Kinsheel & Taha (2010), Table 2")
    print("gravity and friction excluded, as in the paper\n")
    print(f"{'joint':>5} {'q*':>8} {'qd*':>8} {'qdd*':>8} {'T* model':>10} {'Tn paper':>10} {'diff':>8}")
    for i in range(robot.n):
        print(f"{i + 1:>5} {Q[i]:>8.4f} {QD[i]:>8.4f} {QDD[i]:>8.4f} {lin.torque[i]:>10.4f} {TN[i]:>10.4f} {lin.torque[i] - TN[i]:>8.4f}")
    print("\nTable 3, first column of D = M(q*):")
    print(f"{'':>5} " + " ".join(f"{f'D{i + 1}1':>8}" for i in range(6)))
    print(f"{'model':>5} " + " ".join(f"{x:>8.3f}" for x in lin.D[:, 0]))
    print(f"{'paper':>5} " + " ".join(f"{x:>8.3f}" for x in D1))
    worst_t = np.abs(lin.torque - TN).max()
    worst_d = np.abs(lin.D[:, 0] - D1).max()
    print(f"\nlargest difference: torque {worst_t:.4f} N m, D column {worst_d:.4f} kg m^2")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
