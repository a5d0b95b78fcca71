#!/usr/bin/env bash
# The scaling benchmark on a machine without network: the wheels of scripts/bench-wheels.sh are
# unpacked into a temporary directory (those in fallback/ only where the interpreter lacks the
# package), then `emc bench-scaling` (or `scheduling`, named after WHEELDIR) runs with
# the remaining arguments.
#
#   bash scripts/bench-scaling.sh WHEELDIR --fmu dist/EngineMountChassis.fmu --points 192 \
#       --workers 1 4 16 --batching guided equal --csv scaling.csv
#   bash scripts/bench-scaling.sh WHEELDIR scheduling --points 192 --workers 16
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
wheels=$1
shift
benchmark=scaling
if [[ ${1:-} == scaling || ${1:-} == scheduling ]]; then
  benchmark=$1
  shift
fi
python=${PYTHON:-$(command -v python3.12 || command -v python3)}
site=$(mktemp -d)
trap 'rm -rf "$site"' EXIT
unpack() { "$python" -m zipfile -e "$1" "$site"; }
for w in "$wheels"/*.whl; do unpack "$w"; done
for p in numpy pandas lxml dateutil; do
  if ! PYTHONPATH=$site "$python" -c "import $p" 2>/dev/null; then
    for w in "$wheels"/fallback/*.whl; do unpack "$w"; done
    break
  fi
done
echo "$("$python" --version), $(nproc) CPUs; packages from $wheels"
cd "$root"
PYTHONPATH=$site:$root/python exec "$python" -m emc "bench-$benchmark" "$@"
