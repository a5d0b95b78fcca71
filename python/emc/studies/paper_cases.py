"""``emc study-mounts`` and ``emc study-engines``: the paper's comparisons from one command,
each case swept and drawn side by side on common scales."""

from __future__ import annotations

import functools
import time

from ..base.checks import (analysed_signals, case_parameters, check_count, check_pool, check_speeds,
                           parse_settings, sampling_warnings, start_options)
from ..base.errors import UsageError
from ..base.fmu import highest_speed, model_variables, units_of
from ..base.outputs import claim, reduction_notice, safe_name, save, warn_cases, write_metadata
from ..figures import draw_all, preload_figures
from ..running.engine import point_engine
from ..running.sweep_cases import sweep_cases, table_jobs
from ..signals.comfort import comfort_table

STUDY_CASES = {
    "4 mounts": {},
    "3 mounts + stiffening bar": {"configFile": "vehicle_three_mounts.json",
                                  "chassis.stiffeningBar": True},
}

# Paper §7.1, each change alone and all together: the rear right mount removed (the preloads of
# the other three carry the weight), the transverse bar, the stiffer front plate under the
# steering column.
IMPROVEMENT_CASES = {
    "original": {},
    "rear right mount removed": {"configFile": "vehicle_three_mounts.json"},
    "stiffening bar": {"chassis.stiffeningBar": True},
    "stiffer front plate": {"chassis.stiffFrontPlate": True},
    "all three (improved vehicle)": {"configFile": "vehicle_three_mounts.json",
                                     "chassis.stiffeningBar": True,
                                     "chassis.stiffFrontPlate": True},
}

# The M13 inline-3 against the inline-4 it replaced (paper §1), in the same body on the same mounts.
ENGINE_CASES = {
    "inline-3 (M13)": {},
    "inline-4": {"configFile": "vehicle_i4.json"},
    "inline-4 + Lanchester shafts": {"configFile": "vehicle_i4_lanchester.json"},
}


def cmd_study_mounts(args) -> int:
    """Paper §7.1: the original vehicle against the improved one, from one command."""
    return run_study(args, IMPROVEMENT_CASES if args.each else STUDY_CASES)


def cmd_study_engines(args) -> int:
    """The inline-3 against the inline-4 (with and without Lanchester shafts), side by side."""
    return run_study(args, ENGINE_CASES)


def run_study(args, cases: dict) -> int:
    """Sweeps each case and writes side-by-side waterfalls and overlaid order cuts on common
    scales."""
    check_count(args.count)
    check_pool(args)
    options = start_options(args)
    variables = model_variables(args.fmu)
    check_speeds(args.rpm, increasing=args.count > 1, highest=highest_speed(variables))
    common = parse_settings(args.set, variables)
    for name, params in cases.items():
        for key in params:
            if key not in variables:
                raise UsageError(f"this FMU lacks {key}, which case {name!r} needs")
    signals = analysed_signals(args, variables, STUDY_SIGNALS)
    study = [(name, case_parameters(common, params)) for name, params in cases.items()]
    with point_engine(args, study, len(study) * args.count) as engine:
        # After the pool's workers are forked: none inherits a half-done import.
        preload_figures()
        cutoffs = engine.cutoffs(args.fmu, study)
        warn_cases([(label, sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                                              72, cutoff=cutoff))
                    for (label, parameters), cutoff in zip(study, cutoffs)])
        reduction_notice(study[0][1], variables)
        out = claim(args)
        started = time.perf_counter()
        orders, spectra, fmu_warnings = sweep_cases(args, study, signals, out, options, engine)
    from ..figures import plots  # deferred: loaded in the background meanwhile (start-up time)

    suffix = ".parquet" if args.parquet else ".csv"
    units = units_of(variables)
    jobs = [functools.partial(plots.side_by_side, spectra, orders, signal, list(cases),
                              str(out / f"study_waterfall_{safe_name(signal)}.png"),
                              str(out / f"study_order_cuts_{safe_name(signal)}.png"),
                              unit=units.get(signal))
            for signal in args.signal or STUDY_PLOTS]
    exposure = comfort_table(spectra)
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        jobs.append(functools.partial(plots.comfort, exposure, str(out / "comfort.png"),
                                      cases=list(cases)))
    draw_all(jobs[:1] + table_jobs(args, out, orders, spectra) + jobs[1:])
    if not exposure.empty:
        comfort_summary = exposure.groupby("case", sort=False)[["wheel_ahv", "seat_av_comfort"]]
        print("weighted steering-wheel a_hv and seat a_v [m/s²], mean and maximum over the speeds:")
        print(comfort_summary.agg(["mean", "max"]).to_string(float_format=lambda v: f"{v:.3g}"))
    write_metadata(out, args, variables, study,
                   {"speeds": {"from": args.rpm[0], "to": args.rpm[1], "count": args.count},
                    "start": options, "signals": signals}, fmu_warnings)
    summary = (orders[orders.order.isin([1.0, 1.5, 2.0, 4.0])]
               .groupby(["signal", "case", "order"]).amplitude.max().unstack("order"))
    print(summary.to_string(float_format=lambda v: f"{v:.4g}"))
    print(f"study in {time.perf_counter() - started:.1f} s -> {out}")
    return 0


# Recorded in a study: what the comfort values need (all axes of the steering wheel and the
# seat) and the front left mount; plotted: the steering wheel's z and y and that mount.
STUDY_SIGNALS = ([f"steeringWheel.a[{i}]" for i in (1, 2, 3)] + [f"seat.a[{i}]" for i in (1, 2, 3)]
                 + ["mount[1].F[3]"])
STUDY_PLOTS = ["steeringWheel.a[3]", "steeringWheel.a[2]", "mount[1].F[3]"]
