#!/usr/bin/env bash
# What accuracy costs in time: work-precision table (stdout, out/accuracy/accuracy.csv) and a
# log-log plot (out/accuracy/accuracy.png) for a scene (default 2, the engine in the elastic chassis; 1 = rigid ground),
# then `emc accuracy` through the packaged FMU (out/accuracy/fmu/). Usage: bench-accuracy.sh [SCENE]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh
if ! dpkg -s libsundials-dev >/dev/null 2>&1; then
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq libsundials-dev >/dev/null
fi
# The tight reference cross-checked once against SUNDIALS CVODE on the same right-hand side.
cargo run --release --example reference_vs_cvode --features bench-cvode
mkdir -p out/accuracy
cargo run --release --example accuracy_cost -- --scene "${1:-2}" --csv out/accuracy/accuracy.csv
.venv/bin/emc accuracy-plot out/accuracy/accuracy.csv out/accuracy/accuracy.png
echo "plot: out/accuracy/accuracy.png"
# The same tolerance rows through the packaged FMU, as a user measures them for their own car.
bash packaging/package.sh
.venv/bin/emc accuracy --set scene="${1:-2}" --repeat 3 --out out/accuracy/fmu
