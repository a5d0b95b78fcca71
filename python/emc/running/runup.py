"""``emc runup``: a slow linear run-up with the speed given continuously, order-tracked in the
crank-angle domain, for each case (and at the damping band's bounds)."""

from __future__ import annotations

import sys
import time

import numpy as np
import pandas as pd
from tqdm import tqdm

from ..base.checks import (analysed_signals, check_range, check_revolutions, check_speeds, prepare,
                           sampling_warnings)
from ..base.errors import UsageError
from ..base.fmu import highest_speed, units_of
from ..base.outputs import (claim, fmu_warnings_summary, reduction_notice, safe_name, save,
                            warn_cases, write_metadata)
from ..figures import plots
from ..signals.tracking import track_orders
from . import band as bands
from .runner import Runner, cutoffs_in_use


def cmd_runup(args) -> int:
    check_range("--duration", args.duration, 0.0, strict_low=True)
    check_range("--step", args.step, 0.0, 0.01, strict_low=True)
    check_range("--load-torque", args.load_torque)
    check_revolutions(args.block_revolutions, "--block-revolutions")
    variables, cases = prepare(args)
    band = bands.band_of(args, variables, cases)
    check_speeds(args.rpm, increasing=True, highest=highest_speed(variables))
    revolutions = (args.rpm[0] + args.rpm[1]) / 2.0 / 60.0 * args.duration
    if revolutions < 2 * args.block_revolutions:
        raise UsageError(f"a run-up of {args.duration:g} s turns the crank {revolutions:.1f} "
                         f"times: too few for blocks of {args.block_revolutions} revolutions "
                         "(lengthen --duration)")
    if round(args.duration / args.step) < 2:
        raise UsageError(f"--step {args.step:g} s: fewer than 2 steps in --duration "
                         f"{args.duration:g} s")
    signals = analysed_signals(args, variables, ["mount[1].F[3]"])
    periodic = args.start == "periodic" and "initialization.periodic" in variables
    warn_cases([(label, sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                                          step=args.step, cutoff=cutoff))
                for (label, parameters), cutoff in zip(cases, cutoffs_in_use(args.fmu, cases))])
    reduction_notice(cases[0][1], variables)
    out = claim(args)
    started = time.perf_counter()
    records, tracked, fmu_warnings = [], [], []
    runs = [(label, bound if band is not None else None, bands.settings_at(band, parameters, bound))
            for bound in bands.bounds_of(band) for label, parameters in cases]
    for label, bound, parameters in runs:
        start_values = {**parameters, "loadTorque": args.load_torque}
        if periodic:
            # Start on the periodic steady state at FROM: no fade-in transient at the start.
            start_values["initialization.periodic"] = True
        result = run_up(args, signals, start_values, label, bound)
        fmu_warnings += result["warnings"]
        table = pd.DataFrame(result["samples"], columns=signals)
        table.insert(0, "crankAngle", result["crank_angle"])
        table.insert(0, "rpm", result["rpm"])
        table.insert(0, "time", np.arange(1, len(table) + 1) * result["dt"])
        table.insert(0, "case", label)
        # Order tracking: blocks of whole revolutions in the crank-angle domain.
        orders_of_run = track_orders(result["crank_angle"], result["rpm"], result["samples"],
                                     signals, revolutions_per_block=args.block_revolutions,
                                     case=label)
        if bound is not None:
            table, orders_of_run = (bands.with_bound(t, bound) for t in (table, orders_of_run))
        records.append(table)
        tracked.append(orders_of_run)
    elapsed = time.perf_counter() - started
    fmu_warnings_summary(fmu_warnings)
    suffix = ".parquet" if args.parquet else ".csv"
    save(pd.concat(records, ignore_index=True), str(out / f"runup{suffix}"))
    orders = pd.concat(tracked, ignore_index=True)
    save(orders, str(out / f"runup_orders{suffix}"))
    units = units_of(variables)
    labels = [label for label, _ in cases]
    rate = (args.rpm[1] - args.rpm[0]) / args.duration
    what = (f"run-up {args.rpm[0]:g}→{args.rpm[1]:g} rpm in {args.duration:g} s "
            f"({rate:.0f} rpm/s),\norder-tracked in {args.block_revolutions}-revolution blocks")
    if band is not None:
        bands.report_runup(out, band, orders, args.plot or signals, units, what, suffix)
    for signal in [] if band is not None else args.plot or signals:
        name = safe_name(signal)
        plots.order_map(orders, signal, str(out / f"runup_order_map_{name}.png"),
                        unit=units.get(signal), cases=labels,
                        title=f"{signal}: order map of a {what}")
        plots.order_cuts(orders, signal, str(out / f"runup_order_cuts_{name}.png"),
                         unit=units.get(signal), title=f"{signal}: order cuts of a {what}",
                         cases=labels)
    write_metadata(out, args, variables, cases,
                   {"runup": {"from": args.rpm[0], "to": args.rpm[1], "duration": args.duration,
                              "step": args.step, "block_revolutions": args.block_revolutions,
                              "start": "periodic" if periodic else "fade-in",
                              "load_torque": args.load_torque, "signals": signals},
                    **bands.band_metadata(band)},
                   fmu_warnings)
    print(f"{len(runs)} run-up(s) in {elapsed:.1f} s -> {out}")
    return 0


def run_up(args, signals: list[str], start_values: dict, case: str,
           bound: str | None = None) -> dict:
    """One run-up with a progress bar over the simulated time."""
    bar = None
    if not args.quiet:
        desc = " ".join(x for x in (case, bound and f"{bound} damping") if x) or "run-up"
        bar = tqdm(total=args.duration, desc=desc, unit="s", file=sys.stderr,
                   bar_format="{l_bar}{bar}| {n:.2f}/{total:g} s simulated [{elapsed}<{remaining}]")

    def progress(simulated: float):
        if bar is not None:
            bar.update(simulated - bar.n)

    try:
        with Runner(args.fmu) as runner:
            return runner.run_up(args.rpm[0], args.rpm[1], args.duration, signals,
                                 step=args.step, start_values=start_values, progress=progress,
                                 case=case)
    finally:
        if bar is not None:
            bar.close()
