#!/usr/bin/env bash
# Builds and packages the FMUs, then writes the release a user downloads into out/release/ (or
# the folder given with --out): the four FMUs, EngineInBody.ssp, the emc wheel pinned to
# python/requirements.txt, the quick-start notebook and SHA256SUMS (packaging/release.py).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/setup.sh
bash packaging/package.sh
.venv/bin/python packaging/release.py "$@"
