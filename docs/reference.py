"""The guide's reference pages, from the code itself: every ``emc`` command with its options and
defaults (from ``emc.cli.build_parser()``), the fields of the vehicle configuration (from the Rust
types that serde reads, ``src/model/vehicle.rs`` and the modules it names), and the columns of
every result file (from ``emc.base.result_files``).

docs/generate.py writes them into docs/src/reference/*.md; python/tests/test_docs.py fails when
a page differs from what this writes.
"""

from __future__ import annotations

import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))

from emc.base import result_files  # noqa: E402  (the repository's emc, not an installed one)
from emc.cli import build_parser  # noqa: E402


def cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


# ---------------------------------------------------------------------------------------------
# The command line


def commands(parser: argparse.ArgumentParser | None = None) -> dict[str, argparse.ArgumentParser]:
    parser = parser or build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def helps(parser: argparse.ArgumentParser) -> dict[str, str]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {a.dest: a.help or "" for a in sub._choices_actions}


def option_name(action: argparse.Action) -> str:
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    names = ", ".join(action.option_strings)
    if action.nargs == 0:
        return f"`{names}`"
    metavar = action.metavar or action.dest.upper()
    if isinstance(metavar, tuple):
        shown = " ".join(metavar)
    elif action.nargs in ("+", "*"):
        shown = f"{metavar} …"
    elif isinstance(action.nargs, int) and action.nargs > 1:
        shown = " ".join([metavar] * action.nargs)
    else:
        shown = metavar
    if action.choices and not action.metavar:
        shown = "{" + ",".join(str(c) for c in action.choices) + "}"
    return f"`{names} {shown}`"


def default_text(action: argparse.Action) -> str:
    if action.required:
        return "required"
    if action.nargs == 0:
        return "off"
    value = action.default
    if value is None or value == argparse.SUPPRESS:
        return "–"
    if isinstance(value, (list, tuple)):
        return " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) or "–"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def meaning(action: argparse.Action) -> str:
    text = (action.help or "").replace("%%", "%")
    extra = []
    if isinstance(action, argparse._AppendAction):
        extra.append("repeatable")
    return text + (f" ({', '.join(extra)})" if extra and "repeatable" not in text else "")


def anchor(name: str) -> str:
    return "emc-" + name


def cli_reference(parser: argparse.ArgumentParser | None = None) -> str:
    parser = parser or build_parser()
    parts = []
    cmds, summary = commands(parser), helps(parser)
    rows = ["| command | what it does |", "|---|---|"]
    for name in cmds:
        rows.append(f"| [`emc {name}`](#{anchor(name)}) | {cell(summary.get(name, ''))} |")
    parts.append("\n".join(rows))
    shared: dict[str, list[str]] = {}
    for name, parser in cmds.items():
        table = ["| option | default | meaning |", "|---|---|---|"]
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            for option in action.option_strings[:1]:
                shared.setdefault(option, []).append(name)
            table.append(f"| {cell(option_name(action))} | {cell(default_text(action))} | "
                         f"{cell(meaning(action))} |")
        parts.append(f"### emc {name}\n\n{summary.get(name, '')}\n\n" + "\n".join(table))
    rows = ["| option | commands |", "|---|---|"]
    for option, names in sorted(shared.items()):
        if len(names) > 1:
            rows.append(f"| `{option}` | " + ", ".join(f"[`{n}`](#{anchor(n)})" for n in names)
                        + " |")
    parts.append("### Options several commands take\n\n" + "\n".join(rows))
    return "\n\n".join(parts)


# ---------------------------------------------------------------------------------------------
# The vehicle configuration: the Rust types serde reads

# The root of the configuration; every type its fields name that src/ defines is walked.
ROOT_TYPE = ("VehicleConfig", "src/model/vehicle.rs")

ITEM = re.compile(r"((?:[ \t]*(?:///[^\n]*|#\[[^\n]*\])\n)*)[ \t]*pub (struct|enum) (\w+)(?:<[^>]*>)?\s*\{",
                  re.M)
FIELD = re.compile(r"^((?:[ \t]*(?:///[^\n]*|#\[[^\n]*\])\n)*)[ \t]*(?:pub )?(\w+): ([^\n]+?),?[ \t]*\n",
                   re.M)
VARIANT = re.compile(r"^((?:[ \t]*(?:///[^\n]*|#\[[^\n]*\])\n)*)[ \t]*([A-Z]\w*)\s*(\{|\(|,|\n)",
                     re.M)


def top_level(body: str) -> str:
    """``body`` with what nested braces hold blanked (positions kept): an enum's variants."""
    out, depth = [], 0
    for ch in body:
        if ch == "}":
            depth -= 1
        out.append(ch if depth == 0 or ch == "\n" else " ")
        if ch == "{":
            depth += 1
    return "".join(out)


def docs_of(block: str) -> str:
    lines = [ln.strip()[3:].strip() for ln in block.splitlines() if ln.strip().startswith("///")]
    text = " ".join(lines)
    # rustdoc links: [`x`](crate::y) and [`x`] read as `x`.
    text = re.sub(r"\[(`[^`]+`)\]\([^)]*\)", r"\1", text)
    return re.sub(r"\[(`[^`]+`)\]", r"\1", text)


def serde_of(block: str) -> str:
    return " ".join(ln.strip() for ln in block.splitlines() if ln.strip().startswith("#[serde"))


def body_of(text: str, start: int) -> str:
    """The text inside the braces that open at ``start``."""
    depth = 0
    for i in range(start, len(text)):
        if text[i] == "{":
            depth += 1
        elif text[i] == "}":
            depth -= 1
            if depth == 0:
                return text[start + 1:i]
    raise ValueError("unbalanced braces")


def rust_items() -> dict[tuple[str, str], dict]:
    """Every public struct and enum of src/, by (name, file)."""
    items = {}
    for path in sorted((ROOT / "src").rglob("*.rs")):
        text = path.read_text()
        rel = path.relative_to(ROOT).as_posix()
        for m in ITEM.finditer(text):
            items[(m.group(3), rel)] = {
                "name": m.group(3), "kind": m.group(2), "docs": docs_of(m.group(1)),
                "serde": serde_of(m.group(1)), "body": body_of(text, m.end() - 1), "file": rel}
    return items


def resolve(name: str, near: str, items: dict) -> dict | None:
    """The definition of ``name`` as seen from the file ``near``: in the same file, else the
    same folder, else the one definition of that name in src/."""
    same = [i for (n, f), i in items.items() if n == name]
    if not same:
        return None
    for test in (lambda i: i["file"] == near,
                 lambda i: i["file"].rsplit("/", 1)[0] == near.rsplit("/", 1)[0],
                 lambda i: True):
        found = [i for i in same if test(i)]
        if found:
            return found[0]
    return None


def case(name: str, serde: str) -> str:
    rule = re.search(r'rename_all = "(\w+)"', serde)
    if rule and rule.group(1) == "snake_case":
        return re.sub(r"(?<!^)([A-Z])", r"_\1", name).lower()
    if rule and rule.group(1) == "lowercase":
        return name.lower()
    return name


def anchor_of(item: dict) -> str:
    return item["name"].lower()


def walk() -> list[dict]:
    """The types of the configuration tree in the order they are first named."""
    items = rust_items()
    root = resolve(*ROOT_TYPE, items)
    order, seen, queue = [], set(), [root]
    while queue:
        item = queue.pop(0)
        if item is None or (item["name"], item["file"]) in seen:
            continue
        seen.add((item["name"], item["file"]))
        order.append(item)
        for word in re.findall(r"\b([A-Z]\w+)\b", "\n".join(
                m.group(3) for m in FIELD.finditer(item["body"] + "\n"))):
            if word not in ("Option", "Vec", "Box", "String", "PathBuf", "BTreeMap", "HashMap"):
                queue.append(resolve(word, item["file"], items))
    return order


def type_text(rust_type: str, types: dict) -> str:
    shown = re.sub(r"\b(std::collections::|Box<)", "", rust_type)
    shown = re.sub(r"^Option<(.+)>$", r"\1", shown)
    if shown.count(">") > shown.count("<"):
        shown = shown[:len(shown) - (shown.count(">") - shown.count("<"))]
    shown = cell(shown).replace("[", "\\[").replace("]", "\\]")
    shown = shown.replace("<", "&lt;").replace(">", "&gt;")
    for name, item in types.items():
        shown = re.sub(rf"\b{name}\b", f"[{name}](#{anchor_of(item)})", shown)
    return shown


def fields_table(body: str, every_optional: bool, types: dict) -> list[str]:
    rows = ["| field | type | required | meaning |", "|---|---|---|---|"]
    for m in FIELD.finditer(body + "\n"):
        serde = serde_of(m.group(1))
        if re.search(r"\bskip\b(?!_)", serde):
            continue
        renamed = re.search(r'rename = "([^"]+)"', serde)
        optional = every_optional or "default" in serde or m.group(3).startswith("Option<")
        rows.append(f"| `{renamed.group(1) if renamed else m.group(2)}` | "
                    f"{type_text(m.group(3), types)} | {'no' if optional else 'yes'} | "
                    f"{cell(docs_of(m.group(1)))} |")
    return rows


def vehicle_fields() -> str:
    order = walk()
    types = {item["name"]: item for item in order}
    parts = []
    for item in order:
        head = f"### {item['name']}\n\n{item['docs']} (`{item['file']}`)"
        every_optional = bool(re.search(r"#\[serde\(default\b", item["serde"]))
        if every_optional:
            head += "\n\nEvery field may be left out: it takes the default."
        if item["kind"] == "struct":
            parts.append(head + "\n\n" + "\n".join(fields_table(item["body"], every_optional, types)))
            continue
        tag = re.search(r'tag = "(\w+)"', item["serde"])
        lines = [head]
        variants = []
        for m in VARIANT.finditer(top_level(item["body"])):
            name = case(m.group(2), item["serde"])
            variants.append(name)
            if m.group(3) == "{":
                inner = body_of(item["body"], m.end() - 1)
                label = f'`"{tag.group(1)}": "{name}"`' if tag else f"`{name}`"
                lines.append(f"**{label}**: {docs_of(m.group(1))}\n\n"
                             + "\n".join(fields_table(inner, False, types)))
            else:
                lines.append(f"- `\"{name}\"`: {docs_of(m.group(1))}")
        parts.append("\n\n".join(lines))
    return "\n\n".join(parts)


# ---------------------------------------------------------------------------------------------
# Result files


def result_files_reference() -> str:
    parts = []
    for f in result_files.FILES:
        rows = ["| column | meaning |", "|---|---|"]
        rows += [f"| `{c}` | {cell(m)} |" for c, m in f.columns]
        commands_text = ", ".join(f"`emc {c}`" for c in f.commands)
        parts.append(f"### {f.name}\n\nWritten by {commands_text}: {f.what}\n\n" + "\n".join(rows))
    return "\n\n".join(parts)
