"""Every example in examples/ runs as a user would run it, at its quick size, and says what it
shows."""

from __future__ import annotations

import importlib.util
import pathlib
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).parents[2] / "examples"
PANDA_LOG = EXAMPLES.parent.parent / "shared/data/panda-gaz2019/excitation.csv"


def run(script: str, *args: str, cwd: pathlib.Path) -> str:
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args], cwd=cwd, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_paper_example(tmp_path):
    out = run("paper_a465.py", cwd=tmp_path)
    assert "identified D*: [ 9.95" in out and "largest error in D*" in out


def test_panda_local_example(tmp_path):
    out = run("panda_local.py", "--quick", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert "the local model:" in out
    assert (tmp_path / "out/local_model.json").is_file()


def test_panda_direct_example(tmp_path):
    if not PANDA_LOG.is_file():
        pytest.skip(f"the real Panda log {PANDA_LOG} is not there (it lies beside the repository; see docs/data.md)")
    out = run("panda_direct.py", "--quick", "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert "held-out relative RMS error (%), consistent" in out
    assert (tmp_path / "out/base_model.json").is_file()
    if importlib.util.find_spec("matplotlib") is not None:
        assert (tmp_path / "out/validation.png").stat().st_size > 10_000


def test_drive_gains_example(tmp_path):
    out = run("a465_drive_gains.py", "--quick", cwd=tmp_path)
    assert "drive gains (N m per A):" in out and "feed-forward currents" in out
    worst = float(out.split("largest gain error ")[1].split(" %")[0])
    assert worst < 1.0, out
    worst = float(out.split("largest gain error by instrumental variables ")[1].split(" %")[0])
    assert worst < 1.0, out


def test_every_input_the_readme_names_is_in_examples():
    readme = (EXAMPLES.parent / "README.md").read_text()
    for name in ["op.json", "panda_drilling_op.json", "panda_true_robot.json", "panda_workspace.json", "a465_true_robot.json"]:
        assert (EXAMPLES / name).is_file()
        assert f"examples/{name}" in readme, name
