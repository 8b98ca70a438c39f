"""The ``perturbid`` console script: the Rust command line, run through the extension module.
``perturbid study STUDY.toml --scheduler ADDRESS`` runs the study on a Dask cluster from here
(the Rust command line has no Python); every other command is the Rust one."""

from __future__ import annotations

import argparse
import sys

from ._core import cli


def main() -> None:
    sys.stdout.flush()
    argv = sys.argv[1:]
    if argv[:1] == ["study"] and any(a == "--scheduler" or a.startswith("--scheduler=") for a in argv):
        sys.exit(study_on_dask(argv[1:]))
    sys.exit(cli(["perturbid", *argv]))


def study_on_dask(args: list[str]) -> int:
    """``perturbid study STUDY.toml --scheduler ADDRESS [--out DIR]``: the cases on the Dask
    cluster at ADDRESS, the journal and the report here. Returns the exit status."""
    parser = argparse.ArgumentParser(prog="perturbid study", description=study_on_dask.__doc__)
    parser.add_argument("study")
    parser.add_argument("--out", default="study")
    parser.add_argument("--scheduler", required=True)
    a = parser.parse_args(args)
    try:
        from dask.distributed import Client
    except ImportError:
        print("perturbid: --scheduler needs dask.distributed: pip install 'perturbid_rs[dask]'", file=sys.stderr)
        return 1
    from . import PerturbidError
    from ._study import study

    try:
        with Client(a.scheduler, timeout="10s") as client:
            result = study(a.study, a.out, client=client)
    except PerturbidError as e:
        print(f"perturbid: {e}", file=sys.stderr)
        return 1
    except (OSError, TimeoutError) as e:
        print(f"perturbid: cannot reach the Dask scheduler at {a.scheduler}: {e}", file=sys.stderr)
        return 1
    print(result.summary)
    print(f"wrote results.csv, summary.csv, summary.md, error_vs_distance.svg to {a.out}")
    return 0
