#!/usr/bin/env bash
# Installs what the project needs on a fresh Debian machine. Idempotent: a second run does nothing
# that is already done. Used by scripts/demo.sh and scripts/test.sh.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

# System packages: clang/libclang for fmi-sys' bindgen; zip for packaging the FMU; mingw-w64 to
# cross-build the FMU's win64 binary and wine to test it.
apt_packages=(clang libclang-dev zip gcc-mingw-w64-x86-64 wine wine64)
missing=()
for p in "${apt_packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# The Rust target of the win64 binary.
if ! rustup target list --installed | grep -qx x86_64-pc-windows-gnu; then
  echo "setup: adding the Rust target x86_64-pc-windows-gnu"
  rustup target add x86_64-pc-windows-gnu
fi

# mdBook builds the user guide in docs/ (scripts/test.sh). Debian 12 does not package it, so it
# comes from crates.io at a pinned version: a one-time compile of about 2–3 minutes on one core,
# skipped while the installed version matches. Its `serve`/`watch` features (a local web server
# and a file watcher) are left out: the build needs neither, and they bring tokio and axum to compile.
mdbook_version=0.4.52
if [ "$(mdbook --version 2>/dev/null)" != "mdbook v$mdbook_version" ]; then
  echo "setup: installing mdbook $mdbook_version from crates.io (one-time compile)"
  cargo install mdbook --locked --version "$mdbook_version" --no-default-features --features search
fi

# Python environment from the pinned requirements; reinstalled only when they change.
venv="$root/.venv"
req="$root/python/requirements.txt"
stamp="$venv/.requirements.sha256"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
want=$(cat "$req" "$root/python/pyproject.toml" | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing Python requirements and the emc tool"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$req"
  "$venv/bin/pip" install -q --disable-pip-version-check --no-deps -e "$root/python"
  echo "$want" >"$stamp"
fi

# pyNastran, the independent reader of DMIG body files in the Python tests, pins numpy < 2, which
# fmpy above cannot share: it gets a venv of its own inside the main one.
nastran_venv="$venv/pynastran"
nastran_req="$root/python/requirements-pynastran.txt"
nastran_stamp="$nastran_venv/.requirements.sha256"
if [ ! -x "$nastran_venv/bin/python" ]; then
  python3 -m venv "$nastran_venv"
fi
want=$(sha256sum <"$nastran_req" | cut -d' ' -f1)
if [ ! -f "$nastran_stamp" ] || [ "$(cat "$nastran_stamp")" != "$want" ]; then
  echo "setup: installing pyNastran (a venv of its own: it needs numpy < 2)"
  "$nastran_venv/bin/pip" install -q --disable-pip-version-check -r "$nastran_req"
  echo "$want" >"$nastran_stamp"
fi
