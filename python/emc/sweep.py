"""Constant-speed sweeps, serial or in parallel with Dask, into tidy tables.

Parallel runs go through :class:`emc.distributed.FmuPool`: every worker keeps one FMU instance,
reset between points, and takes the points in batches. The FMU is deterministic, so a parallel
sweep gives exactly the numbers of a serial one.
"""

from __future__ import annotations

import functools

import numpy as np
import pandas as pd

from .distributed import FmuPool, progress_bar, serial_map
from .runner import OperatingPoint, Runner
from .spectra import ORDERS, amplitude_spectrum, order_amplitudes


def default_signals(runner: Runner) -> list[str]:
    names = [n for n in runner.outputs() if n.startswith(("mount[", "steeringWheel.a", "seat.a"))]
    return names


def analyse(result: dict, case: str = "") -> tuple[list[dict], list[dict]]:
    """Order amplitudes and spectrum rows of one point's stationary window."""
    point: OperatingPoint = result["point"]
    order_rows, spectrum_rows = [], []
    for j, signal in enumerate(result["signals"]):
        x = result["samples"][:, j]
        amplitudes = order_amplitudes(x, point.revolutions, ORDERS)
        for order, amplitude in amplitudes.items():
            order_rows.append({"case": case, "rpm": point.rpm, "signal": signal, "order": order,
                               "frequency": order * point.rpm / 60.0, "amplitude": amplitude})
        f, a = amplitude_spectrum(x, result["dt"])
        keep = f <= 6.5 * point.rpm / 60.0
        for fi, ai in zip(f[keep], a[keep]):
            spectrum_rows.append({"case": case, "rpm": point.rpm, "signal": signal,
                                  "frequency": fi, "amplitude": ai})
    return order_rows, spectrum_rows


def sweep_point(runner: Runner, point: OperatingPoint, signals: list[str] | None,
                case: str) -> tuple[tuple[list[dict], list[dict]], list[str]]:
    """One point on ``runner``: its analysed rows and the FMU's warnings."""
    result = runner.run_point(point, signals or default_signals(runner), case)
    return analyse(result, case), result["warnings"]


def run_sweep(fmu_path: str, points: list[OperatingPoint], signals: list[str] | None = None,
              case: str = "", parallel: bool = True, scheduler: str | None = None,
              workers: int = 2, progress: bool = True,
              warnings: list | None = None,
              pool: FmuPool | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Runs the points; returns (order table, spectrum table). A failed point raises
    :class:`PointFailed` (with its rpm, case and FMU log); the FMU's warnings of the points that
    succeeded are appended to ``warnings`` if given. ``pool``: a running :class:`FmuPool` of
    this FMU (a study keeps one for all its sweeps); else, if ``parallel``, one is started for
    this sweep (on ``scheduler``, or ``workers`` local processes) and closed after it."""
    bar = progress_bar(len(points), case or "sweep", progress, unit="point")
    evaluate = functools.partial(sweep_point, signals=signals, case=case)
    update = None if bar is None else bar.update
    try:
        if pool is not None:
            done = pool.map(evaluate, points, update)
        elif parallel:
            with FmuPool(fmu_path, workers, scheduler) as own_pool:
                done = own_pool.map(evaluate, points, update)
        else:
            done = serial_map(fmu_path, evaluate, points, update)
    finally:
        if bar is not None:
            bar.close()
    results = [rows for rows, _ in done]
    fmu_warnings = [w for _, point_warnings in done for w in point_warnings]
    if warnings is not None:
        warnings += fmu_warnings
    orders = pd.DataFrame([row for r in results for row in r[0]])
    spectra = pd.DataFrame([row for r in results for row in r[1]])
    sort = ["case", "signal", "rpm"]
    return (orders.sort_values(sort + ["order"]).reset_index(drop=True),
            spectra.sort_values(sort + ["frequency"]).reset_index(drop=True))


def speed_points(rpm_from: float, rpm_to: float, count: int, **kwargs) -> list[OperatingPoint]:
    return [OperatingPoint(rpm=float(r), **kwargs) for r in np.linspace(rpm_from, rpm_to, count)]


def save(table: pd.DataFrame, path: str):
    if path.endswith(".parquet"):
        table.to_parquet(path, index=False)
    else:
        table.to_csv(path, index=False)
