#!/usr/bin/env bash
# Every check the project has, in the order a failure is cheapest to find.
# Usage: scripts/test.sh            (run from anywhere inside the checkout)
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }

step "formatting (cargo fmt --check)"
cargo fmt --all -- --check

step "lints, f64 and f32 (cargo clippy -D warnings)"
# tumble-bench (rapier comparisons) is left out: it compiles rapier, minutes of CI time,
# and holds no test of Tumble's behaviour.
cargo clippy --workspace --exclude tumble-bench --all-targets --locked -- -D warnings
cargo clippy --workspace --exclude tumble-bench --all-targets --locked --features tumble/f32 -- -D warnings

# tumble-py is left out of the cargo test lines: it has no Rust tests (its tests are
# Python's, below), and a test binary of an extension module would have to link libpython.
step "tests in single precision (f32 build: the engine and the scene loader)"
# Precision lives in those two crates; the CLI and the renderer only pass their numbers
# on, and their f32 build is checked by the f32 clippy above. Building and running them in
# f32 too cost CI about two minutes of its twenty.
cargo test -p tumble -p tumble-scene --locked --features tumble/f32

step "tests (default f64 build)"
cargo test --workspace --exclude tumble-bench --exclude tumble-py --locked

step "Python package: build it (maturin, release) and test it (pytest)"
# Everything goes into a virtualenv of its own under target/, made here if missing, with
# the pinned versions of crates/tumble-py/requirements-test.txt: nothing is installed by hand.
venv=target/venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r crates/tumble-py/requirements-test.txt
# One release build of the extension (the tests time physics runs, and the examples run
# whole); without debug info, which only slows the build here.
CARGO_PROFILE_RELEASE_DEBUG=0 VIRTUAL_ENV="$PWD/$venv" PATH="$PWD/$venv/bin:$PATH" \
    "$venv/bin/maturin" develop --release --locked --quiet
MPLBACKEND=Agg "$venv/bin/python" -m pytest -q crates/tumble-py/tests

step "web viewer in headless Chromium (scripts/browser-test.sh; screenshots in target/browser-test/)"
bash scripts/browser-test.sh
