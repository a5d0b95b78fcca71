"""``emc sweep``: constant-speed points over a speed range, for each case (and at the damping
band's bounds), into order and spectrum tables, waterfalls, order cuts and comfort values."""

from __future__ import annotations

import functools
import pathlib
import time

import pandas as pd

from ..base.checks import (analysed_signals, check_count, check_pool, check_range, check_speeds,
                           prepare, sampling_warnings, start_options)
from ..base.fmu import default_signals, highest_speed, units_of
from ..base.outputs import (claim, fmu_warnings_summary, reduction_notice, safe_name, save,
                            warn_cases, write_metadata)
from ..figures import draw_all, preload_figures
from ..signals.comfort import comfort_table
from . import band as bands
from .engine import PointEngine, point_engine
from .sweep import run_sweep, speed_points


def sweep_cases(args, cases: list[tuple[str, dict]], signals: list[str], out: pathlib.Path,
                point_options: dict, engine: PointEngine, band: bands.Band | None = None
                ) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """Every case's speed points on the ``engine``, at the band's three bounds if a band is given
    (a ``bound`` column then), the FMU's warnings summarised; returns (orders, spectra, FMU
    warnings), to be written by :func:`table_jobs`."""
    fmu_warnings: list[str] = []

    def run(_settings: dict, bound: str | None = None):
        tables = []
        for label, parameters in cases:
            if bound is not None:
                parameters = band.applied(parameters, bound)
            points = speed_points(args.rpm[0], args.rpm[1], args.count,
                                  parameters=tuple(parameters.items()), **point_options)
            tables.append(run_sweep(args.fmu, points, signals=signals, case=label,
                                    progress=not args.quiet, warnings=fmu_warnings, pool=engine.pool,
                                    runner=engine.runner))
        return (pd.concat([t[0] for t in tables], ignore_index=True),
                pd.concat([t[1] for t in tables], ignore_index=True))

    if band is None:
        orders, spectra = run({})
    else:
        result = bands.run_band(run, band)
        orders, spectra = result.stack(0), result.stack(1)
    fmu_warnings_summary(fmu_warnings)
    return orders, spectra, fmu_warnings


def table_jobs(args, out: pathlib.Path, orders: pd.DataFrame, spectra: pd.DataFrame) -> list:
    """Writing the order and spectrum tables, as jobs for :func:`emc.figures.draw_all` (beside the
    figures: a 48-point sweep's spectrum table takes 0.15 s to write)."""
    suffix = ".parquet" if args.parquet else ".csv"
    return [functools.partial(save, orders, str(out / f"orders{suffix}")),
            functools.partial(save, spectra, str(out / f"spectra{suffix}"))]


def cmd_sweep(args) -> int:
    check_count(args.count)
    check_range("--steps-per-rev", args.steps_per_rev, 4, 10000)
    check_pool(args)
    check_range("--load-torque", args.load_torque)
    options = start_options(args)
    variables, cases = prepare(args)
    band = bands.band_of(args, variables, cases)
    check_speeds(args.rpm, increasing=args.count > 1, highest=highest_speed(variables))
    signals = analysed_signals(args, variables, default_signals(variables))
    runs = bands.run_count(band, len(cases) * args.count)
    with point_engine(args, cases, runs) as engine:
        # After the pool's workers are forked: none inherits a half-done import.
        preload_figures()
        cutoffs = engine.cutoffs(args.fmu, cases)
        warn_cases([(label, sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                                              args.steps_per_rev, cutoff=cutoff))
                    for (label, parameters), cutoff in zip(cases, cutoffs)])
        reduction_notice(cases[0][1], variables)
        out = claim(args)
        started = time.perf_counter()
        orders, spectra, fmu_warnings = sweep_cases(
            args, cases, signals, out, {**options, "steps_per_revolution": args.steps_per_rev,
                                        "load_torque": args.load_torque}, engine, band)
        elapsed = time.perf_counter() - started
    from ..figures import plots  # deferred: loaded in the background meanwhile (start-up time)

    suffix = ".parquet" if args.parquet else ".csv"
    units = units_of(variables)
    labels = [label for label, _ in cases]
    tables = table_jobs(args, out, orders, spectra)
    if band is not None:
        draw_all(tables)  # the tables first, whatever the band's report meets
        tables = []
        bands.report_sweep(out, band, orders, spectra, signals, args.plot or signals[:1], units,
                           suffix)
    jobs = []
    for signal in [] if band is not None else args.plot or signals[:1]:
        name, unit = safe_name(signal), units.get(signal)
        if len(cases) == 1:
            jobs += [functools.partial(plots.waterfall, spectra, signal,
                                       str(out / f"waterfall_{name}.png"), unit=unit),
                     functools.partial(plots.order_cuts, orders, signal,
                                       str(out / f"order_cuts_{name}.png"), unit=unit)]
        else:
            jobs.append(functools.partial(plots.side_by_side, spectra, orders, signal, labels,
                                          str(out / f"waterfall_{name}.png"),
                                          str(out / f"order_cuts_{name}.png"), unit=unit))
    exposure = comfort_table(spectra) if band is None else pd.DataFrame()
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        jobs.append(functools.partial(plots.comfort, exposure, str(out / "comfort.png"),
                                      cases=labels))
    # The first figure (a waterfall, the costliest) in this process, the rest beside it.
    draw_all(jobs[:1] + tables + jobs[1:])
    write_metadata(out, args, variables, cases,
                   {"speeds": {"from": args.rpm[0], "to": args.rpm[1], "count": args.count},
                    "start": options, "steps_per_revolution": args.steps_per_rev,
                    "load_torque": args.load_torque, "signals": signals,
                    **bands.band_metadata(band)},
                   fmu_warnings)
    print(f"{runs} points in {elapsed:.1f} s -> {out}")
    return 0
