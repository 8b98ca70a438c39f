"""benches/compare_pinocchio.py: the speed-up goals as the script applies them to its table."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("pinocchio", reason="the script imports Pinocchio: pip install pin")

SCRIPT = Path(__file__).resolve().parents[2] / "benches" / "compare_pinocchio.py"


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("compare_pinocchio", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_goals_by_kernel_and_path(script):
    for kernel in ("rnea", "mass_matrix", "regressor"):
        assert script.target(kernel, "avx512") == 10.0
        assert script.target(kernel, "avx2+fma") == 8.0
        assert script.target(kernel, "scalar") is None
    for kernel in ("rnea_derivatives", "linearize"):
        assert script.target(kernel, "avx512") == script.target(kernel, "avx2+fma") == 5.0
    assert script.target("forward_dynamics", "avx512") is None
    assert set(script.KERNELS) >= {"rnea", "mass_matrix", "regressor", "rnea_derivatives",
                                    "linearize", "forward_dynamics"}


def test_verdict_counts_met_edge_and_short(script):
    rows = [
        ("a465", "rnea", 11.3, 10.2),              # met in every round
        ("tree60", "mass_matrix", 10.01, 9.05),    # met by the median only
        ("tree60", "regressor", 3.9, 3.5),         # short
        ("a465", "linearize", 5.2, 4.0),           # 5x goal, met by the median
        ("a465", "forward_dynamics", 1.5, 1.4),    # no goal: not counted
    ]
    text = script.verdict(rows, "avx512", 0.94)
    assert text.startswith("Goals on the avx512 path: 4 of 5 met by the median")
    assert "not in every round: tree60 mass_matrix (10.01x of 10x), a465 linearize (5.20x of 5x)" in text
    assert text.endswith("short: tree60 regressor (3.90x of 10x).")
    # on AVX2 the same ratios meet the 8x goal; a slow Python call is short
    text = script.verdict(rows, "avx2+fma", 1.2)
    assert "3 of 5 met" in text and "one Python call 1.20x" in text.split("short:")[1]
    assert "mass_matrix" not in text.split("short:")[1]
    assert "none for the scalar path" in script.verdict(rows, "scalar", 1.0)
