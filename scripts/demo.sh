#!/usr/bin/env bash
# Builds everything, packages the FMU and runs the demo speed sweep of the engine in the elastic
# chassis (scene 2): 800–2500 rpm, 18 points, each started on its periodic steady state and
# analysed over 8 revolutions (4 working cycles: every half order on a bin), on two local workers,
# at the nominal damping and at the two bounds of the damping band (--band). Tables and the
# waterfall, order-cut and comfort plots (with the band) go to out/demo/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh
bash packaging/package.sh
.venv/bin/emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 \
  --set scene=2 --case "scene 2" --band --out out/demo \
  --signal "steeringWheel.a[3]" --signal "steeringWheel.a[2]" --signal "mount[1].F[3]" \
  --signal "steeringWheel.a[1]" --signal "seat.a[1]" --signal "seat.a[2]" --signal "seat.a[3]" \
  --plot "steeringWheel.a[3]" --plot "steeringWheel.a[2]" --plot "mount[1].F[3]"
.venv/bin/emc campbell --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --set scene=2 --out out/demo/campbell >/dev/null
echo "demo: waterfalls in out/demo/waterfall_*.png, order cuts with the damping band in out/demo/order_cuts_*.png, comfort in out/demo/comfort.{csv,png} and comfort_band.csv, Campbell diagram in out/demo/campbell/campbell.png"
