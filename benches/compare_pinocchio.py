"""Side by side with Pinocchio, in one process: per-call latency from Python, batch
throughput, and a 100,000-sample identification end to end.

    python benches/compare_pinocchio.py            (needs: pip install pin example-robot-data)

Prints a Markdown table (times are medians of repeated runs on this machine)."""

from __future__ import annotations

import os
import statistics
import sys
import time

import numpy as np
import pinocchio as pin

import perturbid_rs as pr

K = 100_000


def median_time(f, repeat=5):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


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
    t_pin = median_time(lambda: [pin.rnea(model, data, q, qd, qdd) for _ in range(calls)]) / calls
    t_our = median_time(lambda: [robot.rnea(q, qd, qdd) for _ in range(calls)]) / calls
    rows.append(("RNEA, one call from Python", t_pin * 1e6, t_our * 1e6, "us"))
    t_pin = median_time(lambda: [pin.computeJointTorqueRegressor(model, data, q, qd, qdd) for _ in range(calls // 4)]) / (calls // 4)
    t_our = median_time(lambda: [robot.regressor(q, qd, qdd) for _ in range(calls // 4)]) / (calls // 4)
    rows.append(("regressor, one call from Python", t_pin * 1e6, t_our * 1e6, "us"))

    # batch throughput: a Python loop over Pinocchio against one batched call
    def pin_batch():
        out = np.empty((K, n))
        for i in range(K):
            out[i] = pin.rnea(model, data, Q[i], QD[i], QDD[i])
        return out

    t_pin = median_time(pin_batch, 3)
    t_our = median_time(lambda: robot.rnea(Q, QD, QDD), 3)
    np.testing.assert_allclose(robot.rnea(Q[:100], QD[:100], QDD[:100]), pin_batch()[:100], atol=1e-9)
    rows.append((f"RNEA, {K:,} samples", t_pin * 1e3, t_our * 1e3, "ms"))
    t_pin = median_time(lambda: [pin.crba(model, data, Q[i]) for i in range(K)], 3)
    t_our = median_time(lambda: robot.mass_matrix(Q), 3)
    rows.append((f"mass matrix, {K:,} samples", t_pin * 1e3, t_our * 1e3, "ms"))

    # identification: 10^5 samples, 60 inertial parameters
    tau = robot.rnea(Q, QD, QDD) + rng.normal(0, 0.01, (K, n))

    def pin_identify():
        phi = np.empty((K * n, 10 * n))
        for i in range(K):
            phi[i * n : (i + 1) * n] = pin.computeJointTorqueRegressor(model, data, Q[i], QD[i], QDD[i])
        theta, *_ = np.linalg.lstsq(phi, tau.reshape(-1), rcond=None)
        return theta

    t0 = time.perf_counter()
    theta_pin = pin_identify()
    t_pin = time.perf_counter() - t0
    t0 = time.perf_counter()
    fit = pr.identify_base_parameters(robot, Q, QD, QDD, tau, friction=False, weighting="ols")
    t_our = time.perf_counter() - t0
    base_pin = theta_pin[fit.kept] + fit.K @ theta_pin[fit.dropped]
    agreement = np.abs(base_pin - fit.theta_base).max() / np.abs(fit.theta_base).max()
    rows.append((f"identification, {K:,} samples (base parameters)", t_pin, t_our, "s"))

    print(f"machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}, Pinocchio {pin.__version__}, perturbid_rs {pr.__version__}\n")
    print("| workload | Pinocchio | perturbid_rs | speed-up |")
    print("|---|---|---|---|")
    for name, a, b, unit in rows:
        print(f"| {name} | {a:.3g} {unit} | {b:.3g} {unit} | {a / b:.1f}x |")
    print(f"\nbase parameters of the two identifications agree to {agreement:.1e} (relative)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
