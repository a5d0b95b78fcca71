#!/usr/bin/env bash
# Checks and installs what the project needs on a Debian-based machine (Debian 12 or newer,
# Ubuntu 24.04 or newer; x86-64). Idempotent: a second run does nothing that is already done.
#
#   bash scripts/setup.sh           what the demo uses: C toolchain and libclang, Rust with the
#                                   win64 target, mingw-w64, the Python venv with the emc tool
#   bash scripts/setup.sh --tests   also what only the tests use: wine, mdBook, pytest, pyNastran
#
# scripts/demo.sh runs the first, scripts/test.sh the second. What cannot be installed here is
# named with the command that installs it, and the script stops.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

tests=false
case "${1:-}" in
  "") ;;
  --tests) tests=true ;;
  *) echo "usage: bash scripts/setup.sh [--tests]" >&2; exit 2 ;;
esac

missing_prerequisite() {
  echo "setup: $1" >&2
  exit 1
}

sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || missing_prerequisite "not root and no sudo: install the packages below as root, then run this again"
  sudo_cmd="sudo"
fi

# --- The system: apt and dpkg (Debian, Ubuntu and their derivatives). ---------------------------
if ! command -v apt-get >/dev/null 2>&1 || ! command -v dpkg >/dev/null 2>&1; then
  missing_prerequisite "this script supports Debian-based systems (apt-get, dpkg). Elsewhere install by hand:
  a C compiler and libclang (bindgen), the mingw-w64 cross compiler for x86_64-w64-mingw32,
  Rust >= $(sed -n 's/^rust-version *= *"\(.*\)"/\1/p' "$root/Cargo.toml") with rustup and the target x86_64-pc-windows-gnu, Python >= 3.11 with venv;
  for the tests also wine (64-bit) and mdBook"
fi
if [ "$(uname -m)" != "x86_64" ]; then
  missing_prerequisite "the FMU's binaries are built for x86-64 (linux64, win64); this machine is $(uname -m)"
fi

# --- System packages. -----------------------------------------------------------------------------
# gcc/libc6-dev: the linker rustc calls; clang/libclang-dev: fmi-sys' bindgen; binutils: strip for
# the shipped library; mingw-w64: the FMU's win64 binary; python3-venv: `python3 -m venv` (Debian
# ships Python without ensurepip otherwise); curl: rustup, if Rust is missing.
apt_packages=(gcc libc6-dev binutils clang libclang-dev gcc-mingw-w64-x86-64 python3 python3-venv curl ca-certificates)
# wine runs the FMU's win64 binary in the host tests.
$tests && apt_packages+=(wine wine64)
missing=()
for p in "${apt_packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]} (apt)"
  { $sudo_cmd apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${missing[@]}" >/dev/null; } ||
    missing_prerequisite "apt could not install ${missing[*]}: install them, then run this again"
fi

# --- Python >= 3.11 with venv. -------------------------------------------------------------------
# The pinned requirements (numpy 2.4, pandas 3) need 3.11 or newer.
python=python3
if ! "$python" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
  missing_prerequisite "Python >= 3.11 is needed; python3 is $("$python" --version 2>&1).
  Debian 12 and Ubuntu 24.04 ship 3.11 and 3.12; elsewhere install a newer python3 with its venv module"
fi
version=$("$python" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
if ! "$python" -c 'import ensurepip, venv' 2>/dev/null; then
  echo "setup: installing python$version-venv (apt): python3 -m venv needs it"
  { $sudo_cmd apt-get update -qq &&
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "python$version-venv" >/dev/null; } ||
    missing_prerequisite "python3 -m venv does not work: install python$version-venv"
fi

# --- Rust, through rustup (the win64 target needs it). --------------------------------------------
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"
if ! command -v rustup >/dev/null 2>&1; then
  if command -v cargo >/dev/null 2>&1; then
    missing_prerequisite "cargo is installed without rustup (a distribution package?): the win64 FMU binary
  needs rustup's target x86_64-pc-windows-gnu. Remove that Rust and run this again, or install rustup:
  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh"
  fi
  echo "setup: installing Rust with rustup (stable, minimal profile) into ~/.cargo"
  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal --component rustfmt,clippy
  . "$HOME/.cargo/env"
fi
want_rust=$(sed -n 's/^rust-version *= *"\(.*\)"/\1/p' "$root/Cargo.toml")
have_rust=$(rustc --version | cut -d' ' -f2)
if [ "$(printf '%s\n%s\n' "$want_rust" "$have_rust" | sort -V | head -1)" != "$want_rust" ]; then
  missing_prerequisite "Rust $have_rust is older than the $want_rust the crate needs: rustup update stable"
fi
if ! rustup target list --installed | grep -qx x86_64-pc-windows-gnu; then
  echo "setup: adding the Rust target x86_64-pc-windows-gnu"
  rustup target add x86_64-pc-windows-gnu
fi

# --- Python environment from the pinned requirements; reinstalled only when they change. ----------
venv="$root/.venv"
if [ ! -x "$venv/bin/python" ]; then
  "$python" -m venv "$venv"
fi
# requirements.txt (fmpy, Dask, matplotlib, libcosimpy) and the emc tool itself.
stamp="$venv/.requirements.sha256"
want=$(cat "$root/python/requirements.txt" "$root/python/pyproject.toml" | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing Python requirements and the emc tool"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$root/python/requirements.txt"
  "$venv/bin/pip" install -q --disable-pip-version-check --no-deps -e "$root/python"
  echo "$want" >"$stamp"
fi

$tests || exit 0

# --- What only the tests use. ----------------------------------------------------------------------
stamp="$venv/.requirements-test.sha256"
want=$(sha256sum <"$root/python/requirements-test.txt" | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "setup: installing the Python test requirements (pytest)"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$root/python/requirements-test.txt"
  echo "$want" >"$stamp"
fi

# mdBook builds the user guide in docs/. Debian 12 does not package it, so it comes from crates.io
# at a pinned version: a one-time compile of about 2–3 minutes on one core, skipped while the
# installed version matches. Its `serve`/`watch` features (a local web server and a file watcher)
# are left out: the build needs neither, and they bring tokio and axum to compile.
mdbook_version=0.4.52
if [ "$(mdbook --version 2>/dev/null)" != "mdbook v$mdbook_version" ]; then
  echo "setup: installing mdbook $mdbook_version from crates.io (one-time compile)"
  cargo install mdbook --locked --version "$mdbook_version" --no-default-features --features search
fi

# pyNastran, the independent reader of DMIG body files in the Python tests, pins numpy < 2, which
# fmpy above cannot share: it gets a venv of its own inside the main one.
nastran_venv="$venv/pynastran"
nastran_req="$root/python/requirements-pynastran.txt"
nastran_stamp="$nastran_venv/.requirements.sha256"
if [ ! -x "$nastran_venv/bin/python" ]; then
  "$python" -m venv "$nastran_venv"
fi
want=$(sha256sum <"$nastran_req" | cut -d' ' -f1)
if [ ! -f "$nastran_stamp" ] || [ "$(cat "$nastran_stamp")" != "$want" ]; then
  echo "setup: installing pyNastran (a venv of its own: it needs numpy < 2)"
  "$nastran_venv/bin/pip" install -q --disable-pip-version-check -r "$nastran_req"
  echo "$want" >"$nastran_stamp"
fi
