#!/usr/bin/env bash
# Work-precision benchmark of the BDF integrator against SUNDIALS CVODE (Debian libsundials-dev).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! dpkg -s libsundials-dev >/dev/null 2>&1; then
    apt-get update && apt-get install -y libsundials-dev
fi
if ! dpkg -s libclang-dev >/dev/null 2>&1; then
    apt-get update && apt-get install -y clang libclang-dev
fi
cargo run --release --example bdf_work_precision --features bench-cvode,bench-diffsol
