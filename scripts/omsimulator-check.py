#!/usr/bin/env python3
"""Runs the shipped SSP archive in OpenModelica's OMSimulator, through its command line and its
Python API, at the coupling step the archive declares, and compares the engine orders with the
monolithic scene 2 (the engine FMU alone in fmpy) at two speeds.

    python scripts/omsimulator-check.py [--ssp dist/EngineInBody.ssp] [--omsimulator OMSimulator]
        [--oms-python-path DIR] [--rpm 1100 2000] [--t-end 1.2]

Needs OMSimulator: its command line (on PATH, or --omsimulator) and its Python package
(importable as ``OMSimulator``, or from --oms-python-path); and this project's Python environment
(fmpy, numpy). OMSimulator's Python package needs lxml. Prints, per host and speed: the exit
status, the errors and warnings OMSimulator logged, the coupling step it took (from the result's
time stamps), the largest deviation of the order amplitudes from scene 2 and where, and the wall
time. Exits 1 if a run failed or logged an error.

First the archive as shipped (a short run: it loads and runs, and what the log says); then, per
speed, a copy whose only change is the engine's ``rpm`` and ``solver.relTol`` (``--rel-tol``) in
its parameter set (``resources/engine.ssv``), run to ``--t-end`` and compared over the last 8
revolutions with emc's order analysis (python/emc/split.py, the libcosim comparison's), scene 2
at the same tolerance. The command line records every
signal at every step: a 1.2 s run writes about 0.6 GB of CSV into a temporary folder.
"""

from __future__ import annotations

import argparse
import csv
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
from fmpy import read_model_description

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))
from emc.running.coupling import COMFORT, Run, forces, largest_deviation  # noqa: E402  (the project's package)
from emc.running.split import scene_2  # noqa: E402
from emc.running.ssp import OMS, OSP, SSC, SSD, SSV  # noqa: E402

NS = {"ssd": SSD, "ssc": SSC, "oms": OMS, "osp": OSP, "ssv": SSV}
MOUNTS = 4
ENGINE_SIGNALS = forces(MOUNTS)
BODY_SIGNALS = COMFORT
SMOKE_T_END = 0.01

PYTHON_API_RUN = """
import sys
from OMSimulator import SSP
ssp_path, t_end, result, pattern = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4]
model = SSP(ssp_path).instantiate()
model.setStopTime(t_end)
if result:
    model.setResultFile(result)
    model.removeSignalsFromResults(".*")
    model.addSignalsToResults(pattern)
model.initialize()
model.simulate()
model.terminate()
model.delete()
"""


def declared_step(ssp: pathlib.Path) -> float:
    """The coupling step the archive declares; OSP's and OpenModelica's annotations must agree."""
    with zipfile.ZipFile(ssp) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    oms = root.find("ssd:System/ssd:Annotations/ssc:Annotation/oms:Annotations/"
                    "oms:SimulationInformation/oms:FixedStepMaster", NS)
    osp = root.find("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation/osp:Algorithm/"
                    "osp:FixedStepAlgorithm", NS)
    if oms is None or osp is None:
        sys.exit(f"error: {ssp}: no oms:FixedStepMaster or osp:FixedStepAlgorithm; "
                 "write the archive with emc ssp")
    step = float(oms.get("stepSize"))
    if step != float(osp.get("baseStepSize")):
        sys.exit(f"error: {ssp}: OpenModelica's step {step} differs from OSP's {osp.get('baseStepSize')}")
    return step


def with_engine_values(ssp: pathlib.Path, values: dict[str, float], out: pathlib.Path) -> pathlib.Path:
    """A copy of ``ssp`` whose engine parameter set also gives the Reals ``values`` (every other
    entry as is)."""
    with zipfile.ZipFile(ssp) as source, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "resources/engine.ssv":
                text = data.decode()
                rows = ""
                for name, value in values.items():
                    if f'name="{name}"' in text:
                        sys.exit(f"error: {ssp}: resources/engine.ssv already sets {name}")
                    rows += f'    <ssv:Parameter name="{name}"><ssv:Real value="{value!r}"/></ssv:Parameter>\n'
                data = text.replace("  </ssv:Parameters>", rows + "  </ssv:Parameters>").encode()
            z.writestr(item, data)
    return out


def engine_fmu_of(ssp: pathlib.Path, work: pathlib.Path) -> pathlib.Path:
    """The engine FMU inside the archive (the one the hosts run), extracted into ``work``."""
    with zipfile.ZipFile(ssp) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
        source = next(c.get("source") for c in root.iterfind("ssd:System/ssd:Elements/ssd:Component", NS)
                      if c.get("name") == "engine")
        out = work / pathlib.PurePosixPath(source).name
        out.write_bytes(z.read(source))
    return out


def default_tolerance(fmu: pathlib.Path) -> float:
    """The engine FMU's own ``solver.relTol``: the archive leaves it, so scene 2 does too."""
    start = next(v.start for v in read_model_description(str(fmu)).modelVariables
                 if v.name == "solver.relTol")
    return float(start)


def log_counts(text: str) -> tuple[int, int]:
    """(errors, warnings) OMSimulator logged: its log lines start with ``error:``/``warning:``."""
    lines = text.splitlines()
    return (sum(line.startswith("error:") for line in lines),
            sum(line.startswith("warning:") for line in lines))


def command_line(exe: str, ssp: pathlib.Path, t_end: float, work: pathlib.Path,
                 result: str | None) -> tuple[int, str, float]:
    args = [exe, str(ssp), f"--stopTime={t_end}", f"--tempDir={work}", f"--workingDir={work}"]
    if result:
        args.append(f"--resultFile={result}")
    started = time.perf_counter()
    proc = subprocess.run(args, cwd=work, capture_output=True, text=True)
    return proc.returncode, proc.stdout + proc.stderr, time.perf_counter() - started


def python_api(python: str, path: str | None, ssp: pathlib.Path, t_end: float, work: pathlib.Path,
               result: str | None) -> tuple[int, str, float]:
    env = dict(os.environ)
    if path:
        env["PYTHONPATH"] = path + os.pathsep + env.get("PYTHONPATH", "")
    names = [f"engine.{n}" for n in ENGINE_SIGNALS] + [f"body.{n}" for n in BODY_SIGNALS]
    pattern = "|".join(".*" + re.escape(n) for n in names)
    started = time.perf_counter()
    proc = subprocess.run([python, "-c", PYTHON_API_RUN, str(ssp), repr(t_end), result or "", pattern],
                          cwd=work, env=env, capture_output=True, text=True)
    return proc.returncode, proc.stdout + proc.stderr, time.perf_counter() - started


def read_result(path: pathlib.Path) -> tuple[float, dict[str, np.ndarray]]:
    """The coupling step taken and each recorded signal at every communication point after the
    start, from an OMSimulator CSV result (which may write a time more than once: the last row
    counts). Signals are named as in the FMUs (the element prefix dropped)."""
    wanted = {f"engine.{n}": n for n in ENGINE_SIGNALS} | {f"body.{n}": n for n in BODY_SIGNALS}
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        columns = {}
        for k, name in enumerate(header):
            for suffix, signal in wanted.items():
                if name == suffix or name.endswith("." + suffix):
                    columns[signal] = k
        missing = sorted(set(wanted.values()) - set(columns))
        if missing:
            raise ValueError(f"{path.name}: no column for {', '.join(missing)}")
        rows: dict[float, list[float]] = {}
        for row in reader:
            rows[float(row[0])] = [float(row[k]) for k in columns.values()]
    times = np.array(sorted(rows))
    data = np.array([rows[t] for t in times])
    steps = np.diff(times)
    return float(np.median(steps)), {name: data[1:, j] for j, name in enumerate(columns)}


def report(host: str, rpm: str, rc: int, log: str, step: str, deviation: str, wall: float) -> bool:
    errors, warnings = log_counts(log)
    print(f"| {host} | {rpm} | {rc} | {errors} / {warnings} | {step} | {deviation} | {wall:.0f} s |",
          flush=True)
    return rc == 0 and errors == 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ssp", default=str(ROOT / "dist" / "EngineInBody.ssp"))
    parser.add_argument("--omsimulator", default="OMSimulator", help="OMSimulator's command line")
    parser.add_argument("--oms-python", default=sys.executable,
                        help="the Python that runs OMSimulator's Python API (default: this one)")
    parser.add_argument("--oms-python-path", help="folder holding OMSimulator's Python package")
    parser.add_argument("--rpm", type=float, nargs=2, default=[1100.0, 2000.0])
    parser.add_argument("--t-end", type=float, default=1.2, help="simulated time per speed, s")
    parser.add_argument("--rel-tol", type=float, default=1e-8,
                        help="the engine's solver.relTol in the compared runs and in scene 2 "
                             "(default 1e-8, as the libcosim comparison: the integrators' own "
                             "error stays out; 0: the FMU's own default)")
    parser.add_argument("--keep", help="keep the runs' files in this folder")
    args = parser.parse_args(argv)

    ssp = pathlib.Path(args.ssp).resolve()
    if not ssp.is_file():
        print(f"error: --ssp {ssp}: no such file (bash packaging/package.sh writes it)", file=sys.stderr)
        return 2
    exe = shutil.which(args.omsimulator)
    if exe is None:
        print(f"error: --omsimulator {args.omsimulator}: not found", file=sys.stderr)
        return 2
    h = declared_step(ssp)
    version = subprocess.run([exe, "--version"], capture_output=True, text=True).stdout.strip()
    print(f"{version}; {ssp.name} declares a coupling step of {h * 1e3:g} ms. Per speed: the "
          f"archive with the engine's rpm{' and solver.relTol = %g' % args.rel_tol if args.rel_tol else ''} "
          f"set, and scene 2 alike, {args.t_end:g} s, orders of the last 8 revolutions.\n")
    print("| host | rpm | exit | errors / warnings logged | step taken | largest order deviation "
          "from scene 2 | wall time |")
    print("|---|---|---|---|---|---|---|")
    ok = True
    with tempfile.TemporaryDirectory() as temp:
        work = pathlib.Path(args.keep or temp).resolve()
        work.mkdir(parents=True, exist_ok=True)
        rc, log, wall = command_line(exe, ssp, SMOKE_T_END, work, None)
        (work / "shipped-command-line.log").write_text(log)
        ok &= report("command line", f"as shipped, {SMOKE_T_END:g} s", rc, log, "", "", wall)
        rc, log, wall = python_api(args.oms_python, args.oms_python_path, ssp, SMOKE_T_END, work, None)
        (work / "shipped-python.log").write_text(log)
        ok &= report("Python API", f"as shipped, {SMOKE_T_END:g} s", rc, log, "", "", wall)

        engine = engine_fmu_of(ssp, work)
        cache = work / "cache"
        tolerance = args.rel_tol or default_tolerance(engine)
        for rpm in args.rpm:
            values = {"rpm": rpm} | ({"solver.relTol": args.rel_tol} if args.rel_tol else {})
            variant = with_engine_values(ssp, values, work / f"EngineInBody-{rpm:.0f}.ssp")
            mono = scene_2(engine, rpm, h, args.t_end, cache, rel_tol=tolerance)
            for host, run in (("command line", lambda r: command_line(exe, variant, args.t_end, work, r)),
                              ("Python API", lambda r: python_api(args.oms_python, args.oms_python_path,
                                                                  variant, args.t_end, work, r))):
                result = work / f"{host.replace(' ', '-')}-{rpm:.0f}.csv"
                rc, log, wall = run(result.name)
                (work / f"{result.stem}.log").write_text(log)
                step = deviation = ""
                if rc == 0 and result.exists():
                    taken, split = read_result(result)
                    step = f"{taken * 1e3:.4g} ms"
                    worst, where = largest_deviation(Run.of(mono, taken), Run.of(split, taken), rpm)
                    deviation = "diverged" if not np.isfinite(worst) else f"{worst * 100:.2f} % ({where})"
                    ok &= abs(taken - h) <= 1e-9 * h
                ok &= report(host, f"{rpm:.0f}", rc, log, step, deviation, wall)
                if not args.keep:
                    result.unlink(missing_ok=True)
    if not ok:
        print("\nA run failed, logged an error or took another step; the logs are "
              + (f"in {args.keep}" if args.keep else "kept with --keep DIR"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
