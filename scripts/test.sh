#!/usr/bin/env bash
# Runs every test of the project: formatting and lints, Rust unit and integration tests (release
# build: the tests simulate stiff systems), then the Python tests on the packaged FMU.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh

cargo fmt --all -- --check
cargo clippy --release --all-targets -- -D warnings
# The ABI tests dlopen the cdylib, which `cargo test` does not build.
cargo build --release
cargo test --release

if [ -d python/tests ] && ls python/tests/test_*.py >/dev/null 2>&1; then
  bash packaging/package.sh
  .venv/bin/python -m pytest -q python/tests
fi
