"""The crate's layout rules (scripts/rust_structure.py): no import circle between the files of
src/, and no function over 80 lines without its reason in its doc comment. The checker is first
shown to find both in a small hand-made tree, then run on the crate."""

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "rust_structure.py"


def run(src: pathlib.Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), str(src)], capture_output=True, text=True)


def test_the_checker_finds_a_circle_through_a_re_export_and_a_long_function(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "lib.rs").write_text("pub mod a;\n")
    (tmp_path / "a" / "mod.rs").write_text("mod x;\nmod y;\npub use x::X;\n")
    (tmp_path / "a" / "x.rs").write_text("use super::y::Y;\npub struct X(Y);\n")
    body = "\n".join(f"    let v{k} = {k};" for k in range(85))
    (tmp_path / "a" / "y.rs").write_text(
        "/// Why not.\npub struct Y(Box<super::X>);\n\n/// Does a lot.\npub fn long() {\n" + body + "\n}\n"
        "\n/// Long on purpose: a table.\npub fn table() {\n" + body + "\n}\n")
    found = run(tmp_path)
    assert found.returncode == 1
    lines = found.stdout.splitlines()
    assert any("import circle: a/x, a/y" in line for line in lines), found.stdout
    assert any("fn long has 87 lines" in line for line in lines), found.stdout
    assert not any("fn table" in line for line in lines), found.stdout


def test_the_crate_has_no_import_circle_and_no_long_function_without_its_reason():
    found = run(ROOT / "src")
    assert found.returncode == 0, found.stdout
