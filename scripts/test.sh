#!/usr/bin/env bash
# Runs every test of the project: formatting and lints, Rust unit, integration and doc tests
# (release build: the tests simulate stiff systems; the doc tests include the user guide's Rust
# examples), the API documentation and the user guide, then the Python tests on the packaged FMU
# (among them the guide's Python examples and its link check, python/tests/test_docs.py).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
# Each phase says how long it took (CI time is a budget: where it goes is in every log).
phase_start=$SECONDS
phase() {
  echo "== test.sh: $1 took $((SECONDS - phase_start)) s (total $SECONDS s)"
  phase_start=$SECONDS
}
bash scripts/setup.sh --tests
phase "setup"

cargo fmt --all -- --check
cargo clippy --release --all-targets -- -D warnings
phase "fmt and clippy"
# The ABI tests dlopen the cdylib, which `cargo test` does not build.
cargo build --release
has_python_tests=false
if [ -d python/tests ] && ls python/tests/test_*.py >/dev/null 2>&1; then
  has_python_tests=true
  # Packaged before `cargo test`, from the build just made: the crate's rlib has one file name
  # whatever the features of its dependencies, and a build with the dev-dependencies' features
  # (tests, examples) and one without (the package) each rebuild the crate over the other
  # (80-90 s each time: the test of the DMIG writer runs an example after packaging).
  bash packaging/package.sh
fi
phase "cargo build and packaging"
cargo test --release
phase "cargo test"
# The API documentation must build without broken intra-doc links.
RUSTDOCFLAGS="-D rustdoc::broken_intra_doc_links" cargo doc --release --no-deps
# The user guide (docs/book/); test_docs.py builds it again into a temporary folder to check it.
mdbook build docs
phase "cargo doc and the guide"

if $has_python_tests; then
  # The slowest tests are listed: the place to look when the suite grows.
  .venv/bin/python -m pytest -q --durations=15 python/tests
  phase "pytest"
fi
