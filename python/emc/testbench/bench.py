"""Benchmark of calibration and correlation at full size (a command that prints a table):

    emc bench-calibration [--fmu dist/EngineMountChassis.fmu] [--workers 2] [--speeds 35]
                          [--revolutions 4] [--keep DIR]

A twin measurement (:mod:`.synthetic`: six hidden parameters, four mount stiffness scales, the
mounts' damping and the body's, 3 % noise and noise floors) of 4 channels × 4 orders at 35
speeds (800-2500 rpm), then ``emc calibrate`` of the six parameters from the nominal and
``emc correlate`` of the measurement (with and without the damping band), each timed: wall
time, the parameter sets and points simulated, the CPU time of the points (the workers'
threads) and of this process; for the correlations also where the time went (``start``: the
pool and the FMU's model description; ``simulation``, ``metrics``, ``plots``, ``total``: the
command's own count, without Python's start and imports). Each command runs as a user runs it,
in a process of its own. The recovered parameters are printed against the truth.
"""

from __future__ import annotations

import json
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
import pandas as pd

from .synthetic import twin_measurement

TRUTH = {"mount[1].stiffnessScale": 1.15, "mount[2].stiffnessScale": 0.88,
         "mount[3].stiffnessScale": 1.10, "mount[4].stiffnessScale": 0.92,
         **{f"mount[{i}].dampingScale": 1.3 for i in range(1, 5)},
         "chassis.modalDampingScale": 0.75}
FITTED = {"mount[1].stiffnessScale": 1.15, "mount[2].stiffnessScale": 0.88,
          "mount[3].stiffnessScale": 1.10, "mount[4].stiffnessScale": 0.92,
          "mount[*].dampingScale": 1.3, "chassis.modalDampingScale": 0.75}
OUTPUTS = {"steeringWheel.a[3]": "g", "seat.a[3]": "m/s^2", "mount[3].F[3]": "N",
           "mount[4].F[3]": "N"}
FLOORS = {"steeringWheel.a[3]": 0.005, "seat.a[3]": 0.005, "mount[3].F[3]": 0.1,
          "mount[4].F[3]": 0.1}
ORDERS = [1.0, 1.5, 2.0, 3.0]


def timed(argv: list[str]) -> tuple[float, float]:
    """(wall, CPU of the command's own process) of one emc command, which must succeed."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "emc", *argv], capture_output=True, text=True)
    wall = time.perf_counter() - wall
    if done.returncode != 0:
        raise RuntimeError(f"emc {argv[0]} failed (exit {done.returncode}): {done.stderr}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def cmd_bench_calibration(args) -> int:
    folder = pathlib.Path(args.keep or tempfile.mkdtemp(prefix="emc-bench-calibration-"))
    speeds = np.linspace(800.0, 2500.0, args.speeds)
    made = time.perf_counter()
    mapping = twin_measurement(args.fmu, folder, TRUTH, list(OUTPUTS), ORDERS, speeds, OUTPUTS,
                               0.03, FLOORS, seed=11, revolutions=args.revolutions)
    made = time.perf_counter() - made
    common = ["--fmu", args.fmu, "--mapping", str(mapping), "--revolutions",
              str(args.revolutions), "--workers", str(args.workers), "--quiet", "--overwrite"]
    rows = []
    out = folder / "calibration"
    wall, cpu = timed(["calibrate", *common, "--out", str(out), "--uncertainty", "0.03"])
    report = json.loads((out / "calibration.json").read_text())
    rows.append({"task": f"calibrate 6 parameters, {len(OUTPUTS)} channels x {len(ORDERS)} "
                         f"orders x {args.speeds} speeds",
                 "evaluations": report["fit"]["nfev"],
                 "parameter_sets": report["parameter_sets_run_now"],
                 "points": report["points_run_now"], "wall_s": wall,
                 "cpu_points_s": report["cpu_seconds_points"], "cpu_command_s": cpu})
    for band in (True, False):
        target = folder / f"correlate{'' if band else '_noband'}"
        wall, cpu = timed(["correlate", *common, "--out", str(target)]
                          + ([] if band else ["--no-band"]))
        points = args.speeds * (3 if band else 1)
        parts = json.loads((target / "metadata.json").read_text())["seconds"]
        rows.append({"task": f"correlate {'with' if band else 'without'} the damping band",
                     "evaluations": 3 if band else 1, "parameter_sets": 3 if band else 1,
                     "points": points, "wall_s": wall, "cpu_points_s": float("nan"),
                     "cpu_command_s": cpu, **{f"{k}_s": v for k, v in parts.items()}})
    table = pd.DataFrame(rows)
    print(f"twin measurement ({args.speeds} speeds, {args.revolutions} revolutions per point) "
          f"simulated in {made:.1f} s; {args.workers} workers")
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    fitted = pd.read_csv(out / "parameters.csv").set_index("parameter")
    fitted["truth"] = pd.Series(FITTED)
    fitted["error_pct"] = 100.0 * (fitted.value / fitted.truth - 1.0)
    fitted["inside_95"] = (fitted.low95 <= fitted.truth) & (fitted.truth <= fitted.high95)
    print(fitted[["truth", "value", "low95", "high95", "error_pct", "inside_95"]].to_string(
        float_format=lambda v: f"{v:.4g}"))
    print(f"-> {folder}")
    return 0

