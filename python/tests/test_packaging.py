"""python/ is packaged as the ecosystem expects: runtime dependencies declared with lower bounds in
pyproject.toml (every third-party module emc imports among them), test dependencies apart, the
pinned lock in requirements.txt consistent with them, no build artefacts in the repository."""

import ast
import pathlib
import re
import shutil
import subprocess
import sys
import tomllib

import pytest

PYTHON = pathlib.Path(__file__).resolve().parents[1]
ROOT = PYTHON.parent
# Import name -> distribution name where they differ.
DISTRIBUTION = {"yaml": "pyyaml", "mpl_toolkits": "matplotlib"}


def requirement_name(spec: str) -> str:
    return re.split(r"[<>=!~;\[ ]", spec, maxsplit=1)[0].strip().lower()


def lower_bound(spec: str) -> tuple[int, ...]:
    match = re.search(r">=\s*([0-9][0-9.]*)", spec)
    assert match, f"{spec}: no lower bound"
    return tuple(int(x) for x in match.group(1).split(".") if x)


@pytest.fixture(scope="module")
def project():
    return tomllib.loads((PYTHON / "pyproject.toml").read_text())["project"]


def third_party_imports() -> set[str]:
    names = set()
    for path in (PYTHON / "emc").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return {n for n in names if n not in sys.stdlib_module_names and n != "emc"}


def test_runtime_dependencies_are_declared_with_lower_bounds(project):
    declared = {requirement_name(spec): spec for spec in project["dependencies"]}
    for spec in declared.values():
        lower_bound(spec)
    imported = {DISTRIBUTION.get(n, n).lower() for n in third_party_imports()}
    assert imported, "emc imports numpy, pandas, fmpy, …"
    missing = imported - set(declared)
    assert not missing, f"imported by emc but not declared in pyproject.toml: {missing}"


def test_test_dependencies_are_apart(project):
    runtime = {requirement_name(s) for s in project["dependencies"]}
    test = {requirement_name(s) for s in project["optional-dependencies"]["test"]}
    assert "pytest" in test and "pytest" not in runtime


def test_the_lock_pins_every_runtime_dependency_within_its_bounds(project):
    pins = {}
    for line in (PYTHON / "requirements.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, _, version = line.partition("==")
            assert version, f"requirements.txt: {line} is not pinned"
            pins[name.strip().lower()] = tuple(int(x) for x in version.split(".") if x.isdigit())
    for spec in project["dependencies"]:
        name = requirement_name(spec)
        assert name in pins, f"{name} is not pinned in requirements.txt"
        assert pins[name] >= lower_bound(spec), f"{name}: the pin is below {spec}"


def test_no_build_artefacts_in_the_repository():
    assert "*.egg-info/" in (ROOT / ".gitignore").read_text().splitlines()
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    tracked = subprocess.run(["git", "ls-files", "python"], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout.splitlines()
    assert tracked, "git lists the python folder"
    assert not [f for f in tracked if ".egg-info/" in f or "__pycache__" in f]


def test_one_version_everywhere(project, fmu_path, fmu3_path):
    # Cargo.toml's version is the release: pyproject.toml, the variable table (the FMUs' version
    # attribute), every packaged FMU and a dated changelog section below "Unreleased" say the same.
    import json
    import xml.etree.ElementTree as ET
    import zipfile

    version = tomllib.loads((ROOT / "Cargo.toml").read_text())["package"]["version"]
    assert project["version"] == version
    assert json.loads((ROOT / "modelDescription" / "variables.json").read_text())["version"] == version
    fmus = sorted((ROOT / "dist").glob("*.fmu"))
    assert len(fmus) >= 2
    for fmu in fmus:
        with zipfile.ZipFile(fmu) as z:
            attribute = ET.fromstring(z.read("modelDescription.xml")).get("version")
        assert attribute == version, f"{fmu.name} says version {attribute}: run bash packaging/package.sh"
    changelog = (ROOT / "CHANGELOG.md").read_text()
    section = re.search(rf"^## \[{re.escape(version)}\] - (\d{{4}}-\d{{2}}-\d{{2}})$", changelog, re.M)
    assert section, f"CHANGELOG.md has no dated section for {version}"
    assert changelog.index("## [Unreleased]") < section.start()
