"""The measured figures that the README and the guide quote, from their one source,
docs/figures.toml: the figure a marker ``<!--f:ID-->…<!--/f-->`` holds, the tables of measured
values with their date, machine and command, the list of machines, and what is wrong with the
source itself (a figure without its date, machine or command, a value that is not a number).

docs/generate.py writes the pages from these; python/tests/test_docs.py checks them.
"""

from __future__ import annotations

import os
import pathlib
import re
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCE = ROOT / "docs" / "figures.toml"
MACHINES_PAGE = ROOT / "docs" / "src" / "evidence" / "commands.md"

MARKER = re.compile(r"<!--f:([\w.:-]+)-->(.*?)<!--/f-->", re.S)
FIELDS = ("what", "date", "machine", "command", "damping")
DAMPING = {
    "5 %": "body damping 5 % of critical, the default",
    "adams": "body damping by the Adams table (1 % below 100 Hz, 10 % to 1 kHz, 100 % above; "
             "`vehicle_adams_damping.json`), not the 5 % default",
    "none": "",
}
NUMBER = r"[−-]?\d[\d,]*(?:\.\d+)?(?:e[−+-]?\d+)?"
VALUE = re.compile(rf"^{NUMBER}(?:–{NUMBER})?$|^\d+ min \d+$")
DATE = re.compile(r"^\d{4}-\d{2}-\d{2}$")


def load(path: pathlib.Path = SOURCE) -> dict:
    with open(path, "rb") as f:
        sources = tomllib.load(f)
    sources.setdefault("machines", {})
    sources.setdefault("tables", {})
    sources.setdefault("figures", {})
    return sources


def provenance(figure: dict, sources: dict) -> dict:
    """The fields that say where a figure comes from: its own, or its table's."""
    if "cell" in figure:
        table = sources["tables"].get(figure["cell"][0], {})
        return {k: table.get(k) for k in FIELDS}
    return {k: figure.get(k) for k in FIELDS}


def value(figure: dict, sources: dict) -> str:
    if "cell" in figure:
        name, row, column = figure["cell"]
        return sources["tables"][name]["rows"][row][column]
    return str(figure["value"])


def text(figure_id: str, sources: dict) -> str:
    """The figure as a page shows it: the value, then its unit (``×`` joined, others spaced)."""
    figure = sources["figures"][figure_id]
    unit = figure.get("unit", "")
    shown = value(figure, sources)
    return shown + ("" if unit in ("", "×") else " ") + unit


def problems(sources: dict) -> list[str]:
    """What makes the source itself unfit: every figure and table must say what was measured,
    when, on which machine, with which command and body damping, and a figure's value must be
    a number or a range of numbers."""
    found = []
    for kind in ("tables", "figures"):
        for name, entry in sources[kind].items():
            where = f"{kind}.{name}"
            if kind == "figures" and "cell" in entry:
                cell = entry["cell"]
                table = sources["tables"].get(cell[0])
                if table is None:
                    found.append(f"{where}: no table {cell[0]!r}")
                    continue
                try:
                    table["rows"][cell[1]][cell[2]]
                except (IndexError, TypeError):
                    found.append(f"{where}: no cell {cell[1:]} in table {cell[0]!r}")
                    continue
            fields = provenance(entry, sources) if kind == "figures" else entry
            for field in FIELDS:
                if not fields.get(field):
                    found.append(f"{where}: no {field}")
            if fields.get("date") and not DATE.match(fields["date"]):
                found.append(f"{where}: date {fields['date']!r} is not YYYY-MM-DD")
            if fields.get("machine") and fields["machine"] not in sources["machines"]:
                found.append(f"{where}: unknown machine {fields['machine']!r}")
            if fields.get("damping") and fields["damping"] not in DAMPING:
                found.append(f"{where}: damping {fields['damping']!r} is not one of {sorted(DAMPING)}")
            if kind == "figures":
                shown = value(entry, sources)
                # A table's cell may carry its unit ("27–35×"); a figure's own value may not.
                if not (re.match(NUMBER, shown) if "cell" in entry else VALUE.match(shown)):
                    found.append(f"{where}: value {shown!r} is not a number or a range")
            else:
                width = len(entry.get("header", []))
                if not width or any(len(row) != width for row in entry.get("rows", [])):
                    found.append(f"{where}: every row needs as many cells as the header")
    return found


def fill(page_text: str, sources: dict, page: str = "") -> str:
    """The page with every marked figure as its source says."""

    def one(m: re.Match) -> str:
        if m.group(1) not in sources["figures"]:
            raise KeyError(f"{page}: figure '{m.group(1)}' is not in {SOURCE.relative_to(ROOT)}")
        return f"<!--f:{m.group(1)}-->{text(m.group(1), sources)}<!--/f-->"

    return MARKER.sub(one, page_text)


def paragraph_at(page_text: str, position: int) -> str:
    start = page_text.rfind("\n\n", 0, position)
    end = page_text.find("\n\n", position)
    return page_text[start + 1 if start >= 0 else 0:end if end >= 0 else len(page_text)]


def unsaid_damping(page_text: str, sources: dict) -> list[str]:
    """Figures measured with the Adams table whose paragraph does not say so."""
    found = []
    for m in MARKER.finditer(page_text):
        figure = sources["figures"].get(m.group(1))
        if figure is None or provenance(figure, sources)["damping"] != "adams":
            continue
        if "Adams" not in paragraph_at(page_text, m.start()):
            line = page_text.count("\n", 0, m.start()) + 1
            found.append(f"line {line}: {m.group(1)} was measured with the Adams table")
    return found


def link(page: pathlib.Path, target: pathlib.Path, anchor: str = "") -> str:
    return os.path.relpath(target, page.parent).replace(os.sep, "/") + anchor


def table_markdown(name: str, sources: dict, page: pathlib.Path) -> str:
    table = sources["tables"][name]
    header = table["header"]
    align = table.get("align", "l" * len(header))
    rule = ["---:" if a == "r" else "---" for a in align]
    rows = ["| " + " | ".join(header) + " |", "|" + "|".join(rule) + "|"]
    rows += ["| " + " | ".join(row) + " |" for row in table["rows"]]
    damping = DAMPING[table["damping"]]
    note = (f"*Measured {table['date']} on machine {table['machine']} ([the machines]"
            f"({link(page, MACHINES_PAGE, '#machines')})): `{table['command']}`"
            + (f"; {damping}" if damping else "") + ".*")
    return "\n".join(rows) + "\n\n" + note


def machines_markdown(sources: dict) -> str:
    rows = ["| machine | dates | what | tables |", "|---|---|---|---|"]
    for name, m in sources["machines"].items():
        rows.append(f"| {name} | {m['dates']} | {m['what']} | {m['tables']} |")
    return "\n".join(rows)


def figure_list_markdown(sources: dict, pages: list[pathlib.Path], page: pathlib.Path) -> str:
    """Every figure: its value, what it is, when, where and how it was measured, and the pages
    that quote it."""
    quoted: dict[str, list[pathlib.Path]] = {}
    for p in pages:
        for m in MARKER.finditer(p.read_text()):
            if p not in quoted.setdefault(m.group(1), []):
                quoted[m.group(1)].append(p)
    rows = ["| figure | value | what | measured | command | body damping | quoted in |",
            "|---|---|---|---|---|---|---|"]
    for figure_id, figure in sources["figures"].items():
        fields = provenance(figure, sources)
        what = fields["what"] if "cell" not in figure else (
            f"table `{figure['cell'][0]}`, row {figure['cell'][1] + 1}, "
            f"{sources['tables'][figure['cell'][0]]['header'][figure['cell'][2]]}: {fields['what']}")
        where = ", ".join(
            "README.md" if q.name == "README.md" and q.parent == ROOT
            else f"[{q.relative_to(ROOT / 'docs' / 'src').as_posix()}]({link(page, q)})"
            for q in quoted.get(figure_id, []))
        damping = {"5 %": "5 %", "adams": "Adams table", "none": "–"}[fields["damping"]]
        rows.append("| " + " | ".join(c.replace("|", "\\|") for c in [
            f"`{figure_id}`", text(figure_id, sources), what,
            f"{fields['date']}, machine {fields['machine']}", f"`{fields['command']}`", damping,
            where or "–"]) + " |")
    return "\n".join(rows)
