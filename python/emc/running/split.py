"""Scene 2 split at the mounts, measured: the engine FMU (scene 3) and the body FMU run from their
SSP archive in libcosim against the monolithic scene 2 of the engine FMU.

    emc split-table [--steps 0.1 1 10] [--rpm 1100 2000]      # coupling steps in ms

prints, per coupling step and speed, whether the split run stayed finite, the largest deviation
of the order amplitudes from scene 2 and the wall time of both.
"""

from __future__ import annotations

import pathlib
import tempfile
import time

import numpy as np
from fmpy import read_model_description, simulate_fmu

from ..base.fmu import mount_count, variable_names
from .coupling import COMFORT, Run, forces, largest_deviation, signals
from .ssp import write_ssp

ROOT = pathlib.Path(__file__).resolve().parents[3]


def scene_2(engine_fmu, rpm: float, h: float, t_end: float, cache, rel_tol: float) -> dict:
    """The monolithic scene 2 through fmpy, sampled every ``h``."""
    start = {"scene": 2, "rpm": rpm, "chassis.cacheDir": str(cache), "solver.relTol": rel_tol}
    recorded = signals(mount_count(variable_names(read_model_description(str(engine_fmu)))))
    r = simulate_fmu(str(engine_fmu), stop_time=t_end, output_interval=h, start_values=start,
                     output=recorded)
    return {name: r[name][1:] for name in recorded}


def split_in_libcosim(ssp, rpm: float, h: float, t_end: float) -> dict:
    """The two FMUs from ``ssp`` in libcosim's fixed-step master, sampled every ``h``; stops early
    (the rest NaN) if a step fails."""
    # Deferred: libcosim's native library is loaded only where a split run is measured.
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp), step_size=int(round(h * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    engine = execution.slave_index_from_instance_name("engine")
    body = execution.slave_index_from_instance_name("body")
    vr_engine = {v.name.decode(): v.reference for v in execution.slave_variables(engine)}
    vr_body = {v.name.decode(): v.reference for v in execution.slave_variables(body)}
    execution.real_initial_value(engine, vr_engine["rpm"], rpm)
    mount_forces = forces(mount_count(vr_engine))
    steps = int(round(t_end / h))
    rows = np.full((steps, len(mount_forces) + len(COMFORT)), np.nan)
    for k in range(steps):
        if not execution.step():
            break
        rows[k] = (observer.last_real_values(engine, [vr_engine[n] for n in mount_forces])
                   + observer.last_real_values(body, [vr_body[n] for n in COMFORT]))
        if not np.all(np.isfinite(rows[k])):
            break
    return dict(zip(mount_forces + COMFORT, rows.T))


def compare(engine_fmu, body_fmu, rpm: float, h: float, t_end: float, work: pathlib.Path,
            rel_tol: float) -> dict:
    """One row of the table: deviation and wall times of the split against scene 2."""
    cache = work / "cache"
    ssp = write_ssp(engine_fmu, body_fmu, work / f"split-{h:g}.ssp",
                    engine_parameters={"chassis.cacheDir": str(cache), "solver.relTol": rel_tol},
                    body_parameters={"chassis.cacheDir": str(cache)}, step_size=h, stop_time=t_end)
    scene_2(engine_fmu, rpm, h, 0.01, cache, rel_tol)  # reduce once, outside the timings
    started = time.perf_counter()
    mono = scene_2(engine_fmu, rpm, h, t_end, cache, rel_tol)
    t_mono = time.perf_counter() - started
    started = time.perf_counter()
    split = split_in_libcosim(ssp, rpm, h, t_end)
    t_split = time.perf_counter() - started
    worst, where = largest_deviation(Run.of(mono, h), Run.of(split, h), rpm)
    return {"rpm": rpm, "h": h, "deviation": worst, "where": where, "t_mono": t_mono,
            "t_split": t_split}


def cmd_split_table(args) -> int:
    """``emc split-table``: scene 2 split at the mounts in libcosim against the monolithic scene 2."""
    print("| coupling step | rpm | largest order deviation from scene 2 | where | wall time scene 2 "
          "(fmpy) | wall time split (libcosim) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as work:
        for h in [ms * 1e-3 for ms in args.steps]:
            for rpm in args.rpm:
                r = compare(args.fmu, args.body_fmu, rpm, h, args.t_end, pathlib.Path(work),
                            args.rel_tol)
                dev = "diverged" if not np.isfinite(r["deviation"]) else \
                    f"{r['deviation'] * 100:.2f} %"
                print(f"| {h * 1e3:g} ms | {rpm:.0f} | {dev} | {r['where']} | "
                      f"{r['t_mono']:.1f} s | {r['t_split']:.1f} s |", flush=True)
    return 0
