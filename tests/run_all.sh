#!/usr/bin/env bash
# Every test of the project: the Rust tests (release build), then the Python package built from
# the same target directory and its tests against Pinocchio. Installs the test dependencies
# named in pyproject.toml ([project.optional-dependencies] test) first. Real-data tests read
# ../shared/data beside the repository.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
# each step's wall time, printed as it ends (CI's budget is read from these lines)
step() {
    local name=$1 start=$SECONDS
    shift
    "$@"
    echo "run_all: $name took $((SECONDS - start)) s" >&2
}

# test dependencies first: the Rust Panda test finds example-robot-data's URDF through Python
# (read without tomllib, which Python 3.9 and 3.10 lack: the list is one line of pyproject.toml)
deps=$("$PY" -c "import re, ast; print(' '.join(ast.literal_eval(re.search(r'^test = (\[.*\])$', open('pyproject.toml').read(), re.M).group(1))))")
step "test dependencies" "$PY" -m pip install --quiet "maturin>=1.7,<2" $deps

step "cargo test" env PYTHON="$PY" cargo test --release
step "bench build" cargo bench --no-run --quiet
# the Rust examples run (docs/parameters.md and docs/a465.md quote what they print)
step "example refit_a465" cargo run --release --quiet --example refit_a465 -- target/refit_a465.urdf
cargo run --release --quiet --example parameters_evidence > target/parameters_evidence.md
# the example study and pipeline through the command line (docs/study.md, docs/pipeline.md)
rm -rf target/study_small
step "example study" cargo run --release --quiet --bin perturbid -- study examples/study_small.toml --out target/study_small > /dev/null
# lints and docs without warnings, over every feature (python includes cli; count-flops builds
# examples/flop_count.rs)
step clippy cargo clippy --release --all-targets --features python,count-flops --quiet -- -D warnings
step rustdoc env RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --features python --quiet

rm -rf target/wheels
step "wheel" "$PY" -m maturin build --release --quiet -o target/wheels
"$PY" -m pip install --quiet --force-reinstall --no-deps target/wheels/perturbid_rs-*.whl
step pytest "$PY" -m pytest -q tests/python --durations=5
