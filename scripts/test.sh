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

step "tests in single precision (f32 build)"
cargo test --workspace --exclude tumble-bench --locked --features tumble/f32

step "tests (default f64 build)"
cargo test --workspace --exclude tumble-bench --locked

step "web viewer in headless Chromium (scripts/browser-test.sh; screenshots in target/browser-test/)"
bash scripts/browser-test.sh
