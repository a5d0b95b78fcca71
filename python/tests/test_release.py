"""The release a user downloads (packaging/release.py): the four FMUs, the SSP archive, the
quick-start notebook and the emc wheel, each with its SHA-256 in SHA256SUMS; the wheel holds every
room of emc and requires exactly the versions python/requirements.txt pins."""

import hashlib
import pathlib
import re
import subprocess
import sys
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def released(tmp_path_factory, fmu_path):
    out = tmp_path_factory.mktemp("release")
    run = subprocess.run([sys.executable, str(ROOT / "packaging" / "release.py"), "--out",
                          str(out)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    return out


def test_the_release_holds_what_a_user_downloads_with_checksums(released):
    names = {p.name for p in released.iterdir()}
    assert {"EngineMountChassis.fmu", "EngineMountChassis-fmi3.fmu", "EngineMountBody.fmu",
            "EngineMountBody-fmi3.fmu", "EngineInBody.ssp", "quickstart.ipynb",
            "requirements.txt", "SHA256SUMS"} <= names
    sums = dict(reversed(line.split("  ")) for line in
                (released / "SHA256SUMS").read_text().splitlines())
    assert set(sums) == names - {"SHA256SUMS"}
    for name, digest in sums.items():
        assert hashlib.sha256((released / name).read_bytes()).hexdigest() == digest, name
    for fmu in ("EngineMountChassis.fmu", "EngineInBody.ssp"):
        assert (released / fmu).read_bytes() == (ROOT / "dist" / fmu).read_bytes()


def test_the_wheel_holds_every_room_and_pins_the_requirements(released):
    wheel = next(released.glob("emc-*.whl"))
    pins = [line.strip() for line in (ROOT / "python" / "requirements.txt").read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    with zipfile.ZipFile(wheel) as z:
        names = set(z.namelist())
        metadata = z.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    rooms = {p.parent.relative_to(ROOT / "python").as_posix()
             for p in (ROOT / "python" / "emc").rglob("*.py")}
    for room in rooms:
        assert f"{room}/__init__.py" in names or any(n.startswith(room + "/") for n in names), room
    assert "emc/base/options.py" in names and "emc/cli.py" in names
    required = re.findall(r"^Requires-Dist: ([^;\n]+)$", metadata, re.M)
    assert sorted(r.replace(" ", "") for r in required) == sorted(pins)
    assert (released / "requirements.txt").read_text() == (
        ROOT / "python" / "requirements.txt").read_text()


def test_a_release_without_the_packaged_fmus_names_the_command(tmp_path, monkeypatch):
    sys.path.insert(0, str(ROOT / "packaging"))
    try:
        import release
    finally:
        sys.path.pop(0)
    monkeypatch.setattr(release, "DIST", tmp_path)
    with pytest.raises(SystemExit) as stop:
        release.release(tmp_path / "out")
    assert "run bash packaging/package.sh first" in str(stop.value)
