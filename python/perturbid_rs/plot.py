"""Figures for notebooks (matplotlib, an optional dependency: ``pip install perturbid_rs[plot]``).

Each function draws on new axes and returns the matplotlib Figure; legends stand outside the
data, and curves that may coincide (measured and predicted) get distinct line styles.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["measured_and_predicted", "noise_fit", "residuals"]


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - exercised without matplotlib only
        raise ImportError("perturbid_rs.plot needs matplotlib: pip install 'perturbid_rs[plot]'") from e
    return plt


def measured_and_predicted(
    t: ArrayLike,
    measured: ArrayLike,
    predicted: ArrayLike,
    joints: Optional[Sequence[str]] = None,
    stderr: Optional[ArrayLike] = None,
) -> Any:
    """One panel per joint: the measured torque (solid, grey), the predicted one (dashed, red)
    and their difference (dotted, blue). ``t`` (k,) in s; ``measured``, ``predicted`` (k, n) in
    N m; ``joints`` names the panels. ``stderr`` (k, n) in N m, the predictions' standard errors
    (a model's ``predict_stderr``), draws the band of +- 2 of them about the prediction (red,
    shaded; a gap where one is unknown, NaN)."""
    plt = _pyplot()
    t = np.asarray(t, dtype=float)
    m = np.atleast_2d(np.asarray(measured, dtype=float))
    p = np.atleast_2d(np.asarray(predicted, dtype=float))
    if m.shape != p.shape or m.shape[0] != t.shape[0]:
        raise ValueError(f"t {t.shape}, measured {m.shape} and predicted {p.shape} disagree: expected (k,), (k, n), (k, n)")
    se = None if stderr is None else np.atleast_2d(np.asarray(stderr, dtype=float))
    if se is not None and se.shape != p.shape:
        raise ValueError(f"stderr {se.shape} and predicted {p.shape} disagree: expected (k, n) for both")
    if se is not None and (se < 0).any():
        raise ValueError("stderr holds negative values: expected standard errors (>= 0, or NaN where unknown)")
    n = m.shape[1]
    names = list(joints) if joints is not None else [f"joint {j + 1}" for j in range(n)]
    fig, axes = plt.subplots(n, 1, figsize=(9, 2.0 * n), sharex=True, squeeze=False)
    for j, ax in enumerate(axes[:, 0]):
        ax.plot(t, m[:, j], "-", color="0.35", lw=1.5, label="measured")
        ax.plot(t, p[:, j], "--", color="tab:red", lw=1.2, label="predicted")
        if se is not None:
            ax.fill_between(t, p[:, j] - 2 * se[:, j], p[:, j] + 2 * se[:, j], color="tab:red", alpha=0.15, lw=0, label="predicted +- 2 s.e.")
        ax.plot(t, m[:, j] - p[:, j], ":", color="tab:blue", lw=1.0, label="residual")
        ax.set_ylabel(f"{names[j]}\n(N m)")
    axes[0, 0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    axes[-1, 0].set_xlabel("t (s)")
    fig.tight_layout()
    return fig


def residuals(validation: Any, t: Optional[ArrayLike] = None) -> Any:
    """The residuals of a ``perturbid_rs.Validation`` per joint (one panel each), with their RMS
    as a band; ``t`` (k,) in s, sample index when omitted."""
    plt = _pyplot()
    r = np.asarray(validation.residuals, dtype=float)
    x = np.arange(r.shape[0]) if t is None else np.asarray(t, dtype=float)
    fig, axes = plt.subplots(r.shape[1], 1, figsize=(9, 1.8 * r.shape[1]), sharex=True, squeeze=False)
    for j, ax in enumerate(axes[:, 0]):
        rms = float(validation.rms[j])
        ax.axhspan(-rms, rms, color="tab:blue", alpha=0.12, label="+- RMS")
        ax.plot(x, r[:, j], "-", color="tab:blue", lw=0.8, label="measured - predicted")
        ax.set_ylabel(f"{validation.joints[j]}\n(N m)")
    axes[0, 0].legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    axes[-1, 0].set_xlabel("t (s)" if t is not None else "sample")
    fig.tight_layout()
    return fig


def noise_fit(fitted: Any, joints: Optional[Sequence[str]] = None) -> Any:
    """A fit's (or a validation's) residuals against the torques' noise measured apart, per
    joint: the residual RMS (blue) beside the noise level (grey) in N m, the model's own error
    ``sqrt(max(r^2 - noise^2, 0))`` marked (red), and the cost over its degrees of freedom with
    its chance from noise alone in the title. ``fitted``: anything with a ``noise_fit`` dict (a
    BaseParameterModel, PayloadFit or Validation); ``joints`` names the bars (the fit's
    ``joint_names`` or ``joints`` when omitted)."""
    plt = _pyplot()
    f = getattr(fitted, "noise_fit", None)
    if f is None:
        raise ValueError("no noise_fit: the fit was given no noise (noise=, or a Recording averaged over its periods)")
    noise = np.asarray(f["noise"], dtype=float)
    rms = np.asarray(f["ratio"], dtype=float) * noise
    error = np.asarray(f["model_error"], dtype=float)
    names = list(joints) if joints is not None else list(
        getattr(fitted, "joint_names", None) or getattr(fitted, "joints", None) or [f"joint {j + 1}" for j in range(len(noise))]
    )
    if len(names) != len(noise):
        raise ValueError(f"{len(names)} joint names for {len(noise)} joints")
    x = np.arange(len(noise))
    fig, ax = plt.subplots(figsize=(max(6, 1.2 * len(noise)), 3.5))
    ax.bar(x - 0.2, noise, 0.4, color="0.6", label="noise")
    ax.bar(x + 0.2, rms, 0.4, color="tab:blue", label="residual RMS")
    ax.plot(x + 0.2, error, "_", color="tab:red", ms=18, mew=2, label="model's own error")
    ax.set_xticks(x, names)
    ax.set_ylabel("N m")
    ax.set_title(f"cost over {f['degrees_of_freedom']:.0f} degrees of freedom: {f['cost'] / f['degrees_of_freedom']:.3g} "
                 f"(1 for noise alone), chance {f['p_value']:.3g}")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()
    return fig
