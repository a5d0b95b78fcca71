"""Benchmarks that print a table: what each effect costs, the FMU's speed through fmpy, and how
a study scales on Dask.

    emc bench-scaling --fmu dist/EngineMountChassis.fmu --points 192 --workers 1 4 16

What each effect costs (``effects_table``): each case runs a constant-speed point (fade-in, then a fixed simulated time) in this process
through fmpy; the CPU time covers the stepping only (not the instantiation, which may reduce the
chassis), including fmpy's per-step call overhead. The integrator counters come from the FMU's
``solver.*`` outputs.
"""

from __future__ import annotations

import datetime
import functools
import itertools
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
import pandas as pd
import psutil

from .base.checks import DEFAULT_PARAMETERS, check_range
from .base.fmu import check_outputs, highest_speed, model_variables
from .base.outputs import save
from .running.distributed import FmuPool
from .running.local_pool import LocalPool
from .running.runner import OperatingPoint, Runner
from .running.sweep import speed_points, sweep_point

EFFECTS = ("gasForces", "massForces", "balanceShaft", "gyroscopic", "ringCarrier", "mountNonlinearity")


def effect_sets(scene: int) -> list[tuple[str, dict]]:
    """All effects on, then each switched off alone, then everything but gas and mass forces off;
    in scene 2 also the rigid chassis and explicit chassis mode cut-offs."""
    cases = [("all effects", {})]
    for e in EFFECTS:
        cases.append((f"without {e}", {f"effects.{e}": False}))
    cases.append(("gas + mass forces only", {f"effects.{e}": False for e in EFFECTS[2:]}))
    if scene == 2:
        cases.append(("without chassisFlexibility", {"effects.chassisFlexibility": False}))
        for cutoff in (60.0, 120.0, 400.0):
            cases.append((f"chassis cut-off {cutoff:g} Hz", {"chassis.modeCutoff": cutoff}))
    return cases


def measure(runner: Runner, rpm: float, seconds: float, parameters: dict, signal: str) -> dict:
    revolutions = max(2, int(round(seconds * rpm / 60 / 2)) * 2)
    # The stepping cost alone: a fade-in start (no periodic initialisation), 4 revolutions.
    point = OperatingPoint(rpm=rpm, revolutions=revolutions, settle_revolutions=4, periodic=False,
                           parameters=tuple(parameters.items()))
    result = runner.run_point(point, [signal])
    cpu, wall, simulated = result["cpu"], result["wall"], result["simulated"]
    counters = runner.slave.getInteger([runner.vr[n] for n in (
        "solver.steps", "solver.rhsEvaluations", "solver.jacobianEvaluations", "solver.factorizations")])
    x = result["samples"][:, 0]
    return {"cpu_s_per_s": cpu / simulated, "realtime_factor": simulated / wall,
            "steps_per_s": counters[0] / simulated, "rhs_per_s": counters[1] / simulated,
            "jac": counters[2], "lu": counters[3], "rms": float(np.std(x))}


def effects_table(fmu_path: str, scenes=(1,), rpm: float = 2000.0, seconds: float = 1.0,
                  signal: str = "mount[1].F[3]") -> pd.DataFrame:
    rows = []
    with Runner(fmu_path) as runner:
        for scene in scenes:
            for name, params in effect_sets(scene):
                row = measure(runner, rpm, seconds, {"scene": scene, **params}, signal)
                rows.append({"scene": scene, "effects": name, **row})
    return pd.DataFrame(rows)


REALTIME_CASES = (
    ("scene 1 (ground)", {"scene": 1}),
    ("scene 2 (body, automatic cut-off)", {"scene": 2}),
    ("scene 2, 1 kHz body", {"scene": 2, "chassis.modeCutoff": 1000.0}),
)


def realtime_table(fmu_path: str, rpm: float = 2000.0, seconds: float = 1.0, repeats: int = 3,
                   step: float = 1e-3) -> pd.DataFrame:
    """The FMU's own speed as a host sees it: after a 0.2 s settling phase, ``repeats`` windows of
    ``seconds`` of fmpy's low-level ``doStep`` + ``getReal`` (every Real output, every step) at a
    fixed communication step; the wall time of that loop only (no ``simulate_fmu`` overhead).
    Reports the range over the windows."""
    rows = []
    with Runner(fmu_path) as runner:
        outputs = [runner.vr[n] for n in runner.outputs()]
        for name, params in REALTIME_CASES:
            runner._start({"rpm": rpm, **params})
            t = 0.0
            n_settle, n_window = int(round(0.2 / step)), int(round(seconds / step))
            for k in range(n_settle):
                runner.slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
                t = (k + 1) * step
            factors = []
            for _ in range(repeats):
                started = time.perf_counter()
                for _ in range(n_window):
                    runner.slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
                    t += step
                    runner.slave.getReal(outputs)
                factors.append(seconds / (time.perf_counter() - started))
            steps = runner.slave.getInteger([runner.vr["solver.steps"]])[0]
            rows.append({"case": name, "rpm": rpm, "outputs read": len(outputs),
                         "x realtime min": min(factors), "x realtime max": max(factors),
                         "us per doStep+getReal": 1e6 / max(factors) * step,
                         "integrator steps per s": steps / t})
    return pd.DataFrame(rows)


def scaling_points(count: int, rpm_from: float = 800.0, rpm_to: float = 4000.0) -> list:
    """The points of the scaling benchmark: what ``emc sweep`` runs by default (scene 2, periodic
    start, 8 revolutions, 72 steps per revolution), ``count`` speeds from ``rpm_from`` to
    ``rpm_to``."""

    return speed_points(rpm_from, rpm_to, count, revolutions=8, periodic=True,
                        parameters=(("scene", 2),))


def _timed(run, repeat: int, cpu) -> tuple[list[float], list[float], object]:
    """Wall times and CPU times (``cpu()`` before and after) of ``repeat`` runs, and the last
    run's result."""
    times, cpus, result = [], [], None
    for _ in range(repeat):
        cpu_before = cpu()
        started = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - started)
        cpus.append(cpu() - cpu_before)
    return times, cpus, result


def same_results(a: list, b: list) -> bool:
    """Whether two lists of analysed points (with their warnings) are equal to the bit."""
    def same(x, y):
        return (x.rpm == y.rpm and x.signals == y.signals
                and all(np.array_equal(getattr(x, f), getattr(y, f), equal_nan=True)
                        for f in ("order_amplitude", "frequency", "amplitude")))

    return len(a) == len(b) and all(same(x, y) and wx == wy for (x, wx), (y, wy) in zip(a, b))


POOL_KINDS = ("local", "dask")


def timed_pool_runs(fmu_path: str, workers: int, batching: str, evaluate, items: list,
                    repeat: int, warm_with=None, threads: int = 1, kind: str = "dask") -> dict:
    """A pool of ``workers`` processes of ``threads`` threads each (``kind``: ``"local"``, the
    process pool of ``--workers``, one thread each, or ``"dask"``, a local Dask cluster;
    ``batching``: "guided" or "equal") started, its instances warmed (and ``evaluate(runner,
    warm_with)`` run once on each, if given), then ``repeat`` timed maps of ``evaluate`` over
    ``items``: the start and warm-up times, each run's wall and CPU time (every process), the
    last run's results, the evaluations' least CPU time and the fastest run's anatomy
    (:meth:`emc.running.batches.MapRecord.anatomy`)."""

    batches = 4 if batching == "equal" else None
    started = time.perf_counter()
    if kind == "local":
        pool = LocalPool(fmu_path, workers, batches_per_worker=batches,
                         warm_with=None if warm_with is None else (evaluate, warm_with))
    else:
        pool = FmuPool(fmu_path, workers=workers, threads_per_worker=threads,
                       batches_per_worker=batches)
    with pool:
        start = time.perf_counter() - started
        started = time.perf_counter()
        if kind == "local":
            pool.warm()
        else:
            pool.warm(evaluate if warm_with is not None else None, warm_with)
        warm = time.perf_counter() - started
        anatomies = []

        def run():
            results = pool.map(evaluate, items)
            anatomies.append(pool.last_map.anatomy(pool.workers))
            return results

        times, cpus, results = _timed(run, repeat, _tree_cpu)
    fastest = anatomies[times.index(min(times))]
    return {"start_s": start, "warm_s": warm, "times": times, "cpus": cpus, "results": results,
            "task_cpu_s": min(a["cpu_s"] for a in anatomies),
            **{k: fastest[k] for k in ("batches", "busy", "first_s", "tail_s")}}


def _tree_cpu() -> float:
    """CPU seconds used so far by this process and all its descendants alive (a local pool's
    scheduler, nannies and workers)."""

    me = psutil.Process()
    total = 0.0
    for p in [me] + me.children(recursive=True):
        try:
            t = p.cpu_times()
            total += t.user + t.system
        except psutil.NoSuchProcess:
            pass
    return total


def scaling_table(fmu_path: str, points: list, workers=(1, 2), repeat: int = 2,
                  batchings=("guided",), out=sys.stdout, threads=(1,),
                  pools=POOL_KINDS) -> pd.DataFrame:
    """Serial against pools of each kind (``pools``: ``"local"``, the process pool of
    ``--workers``, whose workers have one thread each; ``"dask"``, a local Dask cluster), worker
    count, threads per worker and batching (``"guided"``: shrinking batches; ``"equal"``: four
    equal batches per worker), on warm instances: the serial loop runs
    on an instance that has already run a point; each pool is started and its workers' instances
    warmed (one point each, the reduced body read from the cache) before the timed runs. The
    start and warm-up of each pool are reported beside, and the CPU time of each run: the serial
    process's, or that of this process and all its children (scheduler, nannies, workers),
    which load does not change. Of the pool runs also the CPU time of the evaluations alone
    (the worker threads that ran them) and where the workers' time went
    (:meth:`emc.running.batches.MapRecord.anatomy`, the run with the shortest wall time). Every
    run's results are compared with the serial ones to the bit."""

    evaluate = functools.partial(sweep_point, signals=None, case="")
    rows = []
    with Runner(fmu_path) as runner:
        started = time.perf_counter()
        evaluate(runner, points[0])  # reduces the body into the cache if it is not there yet
        first = time.perf_counter() - started
        print(f"first point (instance, body reduced or read from the cache): {first:.1f} s",
              file=out, flush=True)
        times, cpus, serial = _timed(lambda: [evaluate(runner, p) for p in points], repeat,
                                     time.process_time)
    rows.append({"pool": "", "workers": "serial", "threads": "", "batching": "", "start_s": 0.0,
                 "warm_s": 0.0,
                 "run_min_s": min(times), "run_max_s": max(times), "cpu_s": min(cpus),
                 "task_cpu_s": min(cpus), "identical": True})
    print(f"serial: {min(times):.2f}-{max(times):.2f} s", file=out, flush=True)
    for kind, w, t, batching in itertools.product(pools, workers, threads, batchings):
        if kind == "local" and t != 1:
            continue  # a local pool's workers have one thread each
        run = timed_pool_runs(fmu_path, w, batching, evaluate, points, repeat,
                              warm_with=points[0], threads=t, kind=kind)
        rows.append({"pool": kind, "workers": w, "threads": t, "batching": batching,
                     "start_s": run["start_s"],
                     "warm_s": run["warm_s"], "run_min_s": min(run["times"]),
                     "run_max_s": max(run["times"]), "cpu_s": min(run["cpus"]),
                     "task_cpu_s": run["task_cpu_s"], "batches": run["batches"],
                     "busy": run["busy"], "first_s": run["first_s"], "tail_s": run["tail_s"],
                     "identical": same_results(run["results"], serial)})
        times = run["times"]
        print(f"{kind} pool, {w} workers x {t} threads, {batching} batches: start "
              f"{run['start_s']:.2f} s, "
              f"warm-up {run['warm_s']:.1f} s, "
              f"{min(times):.2f}-{max(times):.2f} s", file=out, flush=True)
    table = pd.DataFrame(rows)
    best_serial = table.run_min_s.iloc[0]
    table["speedup"] = best_serial / table.run_min_s
    table["speedup_low"] = best_serial / table.run_max_s
    table["points_per_s"] = len(points) / table.run_min_s
    # CPU of a run relative to the serial loop's: what the pool (scheduler, nannies, workers,
    # this process) costs besides the simulations. On idle cores the speed-up approaches
    # workers × busy / task_cpu_ratio.
    table["cpu_ratio"] = table.cpu_s / table.cpu_s.iloc[0]
    table["task_cpu_ratio"] = table.task_cpu_s / table.cpu_s.iloc[0]
    return table


def wait_point(runner: Runner, seconds: float) -> float:
    """A stand-in evaluation that holds its worker for a point's measured time without using a
    core (see :func:`scheduling_table`)."""
    time.sleep(seconds)
    return seconds


def point_costs(fmu_path: str, points: list) -> list[float]:
    """The wall time of each point, serially on one warm instance (the best of two runs)."""

    evaluate = functools.partial(sweep_point, signals=None, case="")
    costs = [float("inf")] * len(points)
    with Runner(fmu_path) as runner:
        evaluate(runner, points[0])
        for _ in range(2):
            for i, point in enumerate(points):
                started = time.perf_counter()
                evaluate(runner, point)
                costs[i] = min(costs[i], time.perf_counter() - started)
    return costs


def scheduling_table(fmu_path: str, costs: list[float], workers=(16,), repeat: int = 2,
                     batchings=("guided", "equal"), out=sys.stdout,
                     pools=POOL_KINDS) -> pd.DataFrame:
    """What distribution alone costs at any worker count, on a machine with fewer cores: each
    point is replaced by a wait of its measured time (:func:`wait_point`), so the workers hold
    no core while they "compute" and only the pool's own work (scheduling, batching, the
    results' way back, the idle tail) competes for the cores. The speed-up against the sum of
    the waits is what the pool would give if the workers computed as fast as the serial loop;
    a real run on that many cores adds whatever slows a worker's computing (the scaling
    table's task_cpu_ratio)."""
    total = sum(costs)
    rows = []
    for kind, w, batching in itertools.product(pools, workers, batchings):
        run = timed_pool_runs(fmu_path, w, batching, wait_point, costs, repeat, kind=kind)
        if run["results"] != costs:
            raise RuntimeError("the pool returned the items out of order")
        times = run["times"]
        rows.append({"pool": kind, "workers": w, "batching": batching,
                     "start_s": run["start_s"],
                     "run_min_s": min(times), "run_max_s": max(times),
                     "ideal_s": total / w, "speedup": total / min(times),
                     "speedup_low": total / max(times), "efficiency": total / w / min(times),
                     "pool_cpu_s": min(run["cpus"]), "batches": run["batches"],
                     "busy": run["busy"], "first_s": run["first_s"], "tail_s": run["tail_s"]})
        print(f"{kind} pool, {w} workers, {batching} batches: "
              f"{min(times):.2f}-{max(times):.2f} s "
              f"(ideal {total / w:.2f} s)", file=out, flush=True)
    return pd.DataFrame(rows)


def machine_line() -> str:
    load = os.getloadavg()
    return (f"{platform.node()}: {os.cpu_count()} logical CPUs, Python {platform.python_version()}, "
            f"load average {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f} (1 / 5 / 15 min), "
            f"{datetime.datetime.now().astimezone().isoformat(timespec='seconds')}")


def show_table(table: pd.DataFrame, columns: list[str], legend: str, csv: str | None,
               points: int) -> None:
    """Prints a benchmark table (run times as ranges, speed-ups best and worst) with its legend,
    and writes it to ``csv`` if given, with the machine and the number of points."""
    shown = table.copy()
    shown["run s (min-max)"] = [f"{a:.2f}-{b:.2f}" for a, b in zip(table.run_min_s, table.run_max_s)]
    shown["speed-up"] = [f"{a:.2f}x ({b:.2f}x)" for a, b in zip(table.speedup, table.speedup_low)]
    print(shown[columns].to_string(index=False, na_rep="", float_format=lambda v: f"{v:.2f}"))
    print(legend)
    if csv:
        table.insert(0, "machine", machine_line())
        table.insert(1, "points", points)
        table.to_csv(csv, index=False)
        print(f"-> {csv}")


def cmd_scaling(args) -> int:
    points = scaling_points(args.points, *args.rpm)
    print(machine_line(), flush=True)
    print(f"{len(points)} points, {args.rpm[0]:g}-{args.rpm[1]:g} rpm, scene 2, periodic start, "
          f"8 revolutions at 72 steps each; {args.repeat} timed runs per row", flush=True)
    table = scaling_table(args.fmu, points, args.workers, args.repeat, args.batching,
                          threads=args.threads, pools=args.pool)
    load = os.getloadavg()
    print(f"load average after: {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f}")
    show_table(table, ["pool", "workers", "threads", "batching", "start_s", "warm_s",
                       "run s (min-max)", "speed-up", "points_per_s", "cpu_s", "cpu_ratio",
                       "task_cpu_ratio",
                       "batches", "busy", "first_s", "tail_s", "identical"],
               "speed-up: against the serial loop (best; worst); cpu_ratio: the CPU time of every "
               "process against the serial loop's; task_cpu_ratio: that of the evaluations alone "
               "(worker threads); busy: the share of workers x wall time spent in batches; "
               "first_s / tail_s: a worker's mean wait for its first batch / idle time after its "
               "last (fastest run)", args.csv, len(points))
    return 0 if table.identical.all() else 1


def cmd_scheduling(args) -> int:
    points = scaling_points(args.points, *args.rpm)
    print(machine_line(), flush=True)
    costs = point_costs(args.fmu, points)
    scaled = [c * args.scale for c in costs]
    print(f"{len(points)} points, {args.rpm[0]:g}-{args.rpm[1]:g} rpm, scene 2, periodic start: "
          f"measured serially {sum(costs):.2f} s ({min(costs) * 1e3:.0f}-{max(costs) * 1e3:.0f} "
          f"ms a point); waits of {args.scale:g} x that, {sum(scaled):.2f} s in all; "
          f"{args.repeat} timed runs per row", flush=True)
    table = scheduling_table(args.fmu, scaled, args.workers, args.repeat, args.batching,
                             pools=args.pool)
    show_table(table, ["pool", "workers", "batching", "start_s", "run s (min-max)", "ideal_s",
                       "speed-up", "efficiency", "pool_cpu_s", "batches", "busy", "first_s",
                       "tail_s"],
               "speed-up: the sum of the waits over the run's wall time (best; worst); "
               "efficiency: of the ideal sum / workers; pool_cpu_s: CPU time of every process "
               "during the run (the pool's own work, the waits use none)", args.csv, len(points))
    return 0


# ----- emc bench-effects and emc bench-realtime ------------------------------------------------

def cmd_bench_effects(args) -> int:
    if args.scene is None:
        args.scene = [DEFAULT_PARAMETERS["scene"]]
    variables = model_variables(args.fmu)
    scene = variables.get("scene")
    for value in args.scene:
        check_range("--scene", value, int(scene.min) if scene and scene.min else 1,
                    int(scene.max) if scene and scene.max else 2)
    check_range("--rpm-point", args.rpm_point, 0.0, highest_speed(variables), strict_low=True)
    check_range("--seconds", args.seconds, 0.0, strict_low=True)
    check_outputs("--signal-name", [args.signal_name], variables)

    table = effects_table(args.fmu, scenes=args.scene, rpm=args.rpm_point, seconds=args.seconds,
                          signal=args.signal_name)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if args.table:
        save(table, args.table)
    return 0


def cmd_bench_realtime(args) -> int:
    table = realtime_table(args.fmu, rpm=args.rpm_point, seconds=args.seconds, repeats=args.repeats)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    return 0


# ----- emc bench-startup --------------------------------------------------------------------------

def startup_table(fmu_path: str, repeat: int = 3) -> pd.DataFrame:
    """The wall time of whole ``emc`` commands, each in a fresh process as a user runs it: the
    help, an argument error, a 2-point sweep (its fixed cost: start-up, the FMU's instantiation,
    tables, plots, metadata) and 48 points serially and on 2 local workers (the pool's start
    included). The reduced body is in the cache before the first row."""
    emc = [sys.executable, "-m", "emc"]
    work = tempfile.mkdtemp(prefix="emc-startup-")

    def sweep(count: int, *extra: str) -> list[str]:
        return ["sweep", "--fmu", fmu_path, "--rpm", "800", "4000", "--count", str(count),
                "--quiet", "--overwrite", "--out", os.path.join(work, f"sweep-{count}"), *extra]

    rows = [("emc --help", ["--help"], 0), ("an argument error", ["sweep", "--rpm", "800"], 2),
            ("2-point sweep (serial, as emc chooses for so few)", sweep(2), 0),
            ("48-point sweep, --serial", sweep(48, "--serial"), 0),
            ("48-point sweep, --workers 2", sweep(48, "--workers", "2"), 0)]
    subprocess.run(emc + sweep(1, "--serial"), check=True, capture_output=True)  # the cache
    table = []
    try:
        for label, command, expected in rows:
            times, fixed = [], []
            for _ in range(repeat):
                started = time.perf_counter()
                done = subprocess.run(emc + command, capture_output=True, text=True)
                times.append(time.perf_counter() - started)
                if done.returncode != expected:
                    raise RuntimeError(f"emc {' '.join(command)}: exit {done.returncode}\n"
                                       f"{done.stderr}")
                # A sweep says how long its points took ("48 points in 4.2 s"): the rest of
                # the command is its fixed cost.
                points = re.search(r"(\d+) points in ([0-9.]+) s", done.stdout)
                if points:
                    fixed.append(times[-1] - float(points.group(2)))
            table.append({"command": label, "min_s": min(times), "max_s": max(times),
                          "fixed_s": f"{min(fixed):.2f}–{max(fixed):.2f}" if fixed else ""})
    finally:
        shutil.rmtree(work, ignore_errors=True)
    table = pd.DataFrame(table)
    serial = table.min_s.iloc[3]
    table["speed-up"] = [""] * 4 + [f"{serial / table.min_s.iloc[4]:.2f}x "
                                    f"({table.max_s.iloc[3] / table.max_s.iloc[4]:.2f}x)"]
    return table


def cmd_startup(args) -> int:
    print(machine_line(), flush=True)
    table = startup_table(args.fmu, args.repeat)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    print("min_s / max_s: wall time of the whole command over the runs; fixed_s: that time less "
          "the points' own (as the sweep reports it, to 0.1 s), over the runs; speed-up: 48 "
          "points serially against 2 workers (best; worst)")
    if args.csv:
        table.insert(0, "machine", machine_line())
        table.to_csv(args.csv, index=False)
    return 0
