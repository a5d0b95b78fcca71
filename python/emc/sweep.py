"""Constant-speed sweeps, serial or in parallel with Dask, into tidy tables.

Parallel runs follow fmpy's parameter-variation example: the points are split into partitions,
one Dask task and one FMU instance per partition, reused between points with ``reset()``; the FMU
itself is scattered to the workers by content. The FMU is deterministic, so a parallel sweep
gives exactly the numbers of a serial one.
"""

from __future__ import annotations

import hashlib
import logging
import sys

import numpy as np
import pandas as pd

from .runner import OperatingPoint, PointFailed, Runner, fmu_from_content
from .spectra import amplitude_spectrum, order_amplitudes

ORDERS = tuple(k / 2 for k in range(1, 13))  # 0.5 … 6.0


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


def _run_partition(content: bytes, sha256: str, points: list, signals: list[str] | None,
                   case: str):
    """One partition on a worker. The FMU arrives as its content and checksum (scattered once to
    every worker), so workers need not share the caller's file system or working directory.

    Returns (analysed points, FMU warnings, failure or None): a failed point comes back as a
    value, with its log, so that the worker logs no error of its own and the caller reports the
    FMU's cause first."""
    rows, warnings = [], []
    try:
        with Runner(fmu_from_content(content, sha256)) as runner:
            names = signals or default_signals(runner)
            for point in points:
                result = runner.run_point(point, names, case)
                warnings += result["warnings"]
                rows.append(analyse(result, case))
    except PointFailed as failure:
        return rows, warnings, failure
    return rows, warnings, None


def _progress_bar(total: int, case: str, enabled: bool):
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=case or "sweep", unit="point", file=sys.stderr)


def _run_on_dask(fmu_path: str, points: list[OperatingPoint], signals, case: str,
                 scheduler: str | None, workers: int, bar) -> tuple[list, list]:
    from dask.distributed import Client, LocalCluster, as_completed

    with open(fmu_path, "rb") as f:
        content = f.read()
    digest = hashlib.sha256(content).hexdigest()
    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        # Worker logs below ERROR (cancelled tasks after a failure, …) would bury the cause.
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        # The FMU's bytes go to each worker once; every partition refers to them.
        remote = client.scatter(content, broadcast=True, hash=False)
        # Several points per partition reuse one FMU instance; more partitions than workers
        # balance slow low-speed points and let the progress bar move.
        npart = max(1, min(len(points), 3 * workers if not scheduler else len(points)))
        bounds = np.linspace(0, len(points), npart + 1).round().astype(int)
        chunks = [points[a:b] for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
        futures = {client.submit(_run_partition, remote, digest, chunk, signals, case,
                                 pure=False): k for k, chunk in enumerate(chunks)}
        parts: list = [None] * len(chunks)
        warnings: list[str] = []
        for future in as_completed(futures):
            rows, part_warnings, failure = future.result()
            if failure is not None:
                client.cancel(list(futures))
                raise failure
            parts[futures[future]] = rows
            warnings += part_warnings
            if bar is not None:
                bar.update(len(rows))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return [r for part in parts for r in part], warnings


def run_sweep(fmu_path: str, points: list[OperatingPoint], signals: list[str] | None = None,
              case: str = "", parallel: bool = True, scheduler: str | None = None,
              workers: int = 2, progress: bool = True,
              warnings: list | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Runs the points; returns (order table, spectrum table). A failed point raises
    :class:`PointFailed` (with its rpm, case and FMU log); the FMU's warnings of the points that
    succeeded are appended to ``warnings`` if given."""
    bar = _progress_bar(len(points), case, progress)
    try:
        if parallel:
            results, fmu_warnings = _run_on_dask(fmu_path, points, signals, case, scheduler,
                                                 workers, bar)
        else:
            results, fmu_warnings = [], []
            with Runner(fmu_path) as runner:
                names = signals or default_signals(runner)
                for point in points:
                    result = runner.run_point(point, names, case)
                    fmu_warnings += result["warnings"]
                    results.append(analyse(result, case))
                    if bar is not None:
                        bar.update(1)
    finally:
        if bar is not None:
            bar.close()
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
