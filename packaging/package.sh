#!/usr/bin/env bash
# Builds the release library and writes dist/<modelIdentifier>.fmu (see package.py).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exec "$root/.venv/bin/python" "$root/packaging/package.py" "$@"
