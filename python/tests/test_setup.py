"""scripts/setup.sh on machines that lack a prerequisite: it stops and says what is missing and
how to get it. Each case runs the script with a PATH of its own: the few system tools it needs,
linked, and stand-ins for the prerequisite in question (nothing is installed)."""

import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SETUP = ROOT / "scripts" / "setup.sh"
TOOLS = ["bash", "dirname", "sed", "id", "uname", "sort", "head", "cut", "cat", "grep", "sha256sum"]


def run_setup(tmp_path: pathlib.Path, stubs: dict[str, str], tools=TOOLS) -> subprocess.CompletedProcess:
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in tools:
        found = shutil.which(tool)
        assert found, tool
        (bin_dir / tool).symlink_to(found)
    # Root or not, the script may call sudo: a stand-in that runs the command.
    stubs = {"sudo": 'exec "$@"', **stubs}
    for name, body in stubs.items():
        stub = bin_dir / name
        stub.write_text(f"#!{shutil.which('bash')}\n{body}\n")
        stub.chmod(0o755)
    env = {"PATH": str(bin_dir), "HOME": str(tmp_path / "home"), "LANG": "C.UTF-8"}
    (tmp_path / "home").mkdir()
    return subprocess.run([shutil.which("bash"), str(SETUP)], env=env, capture_output=True,
                          text=True, timeout=60)


INSTALLED = {"dpkg": "exit 0", "apt-get": "exit 0"}  # every package installed, apt does nothing
PYTHON = f'exec {sys.executable} "$@"'  # a Python >= 3.11 with venv


def test_a_system_without_apt_is_told_what_to_install(tmp_path):
    run = run_setup(tmp_path, {}, tools=["bash", "dirname", "sed", "id"])
    assert run.returncode == 1
    assert "supports Debian-based systems (apt-get, dpkg)" in run.stderr
    for need in ["libclang", "mingw-w64", "rustup", "x86_64-pc-windows-gnu", "Python >= 3.11",
                 "Rust >= 1."]:
        assert need in run.stderr, need


def test_an_old_python_is_named_with_its_version(tmp_path):
    old = 'if [ "$1" = --version ]; then echo "Python 3.10.12"; exit 0; fi; exit 1'
    run = run_setup(tmp_path, {**INSTALLED, "python3": old})
    assert run.returncode == 1
    assert "Python >= 3.11 is needed; python3 is Python 3.10.12" in run.stderr


def test_python_without_venv_gets_python3_venv_or_says_so(tmp_path):
    # A Python 3.11 whose ensurepip is missing (Debian without python3.11-venv), apt unable to help.
    no_venv = (f'case "$*" in *ensurepip*) exit 1;; esac; exec {sys.executable} "$@"')
    failing_apt = 'echo "E: Unable to locate package $*" >&2; exit 100'
    run = run_setup(tmp_path, {"dpkg": "exit 0", "apt-get": failing_apt, "python3": no_venv})
    assert run.returncode == 1
    assert "installing python3." in run.stdout and "-venv (apt)" in run.stdout
    assert "python3 -m venv does not work: install python3." in run.stderr


def test_cargo_without_rustup_is_refused_with_the_way_out(tmp_path):
    run = run_setup(tmp_path, {**INSTALLED, "python3": PYTHON, "cargo": "exit 0"})
    assert run.returncode == 1
    assert "cargo is installed without rustup" in run.stderr
    assert "x86_64-pc-windows-gnu" in run.stderr and "sh.rustup.rs" in run.stderr


def test_an_old_rust_is_named_with_the_version_the_crate_needs(tmp_path):
    stubs = {**INSTALLED, "python3": PYTHON, "rustup": "exit 0",
             "rustc": 'echo "rustc 1.70.0 (90c541806 2023-05-31)"'}
    run = run_setup(tmp_path, stubs)
    assert run.returncode == 1
    want = next(line.split('"')[1] for line in (ROOT / "Cargo.toml").read_text().splitlines()
                if line.startswith("rust-version"))
    assert f"Rust 1.70.0 is older than the {want} the crate needs: rustup update stable" in run.stderr


def test_another_machine_is_named(tmp_path):
    tools = [t for t in TOOLS if t != "uname"]
    run = run_setup(tmp_path, {**INSTALLED, "uname": "echo aarch64"}, tools=tools)
    assert run.returncode == 1
    assert "built for x86-64 (linux64, win64); this machine is aarch64" in run.stderr


def test_packages_apt_cannot_install_are_named(tmp_path):
    missing = 'case "$2" in clang|wine*) exit 1;; esac; exit 0'  # dpkg -s NAME: clang is missing
    failing_apt = 'echo "E: Unable to locate package" >&2; exit 100'
    run = run_setup(tmp_path, {"dpkg": missing, "apt-get": failing_apt, "python3": PYTHON})
    assert run.returncode == 1
    assert "apt could not install clang: install them, then run this again" in run.stderr
