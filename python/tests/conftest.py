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
