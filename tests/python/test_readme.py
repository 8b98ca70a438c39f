"""The Python examples of README.md and docs/python.md run as written, and the README's main
command prints what it shows."""

import re
import subprocess
import sysconfig
from pathlib import Path

import pytest


@pytest.mark.parametrize("document", ["README.md", "docs/python.md"])
def test_python_examples_run(document, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # the examples write files (plan/)
    text = (Path(__file__).parents[2] / document).read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, f"{document} has no python example"
    for code in blocks:
        exec(compile(code, document, "exec"), {})


def test_readme_main_command_prints_what_it_shows(tmp_path):
    text = (Path(__file__).parents[2] / "README.md").read_text()
    assert "pip install . && perturbid paper --out paper" in text
    shown = re.search(r"prints \(in\nabout 80 s on 2 cores\):\n\n```\n(.*?)```", text, re.S).group(1)
    exe = Path(sysconfig.get_path("scripts")) / "perturbid"
    out = subprocess.run([str(exe), "paper", "--out", "paper"], cwd=tmp_path, capture_output=True, text=True, check=True)
    assert out.stdout == shown
