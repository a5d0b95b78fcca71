"""The house of emc: rooms on floors, imports only downwards, no circle, nothing imported back
into the command line, every command registering itself, every shared option registered once,
and a command line that starts without the numerical libraries."""

import ast
import functools
import pathlib
import re
import subprocess
import sys

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "emc"

# The floor of each room (a module at the package's top is its own room).
FLOORS = {"base": 0, "signals": 1, "figures": 2, "running": 3, "diagnosis": 4, "studies": 4,
          "bench": 4, "testbench": 5, "commands": 6, "cli": 7, "__main__": 8, "__init__": 0}
# Imports inside functions that are meant: a heavy or optional library deferred for start-up
# time, each with a comment saying so where it stands.
DEFERRED = {("base/fmu.py", "fmpy"), ("base/outputs.py", "fmpy"), ("base/outputs.py", "fcntl"),
            ("cli.py", ".running.runner"), ("running/sweep.py", ".distributed"),
            ("running/engine.py", ".distributed"), ("running/sweep_cases.py", "..figures"),
            ("running/band.py", "..figures"), ("studies/paper_cases.py", "..figures"),
            ("running/split.py", "libcosimpy.CosimExecution"),
            ("running/split.py", "libcosimpy.CosimLogging"),
            ("running/split.py", "libcosimpy.CosimObserver"),
            }


@functools.cache
def modules() -> dict[str, ast.Module]:
    return {str(p.relative_to(PACKAGE)): ast.parse(p.read_text()) for p in PACKAGE.rglob("*.py")}


def dotted(path: str) -> str:
    parts = path[:-3].split("/")
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(["emc"] + parts)


def room(name: str) -> str:
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def imported(path: str, node) -> list[str]:
    """The emc modules an import statement in ``path`` names (absolute)."""
    here = dotted(path).split(".")
    package = here if path.endswith("__init__.py") else here[:-1]
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "emc"]
    if node.level == 0:
        base = node.module or ""
        if base.split(".")[0] != "emc":
            return []
    else:
        base = ".".join(package[:len(package) - node.level + 1] + ([node.module] if node.module
                                                                    else []))
    names = [f"{base}.{a.name}" for a in node.names]
    known = {dotted(p) for p in modules()}
    return [n if n in known else base for n in names]


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    edges = {}
    for path, tree in modules().items():
        targets = set()
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                targets |= {t for t in imported(path, node) if t != dotted(path)}
        edges[dotted(path)] = targets
    return edges


def test_every_room_has_a_floor_and_imports_only_downwards(graph):
    upward = []
    for module, targets in graph.items():
        mine = room(module)
        assert mine in FLOORS, f"{module}: a room without a floor"
        for target in targets:
            theirs = room(target)
            if theirs == mine or target == "emc":
                continue
            if FLOORS[theirs] >= FLOORS[mine]:
                upward.append(f"{module} -> {target}")
    assert not upward, upward


def test_no_import_circle(graph):
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(module):
        state[module] = 1
        stack.append(module)
        for target in graph.get(module, ()):
            if target not in graph:
                continue
            if state.get(target) == 1:
                raise AssertionError(" -> ".join(stack[stack.index(target):] + [target]))
            if target not in state:
                visit(target)
        stack.pop()
        state[module] = 2

    for module in graph:
        if module not in state:
            visit(module)


def test_nothing_imports_the_command_line(graph):
    assert [m for m, targets in graph.items() if "emc.cli" in targets] == ["emc.__main__"]


def test_imports_in_functions_are_deferred_on_purpose_and_say_so():
    found = []
    for path, tree in modules().items():
        lines = (PACKAGE / path).read_text().splitlines()
        for function in ast.walk(tree):
            if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(function):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    name = node.names[0].name if isinstance(node, ast.Import) else \
                        "." * node.level + (node.module or "")
                    found.append((path, name))
                    around = "\n".join(lines[max(0, node.lineno - 4):node.lineno])
                    assert "eferred" in around, f"{path}:{node.lineno} imports {name} in a " \
                                                "function without saying why"
    assert set(found) <= DEFERRED, sorted(set(found) - DEFERRED)


def test_every_command_module_registers_itself_once():
    from emc.commands import MODULES

    files = sorted(p.stem for p in (PACKAGE / "commands").glob("*.py") if p.stem != "__init__")
    assert sorted(MODULES) == files
    for name in MODULES:
        tree = ast.parse((PACKAGE / "commands" / f"{name}.py").read_text())
        functions = [n.name for n in tree.body if isinstance(n, ast.FunctionDef)]
        assert "register" in functions, name
    # add_parser is called in the command modules only.
    for path, tree in modules().items():
        calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)
                 and isinstance(n.func, ast.Attribute) and n.func.attr == "add_parser"]
        if calls:
            assert path.startswith("commands/") or path == "bench.py", path


# Options of the same name that mean something else where they stand: a list of worker counts
# (the scaling benchmarks), a study's or a coupled run's own window and start, the accuracy
# study's time settings, a list of speeds or coupling steps (the coupled-FMU tables).
OWN_MEANING = {("commands/bench.py", "--workers"), ("commands/bench.py", "--repeat"),
               ("commands/bench.py", "--revolutions"), ("commands/testbench.py", "--revolutions"),
               ("commands/bench.py", "--speeds"),
               ("commands/why.py", "--start"), ("commands/why.py", "--settle"),
               ("commands/why.py", "--revolutions"), ("commands/tuning.py", "--revolutions"),
               ("commands/accuracy.py", "--start"), ("commands/accuracy.py", "--settle"),
               ("commands/accuracy.py", "--step"), ("commands/accuracy.py", "--duration"),
               ("commands/accuracy.py", "--order"), ("commands/tools.py", "--rpm"),
               ("commands/tools.py", "--steps"), ("commands/tools.py", "--step"),
               ("commands/why.py", "--points")}


def test_each_shared_option_is_registered_once():
    """An option several commands take is added in emc.base.options alone (once per meaning);
    a command module adds only options of its own."""
    registered: dict[str, list[str]] = {}
    for path in modules():
        source = (PACKAGE / path).read_text()
        for option in re.findall(r'add_argument\(\s*"(--[\w-]+)"', source):
            registered.setdefault(option, []).append(path)
    shared = {option for option, paths in registered.items() if "base/options.py" in paths}
    assert {"--rpm", "--set", "--case", "--signal", "--out", "--overwrite", "--workers",
            "--scheduler", "--serial", "--quiet", "--band", "--count"} <= shared
    for option, paths in registered.items():
        elsewhere = [p for p in paths if p != "base/options.py" and (p, option) not in OWN_MEANING]
        if option in shared:
            assert elsewhere == [], (option, elsewhere)
        else:
            own = [p for p in paths if (p, option) not in OWN_MEANING]
            assert len(own) <= 1, f"{option} is registered in {paths}: put it in base/options.py"
    # --fmu goes through options.add_fmu alone.
    assert all("--fmu" not in registered or paths == [] for paths in [
        [p for p in registered.get("--fmu", []) if p != "base/options.py"]])


def test_the_command_line_starts_without_the_numerical_libraries():
    """``emc --help`` and an argument error build every parser: none of them may import numpy,
    pandas, matplotlib, fmpy, dask or scipy (the start-up time is in ``emc bench-startup``)."""
    code = ("import sys\nfrom emc.cli import build_parser\nbuild_parser()\n"
            "heavy = ('numpy', 'pandas', 'matplotlib', 'fmpy', 'dask', 'scipy', 'SALib')\n"
            "print(sorted(m for m in heavy if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
