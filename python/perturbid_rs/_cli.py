"""The ``perturbid`` console script: the Rust command line, run through the extension module."""

import sys

from ._core import cli


def main() -> None:
    sys.stdout.flush()
    sys.exit(cli(["perturbid", *sys.argv[1:]]))
