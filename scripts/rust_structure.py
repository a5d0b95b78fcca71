"""Two rules of the crate's layout, checked on its source: no import circle between the files of
`src/` (a file's `crate::`, `super::` and `self::` paths outside its test module, resolved through
`pub use` re-exports to the file that defines the item), and no function of more than LIMIT lines
without its reason in its doc comment ("Long on purpose: ..."). Prints every violation; exit 1 if
any.

    python3 scripts/rust_structure.py [src]
"""
import pathlib
import re
import sys

LIMIT = 80
REASON = "Long on purpose"


def modules(root: pathlib.Path) -> dict[tuple[str, ...], pathlib.Path]:
    out = {}
    for p in root.rglob("*.rs"):
        parts = list(p.relative_to(root).with_suffix("").parts)
        if parts[-1] in ("mod", "lib"):
            parts = parts[:-1]
        out[tuple(parts)] = p
    return out


def without_tests_and_comments(text: str) -> str:
    m = re.search(r"#\[cfg\(test\)\]\s*mod tests", text)
    text = text[:m.start()] if m else text
    return re.sub(r"//[^\n]*", "", text)


def import_graph(root: pathlib.Path) -> dict[tuple[str, ...], set[tuple[str, ...]]]:
    mods = modules(root)
    texts = {m: without_tests_and_comments(p.read_text()) for m, p in mods.items()}
    reexports: dict[tuple[str, ...], dict[str, str]] = {}
    for m, t in texts.items():
        names = {}
        for u in re.finditer(r"pub use ([\w:]+)::\{([^}]*)\};|pub use ([\w:]+)::(\w+)(?: as (\w+))?;", t):
            if u.group(1):
                for n in u.group(2).split(","):
                    if n.strip():
                        names[n.strip().split(" as ")[-1]] = u.group(1)
            else:
                names[u.group(5) or u.group(4)] = u.group(3)
        reexports[m] = names

    def resolve(m, path, depth=0):
        segs = path.split("::")
        if segs[0] == "crate":
            cur, segs = [], segs[1:]
        else:
            cur = list(m)
            while segs and segs[0] in ("super", "self"):
                if segs[0] == "super":
                    cur = cur[:-1]
                segs = segs[1:]
        cur = tuple(cur)
        while segs and cur + (segs[0],) in mods:
            cur, segs = cur + (segs[0],), segs[1:]
        if segs and depth < 5 and segs[0] in reexports.get(cur, {}):
            return resolve(cur, reexports[cur][segs[0]] + "::" + segs[0], depth + 1) or cur
        return cur

    path = re.compile(r"\b((?:crate|super|self)(?:::\w+)+)(?:::\{([^}]*)\})?")
    edges = {m: set() for m in mods}
    for m, t in texts.items():
        for statement in t.split(";"):
            if re.match(r"\s*(pub(\(crate\))? )?mod ", statement):
                continue
            if re.match(r"\s*pub use ", statement) and mods[m].name in ("mod.rs", "lib.rs"):
                continue  # a re-export is the parent showing a child, not a dependency
            for p in path.finditer(statement):
                paths = [p.group(1)]
                if p.group(2):
                    paths += [p.group(1) + "::" + x.strip().split("::")[0].split(" as ")[0]
                              for x in p.group(2).split(",") if x.strip() and x.strip() != "self"]
                for q in paths:
                    r = resolve(m, q)
                    if r != m and r in mods:
                        edges[m].add(r)
    return edges


def cycles(edges) -> list[list[tuple[str, ...]]]:
    """Strongly connected components of more than one file (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(comp)

    sys.setrecursionlimit(10000)
    for v in edges:
        if v not in index:
            visit(v)
    return out


def long_functions_without_reason(root: pathlib.Path) -> list[str]:
    out = []
    head = re.compile(r'^(\s*)(pub(\([\w:]+\))? )?(const )?(unsafe )?(extern "C" )?fn (\w+)')
    for p in sorted(root.rglob("*.rs")):
        lines = p.read_text().split("\n")
        for k, line in enumerate(lines):
            if re.match(r"\s*#\[cfg\(test\)\]", line) and k + 1 < len(lines) \
                    and re.match(r"\s*mod tests", lines[k + 1]):
                break
            m = head.match(line)
            if not m:
                continue
            indent = m.group(1)
            end = next((j for j in range(k, len(lines)) if lines[j] == indent + "}"), None)
            if end is None or end - k + 1 <= LIMIT:
                continue
            j = k - 1
            while j >= 0 and lines[j].strip().startswith("#["):
                j -= 1
            doc = []
            while j >= 0 and lines[j].strip().startswith("///"):
                doc.append(lines[j])
                j -= 1
            if not any(REASON in d for d in doc):
                out.append(f"{p}:{k + 1}: fn {m.group(7)} has {end - k + 1} lines and no "
                           f"'{REASON}: ...' in its doc comment")
    return out


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "src")
    problems = long_functions_without_reason(root)
    edges = import_graph(root)
    for comp in cycles(edges):
        names = sorted("/".join(x) or "lib" for x in comp)
        arrows = sorted(f"{'/'.join(a)} -> {'/'.join(b)}" for a in comp for b in edges[a] if b in comp)
        problems.append(f"import circle: {', '.join(names)} ({'; '.join(arrows)})")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
