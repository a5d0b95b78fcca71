#!/usr/bin/env bash
# What accuracy costs in time: work-precision table (stdout, out/accuracy/accuracy.csv) and a
# log-log plot (out/accuracy/accuracy.png) for a scene (default 1). Usage: bench-accuracy.sh [SCENE]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh
mkdir -p out/accuracy
cargo run --release --example accuracy_cost -- --scene "${1:-1}" --csv out/accuracy/accuracy.csv
.venv/bin/python -m emc.accuracy_plot out/accuracy/accuracy.csv out/accuracy/accuracy.png
echo "plot: out/accuracy/accuracy.png"
