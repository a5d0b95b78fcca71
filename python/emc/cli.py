"""The ``emc`` command: speed sweeps and run-ups with the packaged FMU, tables and plots.

Examples:
    emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 --out out/sweep
    emc sweep ... --set effects.balanceShaft=false --case no-balance-shaft
    emc sweep ... --scheduler tcp://10.0.0.5:8786        # a running Dask cluster
    emc runup --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --duration 10 --out out/runup
"""

from __future__ import annotations

import argparse
import datetime
import difflib
import hashlib
import json
import math
import pathlib
import platform
import re
import sys
import time

import numpy as np
import pandas as pd

from . import plots
from .comfort import comfort_table
from .runner import OperatingPoint, PointFailed, Runner
from .sweep import run_sweep, save, speed_points
from .tracking import track_orders


class UsageError(Exception):
    """A bad option or setting: reported as one line before anything runs."""


# The default of every command: the engine in the elastic body (scene 1 has no steering wheel).
DEFAULT_PARAMETERS = {"scene": 2}
BOOLEAN_SPELLINGS = {"true": True, "1": True, "yes": True, "on": True,
                     "false": False, "0": False, "no": False, "off": False}
HIGHEST_ORDER = 6.5  # what the analysis resolves (orders 0.5 … 6 and the band to 6.5)


def model_variables(fmu: str) -> dict:
    """The FMU's variables by name (from its model description)."""
    from fmpy import read_model_description

    if not pathlib.Path(fmu).is_file():
        raise UsageError(f"--fmu {fmu}: no such file (package it with bash packaging/package.sh)")
    return {v.name: v for v in read_model_description(fmu).modelVariables}


def typed_value(variable, text: str):
    """``text`` as a value of ``variable``, checked against its type and declared range."""
    name = variable.name
    if variable.causality not in ("parameter", "input"):
        raise UsageError(f"--set {name}: a {variable.causality} cannot be set")
    kind = variable.type
    if kind == "Boolean":
        value = BOOLEAN_SPELLINGS.get(text.strip().lower())
        if value is None:
            raise UsageError(f"--set {name}={text}: a Boolean is one of "
                             + "/".join(BOOLEAN_SPELLINGS))
        return value
    if kind == "String":
        return text
    try:
        value = int(text) if kind == "Integer" else float(text)
    except ValueError:
        raise UsageError(f"--set {name}={text}: not a{'n Integer' if kind == 'Integer' else ' Real'}"
                         ) from None
    if not math.isfinite(value):
        raise UsageError(f"--set {name}={text}: must be finite")
    low = None if variable.min is None else float(variable.min)
    high = None if variable.max is None else float(variable.max)
    if (low is not None and value < low) or (high is not None and value > high):
        raise UsageError(f"--set {name}={text}: outside the declared range "
                         f"[{variable.min if low is not None else '-inf'}, "
                         f"{variable.max if high is not None else 'inf'}]")
    return value


def parse_settings(items: list[str], variables: dict) -> dict:
    """``name=value`` items checked against the model description, in order."""
    out = {}
    for item in items or []:
        if "=" not in item:
            raise UsageError(f"--set expects name=value, got {item!r}")
        name, value = (part.strip() for part in item.split("=", 1))
        if name not in variables:
            close = difflib.get_close_matches(name, list(variables), n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise UsageError(f"--set {name}: the FMU has no such variable{hint}")
        out[name] = typed_value(variables[name], value)
    return out


def parse_cases(items: list[str] | None, variables: dict) -> list[tuple[str, dict]]:
    """``--case NAME`` or ``--case NAME:name=value,name=value``; several cases accumulate."""
    cases = []
    for item in items or []:
        label, _, settings = item.partition(":")
        label = label.strip()
        if not label:
            raise UsageError(f"--case {item!r}: a case needs a name")
        if label in [c[0] for c in cases]:
            raise UsageError(f"--case {label!r} given twice")
        cases.append((label, parse_settings([s for s in settings.split(",") if s.strip()],
                                            variables)))
    return cases or [("", {})]


def case_parameters(common: dict, own: dict) -> dict:
    return {**DEFAULT_PARAMETERS, **common, **own}


def start_value(variables: dict, parameters: dict, name: str):
    if name in parameters:
        return parameters[name]
    v = variables.get(name)
    return None if v is None or v.start is None else float(v.start)


def sampling_warnings(variables: dict, parameters: dict, rpm_from: float, rpm_to: float,
                      steps_per_revolution: int | None) -> list[str]:
    """What the chosen sampling and speeds cannot represent: aliasing and speeds beyond what the
    chassis model covers."""
    warnings = []
    scene = int(start_value(variables, parameters, "scene") or 1)
    if steps_per_revolution is not None and steps_per_revolution / 2 <= HIGHEST_ORDER:
        warnings.append(f"--steps-per-rev {steps_per_revolution}: orders above "
                        f"{steps_per_revolution / 2:g} alias onto lower ones, the analysis "
                        f"reaches order {HIGHEST_ORDER:g} (use at least 14; default 72)")
    max_rpm = start_value(variables, parameters, "scene.maxRpm")
    max_order = start_value(variables, parameters, "scene.maxEngineOrder")
    cutoff = start_value(variables, parameters, "chassis.modeCutoff") or 0.0
    if scene == 2 and max_rpm is not None and max_order is not None:
        if cutoff <= 0.0:
            cutoff = max_rpm / 60.0 * max_order * 1.2
            if rpm_to > max_rpm:
                warnings.append(f"speeds up to {rpm_to:g} rpm exceed scene.maxRpm = {max_rpm:g}: "
                                f"the automatic chassis cut-off ({cutoff:.0f} Hz) covers order "
                                f"{max_order:g} only up to {max_rpm:g} rpm (--set "
                                f"scene.maxRpm={rpm_to:g})")
        elif max_order * rpm_to / 60.0 > cutoff:
            warnings.append(f"order {max_order:g} at {rpm_to:g} rpm is "
                            f"{max_order * rpm_to / 60:.0f} Hz, above chassis.modeCutoff = "
                            f"{cutoff:g} Hz: the body's response there is missing")
        if steps_per_revolution is not None:
            nyquist = steps_per_revolution * rpm_from / 60.0 / 2.0
            if nyquist < cutoff:
                warnings.append(f"at {rpm_from:g} rpm, {steps_per_revolution} samples per "
                                f"revolution resolve {nyquist:.0f} Hz; body modes up to the "
                                f"{cutoff:.0f} Hz cut-off alias into the spectrum")
    return warnings


def warn(lines: list[str]):
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)


def check_range(name: str, value, low=None, high=None, strict_low=False):
    bad = ((low is not None and (value <= low if strict_low else value < low))
           or (high is not None and value > high) or not math.isfinite(value))
    if bad:
        bound = (f"> {low}" if strict_low else f">= {low}") if low is not None else ""
        bound += (" and " if bound and high is not None else "") + (f"<= {high}" if high is not None else "")
        raise UsageError(f"{name} must be {bound}, got {value}")


def check_speeds(rpm: list[float]):
    check_range("--rpm FROM", rpm[0], 0.0, 6000.0, strict_low=True)
    check_range("--rpm TO", rpm[1], 0.0, 6000.0, strict_low=True)
    if rpm[1] < rpm[0]:
        raise UsageError(f"--rpm FROM TO must not decrease, got {rpm[0]:g} {rpm[1]:g}")


def write_metadata(out: pathlib.Path, args, variables: dict, cases: list[tuple[str, dict]],
                   extra: dict | None = None):
    """metadata.json: which FMU (checksum), which non-default parameters per case, the command,
    the package versions and the date: what a result in a report must be traceable to."""
    from importlib import metadata as importlib_metadata

    from fmpy import read_model_description

    fmu = args.fmu
    with open(fmu, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    md = read_model_description(fmu)

    def non_default(parameters: dict) -> dict:
        changed = {}
        for name, value in parameters.items():
            v = variables.get(name)
            start = None if v is None else v.start
            if v is not None and v.type == "Boolean" and isinstance(start, str):
                start = start.lower() == "true"
            try:
                same = start is not None and type(value)(start) == value
            except (TypeError, ValueError):
                same = False
            if not same:
                changed[name] = value
        return changed

    def version(package: str) -> str | None:
        try:
            return importlib_metadata.version(package)
        except importlib_metadata.PackageNotFoundError:
            return None

    record = {
        "fmu": {"path": str(pathlib.Path(fmu).resolve()), "sha256": digest, "guid": md.guid,
                "generationDateAndTime": md.generationDateAndTime, "modelName": md.modelName},
        "cases": {label: non_default(params) for label, params in cases},
        "command": args.command_line,
        "versions": {"python": platform.python_version(),
                     **{p: version(p) for p in ("emc", "fmpy", "numpy", "pandas", "dask",
                                                "distributed", "matplotlib")}},
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        **(extra or {}),
    }
    (out / "metadata.json").write_text(json.dumps(record, indent=2, default=str) + "\n")


def reduction_notice(parameters: dict, variables: dict):
    if int(start_value(variables, parameters, "scene") or 1) == 2:
        print("note: the first run of a chassis configuration reduces the body (seconds to "
              "minutes); later runs read it from the cache", file=sys.stderr)


def units_of(variables: dict) -> dict:
    return {name: v.unit for name, v in variables.items()}


def start_options(args) -> dict:
    """How each speed point starts: on the periodic steady state, or settled after a fade-in."""
    # A periodic response is resolved exactly by whole working cycles: 8 revolutions (4 cycles)
    # put every half order on a bin without leakage. After a settle the longer window averages
    # what is left of the transients.
    if args.start == "periodic":
        if args.settle is not None:
            raise UsageError("--settle applies to --start settle only (a periodic start has no "
                             "transient to wait for)")
        options = {"periodic": True, "settle_revolutions": 0, "revolutions": 8}
    else:
        settle = 20 if args.settle is None else args.settle
        if settle < 0:
            raise UsageError(f"--settle must be >= 0, got {settle}")
        options = {"periodic": False, "settle_revolutions": settle, "revolutions": 40}
    if args.revolutions is not None:
        if args.revolutions < 2 or args.revolutions % 2:
            raise UsageError(f"--revolutions must be even and >= 2, got {args.revolutions}")
        options["revolutions"] = args.revolutions
    return options


def add_start_options(p):
    p.add_argument("--start", choices=("periodic", "settle"), default="periodic",
                   help="periodic (default): each point starts on its periodic steady state and "
                        "simulates only the window; settle: fade the excitation in and wait "
                        "--settle revolutions")
    p.add_argument("--settle", type=int, default=None,
                   help="revolutions before the window with --start settle (default 20)")


def safe_name(signal: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", re.sub(r"\[(\d+)\]", r"\1", signal)).strip("_")


def prepare(args, cases_wanted: bool = True):
    """Checks the FMU, every --set and --case against its model description and the numeric
    options, before anything runs. Returns (variables, [(case, parameters)])."""
    variables = model_variables(args.fmu)
    common = parse_settings(args.set, variables)
    own_cases = parse_cases(getattr(args, "case", None), variables) if cases_wanted else [("", {})]
    for signal in getattr(args, "signal", None) or []:
        if signal not in variables or variables[signal].causality != "output":
            close = difflib.get_close_matches(signal, [n for n, v in variables.items()
                                                       if v.causality == "output"], n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise UsageError(f"--signal {signal}: not an output of the FMU{hint}")
    cases = [(label, case_parameters(common, own)) for label, own in own_cases]
    return variables, cases


def cmd_sweep(args) -> int:
    check_speeds(args.rpm)
    check_range("--count", args.count, 1)
    check_range("--steps-per-rev", args.steps_per_rev, 4, 10000)
    check_range("--workers", args.workers, 1)
    options = start_options(args)
    variables, cases = prepare(args)
    for _, parameters in cases:
        warn(sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                               args.steps_per_rev))
    reduction_notice(cases[0][1], variables)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    tables = []
    for label, parameters in cases:
        points = speed_points(args.rpm[0], args.rpm[1], args.count,
                              steps_per_revolution=args.steps_per_rev,
                              load_torque=args.load_torque,
                              parameters=tuple(parameters.items()), **options)
        tables.append(run_sweep(args.fmu, points, signals=args.signal or None, case=label,
                                parallel=not args.serial, scheduler=args.scheduler,
                                workers=args.workers, progress=not args.quiet))
    elapsed = time.perf_counter() - started
    orders = pd.concat([t[0] for t in tables], ignore_index=True)
    spectra = pd.concat([t[1] for t in tables], ignore_index=True)
    suffix = ".parquet" if args.parquet else ".csv"
    save(orders, str(out / f"orders{suffix}"))
    save(spectra, str(out / f"spectra{suffix}"))
    units = units_of(variables)
    labels = [label for label, _ in cases]
    for signal in args.plot or sorted(orders.signal.unique())[:1]:
        name = safe_name(signal)
        if len(cases) == 1:
            plots.waterfall(spectra, signal, str(out / f"waterfall_{name}.png"), unit=units.get(signal))
            plots.order_cuts(orders, signal, str(out / f"order_cuts_{name}.png"), unit=units.get(signal))
        else:
            plots.side_by_side(spectra, orders, signal, labels, str(out / f"waterfall_{name}.png"),
                               str(out / f"order_cuts_{name}.png"), unit=units.get(signal))
    exposure = comfort_table(spectra)
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"))
    write_metadata(out, args, variables, cases,
                   {"speeds": {"from": args.rpm[0], "to": args.rpm[1], "count": args.count},
                    "start": options, "steps_per_revolution": args.steps_per_rev})
    print(f"{len(cases) * args.count} points in {elapsed:.1f} s -> {out}")
    return 0


def cmd_runup(args) -> int:
    check_speeds(args.rpm)
    check_range("--duration", args.duration, 0.0, strict_low=True)
    check_range("--step", args.step, 0.0, 0.01, strict_low=True)
    variables, cases = prepare(args, cases_wanted=False)
    parameters = cases[0][1]
    # The tracked spectrum needs the outputs sampled finely enough at the top speed.
    samples_per_revolution = 60.0 / args.rpm[1] / args.step
    warn(sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                           int(samples_per_revolution)))
    reduction_notice(parameters, variables)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    signals = args.signal or ["mount[1].F[3]"]
    bar = None
    if not args.quiet:
        from tqdm import tqdm
        bar = tqdm(total=100, desc="run-up", unit="%")
    last = [0]

    def progress(fraction):
        if bar is not None:
            bar.update(int(round(100 * fraction)) - last[0])
            last[0] = int(round(100 * fraction))

    try:
        with Runner(args.fmu) as runner:
            result = runner.run_up(args.rpm[0], args.rpm[1], args.duration, signals, step=args.step,
                                   start_values=parameters, progress=progress)
    finally:
        if bar is not None:
            bar.close()
    table = pd.DataFrame(result["samples"], columns=signals)
    table.insert(0, "crankAngle", result["crank_angle"])
    table.insert(0, "rpm", result["rpm"])
    table.insert(0, "time", np.arange(1, len(table) + 1) * result["dt"])
    suffix = ".parquet" if args.parquet else ".csv"
    save(table, str(out / f"runup{suffix}"))
    # Order tracking: blocks of whole revolutions in the crank-angle domain.
    orders = track_orders(result["crank_angle"], result["rpm"], result["samples"], signals,
                          revolutions_per_block=args.block_revolutions)
    save(orders, str(out / f"runup_orders{suffix}"))
    units = units_of(variables)
    for signal in signals:
        name = safe_name(signal)
        plots.order_map(orders, signal, str(out / f"runup_order_map_{name}.png"),
                        unit=units.get(signal),
                        title=f"{signal}: run-up {args.rpm[0]:g}→{args.rpm[1]:g} rpm in "
                              f"{args.duration:g} s, order-tracked")
        plots.order_cuts(orders, signal, str(out / f"runup_order_cuts_{name}.png"),
                         unit=units.get(signal),
                         title=f"{signal}: run-up order cuts ({args.block_revolutions}-revolution blocks)")
    write_metadata(out, args, variables, cases,
                   {"runup": {"from": args.rpm[0], "to": args.rpm[1], "duration": args.duration,
                              "step": args.step, "block_revolutions": args.block_revolutions}})
    print(f"run-up -> {out}")
    return 0


def cmd_campbell(args) -> int:
    """Campbell diagram: the engine orders against the model's coupled natural frequencies."""
    from . import campbell

    check_speeds(args.rpm)
    variables, cases = prepare(args)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    reduction_notice(cases[0][1], variables)
    tables = [campbell.natural_modes(args.fmu, parameters, case=label)
              for label, parameters in cases]
    modes = pd.concat(tables, ignore_index=True)
    save(modes, str(out / "natural_modes.csv"))
    crossings = pd.concat([campbell.crossings(t, args.rpm[0], args.rpm[1]) for t in tables],
                          ignore_index=True)
    save(crossings, str(out / "crossings.csv"))
    for label, table in zip([c[0] for c in cases], tables):
        suffix = f"_{safe_name(label)}" if label else ""
        campbell.plot(table, args.rpm[0], args.rpm[1], str(out / f"campbell{suffix}.png"),
                      title=f"Campbell diagram{': ' + label if label else ''} "
                            f"({len(table)} natural modes of the linearised model)")
    write_metadata(out, args, variables, cases)
    powertrain = crossings[crossings.powertrain_share >= 0.5]
    print(powertrain.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"Campbell diagram -> {out}")
    return 0


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
    check_speeds(args.rpm)
    check_range("--count", args.count, 1)
    check_range("--workers", args.workers, 1)
    options = start_options(args)
    variables = model_variables(args.fmu)
    common = parse_settings(args.set, variables)
    for name, params in cases.items():
        for key in params:
            if key not in variables:
                raise UsageError(f"this FMU lacks {key}, which case {name!r} needs")
    study = [(name, case_parameters(common, params)) for name, params in cases.items()]
    warn(sampling_warnings(variables, study[0][1], args.rpm[0], args.rpm[1], 72))
    reduction_notice(study[0][1], variables)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tables = []
    started = time.perf_counter()
    for case, params in study:
        points = speed_points(args.rpm[0], args.rpm[1], args.count,
                              parameters=tuple(params.items()), **options)
        tables.append(run_sweep(args.fmu, points, signals=args.signal or STUDY_SIGNALS, case=case,
                                parallel=not args.serial, scheduler=args.scheduler,
                                workers=args.workers, progress=not args.quiet))
    orders = pd.concat([t[0] for t in tables], ignore_index=True)
    spectra = pd.concat([t[1] for t in tables], ignore_index=True)
    suffix = ".parquet" if args.parquet else ".csv"
    save(orders, str(out / f"orders{suffix}"))
    save(spectra, str(out / f"spectra{suffix}"))
    units = units_of(variables)
    for signal in args.signal or STUDY_PLOTS:
        name = safe_name(signal)
        plots.side_by_side(spectra, orders, signal, list(cases),
                           str(out / f"study_waterfall_{name}.png"),
                           str(out / f"study_order_cuts_{name}.png"), unit=units.get(signal))
    exposure = comfort_table(spectra)
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"))
        comfort_summary = exposure.groupby("case", sort=False)[["wheel_ahv", "seat_av_comfort"]]
        print("weighted steering-wheel a_hv and seat a_v [m/s²], mean and maximum over the speeds:")
        print(comfort_summary.agg(["mean", "max"]).to_string(float_format=lambda v: f"{v:.3g}"))
    write_metadata(out, args, variables, study, {"start": options})
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


def cmd_bench_effects(args) -> int:
    from .bench import effects_table

    table = effects_table(args.fmu, scenes=args.scene, rpm=args.rpm_point, seconds=args.seconds,
                          signal=args.signal_name)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if args.out:
        save(table, args.out)
    return 0


def cmd_bench_realtime(args) -> int:
    from .bench import realtime_table

    table = realtime_table(args.fmu, rpm=args.rpm_point, seconds=args.seconds, repeats=args.repeats)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="emc", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("--fmu", default="dist/EngineMountChassis.fmu")
        p.add_argument("--rpm", nargs=2, type=float, default=[800.0, 2500.0], metavar=("FROM", "TO"))
        p.add_argument("--signal", action="append", help="output to analyse (repeatable)")
        p.add_argument("--set", action="append", metavar="NAME=VALUE",
                       help="FMU start value for every case, e.g. effects.balanceShaft=off "
                            "(repeatable; checked against the model description; default scene=2)")
        p.add_argument("--out", required=True)
        p.add_argument("--parquet", action="store_true", help="write Parquet instead of CSV")
        p.add_argument("--quiet", action="store_true", help="no progress bars")

    def parallel_options(p):
        p.add_argument("--serial", action="store_true", help="no Dask")
        p.add_argument("--workers", type=int, default=2)
        p.add_argument("--scheduler", help="address of a running Dask scheduler (the FMU is sent "
                                           "to the workers by content)")

    s = sub.add_parser("sweep", help="constant-speed points on their periodic steady state")
    common(s)
    s.add_argument("--count", type=int, default=18)
    s.add_argument("--revolutions", type=int, default=None,
                   help="analysed window (even; default 8 with a periodic start, 40 after a settle)")
    add_start_options(s)
    s.add_argument("--steps-per-rev", type=int, default=72)
    s.add_argument("--load-torque", type=float, default=0.0)
    s.add_argument("--case", action="append", metavar="NAME[:NAME=VALUE,...]",
                   help="a case with its own settings (repeatable: cases accumulate and overlay)")
    s.add_argument("--plot", action="append", help="signal to plot (default: the first)")
    parallel_options(s)
    s.set_defaults(func=cmd_sweep)

    r = sub.add_parser("runup", help="slow linear run-up with continuous speed input, "
                                     "order-tracked in the crank-angle domain")
    common(r)
    r.add_argument("--duration", type=float, default=10.0)
    r.add_argument("--step", type=float, default=2e-4)
    r.add_argument("--block-revolutions", type=int, default=4,
                   help="revolutions per order-tracking block (even)")
    r.set_defaults(func=cmd_runup)

    c = sub.add_parser("campbell", help="Campbell diagram: engine orders against the model's "
                                        "natural frequencies, crossings listed")
    common(c)
    c.add_argument("--case", action="append", metavar="NAME[:NAME=VALUE,...]",
                   help="a case with its own settings (one diagram each)")
    c.set_defaults(func=cmd_campbell)

    studies = [("study-mounts", "paper §7.1: 4 mounts vs 3 mounts + stiffening bar (scene 2; "
                                "--each: every change alone and all three)", cmd_study_mounts),
               ("study-engines", "inline-3 (M13) vs the inline-4 it replaced, with and without Lanchester "
                                 "shafts (scene 2)", cmd_study_engines)]
    for name, help_text, func in studies:
        m = sub.add_parser(name, help=help_text)
        common(m)
        m.add_argument("--count", type=int, default=18)
        m.add_argument("--revolutions", type=int, default=None,
                       help="analysed window (even; default 8 with a periodic start, 40 after a settle)")
        add_start_options(m)
        parallel_options(m)
        if name == "study-mounts":
            m.add_argument("--each", action="store_true",
                           help="the original, each improvement alone (mount removed, bar, stiffer "
                                "front plate) and all three")
        m.set_defaults(func=func)

    b = sub.add_parser("bench-effects", help="CPU time per simulated second for each scene and effect set")
    b.add_argument("--fmu", default="dist/EngineMountChassis.fmu")
    b.add_argument("--scene", type=int, action="append", help="scene(s) to measure (default 1)")
    b.add_argument("--rpm-point", type=float, default=2000.0)
    b.add_argument("--seconds", type=float, default=1.0, help="simulated time per case")
    b.add_argument("--signal-name", default="mount[1].F[3]", help="signal whose RMS is reported")
    b.add_argument("--out", help="also write the table (CSV or .parquet)")
    b.set_defaults(func=cmd_bench_effects)

    r = sub.add_parser("bench-realtime", help="the FMU's speed through fmpy's low-level doStep + getReal "
                                              "loop (1 ms step, every output read every step)")
    r.add_argument("--fmu", default="dist/EngineMountChassis.fmu")
    r.add_argument("--rpm-point", type=float, default=2000.0)
    r.add_argument("--seconds", type=float, default=1.0, help="simulated time per window")
    r.add_argument("--repeats", type=int, default=3, help="windows per case (the range is reported)")
    r.set_defaults(func=cmd_bench_realtime)

    args = parser.parse_args(argv)
    args.command_line = ["emc"] + list(sys.argv[1:] if argv is None else argv)
    if getattr(args, "scene", None) is None and args.command == "bench-effects":
        args.scene = [1]
    try:
        return args.func(args)
    except UsageError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except PointFailed as failure:
        print(failure.report(), file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
