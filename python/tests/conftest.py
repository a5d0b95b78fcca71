import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def fmu_path() -> pathlib.Path:
    """The packaged FMU; packaged here if scripts/test.sh did not do it already."""
    path = ROOT / "dist" / "EngineMountChassis.fmu"
    if not path.exists():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return path


@pytest.fixture(scope="session")
def fmu3_path(fmu_path) -> pathlib.Path:
    """The packaged FMI 3.0 FMU, which package.py writes beside the 2.0 one."""
    path = ROOT / "dist" / "EngineMountChassis-fmi3.fmu"
    if not path.exists():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return path


@pytest.fixture(scope="session")
def body_fmu_path(fmu_path) -> pathlib.Path:
    """The packaged body FMU, which package.py writes beside the engine FMU."""
    path = ROOT / "dist" / "EngineMountBody.fmu"
    if not path.exists():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return path
