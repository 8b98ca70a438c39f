#!/usr/bin/env bash
# Every test of the project: the Rust tests (release build), then the Python package built from
# the same target directory and its tests against Pinocchio. Installs the test dependencies
# named in pyproject.toml ([project.optional-dependencies] test) first.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}

cargo test --release
cargo bench --no-run --quiet

deps=$("$PY" -c "import tomllib; print(' '.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['test']))")
"$PY" -m pip install --quiet $deps

rm -rf target/wheels
"$PY" -m maturin build --release --quiet -o target/wheels
"$PY" -m pip install --quiet --force-reinstall --no-deps target/wheels/perturbid_rs-*.whl
"$PY" -m pytest -q tests/python
