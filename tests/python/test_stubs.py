"""The type stubs (`_core.pyi`) match the compiled module: every name, every signature and every
default, checked by mypy's stubtest against the installed package."""

import subprocess
import sys


def test_stubs_match_the_module():
    # --ignore-disjoint-bases: PEP 800's @disjoint_base marker is newer than the Python versions
    # the package supports (3.9+); every other check of stubtest runs.
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "--ignore-disjoint-bases", "perturbid_rs"],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr
