"""The documentation as its readers meet it: the user guide (mdBook in docs/) builds, every link in
it leads somewhere, every Python example in it and in the README runs against the packaged FMU,
and the FMU's own documentation page links to nothing outside the FMU.

Links are checked here, on the HTML mdBook writes, instead of by an mdBook plugin: the plugin would
be a second crate to compile on every fresh machine, while this check needs only the standard
library and also covers the README's links into docs/."""

import html.parser
import pathlib
import re
import shutil
import subprocess
import sys
import urllib.parse
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BOOK_SRC = ROOT / "docs" / "src"
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)


def pages() -> list[pathlib.Path]:
    return [ROOT / "README.md"] + sorted(BOOK_SRC.rglob("*.md"))


def code_blocks(page: pathlib.Path, language: str) -> list[str]:
    return [body for lang, body in FENCE.findall(page.read_text()) if lang == language]


PYTHON_PAGES = [p for p in pages() if code_blocks(p, "python")]


def test_the_guide_and_the_readme_carry_python_examples():
    names = {p.relative_to(ROOT).as_posix() for p in PYTHON_PAGES}
    assert "README.md" in names
    assert len(names) >= 8, names


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_python_examples_run_against_the_packaged_fmu(page, fmu_path):
    # The blocks of one page run in order in one interpreter, as a reader would paste them, from
    # the repository root where their relative paths (dist/…, resources/…) point.
    assert fmu_path == ROOT / "dist" / "EngineMountChassis.fmu"
    code = "\n".join(code_blocks(page, "python"))
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, f"{page.relative_to(ROOT)}:\n{run.stdout}\n{run.stderr}"


def test_rust_examples_of_the_guide_are_doctests():
    # cargo test runs a page's Rust blocks only if src/lib.rs includes the page as documentation.
    lib = (ROOT / "src" / "lib.rs").read_text()
    included = {(ROOT / "src" / m).resolve() for m in re.findall(r'include_str!\("([^"]+)"\)', lib)}
    with_rust = {p.resolve() for p in sorted(BOOK_SRC.rglob("*.md")) if code_blocks(p, "rust")}
    assert with_rust, "the guide has no Rust example"
    assert with_rust <= included, f"Rust examples not run as doctests: {with_rust - included}"


class _Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name"):
            if a.get(key):
                self.ids.add(a[key])
        for key in ("href", "src"):
            if a.get(key):
                self.links.append(a[key])


def _parse(path: pathlib.Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(errors="replace"))
    return p


def broken_links(root: pathlib.Path, files: list[pathlib.Path]) -> list[str]:
    """Every relative href/src of `files` must name an existing file under `root`, and a fragment
    an id in that file. Links with a scheme (https:, mailto:) are returned as broken too: the
    pages are read offline and say in words what they cite."""
    parsed = {f: _parse(f) for f in files}
    broken = []
    for f, p in parsed.items():
        for link in p.links:
            url = urllib.parse.urlsplit(link)
            where = f"{f.relative_to(root)}: {link}"
            if url.scheme or link.startswith("//"):
                if url.scheme != "data":
                    broken.append(f"{where} (leads outside)")
                continue
            target = f if not url.path else (f.parent / urllib.parse.unquote(url.path)).resolve()
            if target.is_dir():
                target = target / "index.html"
            if not target.is_file() or root.resolve() not in target.resolve().parents:
                broken.append(f"{where} (no such file)")
                continue
            if url.fragment and target.suffix == ".html":
                ids = parsed[target].ids if target in parsed else _parse(target).ids
                if urllib.parse.unquote(url.fragment) not in ids:
                    broken.append(f"{where} (no anchor #{url.fragment})")
    return broken


@pytest.fixture(scope="module")
def book(tmp_path_factory) -> pathlib.Path:
    mdbook = shutil.which("mdbook")
    if mdbook is None:
        pytest.fail("mdbook is not installed: run bash scripts/setup.sh")
    out = tmp_path_factory.mktemp("book")
    run = subprocess.run([mdbook, "build", str(ROOT / "docs"), "--dest-dir", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    # mdBook reports what it could not resolve (a missing chapter, a bad include) on stderr.
    assert "[ERROR]" not in run.stderr and "[WARN]" not in run.stderr, run.stderr
    return out


def test_every_chapter_of_the_summary_is_built(book):
    summary = (BOOK_SRC / "SUMMARY.md").read_text()
    chapters = re.findall(r"\]\(([^)]+\.md)\)", summary)
    assert len(chapters) >= 25
    for chapter in chapters:
        assert (BOOK_SRC / chapter).is_file(), chapter
        assert (book / chapter).with_suffix(".html").is_file(), chapter


def test_every_link_and_anchor_in_the_book_resolves(book):
    files = sorted(book.rglob("*.html"))
    # print.html repeats every chapter on one page with rewritten links; the chapters are checked.
    files = [f for f in files if f.name not in ("print.html", "404.html")]
    broken = broken_links(book, files)
    assert not broken, "\n".join(broken)


def test_the_checker_finds_a_broken_link_and_a_missing_anchor(tmp_path):
    (tmp_path / "a.html").write_text('<h1 id="top">A</h1><a href="b.html#nowhere">b</a>'
                                     '<a href="c.html">c</a><a href="#top">top</a>'
                                     '<a href="https://example.org/">out</a>')
    (tmp_path / "b.html").write_text('<h2 id="here">B</h2>')
    broken = broken_links(tmp_path, [tmp_path / "a.html", tmp_path / "b.html"])
    assert len(broken) == 3, broken
    assert any("no anchor #nowhere" in b for b in broken)
    assert any("c.html (no such file)" in b for b in broken)
    assert any("leads outside" in b for b in broken)


MD_LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("name", ["README.md", "CHANGELOG.md"])
def test_front_page_links_lead_to_files_of_the_repository(name):
    text = (ROOT / name).read_text()
    links = [link for link in MD_LINK.findall(text) if not re.match(r"\w+:", link)]
    if name == "README.md":
        assert any(link.startswith("docs/src/") for link in links)
    for link in links:
        path = link.split("#")[0]
        assert (ROOT / path).exists(), f"{name}: {link}"


def test_readme_is_a_front_page():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 120
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    image = re.search(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert image and (ROOT / image.group(1)).is_file()
    assert (ROOT / image.group(1)).stat().st_size <= 200_000


def test_the_fmu_documentation_page_links_to_nothing_outside_the_fmu(fmu_path, tmp_path):
    with zipfile.ZipFile(fmu_path) as z:
        z.extractall(tmp_path)
    docs = tmp_path / "documentation"
    page = docs / "index.html"
    assert page.is_file()
    broken = broken_links(tmp_path, sorted(docs.rglob("*.html")))
    assert not broken, "\n".join(broken)
    # Every variable of the model description is on the page.
    md = (tmp_path / "modelDescription.xml").read_text()
    text = page.read_text()
    names = re.findall(r'<ScalarVariable[^>]*\bname="([^"]+)"', md)
    assert names
    missing = [n for n in names if f"<code>{n}</code>" not in text]
    assert not missing, missing[:10]


def test_the_commands_the_guide_names_exist():
    # Every table says which command makes it: those commands must exist under these names.
    text = "\n".join(p.read_text() for p in pages())
    examples = set(re.findall(r"--example (\w+)", text))
    assert {"realtime", "accuracy_cost", "engine_modes", "hybrid_modes"} <= examples
    for name in examples:
        assert (ROOT / "examples" / f"{name}.rs").is_file(), name
    for script in set(re.findall(r"bash (scripts/[\w-]+\.sh|packaging/[\w-]+\.sh)", text)):
        assert (ROOT / script).is_file(), script
    for test in set(re.findall(r"--test (\w+)", text)):
        assert (ROOT / "tests" / test).is_dir() or (ROOT / "tests" / f"{test}.rs").is_file(), test
    paths = set(re.findall(
        r"`((?:src|tests|python|tools|resources|scripts)/[\w./-]+\.(?:rs|py|c|json))`", text))
    assert len(paths) >= 20
    for path in paths:
        assert (ROOT / path).is_file(), path
    # The commands the emc parser has (each command module registers its own).
    from emc.cli import build_parser

    subcommands = set(build_parser()._subparsers._group_actions[0].choices)
    commands = set(re.findall(r"(?:`|bin/)emc ([a-z][\w-]+)", text))
    assert {"sweep", "runup", "campbell", "study-mounts", "bench-realtime"} <= commands
    for command in commands:
        assert command in subcommands, f"emc {command}"


def _generator():
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        import generate
    finally:
        sys.path.pop(0)
    return generate


def test_generated_sections_are_current(fmu_path, fmu3_path):
    # The variable tables, the FMI 3.0 terminals and the card table are generated from the model
    # descriptions and the deck reader (docs/generate.py); a page whose section differs is stale.
    generate = _generator()
    assert len(generate.pages()) >= 2
    stale = [p.relative_to(ROOT).as_posix() for p in generate.stale_pages()]
    assert not stale, f"stale generated sections in {stale}: regenerate with `{generate.COMMAND}`"


def test_a_stale_generated_section_is_found(fmu_path, fmu3_path):
    generate = _generator()
    page = BOOK_SRC / "fmu" / "variables.md"
    text = page.read_text()
    assert generate.regenerate(text, page, {}) == text
    stale = text.replace("| `rpm` | input |", "| `rpm` | output |", 1)
    assert stale != text and generate.regenerate(stale, page, {}) == text


# Phrases that tell the story of how the guide came to be instead of what holds now: the history
# belongs in CHANGELOG.md and git, evidence pages give what was measured, the command, the date
# and the machine.
HISTORY = re.compile(r"|".join([
    r"\bissue \d+", r"\b(first|second|third|last|this|that|previous|earlier|same) (session|sitting)s?\b",
    r"\bthe day before\b", r"\bthe same morning\b", r"\bthis morning\b", r"\byesterday\b",
    r"\b(before|after|since) the (fix|speed-ups?|change)\b", r"\bre-?run since\b",
    r"\bthe former\b", r"\bformerly\b", r"\bof that day\b", r"\buntil now\b",
    r"\bprevious(ly)? (version|release|code|solver)\b", r"\bearlier (runs|measurements|version|code)\b",
    r"\b(has|have) not been re-?(run|measured)\b",
    # What a default or a version was, and targets met or missed: the page says what holds and
    # what was measured with which setting.
    r"\b(previous|old|former|earlier) defaults?\b", r"\bversion \d+(\.\d+)+ (used|had|was)\b",
    r"\bgoals?\b", r"\b(is|are|was|were) (met|missed|not met)\b",
]), re.I)


def history_phrases(text: str) -> list[str]:
    return [f"line {text.count(chr(10), 0, m.start()) + 1}: '{m.group(0)}'"
            for m in HISTORY.finditer(text)]


def test_the_guide_has_no_history_phrases():
    found = {p.relative_to(ROOT).as_posix(): history_phrases(p.read_text()) for p in pages()}
    found = {page: hits for page, hits in found.items() if hits}
    assert not found, found


def test_the_history_check_finds_history():
    text = "Fast.\n607.9 s the day before (issue 27, first sitting); measured before the fix.\n"
    assert len(history_phrases(text)) == 4
    assert history_phrases("The solver holds the order down for a while.") == []
    text = ("The previous default, 1 %, gave more. Version 0.1.0 used 1e-8. Against the goals\n"
            "(150×) it is short; the goal of 1.8× is met.\n")
    assert len(history_phrases(text)) == 5, history_phrases(text)
    assert history_phrases("The default is 5 %; the Adams table gives 6.2 m/s² there.") == []


# ---------------------------------------------------------------------------------------------
# Measured figures: one source (docs/figures.toml), quoted between markers


def _figures():
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        import figures
    finally:
        sys.path.pop(0)
    return figures


def test_every_figure_says_when_where_and_how_it_was_measured():
    figures = _figures()
    sources = figures.load()
    assert not figures.problems(sources), figures.problems(sources)
    assert len(sources["figures"]) >= 30 and len(sources["tables"]) >= 5
    broken = dict(sources, figures={"x": {"value": "about 3", "what": "w", "date": "4 Dec",
                                          "machine": "Z", "command": "c", "damping": "1 %"}})
    assert len(figures.problems(broken)) == 4, figures.problems(broken)


def quoted_figures_that_differ(text: str, sources: dict) -> list[str]:
    figures = _figures()
    wrong = []
    for m in figures.MARKER.finditer(text):
        if m.group(1) not in sources["figures"]:
            wrong.append(f"{m.group(1)}: not in docs/figures.toml")
        elif m.group(2) != figures.text(m.group(1), sources):
            wrong.append(f"{m.group(1)}: '{m.group(2)}', the source says "
                         f"'{figures.text(m.group(1), sources)}'")
    return wrong


def test_every_quoted_figure_and_figure_table_equals_its_source():
    figures = _figures()
    sources = figures.load()
    wrong = {p.relative_to(ROOT).as_posix(): quoted_figures_that_differ(p.read_text(), sources)
             for p in pages()}
    wrong = {page: hits for page, hits in wrong.items() if hits}
    assert not wrong, wrong
    # Every figure and every table of the source is on a page.
    text = "\n".join(p.read_text() for p in pages())
    quoted = {m.group(1) for m in figures.MARKER.finditer(text)}
    assert not set(sources["figures"]) - quoted, set(sources["figures"]) - quoted
    tables = set(re.findall(r"<!-- generated: table-([\w-]+) -->", text))
    assert tables == set(sources["tables"]), set(sources["tables"]) ^ tables
    # The figure tables, the machines and the list of figures as docs/generate.py writes them.
    generate = _generator()
    stale = [p.relative_to(ROOT).as_posix() for p in generate.stale_pages(generate.light)]
    assert not stale, f"stale figures in {stale}: run `{generate.COMMAND} --light`"


def test_a_figure_that_differs_from_its_source_is_found():
    figures = _figures()
    sources = figures.load()
    readme = (ROOT / "README.md").read_text()
    marked = "<!--f:realtime.scene2.2000-->" + figures.text("realtime.scene2.2000", sources)
    assert marked in readme
    edited = readme.replace(marked, "<!--f:realtime.scene2.2000-->12–14×", 1)
    assert quoted_figures_that_differ(edited, sources) == [
        "realtime.scene2.2000: '12–14×', the source says '11.8–14×'"]
    assert figures.fill(edited, sources) == readme
    # A new measurement in the source makes every page that quotes it stale.
    remeasured = dict(sources, tables={**sources["tables"], "realtime": dict(
        sources["tables"]["realtime"],
        rows=[sources["tables"]["realtime"]["rows"][0],
              ["2", "211", "16–19×", "13–15×", "7.2–8.2×"]])})
    assert quoted_figures_that_differ(readme, remeasured) == [
        "realtime.scene2.2000: '11.8–14×', the source says '13–15×'"]


def test_a_figure_measured_with_the_adams_table_says_so():
    figures = _figures()
    sources = figures.load()
    unsaid = {p.relative_to(ROOT).as_posix(): figures.unsaid_damping(p.read_text(), sources)
              for p in pages()}
    unsaid = {page: hits for page, hits in unsaid.items() if hits}
    assert not unsaid, unsaid
    assert sources["figures"]["comfort.wheel.1100.adams"]["damping"] == "adams"
    page = "Fast.\n\nThe wheel: <!--f:comfort.wheel.1100.adams-->6.2 m/s²<!--/f-->.\n"
    assert len(figures.unsaid_damping(page, sources)) == 1
    assert figures.unsaid_damping(page.replace("The wheel", "With the Adams table"), sources) == []


def unmarked_copies(text: str, sources: dict) -> list[str]:
    """Ranges with a unit (distinctive enough not to be another quantity that happens to read
    alike) written out on a page without their marker: a copy that would not follow its source."""
    figures = _figures()
    bare = figures.MARKER.sub("", text)
    bare = re.sub(r"<!-- generated: ([\w-]+) -->.*?<!-- end generated: \1 -->", "", bare,
                  flags=re.S)
    found = []
    for figure_id in sources["figures"]:
        shown = figures.text(figure_id, sources)
        if not sources["figures"][figure_id].get("unit") and not shown.endswith("×"):
            continue
        if "–" not in shown:
            continue
        if re.search(r"(?<![\w.–-])" + re.escape(shown) + r"(?![\w–])", bare):
            found.append(f"{figure_id}: '{shown}' without its marker")
    return found


def test_a_quoted_figure_carries_its_marker():
    figures = _figures()
    sources = figures.load()
    found = {p.relative_to(ROOT).as_posix(): unmarked_copies(p.read_text(), sources)
             for p in pages()}
    found = {page: hits for page, hits in found.items() if hits}
    assert not found, found
    assert unmarked_copies("scene 2 at 11.8–14× real time", sources) == [
        "realtime.scene2.2000: '11.8–14×' without its marker"]


# ---------------------------------------------------------------------------------------------
# Reference pages generated from the code


REFERENCE_PAGES = {"reference/cli.md": "cli-reference", "reference/vehicle.md": "vehicle-fields",
                   "reference/results.md": "result-files"}


@pytest.mark.parametrize("page", REFERENCE_PAGES)
def test_a_reference_page_is_what_the_code_says(page):
    generate = _generator()
    path = BOOK_SRC / page
    text = path.read_text()
    assert f"<!-- generated: {REFERENCE_PAGES[page]} -->" in text
    assert generate.regenerate(text, path, {}, generate.light) == text, (
        f"{page} is stale: run `{generate.COMMAND} --light`")
    assert f"]({page})" in (BOOK_SRC / "SUMMARY.md").read_text()


def test_the_cli_reference_names_every_command_and_option():
    generate = _generator()
    text = (BOOK_SRC / "reference" / "cli.md").read_text()
    from emc.cli import build_parser

    emc_parser = build_parser()
    commands = generate.reference.commands(emc_parser)
    assert len(commands) >= 20
    for name, command in commands.items():
        assert f"### emc {name}\n" in text, name
        section = text.split(f"### emc {name}\n", 1)[1].split("\n### ", 1)[0]
        for action in command._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    assert f"`{option}" in section, f"emc {name} {option}"
    # A new option is on the page at once.
    accuracy = commands["accuracy"]
    accuracy.add_argument("--brand-new", type=float, default=3.5, help="an option")
    assert "| `--brand-new BRAND_NEW` | 3.5 | an option |" in generate.reference.cli_reference(emc_parser)
    assert "--brand-new" not in generate.reference.cli_reference()


def test_the_vehicle_reference_has_every_field_of_the_mount():
    # Counted independently of the generator: the `pub` fields of MountConfig in its source.
    source = (ROOT / "src" / "model" / "mount" / "config.rs").read_text()
    struct = source.split("pub struct MountConfig {", 1)[1].split("\n}", 1)[0]
    fields = re.findall(r"^\s*pub (\w+):", struct, re.M)
    assert {"bracket", "body_node", "preload", "active"} <= set(fields)
    text = (BOOK_SRC / "reference" / "vehicle.md").read_text()
    section = text.split("### MountConfig\n", 1)[1].split("\n### ", 1)[0]
    assert re.findall(r"^\| `(\w+)` \|", section, re.M) == fields
    for name in ("VehicleConfig", "BodyConfig", "BodyDamping", "DampingTable", "ChassisConfig",
                 "EngineConfig", "MountCurve"):
        assert f"### {name}\n" in text, name
    assert '`"kind": "nastran"`' in text and "| `include_root` |" in text
