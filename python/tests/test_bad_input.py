"""Bad input 4: the analysis and study commands answer every mistake in one line, before any
simulation starts, and never look surer than they are (the 240-case trial of issue 50, by its
groups: FMU arguments, requests without bounds, options checked first, damaged study stores,
sensitivity indices, interruption). The damping tables' cases are in the Rust suites."""

import fcntl
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import pandas as pd
import pytest

from emc.cli import main
from emc.studies import doe

DIST = pathlib.Path(__file__).resolve().parents[2] / "dist"


def one_line_error(capsys, *argv) -> str:
    """Runs ``emc argv``: it must fail with exit 2 and one line on stderr, which is returned."""
    code = main(list(argv))
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if line.startswith("error")]
    assert code == 2 and len(errors) == 1, err
    assert "Traceback" not in err
    return errors[0]


def temporary_entries() -> set[str]:
    return set(os.listdir(tempfile.gettempdir()))


# --- FMU arguments that are not usable FMUs -----------------------------------------------------

@pytest.mark.parametrize("argv,message", [
    (["tpa-coupled", "--rpm-point", "1100", "--body-fmu", "MISSING.fmu"],
     "--body-fmu MISSING.fmu: no such file"),
    (["tpa", "--fmu", str(DIST / "EngineMountChassis-fmi3.fmu")],
     "an FMI 3.0 FMU; emc drives FMI 2.0 FMUs (the FMI 2.0 twin of EngineMountChassis-fmi3.fmu "
     "is EngineMountChassis.fmu)"),
    (["tpa-coupled", "--rpm-point", "1100", "--body-fmu", str(DIST / "EngineMountBody-fmi3.fmu")],
     "an FMI 3.0 FMU"),
    (["tpa", "--fmu", str(pathlib.Path(__file__))], "not an FMU (not a zip archive)"),
    (["tpa", "--fmu", str(DIST / "EngineMountBody.fmu")],
     "is the body FMU; --fmu takes the engine FMU (EngineMountChassis.fmu)"),
])
def test_fmu_arguments_that_are_not_usable_fmus_are_one_line_and_leave_nothing(
        capsys, tmp_path, fmu_path, argv, message):
    before = temporary_entries()
    error = one_line_error(capsys, *argv, "--out", str(tmp_path / "out"))
    assert message in error
    assert temporary_entries() - before == set()
    assert not (tmp_path / "out").exists()


# --- requests without bounds --------------------------------------------------------------------

@pytest.mark.parametrize("argv,message", [
    (["frf", "--points", "10", "--verify", "1e6"], "--verify must be >= 2.0 and <= 200.0"),
    (["frf", "--verify", "27.5", "--verify-amplitude", "1e9"],
     "--verify-amplitude must be > 0.0 and <= 5000.0"),
    (["frf", "--verify", "27.5", "--verify-amplitude", "0"], "--verify-amplitude must be > 0.0"),
    (["tpa", "--count", "100000"], "--count must be >= 1 and <= 2000"),
    (["frf", "--points", "1000000"], "--points must be >= 2 and <= 20000"),
    (["sweep", "--count", "5000"], "--count must be >= 1 and <= 2000"),
])
def test_requests_beyond_what_a_machine_does_in_reasonable_time_are_refused(
        capsys, tmp_path, fmu_path, argv, message):
    started = time.perf_counter()
    error = one_line_error(capsys, *argv, "--fmu", str(fmu_path), "--out", str(tmp_path / "o"))
    assert message in error
    assert time.perf_counter() - started < 20  # refused before anything runs


# --- options checked before the work ------------------------------------------------------------

@pytest.mark.parametrize("argv,message", [
    (["ods", "--rpm-point", "1100", "--revolutions", "1"], "--revolutions must be even"),
    (["ods", "--rpm-point", "1100", "--steps-per-rev", "0"], "--steps-per-rev must be >= 14"),
    (["frf", "--mark-rpm=-100"], "--mark-rpm must be > 0.0"),
    (["frf", "--mark-rpm", "1000", "--mark-order", "nan"], "--mark-order: must be finite"),
    (["frf", "--mark-order", "1.5"], "--mark-order needs --mark-rpm"),
    (["sweep", "--band-body", "1.4", "0.6"], "LOW is the less damped body's scale"),
    (["sweep", "--band-mounts", "0.5", "2"], "LOW is the more damped mounts' scale"),
])
def test_options_are_checked_before_any_simulation(capsys, tmp_path, fmu_path, argv, message):
    started = time.perf_counter()
    error = one_line_error(capsys, *argv, "--fmu", str(fmu_path), "--out", str(tmp_path / "o"))
    assert message in error
    assert time.perf_counter() - started < 20
    assert not (tmp_path / "o").exists()


def test_negative_values_need_no_equals_sign():
    from emc.cli import build_parser

    args = build_parser().parse_args(["sweep", "--load-torque", "-1e-4", "--out", "x"])
    assert args.load_torque == -1e-4
    args = build_parser().parse_args(["frf", "--mark-rpm", "-100", "--out", "x"])
    assert args.mark_rpm == -100


def test_one_speed_of_a_tuning_study_may_have_equal_limits(fmu_path):
    """As emc tpa and the tuning page's Python example: --rpm 1100 1100 with --count 1."""
    from emc.cli import build_parser
    from emc.studies.mount_study import problem_from_args

    args = build_parser().parse_args(["doe", "--fmu", str(fmu_path), "--rpm", "1100", "1100",
                                      "--count", "1", "--out", "x"])
    problem, _, _ = problem_from_args(args)
    assert (problem.rpm_from, problem.rpm_to, problem.count) == (1100.0, 1100.0, 1)


# --- study stores: damaged, empty, shared --------------------------------------------------------

STUDY = ["--var", "mount[1].stiffnessScale", "--method", "sobol", "--samples", "2",
         "--rpm", "1200", "1200", "--count", "1", "--revolutions", "2", "--serial", "--quiet"]


@pytest.fixture(scope="module")
def study(fmu_path, tmp_path_factory) -> pathlib.Path:
    """A small DOE's folder (the current design and 6 of the plan, one variable, one speed)."""
    out = tmp_path_factory.mktemp("study") / "doe"
    assert main(["doe", "--fmu", str(fmu_path), *STUDY, "--out", str(out)]) == 0
    return out


def copy_of(study: pathlib.Path, tmp_path: pathlib.Path) -> pathlib.Path:
    folder = tmp_path / "doe"
    shutil.copytree(study, folder)
    return folder


def edit_record(folder: pathlib.Path, line: int, change):
    path = folder / "evaluations.jsonl"
    lines = path.read_text().splitlines()
    lines[line - 1] = change(lines[line - 1])
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("change,message", [
    (lambda line: json.dumps({k: v for k, v in json.loads(line).items() if k != "x"}),
     "line 3: a design without x"),
    (lambda line: json.dumps({k: v for k, v in json.loads(line).items() if k != "feasible"}),
     "line 3: a design without feasible"),
    (lambda line: line.replace('"objective": ', '"objective": NaN, "was": '),
     "has the objective nan, not a finite number"),
])
def test_a_damaged_design_in_a_store_is_one_line_naming_file_and_line(
        capsys, tmp_path, fmu_path, study, change, message):
    folder = copy_of(study, tmp_path)
    edit_record(folder, 3, change)
    error = one_line_error(capsys, "doe", "--fmu", str(fmu_path), *STUDY, "--out", str(folder))
    assert str(folder / "evaluations.jsonl") in error and message in error


def test_a_damaged_header_is_one_line(capsys, tmp_path, fmu_path, study):
    folder = copy_of(study, tmp_path)
    edit_record(folder, 1, lambda line: line[:20])
    error = one_line_error(capsys, "doe", "--fmu", str(fmu_path), *STUDY, "--out", str(folder))
    assert "line 1 (the study's header) is damaged" in error


def test_a_torn_line_is_run_again_and_an_empty_store_is_a_new_study(capsys, tmp_path, fmu_path,
                                                                     study):
    folder = copy_of(study, tmp_path)
    edit_record(folder, 4, lambda line: line[:40])  # cut short by an interruption
    assert main(["doe", "--fmu", str(fmu_path), *STUDY, "--out", str(folder)]) == 0
    assert "6 designs (1 run now)" in capsys.readouterr().out
    empty = copy_of(study, tmp_path / "e")
    (empty / "evaluations.jsonl").write_text("")
    assert main(["doe", "--fmu", str(fmu_path), *STUDY, "--out", str(empty)]) == 0
    out = capsys.readouterr()
    assert "another FMU" not in out.err and "(1 run now)" not in out.out


def test_start_from_drops_a_garbage_line_and_says_which_design_it_starts_from(
        capsys, tmp_path, fmu_path, study):
    from emc.cli import build_parser
    from emc.studies.mount_study import problem_from_args
    from emc.studies.optimise import best_of_study

    folder = copy_of(study, tmp_path)
    with open(folder / "evaluations.jsonl", "a") as f:
        f.write("garbage {\n")
    args = build_parser().parse_args(["optimise", "--fmu", str(fmu_path), *STUDY[:2], "--rpm",
                                      "1200", "1200", "--count", "1", "--out", "x"])
    problem, _, _ = problem_from_args(args)
    x = best_of_study(folder, problem)
    err = capsys.readouterr().err
    assert "note: starting from the best feasible design of" in err
    assert f"mount[1].stiffnessScale={x[0]:.4g}" in err


def test_a_second_run_in_a_folder_being_written_is_refused_naming_the_first(
        capsys, tmp_path, fmu_path, study):
    folder = copy_of(study, tmp_path)
    with open(folder / ".emc.lock", "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        lock.seek(0)
        lock.truncate()
        lock.write("4242\n")
        lock.flush()
        error = one_line_error(capsys, "doe", "--fmu", str(fmu_path), *STUDY, "--out",
                               str(folder))
    assert "another emc run (process 4242) is writing this folder" in error


# --- sensitivity indices that cannot be trusted say so -------------------------------------------

def test_an_index_of_a_variable_the_response_ignores_is_told_from_zero_only_when_it_is_not():
    """Truth: y = x0 depends on x0 alone. RBD-FAST on 24 designs reports a sizeable S1 for x1
    (its small-sample bias) and the permutation floor covers it: indistinguishable from zero;
    x0's index stands above its floor. With 24 designs the floor is above 0.1: the warning says
    so, with the sample that would bring it down."""
    problem = doe.salib_problem(["x0", "x1"], [(0.0, 1.0)] * 2)
    X = doe.sample(problem, "lhs", 24, seed=1)
    table = doe.indices(problem, "lhs", X, X[:, 0], seed=1)
    assert list(table.zero) == [False, True]
    assert (table.S1_conf > 0).all()
    [warning] = [w for w in doe.precision_warnings(table, "lhs", 24) if "RBD-FAST" in w]
    assert "cannot be told from zero" in warning
    # Sobol' with 4 base samples: intervals wider than 0.1 are said.
    X = doe.sample(problem, "sobol", 4, seed=1)
    table = doe.indices(problem, "sobol", X, X[:, 0] + 0.1 * X[:, 1] ** 2, seed=1)
    assert any("confidence half-widths" in w for w in doe.precision_warnings(table, "sobol", 4))


def test_a_damping_scale_is_reported_as_no_sensitivity_of_the_static_deflection(
        capsys, tmp_path, fmu_path):
    """The static deflection does not depend on a mount's damping by construction: its index
    must be reported as indistinguishable from zero, the stiffness scale's not; the report names
    the current design and the sample's precision."""
    out = tmp_path / "doe"
    assert main(["doe", "--fmu", str(fmu_path), "--var", "mount[1].stiffnessScale",
                 "--var", "mount[1].dampingScale", "--method", "lhs", "--samples", "24",
                 "--rpm", "1200", "1200", "--count", "1", "--revolutions", "2", "--serial",
                 "--quiet", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    table = pd.read_csv(out / "sensitivity.csv")
    deflection = table[table.response == "max_deflection_mm"].set_index("variable")
    assert bool(deflection.zero["mount[1].dampingScale"])
    assert not bool(deflection.zero["mount[1].stiffnessScale"])
    assert "current design: objective" in captured.out
    assert "cannot be told from zero" in captured.err
    report = json.loads((out / "doe.json").read_text())
    assert report["current_design"]["mount[1].stiffnessScale"] == 1.0
    assert report["warnings"]


# --- interruption ---------------------------------------------------------------------------------

def test_ctrl_c_during_a_study_on_local_workers_prints_one_line(tmp_path, fmu_path):
    """The terminal's interrupt reaches the whole process group: the workers must not print
    their own tracebacks before the command's one line."""
    command = [sys.executable, "-m", "emc", "doe", "--fmu", str(fmu_path),
               "--var", "mount[1].stiffnessScale", "--method", "sobol", "--samples", "64",
               "--rpm", "1000", "1600", "--count", "3", "--revolutions", "2", "--quiet",
               "--workers", "2", "--out", str(tmp_path / "doe")]
    # As a terminal runs a command in the foreground: with SIGINT at its default. A runner that
    # starts the tests as a background job hands them SIGINT ignored, which a child inherits
    # and Python then keeps (such a command is not meant to stop on the terminal's Ctrl-C).
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True, start_new_session=True,
                               preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 120
    store = tmp_path / "doe" / "evaluations.jsonl"
    # Interrupted once designs are being evaluated on the pool.
    while time.monotonic() < deadline and (not store.exists()
                                           or len(store.read_text().splitlines()) < 3):
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "Traceback" not in err and err.strip().endswith("error: interrupted"), err
