"""Writes what a user downloads, into one folder (default out/release/): the four FMUs (the engine
and the body, FMI 2.0 and 3.0), the SSP archive that connects the two 2.0 FMUs, the emc wheel
whose requirements are pinned to python/requirements.txt, the quick-start notebook, and
SHA256SUMS over all of them (check with `sha256sum -c SHA256SUMS`).

Usage (after `bash packaging/package.sh`, which writes dist/):

    .venv/bin/python packaging/release.py [--out out/release]

The wheel is built from a copy of python/ whose pyproject.toml lists the exact versions of
python/requirements.txt (a user's `pip install emc-….whl` then gets the versions the project
tests with), with the build backend already in this environment (no network).
"""

from __future__ import annotations

import argparse
import hashlib
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
ARTEFACTS = ("EngineMountChassis.fmu", "EngineMountChassis-fmi3.fmu", "EngineMountBody.fmu",
             "EngineMountBody-fmi3.fmu", "EngineInBody.ssp")
NOTEBOOK = ROOT / "examples" / "quickstart.ipynb"
DEPENDENCIES = re.compile(r"^dependencies = \[\n.*?^\]\n", re.S | re.M)


def pins(requirements: pathlib.Path) -> list[str]:
    """The ``name==version`` lines of a requirements file (comments and blanks left out)."""
    out = []
    for line in requirements.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        if not re.fullmatch(r"[A-Za-z0-9_.\-\[\]]+==[\w.]+", line):
            sys.exit(f"release: {requirements.relative_to(ROOT)}: '{line}' is not pinned (name==version)")
        out.append(line)
    return out


def pinned_pyproject(text: str, requirements: list[str]) -> str:
    if not DEPENDENCIES.search(text):
        sys.exit("release: python/pyproject.toml has no 'dependencies = [' list")
    listed = "".join(f'    "{r}",\n' for r in requirements)
    return DEPENDENCIES.sub(lambda _: f"dependencies = [\n{listed}]\n", text, count=1)


def build_wheel(out: pathlib.Path) -> pathlib.Path:
    with tempfile.TemporaryDirectory() as tmp:
        source = pathlib.Path(tmp) / "python"
        shutil.copytree(ROOT / "python", source,
                        ignore=shutil.ignore_patterns("tests", "__pycache__", "*.egg-info", "build"))
        shutil.copy(ROOT / "LICENSE", source / "LICENSE")
        pyproject = source / "pyproject.toml"
        pyproject.write_text(pinned_pyproject(pyproject.read_text(),
                                              pins(ROOT / "python" / "requirements.txt")))
        run = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps",
                              "--no-build-isolation", "--wheel-dir", str(out), str(source)],
                             capture_output=True, text=True)
        if run.returncode != 0:
            sys.exit(f"release: building the emc wheel failed:\n{run.stdout}\n{run.stderr}")
    wheels = sorted(out.glob("emc-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"release: expected one emc wheel in {out}, found {[w.name for w in wheels]}")
    return wheels[0]


def sha256(path: pathlib.Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def release(out: pathlib.Path) -> list[pathlib.Path]:
    missing = [name for name in ARTEFACTS if not (DIST / name).is_file()]
    if missing:
        sys.exit(f"release: {', '.join(missing)} missing in dist/: run bash packaging/package.sh first")
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    files = [pathlib.Path(shutil.copy2(DIST / name, out / name)) for name in ARTEFACTS]
    files.append(pathlib.Path(shutil.copy2(NOTEBOOK, out / NOTEBOOK.name)))
    files.append(pathlib.Path(shutil.copy2(ROOT / "python" / "requirements.txt",
                                           out / "requirements.txt")))
    files.append(build_wheel(out))
    (out / "SHA256SUMS").write_text("".join(f"{sha256(f)}  {f.name}\n" for f in files))
    return files


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(ROOT / "out" / "release"),
                        help="the folder to write (replaced; default out/release)")
    args = parser.parse_args(argv)
    out = pathlib.Path(args.out).resolve()
    for f in release(out):
        print(f"{f.stat().st_size / 1e6:8.1f} MB  {f.name}")
    print(f"SHA256SUMS in {out}")


if __name__ == "__main__":
    main()
