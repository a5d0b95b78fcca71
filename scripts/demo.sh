#!/usr/bin/env bash
# Builds everything, packages the FMU and runs the demo speed sweep (800–2500 rpm, 18 points,
# 40 stationary revolutions each, in parallel with Dask), writing tables and a waterfall plot to
# out/demo/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh
bash packaging/package.sh
.venv/bin/emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 \
  --revolutions 40 --settle 20 --out out/demo --plot "mount[1].F[3]" --plot "mount[3].F[1]"
echo "demo: waterfall plots in out/demo/waterfall_*.png, order cuts in out/demo/order_cuts_*.png"
