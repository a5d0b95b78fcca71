"""Writes the guide's generated sections from where their truth is: the variable tables from the
model descriptions that build.rs writes from modelDescription/variables.json (with the family
names and descriptions of variables.json itself), the FMI 3.0 terminals from the 3.0 FMUs'
terminalsAndIcons.xml, the supported bulk-data cards from the deck reader's dispatch table, the
measured figures and their tables from docs/figures.toml, and the reference pages from the code
(docs/reference.py: the emc command line, the vehicle configuration, the result files).

A generated section sits in a page (or the README) between two markers:

    <!-- generated: NAME -->
    ...
    <!-- end generated: NAME -->

and a measured figure quoted in running text between two short ones, filled from
docs/figures.toml:

    <!--f:ID-->11.8–14×<!--/f-->

Usage (after `bash packaging/package.sh`, which writes the FMUs this reads):

    .venv/bin/python docs/generate.py           # rewrite every generated section
    .venv/bin/python docs/generate.py --check   # list stale pages, exit 1 if any

python/tests/test_docs.py runs the check: a page whose generated section is stale fails it.
"""

from __future__ import annotations

import argparse
import json
import pathlib
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import figures  # noqa: E402  (beside this script, not a package)
import reference  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGES = ROOT / "docs" / "src"
DIST = ROOT / "dist"
TABLE = ROOT / "modelDescription" / "variables.json"
COMMAND = ".venv/bin/python docs/generate.py"

BEGIN = re.compile(r"<!-- generated: ([\w-]+) -->\n")
END = "<!-- end generated: {} -->"
INDICES = ["i", "j", "k"]
_SOURCES: dict = {}


def SOURCES() -> dict:  # noqa: N802 - read once, like a constant
    if not _SOURCES:
        _SOURCES.update(figures.load())
    return _SOURCES


CAUSALITY_ORDER = ["input", "output", "parameter", "calculatedParameter", "structuralParameter",
                   "local", "independent"]


# ---------------------------------------------------------------------------------------------
# Variables: the FMI 2.0 model descriptions, families named as in variables.json


def fmu_text(fmu: pathlib.Path, member: str) -> str:
    if not fmu.is_file():
        sys.exit(f"generate: {fmu.relative_to(ROOT)} is missing: run bash packaging/package.sh first")
    with zipfile.ZipFile(fmu) as z:
        return z.read(member).decode("utf-8")


class Family:
    """Scalars that share a name template of variables.json (``mount[{i}].F[{j}]``), or a scalar
    that no template names."""

    def __init__(self, name: str, description: str, dims: list[int], pattern: re.Pattern | None):
        self.name, self.description, self.dims, self.pattern = name, description, dims, pattern
        self.scalars: list[tuple[dict, tuple[int, ...]]] = []  # (attributes, indices)

    def display(self) -> str:
        return self.name.format(**dict(zip(INDICES, INDICES)))

    def text(self) -> str:
        return self.description.format(**dict(zip(INDICES, INDICES)))


def templates(fmu_key: str) -> list[Family]:
    """The families variables.json declares for the FMU ``fmu_key`` (engine or body)."""
    out = []
    for v in json.loads(TABLE.read_text())["variables"]:
        if fmu_key not in v.get("fmus", ["engine"]):
            continue
        pattern = re.escape(v["name"])
        for index in INDICES:
            pattern = pattern.replace(re.escape("{" + index + "}"), r"(\d+)")
        out.append(Family(v["name"], v["description"], v.get("dims", []), re.compile(pattern + "$")))
    return out


def fmu_key(model_name: str) -> str:
    table = json.loads(TABLE.read_text())
    if model_name == table["modelName"]:
        return "engine"
    if model_name == table.get("bodyModel", {}).get("modelName"):
        return "body"
    sys.exit(f"generate: {model_name} is neither model of {TABLE.relative_to(ROOT)}")


def read_variables(fmu: pathlib.Path) -> tuple[ET.Element, list[dict], dict[int, list[int] | None]]:
    """The model description root, its scalar variables (attributes, the type element's attributes
    as ``type`` and ``kind``), and each output's direct dependencies (indices into the list,
    0-based; None where the attribute is absent: dependent on every input)."""
    root = ET.fromstring(fmu_text(fmu, "modelDescription.xml"))
    scalars = []
    for sv in root.iter("ScalarVariable"):
        typed = next(iter(sv))
        scalars.append({**sv.attrib, "kind": typed.tag, "type": dict(typed.attrib)})
    dependencies: dict[int, list[int] | None] = {}
    outputs = root.find("ModelStructure/Outputs")
    for unknown in ([] if outputs is None else outputs.iter("Unknown")):
        deps = unknown.get("dependencies")
        dependencies[int(unknown.get("index")) - 1] = (
            None if deps is None else [int(d) - 1 for d in deps.split()])
    return root, scalars, dependencies


def families_of(scalars: list[dict], key: str) -> tuple[list[Family], dict[int, tuple[Family, tuple]]]:
    families = templates(key)
    where: dict[int, tuple[Family, tuple]] = {}
    for n, s in enumerate(scalars):
        for f in families:
            m = f.pattern.match(s["name"])
            if m:
                indices = tuple(int(g) for g in m.groups())
                break
        else:
            f = Family(s["name"].replace("{", "{{").replace("}", "}}"),
                       s.get("description", "").replace("{", "{{").replace("}", "}}"), [], None)
            families.append(f)
            indices = ()
        f.scalars.append((s, indices))
        where[n] = (f, indices)
    return [f for f in families if f.scalars], where


def number(text: str | None) -> str:
    if text is None:
        return ""
    try:
        v = float(text)
    except ValueError:
        return text
    return f"{v:g}"


def unit_text(f: Family) -> str:
    t = f.scalars[0][0]["type"]
    unit = t.get("unit", "")
    display = t.get("displayUnit")
    if unit and display and display != unit:
        return f"{unit} ({display})"
    return unit


def range_text(f: Family) -> str:
    t = f.scalars[0][0]["type"]
    lo, hi = number(t.get("min")), number(t.get("max"))
    if lo and hi:
        return f"{lo} … {hi}"
    if lo:
        return f"≥ {lo}"
    if hi:
        return f"≤ {hi}"
    return ""


def start_text(f: Family) -> str:
    s, _ = f.scalars[0]
    start = s["type"].get("start")
    if start is None:
        return ""
    if s["kind"] == "String":
        return f'`"{start}"`'
    return number(start) if s["kind"] in ("Real", "Integer") else start


def dependencies_text(f: Family, scalars: list[dict], dependencies: dict, where: dict) -> str:
    """The inputs an output responds to at once (its direct dependencies in <ModelStructure>)."""
    if f.scalars[0][0].get("causality") != "output":
        return ""
    index_of = {id(s): n for n, s in enumerate(scalars)}
    inputs: dict[int, tuple[Family, set]] = {}  # by id(family): (family, the elements named)
    same_first_index = True
    for s, indices in f.scalars:
        deps = dependencies.get(index_of[id(s)], None)
        if deps is None:
            return "every input"
        for d in deps:
            dep_family, dep_indices = where[d]
            inputs.setdefault(id(dep_family), (dep_family, set()))[1].add(dep_indices)
            if not (indices and dep_indices and dep_indices[0] == indices[0]):
                same_first_index = False
    if not inputs:
        return "none"
    names = ", ".join(f"`{g.display()}`" for g, _ in inputs.values())
    if same_first_index:
        return f"{names} with the same {INDICES[0]}"
    if all(len(named) == len(g.scalars) for g, named in inputs.values()):
        return f"all of {names}" if any(g.scalars[0][1] for g, _ in inputs.values()) else names
    return names + " (some elements)"


def cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def variables_table(fmu: pathlib.Path) -> str:
    root, scalars, dependencies = read_variables(fmu)
    key = fmu_key(root.get("modelName"))
    families, where = families_of(scalars, key)
    families.sort(key=lambda f: CAUSALITY_ORDER.index(f.scalars[0][0].get("causality", "local")))
    rows = ["| variable | causality | type | unit (display) | range | start | responds at once to | description |",
            "|---|---|---|---|---|---|---|---|"]
    for f in families:
        s, indices = f.scalars[0]
        counts = [max(ix[n] for _, ix in f.scalars) for n in range(len(indices))]
        name = f"`{f.display()}`"
        if counts:
            name += " " + ", ".join(f"{INDICES[n]} = 1…{c}" for n, c in enumerate(counts))
        causality = s.get("causality", "local")
        if s.get("variability") == "tunable":
            causality += " (tunable)"
        rows.append("| " + " | ".join(cell(c) for c in [
            name, causality, s["kind"], unit_text(f), range_text(f), start_text(f),
            dependencies_text(f, scalars, dependencies, where), f.text()]) + " |")
    head = (f"`{fmu.name}`, {len(scalars)} scalar variables (FMI {root.get('fmiVersion')}, "
            f"`{root.find('CoSimulation').get('modelIdentifier')}`):")
    return head + "\n\n" + "\n".join(rows)


def engine_variables() -> str:
    return variables_table(DIST / "EngineMountChassis.fmu")


def body_variables() -> str:
    return variables_table(DIST / "EngineMountBody.fmu")


# ---------------------------------------------------------------------------------------------
# FMI 3.0 terminals


def terminal_rows(terminal: ET.Element, prefix: str = "") -> list[str]:
    name = prefix + terminal.get("name")
    members = []
    for m in terminal.findall("TerminalMemberVariable"):
        text = f"`{m.get('variableName')}`"
        if m.get("memberName") and m.get("memberName") != m.get("variableName"):
            text += f" as `{m.get('memberName')}`"
        members.append(text)
    rows = ["| " + " | ".join(cell(c) for c in [
        f"`{name}`", terminal.get("matchingRule", ""),
        ", ".join(members), terminal.get("description", "")]) + " |"]
    for child in terminal.findall("Terminal"):
        rows += terminal_rows(child, name + ".")
    return rows


def fmi3_terminals() -> str:
    parts = []
    for fmu in sorted(DIST.glob("*-fmi3.fmu")):
        with zipfile.ZipFile(fmu) as z:
            if "terminalsAndIcons/terminalsAndIcons.xml" not in z.namelist():
                parts.append(f"`{fmu.name}` declares no terminals.")
                continue
        root = ET.fromstring(fmu_text(fmu, "terminalsAndIcons/terminalsAndIcons.xml"))
        rows = ["| terminal | matching rule | members | description |", "|---|---|---|---|"]
        terminals = root.find("Terminals")
        for t in ([] if terminals is None else terminals.findall("Terminal")):
            rows += terminal_rows(t)
        parts.append(f"`{fmu.name}`:\n\n" + "\n".join(rows))
    if not parts:
        sys.exit(f"generate: no FMI 3.0 FMU in {DIST} (run bash packaging/package.sh)")
    return "\n\n".join(parts)


# ---------------------------------------------------------------------------------------------
# Supported bulk-data cards: the deck reader's table, printed by an example


def supported_cards() -> str:
    run = subprocess.run(["cargo", "run", "--release", "--quiet", "--example", "supported_cards"],
                         cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"generate: cargo run --example supported_cards failed:\n{run.stderr}")
    return run.stdout


# ---------------------------------------------------------------------------------------------
# Pages

SECTIONS = {
    "machines": lambda: figures.machines_markdown(SOURCES()),
    "engine-variables": engine_variables,
    "body-variables": body_variables,
    "fmi3-terminals": fmi3_terminals,
    "supported-cards": supported_cards,
    "cli-reference": reference.cli_reference,
    "vehicle-fields": reference.vehicle_fields,
    "result-files": reference.result_files_reference,
}


LIGHT = {"machines", "figure-list", "cli-reference", "vehicle-fields", "result-files"}


def section(name: str, page: pathlib.Path, cache: dict[str, str]) -> str:
    """A generated section's text; the figure tables and the list of figures depend on the page
    (their links are relative to it)."""
    if name.startswith("table-"):
        if name[len("table-"):] not in SOURCES()["tables"]:
            sys.exit(f"generate: {page.relative_to(ROOT)} asks for '{name}', which "
                     f"{figures.SOURCE.relative_to(ROOT)} does not hold")
        return figures.table_markdown(name[len("table-"):], SOURCES(), page)
    if name == "figure-list":
        return figures.figure_list_markdown(SOURCES(), pages(), page)
    if name not in SECTIONS:
        sys.exit(f"generate: {page.relative_to(ROOT)} asks for an unknown section '{name}'")
    if name not in cache:
        cache[name] = SECTIONS[name]().rstrip("\n")
    return cache[name]


# The sections written from docs/figures.toml and the code alone: no packaged FMU, no cargo.
def light(name: str) -> bool:
    return name.startswith("table-") or name in LIGHT


def regenerate(text: str, page: pathlib.Path, cache: dict[str, str], only=None) -> str:
    """The page with its generated sections and figures as their sources say; with ``only`` (a
    test of section names), the other sections are left as they are."""
    out, pos = [], 0
    for m in BEGIN.finditer(text):
        name = m.group(1)
        end = text.find(END.format(name), m.end())
        if end < 0:
            sys.exit(f"generate: {page.relative_to(ROOT)}: '{END.format(name)}' is missing")
        if only is not None and not only(name):
            out.append(text[pos:end])
        else:
            out += [text[pos:m.end()], "\n", section(name, page, cache).rstrip("\n"), "\n\n"]
        pos = end
    out.append(text[pos:])
    try:
        return figures.fill("".join(out), SOURCES(), page.relative_to(ROOT).as_posix())
    except KeyError as missing:
        sys.exit(f"generate: {missing.args[0]}")


def pages() -> list[pathlib.Path]:
    """The README and the guide's pages that hold a generated section or a marked figure."""
    return [p for p in [ROOT / "README.md"] + sorted(PAGES.rglob("*.md"))
            if BEGIN.search(p.read_text()) or figures.MARKER.search(p.read_text())]


def stale_pages(only=None) -> list[pathlib.Path]:
    """The pages whose generated sections (with ``only``, those it accepts) or figures differ
    from what this script writes now."""
    cache: dict[str, str] = {}
    return [p for p in pages() if regenerate(p.read_text(), p, cache, only) != p.read_text()]


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only list stale pages; exit 1 if any")
    parser.add_argument("--light", action="store_true",
                        help="only the figures and the sections that need no packaged FMU and no "
                             "cargo (figure tables, machines, reference pages)")
    args = parser.parse_args(argv)
    only = light if args.light else None
    if args.check:
        stale = stale_pages(only)
        for p in stale:
            print(f"stale: {p.relative_to(ROOT)} (regenerate with `{COMMAND}`)")
        sys.exit(1 if stale else 0)
    cache: dict[str, str] = {}
    for p in pages():
        text = p.read_text()
        new = regenerate(text, p, cache, only)
        if new != text:
            p.write_text(new)
            print(f"wrote {p.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
