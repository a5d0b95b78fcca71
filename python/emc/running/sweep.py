"""Constant-speed sweeps, serial or in parallel, into tidy tables.

Parallel runs go through a pool (:func:`emc.running.engine.start_pool`): every worker keeps one
FMU instance, reset between points, and takes the points in batches. The FMU is deterministic,
so a parallel sweep gives exactly the numbers of a serial one.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools

import numpy as np
import pandas as pd

from ..base.fmu import default_signals
from ..base.orders import HIGHEST_ORDER, ORDERS
from ..signals.spectra import amplitude_spectrum, order_amplitudes
from .engine import PointEngine, start_pool
from .runner import OperatingPoint, Runner, progress_bar


@dataclasses.dataclass
class Analysis:
    """One point's stationary window analysed, in arrays (small to send back from a worker): the
    order amplitudes (signals × :data:`ORDERS`) and the amplitude spectrum up to :data:`HIGHEST_ORDER` orders
    (signals × lines)."""

    rpm: float
    signals: list[str]
    order_amplitude: np.ndarray
    frequency: np.ndarray
    amplitude: np.ndarray


def analyse(result: dict) -> Analysis:
    """Order amplitudes and spectrum of one point's stationary window, signal by signal."""
    point: OperatingPoint = result["point"]
    orders, spectra = [], []
    for j in range(len(result["signals"])):
        x = result["samples"][:, j]
        orders.append(list(order_amplitudes(x, point.revolutions, ORDERS).values()))
        f, a = amplitude_spectrum(x, result["dt"])
        keep = f <= HIGHEST_ORDER * point.rpm / 60.0
        spectra.append(a[keep])
    return Analysis(point.rpm, list(result["signals"]), np.array(orders), f[keep],
                    np.array(spectra))


def tables(analyses: list[Analysis], case: str = "") -> tuple[pd.DataFrame, pd.DataFrame]:
    """The order table (case, rpm, signal, order, frequency, amplitude) and the spectrum table
    (case, rpm, signal, frequency, amplitude) of analysed points, sorted by case, signal, speed
    and order or frequency."""
    order_parts, spectrum_parts = [], []
    orders = np.array(ORDERS)
    for a in analyses:
        n_signals, n_lines = len(a.signals), len(a.frequency)
        order_parts.append(pd.DataFrame({
            "case": case, "rpm": a.rpm, "signal": np.repeat(a.signals, len(orders)),
            "order": np.tile(orders, n_signals), "frequency": np.tile(orders * a.rpm / 60.0,
                                                                      n_signals),
            "amplitude": a.order_amplitude.ravel()}))
        spectrum_parts.append(pd.DataFrame({
            "case": case, "rpm": a.rpm, "signal": np.repeat(a.signals, n_lines),
            "frequency": np.tile(a.frequency, n_signals), "amplitude": a.amplitude.ravel()}))
    sort = ["case", "signal", "rpm"]
    order_table = pd.concat(order_parts, ignore_index=True) if order_parts else pd.DataFrame()
    spectrum_table = (pd.concat(spectrum_parts, ignore_index=True) if spectrum_parts
                      else pd.DataFrame())
    if order_table.empty:
        return order_table, spectrum_table
    return (order_table.sort_values(sort + ["order"]).reset_index(drop=True),
            spectrum_table.sort_values(sort + ["frequency"]).reset_index(drop=True))


def sweep_point(runner: Runner, point: OperatingPoint, signals: list[str] | None,
                case: str) -> tuple[Analysis, list[str]]:
    """One point on ``runner``: its analysis and the FMU's warnings."""
    result = runner.run_point(point, signals or default_signals({v.name: v for v in runner.md.modelVariables}), case)
    return analyse(result), result["warnings"]


def run_sweep(fmu_path: str, points: list[OperatingPoint], signals: list[str] | None = None,
              case: str = "", parallel: bool = True, scheduler: str | None = None,
              workers: int = 2, progress: bool = True,
              warnings: list | None = None,
              pool=None, runner: Runner | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Runs the points; returns (order table, spectrum table). A failed point raises
    :class:`PointFailed` (with its rpm, case and FMU log); the FMU's warnings of the points that
    succeeded are appended to ``warnings`` if given. ``pool``: a running pool
    (:class:`emc.running.batches.BatchPool`) of this FMU (a study keeps one for all its
    sweeps); else ``runner``: an instance in this process to run them on, one after the other;
    else, if ``parallel``, a pool is started for this sweep (on ``scheduler``, or ``workers``
    local processes) and closed after it; else an instance of its own."""
    bar = progress_bar(len(points), case or "sweep", progress, unit="point")
    evaluate = functools.partial(sweep_point, signals=signals, case=case)
    update = None if bar is None else bar.update
    try:
        with contextlib.ExitStack() as own:
            if pool is None and runner is None:
                if parallel:
                    pool = own.enter_context(start_pool(fmu_path, workers, scheduler))
                else:
                    runner = own.enter_context(Runner(fmu_path))
            done = PointEngine(runner=runner, pool=pool).map(evaluate, points, update)
    finally:
        if bar is not None:
            bar.close()
    fmu_warnings = [w for _, point_warnings in done for w in point_warnings]
    if warnings is not None:
        warnings += fmu_warnings
    return tables([analysis for analysis, _ in done], case)


def speed_points(rpm_from: float, rpm_to: float, count: int, **kwargs) -> list[OperatingPoint]:
    return [OperatingPoint(rpm=float(r), **kwargs) for r in np.linspace(rpm_from, rpm_to, count)]
