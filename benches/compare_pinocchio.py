"""Side by side with Pinocchio, in one process: per-call latency from Python, batch
throughput, and a 100,000-sample identification end to end.

    python benches/compare_pinocchio.py            (needs: pip install pin)

Prints a Markdown table. Every figure is the median of several runs, and the two libraries take
turns (Pinocchio, then perturbid_rs, then Pinocchio again, ...), each after a short idle gap, so
that a slow spell of a shared machine or numpy's BLAS threads still spinning after
`numpy.linalg.lstsq` do not fall on one side only."""

from __future__ import annotations

import os
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

import perturbid_rs as pr

K = 100_000
IDLE = 0.3  # s between timed runs


def compare(pin_run, our_run, rounds):
    """Median times (s) of `pin_run` and `our_run`, timed in alternation."""
    t_pin, t_our = [], []
    for _ in range(rounds):
        for f, times in ((pin_run, t_pin), (our_run, t_our)):
            time.sleep(IDLE)
            t = time.perf_counter()
            f()
            times.append(time.perf_counter() - t)
    return statistics.median(t_pin), statistics.median(t_our)


def main() -> int:
    urdf = pr.robots.a465_urdf("kinsheel2010")
    robot = pr.Robot.from_urdf_string(urdf, check_triangle_inequality=False)
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    n = robot.n
    rng = np.random.default_rng(0)
    Q, QD, QDD = rng.uniform(-1, 1, (3, K, n))
    rows = []

    # per-call latency from Python (one sample)
    q, qd, qdd = Q[0], QD[0], QDD[0]
    calls = 20_000
    t_pin, t_our = compare(
        lambda: [pin.rnea(model, data, q, qd, qdd) for _ in range(calls)],
        lambda: [robot.rnea(q, qd, qdd) for _ in range(calls)],
        5,
    )
    rows.append(("RNEA, one call from Python", t_pin / calls * 1e6, t_our / calls * 1e6, "us"))
    calls //= 4
    t_pin, t_our = compare(
        lambda: [pin.computeJointTorqueRegressor(model, data, q, qd, qdd) for _ in range(calls)],
        lambda: [robot.regressor(q, qd, qdd) for _ in range(calls)],
        5,
    )
    rows.append(("regressor, one call from Python", t_pin / calls * 1e6, t_our / calls * 1e6, "us"))

    # batch throughput: a Python loop over Pinocchio against one batched call
    def pin_rnea():
        out = np.empty((K, n))
        for i in range(K):
            out[i] = pin.rnea(model, data, Q[i], QD[i], QDD[i])
        return out

    def pin_crba():
        out = np.empty((K, n, n))
        for i in range(K):
            out[i] = pin.crba(model, data, Q[i])
        return out

    np.testing.assert_allclose(robot.rnea(Q[:100], QD[:100], QDD[:100]), pin_rnea()[:100], atol=1e-9)
    t_pin, t_our = compare(pin_rnea, lambda: robot.rnea(Q, QD, QDD), 5)
    rows.append((f"RNEA, {K:,} samples (Pinocchio: Python loop)", t_pin * 1e3, t_our * 1e3, "ms"))
    t_pin, t_our = compare(pin_crba, lambda: robot.mass_matrix(Q), 5)
    rows.append((f"mass matrix, {K:,} samples", t_pin * 1e3, t_our * 1e3, "ms"))

    # identification: 10^5 samples, 60 inertial parameters
    tau = robot.rnea(Q, QD, QDD) + rng.normal(0, 0.01, (K, n))
    fits = {}

    def pin_identify():
        phi = np.empty((K * n, 10 * n))
        for i in range(K):
            phi[i * n : (i + 1) * n] = pin.computeJointTorqueRegressor(model, data, Q[i], QD[i], QDD[i])
        fits["pin"], *_ = np.linalg.lstsq(phi, tau.reshape(-1), rcond=None)

    def our_identify():
        fits["ours"] = pr.identify_base_parameters(robot, Q, QD, QDD, tau, friction=None, weighting="ols")

    t_pin, t_our = compare(pin_identify, our_identify, 3)
    fit, theta_pin = fits["ours"], fits["pin"]
    base_pin = theta_pin[fit.kept] + fit.K @ theta_pin[fit.dropped]
    agreement = np.abs(base_pin - fit.theta_base).max() / np.abs(fit.theta_base).max()
    rows.append((f"identification, {K:,} samples (regressor + least squares)", t_pin, t_our, "s"))

    print(f"machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}, Pinocchio {pin.__version__}, perturbid_rs {pr.__version__}\n")
    print("| workload | Pinocchio | perturbid_rs | speed-up |")
    print("|---|---|---|---|")
    for name, a, b, unit in rows:
        print(f"| {name} | {a:.3g} {unit} | {b:.3g} {unit} | {a / b:.1f}x |")
    print(f"\nbase parameters of the two identifications agree to {agreement:.1e} (relative)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
