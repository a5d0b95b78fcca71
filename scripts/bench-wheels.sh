#!/usr/bin/env bash
# Downloads the wheels the scaling benchmark needs on a machine without network that has CPython
# 3.12 with numpy, pandas and lxml (and, as a fallback, those three too) into DIR (default
# target/wheels-bench). Copy DIR, dist/EngineMountChassis.fmu and python/ there and run
# scripts/bench-scaling.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$root/target/wheels-bench}
pip=("$root/.venv/bin/pip" download -q --no-deps --only-binary=:all: --python-version 3.12
     --implementation cp --abi cp312 --platform manylinux2014_x86_64
     --platform manylinux_2_17_x86_64 --platform manylinux_2_28_x86_64)
version() { "$root/.venv/bin/pip" show "$1" | awk '/^Version/{print $2}'; }
# fmpy, dask and distributed as pinned in python/requirements.txt; what they import at the
# versions the project's environment has.
pinned() { grep -i "^$1==" "$root/python/requirements.txt"; }
"${pip[@]}" -d "$dir" "$(pinned fmpy)" "$(pinned dask)" "$(pinned distributed)"
for p in attrs click cloudpickle fsspec locket Jinja2 MarkupSafe msgpack packaging partd psutil \
         PyYAML sortedcontainers tblib toolz tornado zict; do
  "${pip[@]}" -d "$dir" "$p==$(version "$p")"
done
for p in numpy pandas lxml python-dateutil tzdata; do
  "${pip[@]}" -d "$dir/fallback" "$p==$(version "$p")"
done
du -sh "$dir"
