"""Constant-speed sweeps, serial or in parallel with Dask, into tidy tables.

Parallel runs follow fmpy's parameter-variation example: a Dask bag partitioned over workers,
one FMU instance per partition, reused between points with ``reset()``. The FMU is deterministic,
so a parallel sweep gives exactly the numbers of a serial one.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

import hashlib

from .runner import OperatingPoint, Runner, fmu_from_content
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


def _run_partition(fmu: tuple[bytes, str], points: list, signals: list[str] | None, case: str):
    """One partition on a worker: the FMU arrives as its content (and checksum), so workers need
    not share the caller's file system."""
    rows = []
    with Runner(fmu_from_content(*fmu)) as runner:
        names = signals or default_signals(runner)
        for point in points:
            rows.append(analyse(runner.run_point(point, names, case), case))
    return [rows]


def run_sweep(fmu_path: str, points: list[OperatingPoint], signals: list[str] | None = None,
              case: str = "", parallel: bool = True, scheduler: str | None = None,
              workers: int = 2, progress: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Runs the points; returns (order table, spectrum table)."""
    if parallel:
        import dask.bag as db
        from dask.distributed import Client, LocalCluster

        cluster = None
        if scheduler:
            client = Client(scheduler)
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
        try:
            # Several points per partition reuse one FMU instance; more partitions than workers
            # balance slow low-speed points and give the progress bar something to show.
            npart = max(1, min(len(points), 3 * workers if not scheduler else len(points)))
            bag = db.from_sequence(points, npartitions=npart)
            with open(fmu_path, "rb") as f:
                content = f.read()
            fmu = (content, hashlib.sha256(content).hexdigest())
            delayed_parts = bag.map_partitions(lambda part: _run_partition(fmu, list(part), signals, case))
            futures = client.compute(delayed_parts)
            if progress:
                from dask.distributed import progress as dask_progress
                dask_progress(futures, notebook=False)
            partitions = futures.result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
        results = [r for part in partitions for r in part]
    else:
        iterator = points
        if progress:
            from tqdm import tqdm
            iterator = tqdm(points, desc=case or "sweep", unit="point")
        results = []
        with Runner(fmu_path) as runner:
            names = signals or default_signals(runner)
            for point in iterator:
                results.append(analyse(runner.run_point(point, names, case), case))
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
