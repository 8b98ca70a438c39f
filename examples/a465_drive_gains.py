"""A robot that logs motor currents, not torques: its drive gains and base parameters at once.

The A465 runs an optimised excitation twice, once alone and once with a known 2 kg payload
bolted onto its flange, and logs its joint positions and motor currents only (a rehearsal here:
friction, torque noise and encoder counts on a true robot, the currents its torques over gains
the fit is not told). The raw logs are preprocessed (filtered, differentiated), and
`identify_drive_gains` gives each joint's gain (N m per A) with the robot's base parameters;
the model then gives the currents a new motion needs (feed-forward).

    python examples/a465_drive_gains.py [--quick]

With a real robot, replace `pr.simulate(...)` by the logs of the two runs (t, q and the
currents; `pr.Recording.load` reads the command line's CSV) and `payload` by your payload's
mass, centre of mass and inertia in the flange link's frame.
"""

import argparse

import numpy as np

import perturbid_rs as pr

GAINS = np.array([42.0, 65.0, 38.0, 9.0, 7.5, 4.0])  # N m per A: the truth the fit is not told
PAYLOAD = {"link": "link6", "mass": 2.0, "com": [0.0, 0.0, 0.08],  # kg, m
           "inertia": [0.004, 0.0, 0.0, 0.004, 0.0, 0.002]}  # kg m^2 about its centre of mass


def true_robot(payload):
    spec = {
        "seed": 3 if payload else 2,
        "friction": {"viscous": [0.5, 0.4, 0.3, 0.2, 0.1, 0.05], "coulomb": [1.0, 0.8, 0.6, 0.4, 0.2, 0.1]},
        "sensors": {"torque_noise": [0.05, 0.05, 0.05, 0.02, 0.02, 0.02],
                    "encoder_counts": [409600] * 6},
    }
    if payload:
        spec["payload"] = payload
    return pr.TrueRobot(spec)


def main() -> None:
    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--quick", action="store_true", help="a shorter excitation design (for CI)")
    a = args.parse_args()
    robot = pr.robots.a465()
    design = pr.design_excitation(robot, harmonics=5, base_frequency=0.1, seed=0,
                                  max_evaluations=300 if a.quick else 2000)
    print(f"excitation: cond(Phi_base) {design.cond:.1f}")
    runs = []
    for payload in [None, PAYLOAD]:
        log = pr.simulate(robot, design, true_robot=true_robot(payload), rate=1000.0, periods=2.0)
        current = log.tau / GAINS  # what the robot logs (A)
        runs.append(pr.preprocess(log.t, log.q, current, name="loaded" if payload else "alone"))
    friction = ["viscous", "coulomb"]
    fit = pr.identify_drive_gains(robot, runs, [None, PAYLOAD], friction=friction)
    g = fit.drive_gains
    # by instrumental variables too: unbiased by the currents' noise, at a larger variance
    iv = pr.identify_drive_gains(robot, runs, [None, PAYLOAD], friction=friction,
                                 estimator="instrumental").drive_gains
    print("drive gains (N m per A):")
    print(f"  {'joint':<8} {'true':>8} {'identified':>12} {'std. error':>11} {'noise bias':>11}"
          f" {'agreement':>10} {'instrumental':>13}")
    for j, name in enumerate(robot.joint_names):
        print(f"  {name:<8} {GAINS[j]:8.3f} {g['gain'][j]:12.4f} {g['stderr'][j]:11.4f}"
              f" {100 * g['noise_bias'][j]:9.3f} % {g['agreement'][j]:10.3f} {iv['gain'][j]:13.4f}")
    worst = np.max(np.abs(g["gain"] / GAINS - 1))
    print(f"largest gain error {100 * worst:.2f} %; {len(fit.theta_base)} base parameters, cond {fit.cond:.1f}")
    print(f"largest gain error by instrumental variables {100 * np.max(np.abs(iv['gain'] / GAINS - 1)):.2f} %")
    # the currents another motion needs, with their standard errors
    t = np.linspace(0.0, 2.0, 5)
    q, qd, qdd = design.trajectory.sample(t)
    current = fit.predict(q, qd, qdd, signal=True)[:, 1]
    se = fit.predict_stderr(q, qd, qdd, signal=True)[:, 1]
    print("feed-forward currents (A) along the excitation's first 2 s, joint 2:",
          " ".join(f"{c:.4f}+-{s:.1e}" for c, s in zip(current, se)))


if __name__ == "__main__":
    main()
