"""The command line installed by pip: the same Rust program as the cargo binary."""

import os
import subprocess
import sys
import sysconfig
from pathlib import Path


def perturbid() -> str:
    exe = Path(sysconfig.get_path("scripts")) / ("perturbid.exe" if os.name == "nt" else "perturbid")
    assert exe.is_file(), f"the console script was not installed: {exe}"
    return str(exe)


def test_console_script_info_and_errors():
    out = subprocess.run([perturbid(), "info", "a465"], capture_output=True, text=True)
    assert out.returncode == 0 and "joint6" in out.stdout
    bad = subprocess.run([perturbid(), "info", "a466"], capture_output=True, text=True)
    assert bad.returncode == 1 and bad.stderr.startswith("perturbid: unknown robot") and "Traceback" not in bad.stderr


def test_python_m_paper(tmp_path):
    out = subprocess.run([sys.executable, "-m", "perturbid_rs", "paper", "--out", str(tmp_path), "--excitation-seeds", "2", "--no-study"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "Table 3" in out.stdout
    assert (tmp_path / "report.md").is_file() and (tmp_path / "fig4_joint3.svg").is_file()


def test_a_file_name_that_is_not_utf8_gets_an_error_not_a_crash(tmp_path):
    name = os.fsdecode(b"model-\xff.json")  # surrogate-escaped, as Python hands it over
    out = subprocess.run([perturbid(), "predict", name, "data.csv"], cwd=tmp_path, capture_output=True, text=True, errors="replace")
    assert out.returncode == 1, out.stderr
    assert out.stderr.startswith("perturbid: model-") and out.stderr.count("\n") == 1, out.stderr
    assert "Traceback" not in out.stderr
