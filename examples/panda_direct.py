"""The direct method on a real robot's log: the Franka Emika Panda excitation of Gaz et al.
(2019), which lies beside the repository (docs/data.md). Preprocess (resample, zero-phase
low-pass, accelerations, decimate), identify the base parameters on the first 70 %, the
physically consistent ones too, and validate both on the last 30 %; with matplotlib installed,
plot measured against predicted torques.

    python examples/panda_direct.py [--quick] [--log PATH] [--out DIR]
"""

import argparse
import pathlib
import sys
import sysconfig

import numpy as np

import perturbid_rs as pr

HERE = pathlib.Path(__file__).parent
LOG = HERE.parent.parent / "shared/data/panda-gaz2019/excitation.csv"


def panda_urdf() -> pathlib.Path:
    root = pathlib.Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
    path = root / "panda_description/urdf/panda.urdf"
    if not path.is_file():
        raise SystemExit(f"the Panda URDF is not at {path}: pip install example-robot-data")
    return path


def relative_rms(predicted: np.ndarray, measured: np.ndarray) -> np.ndarray:
    return np.sqrt(np.sum((predicted - measured) ** 2, axis=0) / np.sum(measured**2, axis=0))


def main() -> None:
    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--quick", action="store_true", help="the first 8 s of the log only (for CI)")
    args.add_argument("--log", type=pathlib.Path, default=LOG)
    args.add_argument("--out", type=pathlib.Path, default=pathlib.Path("panda_direct"))
    a = args.parse_args()
    if not a.log.is_file():
        print(f"the Panda log is not at {a.log} (it lies beside the repository; see docs/data.md)")
        sys.exit(2)
    data = np.loadtxt(a.log, delimiter=",", skiprows=1)
    if a.quick:
        data = data[data[:, 0] < data[0, 0] + 8.0]
    t, q, qd, tau = data[:, 0], data[:, 1:8], data[:, 8:15], data[:, 15:22]
    robot = pr.Robot.from_urdf(panda_urdf(), lock={"panda_finger_joint1": 0.0})
    rec = pr.preprocess(t, q, tau, qd)
    k = len(rec)
    split = int(0.7 * k)
    # the recording given whole brings its time (the derivatives' check) and the Coulomb
    # term's column filtered as its torques were (parallel filtering)
    fit_part, held_out = rec[:split], rec[split:]
    base = pr.identify_base_parameters(robot, fit_part, friction="all")
    consistent = pr.identify_consistent_parameters(robot, fit_part, friction="all")
    np.set_printoptions(precision=1, suppress=True)
    print(f"{k} samples after preprocessing, {len(base.theta_base)} base parameters, cond {base.cond:.1f}")
    print(f"consistent fit: residual grows by {consistent.residual_growth:.3f}, {len(consistent.active)} constraints active")
    measured = held_out.tau
    for name, m in [("unconstrained", base), ("consistent", consistent.model)]:
        print(f"held-out relative RMS error (%), {name}:", 100 * relative_rms(m.predict(held_out), measured))
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "base_model.json").write_text(consistent.model.to_json())
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure")
        return
    predicted = consistent.model.predict(held_out)
    fig, axes = plt.subplots(7, 1, figsize=(9, 14), sharex=True)
    for j, ax in enumerate(axes):
        ax.plot(held_out.t, measured[:, j], color="0.3", label="measured")
        ax.plot(held_out.t, predicted[:, j], "--", color="tab:red", label="predicted (consistent)")
        ax.set_ylabel(f"joint {j + 1} (N m)")
    axes[0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1].set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(a.out / "validation.png", dpi=80)
    print(f"wrote {a.out / 'base_model.json'} and {a.out / 'validation.png'}")


if __name__ == "__main__":
    main()
