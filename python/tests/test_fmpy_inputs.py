"""A run-up as users script it with fmpy's simulate_fmu: the example in examples/ and the guide
(docs/src/fmu/inputs.md) give fmpy a table with every input, so the run prints its result and
nothing else — no "missing input" line from fmpy, no warning from the FMU about inputs its scene
does not use (the body points of scene 3 at rest)."""

import pathlib
import subprocess
import sys

from test_docs import FENCE

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_fmpy_run_up_example_prints_only_its_result(fmu_path):
    run = subprocess.run([sys.executable, str(ROOT / "examples" / "fmpy_runup.py"), str(fmu_path)],
                         cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    lines = (run.stdout + run.stderr).splitlines()
    assert len(lines) == 1, lines
    # 800 -> 1400 rpm linearly in 2 s: 1100 rpm on average, 2 s x 1100 / 60 = 36.7 revolutions.
    assert lines[0].startswith("36.7 revolutions"), lines


def test_the_guides_fmpy_run_up_prints_no_warning(fmu_path):
    page = ROOT / "docs" / "src" / "fmu" / "inputs.md"
    code = "\n".join(body for lang, body in FENCE.findall(page.read_text()) if lang == "python")
    assert "simulate_fmu" in code
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr
    output = run.stdout + run.stderr
    assert "Warning" not in output and "WARNING" not in output, output
