"""The ``emc`` command: speed sweeps and run-ups with the packaged FMU, tables and plots.

Examples:
    emc sweep --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --count 18 --out out/sweep
    emc sweep ... --case "with shaft" --case "no shaft:effects.balanceShaft=off"
    emc sweep ... --scheduler tcp://10.0.0.5:8786        # a running Dask cluster
    emc runup --fmu dist/EngineMountChassis.fmu --rpm 800 2500 --duration 20 --out out/runup
    emc accuracy --set configFile=/path/my_car.json --out out/accuracy  # what accuracy costs
    emc tpa --rpm 800 2500 --at 1100 --order 1.5 --out out/tpa   # which mount path carries it
    emc frf / emc ods --rpm-point 1100 / emc decoupling --out ...  # transfer functions, shapes, mounts

Every command runs scene 2 (the engine in the elastic body) unless --set scene=1. A case is
--case NAME or --case NAME:name=value,name=value (repeatable; the common --set values apply to
every case, a case's own settings on top). Settings are checked against the FMU's model
description before anything runs.
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

from . import band as bands
from . import plots
from .comfort import comfort_table
from .runner import PointFailed, Runner, keep_freed_memory
from .sweep import DEFAULT_SIGNAL_PREFIXES, run_sweep, save, speed_points
from .tracking import track_orders


class UsageError(Exception):
    """A bad option or setting: reported as one line before anything runs."""


# The default of every command: the engine in the elastic body (scene 1 has no steering wheel).
DEFAULT_PARAMETERS = {"scene": 2}
BOOLEAN_SPELLINGS = {"true": True, "1": True, "yes": True, "on": True,
                     "false": False, "0": False, "no": False, "off": False}
HIGHEST_ORDER = 6.5  # what the analysis resolves (orders 0.5 … 6 and the band to 6.5)
CUTOFF_IN_USE = "chassis.modeCutoffInUse"
# Inputs and parameters each point's speed, load and start come from: set by the command's own
# options, never by --set (a --set rpm would run every point at that speed, labelled otherwise).
CONTROLLED = {"rpm": "--rpm", "loadTorque": "--load-torque", "initialization.periodic": "--start"}


def model_variables(fmu: str) -> dict:
    """The FMU's variables by name (from its model description)."""
    from fmpy import read_model_description

    if not pathlib.Path(fmu).is_file():
        raise UsageError(f"--fmu {fmu}: no such file (package it with bash packaging/package.sh)")
    return {v.name: v for v in read_model_description(fmu).modelVariables}


def typed_value(variable, text: str, controlled: dict = CONTROLLED):
    """``text`` as a value of ``variable``, checked against its type and declared range
    (``controlled``: names the caller sets itself, refused)."""
    name = variable.name
    if name in controlled:
        raise UsageError(f"--set {name}: emc sets it for every point; use {controlled[name]}")
    if variable.causality not in ("parameter", "input"):
        article = "an" if variable.causality[0] in "aeiou" else "a"
        raise UsageError(f"--set {name}: only parameters and inputs can be set, this is "
                         f"{article} {variable.causality}")
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
        label, colon, settings = item.partition(":")
        label = label.strip()
        if not label or (not colon and "=" in label):
            raise UsageError(f"--case {item!r}: a case needs a name first, "
                             "e.g. --case 'no shaft:effects.balanceShaft=off'")
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


def cutoffs_in_use(fmu: str, cases: list[tuple[str, dict]]) -> list[float | None]:
    """The chassis mode cut-off (Hz) each case's body keeps, as the FMU reports it
    (``chassis.modeCutoffInUse``; None for an FMU without it)."""
    with Runner(fmu) as runner:
        if CUTOFF_IN_USE not in runner.vr:
            return [None for _ in cases]
        return [runner.initial_values(parameters, [CUTOFF_IN_USE])[0] for _, parameters in cases]


def sampling_warnings(variables: dict, parameters: dict, rpm_from: float, rpm_to: float,
                      steps_per_revolution: int | None = None,
                      step: float | None = None, cutoff: float | None = None) -> list[str]:
    """What the chosen sampling and speeds cannot represent: aliasing and speeds beyond what the
    chassis model covers. A sweep samples ``steps_per_revolution`` times per revolution, a run-up
    every ``step`` seconds; ``cutoff`` is the chassis mode cut-off in use (Hz,
    :func:`cutoffs_in_use`)."""
    warnings = []
    scene = int(start_value(variables, parameters, "scene") or 1)
    if step is not None:
        fewest = 60.0 / rpm_to / step            # samples per revolution at the top speed
        rate_low = 1.0 / step                    # Hz, the same at every speed
        knob = f"--step {step:g} s ({fewest:.1f} samples per revolution at {rpm_to:g} rpm)"
        remedy = f"use --step {60.0 / rpm_to / 14:.2g} or less"
    elif steps_per_revolution is not None:
        fewest = float(steps_per_revolution)
        rate_low = steps_per_revolution * rpm_from / 60.0
        knob = f"--steps-per-rev {steps_per_revolution}"
        remedy = "use at least 14; default 72"
    else:
        fewest = rate_low = None
    if fewest is not None and fewest / 2 <= HIGHEST_ORDER:
        warnings.append(f"{knob}: orders above {fewest / 2:.3g} alias onto lower ones, the "
                        f"analysis reaches order {HIGHEST_ORDER:g} ({remedy})")
    max_rpm = start_value(variables, parameters, "scene.maxRpm")
    max_order = start_value(variables, parameters, "scene.maxEngineOrder")
    automatic = (start_value(variables, parameters, "chassis.modeCutoff") or 0.0) <= 0.0
    if scene == 2 and cutoff is not None and max_rpm is not None and max_order is not None:
        if automatic:
            if rpm_to > max_rpm:
                warnings.append(f"speeds up to {rpm_to:g} rpm exceed scene.maxRpm = {max_rpm:g}: "
                                f"the automatic chassis cut-off ({cutoff:.0f} Hz) covers order "
                                f"{max_order:g} only up to {max_rpm:g} rpm (--set "
                                f"scene.maxRpm={rpm_to:g})")
        elif max_order * rpm_to / 60.0 > cutoff:
            warnings.append(f"order {max_order:g} at {rpm_to:g} rpm is "
                            f"{max_order * rpm_to / 60:.0f} Hz, above chassis.modeCutoff = "
                            f"{cutoff:g} Hz: the body's response there is missing")
        if rate_low is not None and rate_low / 2.0 < cutoff:
            warnings.append(f"at {rpm_from:g} rpm, {knob} samples at {rate_low:.0f} Hz and "
                            f"resolves {rate_low / 2:.0f} Hz; body modes up to the {cutoff:.0f} Hz "
                            "cut-off alias into the spectrum")
    return warnings


def warn(lines: list[str]):
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)


def warn_cases(per_case: list[tuple[str, list[str]]]):
    """Each warning once: unlabelled if every case has it, else with the cases it concerns."""
    seen: dict[str, list[str]] = {}
    for label, lines in per_case:
        for line in lines:
            seen.setdefault(line, []).append(label)
    everyone = len(per_case)
    for line, labels in seen.items():
        if len(labels) == everyone or not any(labels):
            warn([line])
        else:
            warn([f"case {', '.join(repr(x) for x in labels)}: {line}"])


def fmu_warnings_summary(lines: list[str], shown: int = 5):
    """The FMU's warnings of successful points, each distinct message once."""
    distinct = list(dict.fromkeys(lines))
    if not distinct:
        return
    print(f"warning: the FMU reported {len(lines)} warning(s), {len(distinct)} distinct:",
          file=sys.stderr)
    for line in distinct[:shown]:
        print(f"  {line}", file=sys.stderr)
    if len(distinct) > shown:
        print(f"  … and {len(distinct) - shown} more (all in metadata.json)", file=sys.stderr)


def check_range(name: str, value, low=None, high=None, strict_low=False):
    bad = ((low is not None and (value <= low if strict_low else value < low))
           or (high is not None and value > high) or not math.isfinite(value))
    if bad:
        bound = (f"> {low}" if strict_low else f">= {low}") if low is not None else ""
        bound += (" and " if bound and high is not None else "") + (f"<= {high}" if high is not None else "")
        raise UsageError(f"{name} must be {bound or 'finite'}, got {value}")


def check_speeds(rpm: list[float], increasing: bool = False, highest: float = 6000.0):
    """FROM and TO positive and at most the FMU's highest speed; TO above FROM where the command
    needs a range (a run-up, a sweep of several points)."""
    check_range("--rpm FROM", rpm[0], 0.0, highest, strict_low=True)
    check_range("--rpm TO", rpm[1], 0.0, highest, strict_low=True)
    if rpm[1] < rpm[0] or (increasing and rpm[1] == rpm[0]):
        need = "increase" if increasing else "not decrease"
        raise UsageError(f"--rpm FROM TO must {need}, got {rpm[0]:g} {rpm[1]:g}")


def write_metadata(out: pathlib.Path, args, variables: dict, cases: list[tuple[str, dict]],
                   extra: dict | None = None, fmu_warnings: list[str] | None = None):
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
                "generationDateAndTime": md.generationDateAndTime, "modelName": md.modelName,
                "fileModified": datetime.datetime.fromtimestamp(
                    pathlib.Path(fmu).stat().st_mtime, datetime.timezone.utc
                ).isoformat(timespec="seconds")},
        # Per case: the parameters that differ from the model description's start values, and
        # every start value emc set (its defaults, the common --set, the case's own).
        "cases": {label: non_default(params) for label, params in cases},
        "settings": {label: dict(params) for label, params in cases},
        "command": args.command_line,
        "versions": {"python": platform.python_version(),
                     **{p: version(p) for p in ("emc", "fmpy", "numpy", "pandas", "dask",
                                                "distributed", "matplotlib")}},
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "fmu_warnings": list(dict.fromkeys(fmu_warnings or [])),
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


def output_names(variables: dict) -> list[str]:
    return [n for n, v in variables.items() if v.causality == "output"]


def check_outputs(option: str, names: list[str], variables: dict, among: list[str] | None = None):
    """Each name an output of the FMU (and, if ``among`` is given, one of those)."""
    outputs = output_names(variables)
    for name in names:
        if name not in variables or variables[name].causality != "output":
            close = difflib.get_close_matches(name, outputs, n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise UsageError(f"{option} {name}: not an output of the FMU{hint}")
        if among is not None and name not in among:
            raise UsageError(f"{option} {name}: not among the analysed signals "
                             f"({', '.join(among)}); add --signal {name}")


def analysed_signals(args, variables: dict, default: list[str]) -> list[str]:
    """--signal (checked), else ``default``; --plot (checked) must be among them."""
    signals = list(dict.fromkeys(getattr(args, "signal", None) or []))
    check_outputs("--signal", signals, variables)
    signals = signals or default
    check_outputs("--plot", getattr(args, "plot", None) or [], variables, among=signals)
    return signals


def default_signals(variables: dict) -> list[str]:
    """What a sweep records without --signal: the mount forces and the comfort points."""
    return [n for n in output_names(variables) if variables[n].type == "Real"
            and n.startswith(DEFAULT_SIGNAL_PREFIXES)]


def check_config_file(fmu: str, parameters: dict, remote: bool = False):
    """A configFile names a file in the FMU's resources (relative) or an existing file (absolute;
    on a Dask cluster the workers' file system counts, so it is not checked there)."""
    import zipfile

    name = str(parameters.get("configFile", "") or "")
    if not name:
        return
    if pathlib.PurePosixPath(name).is_absolute():
        if not remote and not pathlib.Path(name).is_file():
            raise UsageError(f"--set configFile={name}: no such file")
        return
    with zipfile.ZipFile(fmu) as z:
        resources = [n[len("resources/"):] for n in z.namelist()
                     if n.startswith("resources/") and not n.endswith("/")]
    if name not in resources:
        close = difflib.get_close_matches(name, resources, n=3)
        hint = f"did you mean {', '.join(close)}? " if close else ""
        raise UsageError(f"--set configFile={name}: not in the FMU's resources ({hint}"
                         f"available: {', '.join(sorted(resources))}); or give an absolute path")


def prepare(args, cases_wanted: bool = True):
    """Checks the FMU, every --set and --case against its model description, before anything
    runs. Returns (variables, [(case, parameters)])."""
    variables = model_variables(args.fmu)
    common = parse_settings(args.set, variables)
    own_cases = parse_cases(getattr(args, "case", None), variables) if cases_wanted else [("", {})]
    cases = [(label, case_parameters(common, own)) for label, own in own_cases]
    for _, parameters in cases:
        check_config_file(args.fmu, parameters, remote=bool(getattr(args, "scheduler", None)))
    return variables, cases


def highest_speed(variables: dict) -> float:
    rpm = variables.get("rpm")
    return float(rpm.max) if rpm is not None and rpm.max is not None else 6000.0


def sweep_cases(args, cases: list[tuple[str, dict]], signals: list[str], out: pathlib.Path,
                point_options: dict, band: bands.Band | None = None
                ) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """Every case's speed points (serial or on Dask), at the band's three bounds if a band is
    given (a ``bound`` column then), the FMU's warnings summarised, the order and spectrum tables
    of all cases written; returns (orders, spectra, FMU warnings)."""
    from .distributed import FmuPool

    fmu_warnings = []
    # One pool for every case and bound: its workers start and load the FMU once.
    pool = None if args.serial else FmuPool(args.fmu, args.workers, args.scheduler)

    def run(_settings: dict, bound: str | None = None):
        tables = []
        for label, parameters in cases:
            if bound is not None:
                parameters = band.applied(parameters, bound)
            points = speed_points(args.rpm[0], args.rpm[1], args.count,
                                  parameters=tuple(parameters.items()), **point_options)
            tables.append(run_sweep(args.fmu, points, signals=signals, case=label,
                                    parallel=not args.serial, progress=not args.quiet,
                                    warnings=fmu_warnings, pool=pool))
        return (pd.concat([t[0] for t in tables], ignore_index=True),
                pd.concat([t[1] for t in tables], ignore_index=True))

    try:
        if band is None:
            orders, spectra = run({})
        else:
            result = bands.run_band(run, band)
            orders, spectra = result.stack(0), result.stack(1)
    finally:
        if pool is not None:
            pool.close()
    fmu_warnings_summary(fmu_warnings)
    suffix = ".parquet" if args.parquet else ".csv"
    save(orders, str(out / f"orders{suffix}"))
    save(spectra, str(out / f"spectra{suffix}"))
    return orders, spectra, fmu_warnings


def band_of(args, variables: dict, cases: list[tuple[str, dict]]) -> bands.Band | None:
    """The damping band the options ask for, its settings checked like --set values."""
    try:
        band = bands.from_options(args, variables)
    except ValueError as error:
        raise UsageError(str(error)) from None
    if band is not None:
        for _, parameters in cases:
            for bound in ("low", "high"):
                for name in band.settings(bound):
                    typed_value(variables[name], repr(band.applied(parameters, bound)[name]))
    return band


def band_metadata(band: bands.Band | None) -> dict:
    if band is None:
        return {}
    return {"band": {"description": band.description, "low": band.low,
                     "nominal": band.nominal, "high": band.high}}


def cmd_sweep(args) -> int:
    check_range("--count", args.count, 1)
    check_range("--steps-per-rev", args.steps_per_rev, 4, 10000)
    check_range("--workers", args.workers, 1)
    check_range("--load-torque", args.load_torque)
    options = start_options(args)
    variables, cases = prepare(args)
    band = band_of(args, variables, cases)
    check_speeds(args.rpm, increasing=args.count > 1, highest=highest_speed(variables))
    signals = analysed_signals(args, variables, default_signals(variables))
    warn_cases([(label, sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1],
                                          args.steps_per_rev, cutoff=cutoff))
                for (label, parameters), cutoff in zip(cases, cutoffs_in_use(args.fmu, cases))])
    reduction_notice(cases[0][1], variables)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    orders, spectra, fmu_warnings = sweep_cases(
        args, cases, signals, out, {**options, "steps_per_revolution": args.steps_per_rev,
                                    "load_torque": args.load_torque}, band)
    elapsed = time.perf_counter() - started
    suffix = ".parquet" if args.parquet else ".csv"
    units = units_of(variables)
    labels = [label for label, _ in cases]
    if band is not None:
        bands.report_sweep(out, band, orders, spectra, signals, args.plot or signals[:1], units,
                           suffix)
    for signal in [] if band is not None else args.plot or signals[:1]:
        name = safe_name(signal)
        if len(cases) == 1:
            plots.waterfall(spectra, signal, str(out / f"waterfall_{name}.png"), unit=units.get(signal))
            plots.order_cuts(orders, signal, str(out / f"order_cuts_{name}.png"),
                             unit=units.get(signal))
        else:
            plots.side_by_side(spectra, orders, signal, labels, str(out / f"waterfall_{name}.png"),
                               str(out / f"order_cuts_{name}.png"), unit=units.get(signal))
    exposure = comfort_table(spectra) if band is None else pd.DataFrame()
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"), cases=labels)
    write_metadata(out, args, variables, cases,
                   {"speeds": {"from": args.rpm[0], "to": args.rpm[1], "count": args.count},
                    "start": options, "steps_per_revolution": args.steps_per_rev,
                    "load_torque": args.load_torque, "signals": signals,
                    **band_metadata(band)},
                   fmu_warnings)
    runs = len(cases) * args.count * (1 if band is None else len(bands.BOUNDS))
    print(f"{runs} points in {elapsed:.1f} s -> {out}")
    return 0


def cmd_runup(args) -> int:
    check_range("--duration", args.duration, 0.0, strict_low=True)
    check_range("--step", args.step, 0.0, 0.01, strict_low=True)
    check_range("--load-torque", args.load_torque)
    if args.block_revolutions < 2 or args.block_revolutions % 2:
        raise UsageError(f"--block-revolutions must be even and >= 2 (half orders on bins), "
                         f"got {args.block_revolutions}")
    variables, cases = prepare(args)
    band = band_of(args, variables, cases)
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
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    records, tracked, fmu_warnings = [], [], []
    runs = ([(label, None, parameters) for label, parameters in cases] if band is None else
            [(label, bound, band.applied(parameters, bound))
             for bound in bands.BOUNDS for label, parameters in cases])
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
                    **band_metadata(band)},
                   fmu_warnings)
    print(f"{len(runs)} run-up(s) in {elapsed:.1f} s -> {out}")
    return 0


def run_up(args, signals: list[str], start_values: dict, case: str,
           bound: str | None = None) -> dict:
    """One run-up with a progress bar over the simulated time."""
    bar = None
    if not args.quiet:
        from tqdm import tqdm

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
    check_range("--count", args.count, 1)
    check_range("--workers", args.workers, 1)
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
    warn_cases([(label, sampling_warnings(variables, parameters, args.rpm[0], args.rpm[1], 72,
                                          cutoff=cutoff))
                for (label, parameters), cutoff in zip(study, cutoffs_in_use(args.fmu, study))])
    reduction_notice(study[0][1], variables)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    orders, spectra, fmu_warnings = sweep_cases(args, study, signals, out, options)
    suffix = ".parquet" if args.parquet else ".csv"
    units = units_of(variables)
    for signal in args.signal or STUDY_PLOTS:
        name = safe_name(signal)
        plots.side_by_side(spectra, orders, signal, list(cases),
                           str(out / f"study_waterfall_{name}.png"),
                           str(out / f"study_order_cuts_{name}.png"), unit=units.get(signal))
    exposure = comfort_table(spectra)
    if not exposure.empty:
        save(exposure, str(out / f"comfort{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"), cases=list(cases))
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


def cmd_bench_effects(args) -> int:
    from .bench import effects_table

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
    if args.out:
        save(table, args.out)
    return 0


def cmd_bench_realtime(args) -> int:
    from .bench import realtime_table

    table = realtime_table(args.fmu, rpm=args.rpm_point, seconds=args.seconds, repeats=args.repeats)
    with pd.option_context("display.width", 160, "display.max_columns", 20):
        print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    return 0


def runup_options(parser):
    """The run-up's options (``emc runup``, ``emc tpa-runup``): duration, sampling, blocks,
    start and load."""
    parser.add_argument("--duration", type=float, default=20.0,
                        help="s, FROM to TO (default 20)")
    parser.add_argument("--step", type=float, default=2e-4,
                        help="communication step, s: the outputs' sampling (default 2e-4)")
    parser.add_argument("--block-revolutions", type=int, default=4,
                        help="revolutions per order-tracking block (even; default 4)")
    parser.add_argument("--start", choices=("periodic", "fade-in"), default="periodic",
                        help="periodic (default): start on the periodic steady state at FROM; "
                             "fade-in: from the static equilibrium, the excitation faded in")
    parser.add_argument("--load-torque", type=float, default=0.0, help="N·m, constant")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="emc", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("--fmu", default="dist/EngineMountChassis.fmu",
                       help="the packaged FMU (default dist/EngineMountChassis.fmu)")
        p.add_argument("--rpm", nargs=2, type=float, default=[800.0, 2500.0], metavar=("FROM", "TO"),
                       help="speed range, rpm (default 800 2500)")
        p.add_argument("--signal", action="append",
                       help="output to analyse (repeatable; default: a sweep records every "
                            "mount force and comfort-point acceleration, a run-up mount[1].F[3], "
                            "a study the steering wheel, the seat and mount[1].F[3])")
        p.add_argument("--set", action="append", metavar="NAME=VALUE",
                       help="FMU start value for every case, e.g. effects.balanceShaft=off "
                            "(repeatable; checked against the model description; default scene=2)")
        p.add_argument("--out", required=True, help="result folder (tables, plots, metadata.json)")
        p.add_argument("--parquet", action="store_true", help="write Parquet instead of CSV")
        p.add_argument("--quiet", action="store_true", help="no progress bars")

    def case_option(p):
        p.add_argument("--case", action="append", metavar="NAME[:NAME=VALUE,...]",
                       help="a case with its own settings on top of the common --set values "
                            "(repeatable: the cases accumulate in one table and are overlaid)")

    def parallel_options(p):
        p.add_argument("--serial", action="store_true", help="no Dask")
        p.add_argument("--workers", type=int, default=2, help="local Dask workers (default 2)")
        p.add_argument("--scheduler", help="address of a running Dask scheduler (the FMU is sent "
                                           "to the workers by content)")

    s = sub.add_parser("sweep", help="constant-speed points on their periodic steady state")
    common(s)
    case_option(s)
    s.add_argument("--count", type=int, default=18, help="speed points, FROM to TO (default 18)")
    s.add_argument("--revolutions", type=int, default=None,
                   help="analysed window (even; default 8 with a periodic start, 40 after a settle)")
    add_start_options(s)
    s.add_argument("--steps-per-rev", type=int, default=72,
                   help="communication steps (output samples) per revolution (default 72)")
    s.add_argument("--load-torque", type=float, default=0.0, help="N·m, every point")
    s.add_argument("--plot", action="append",
                   help="analysed signal to plot (repeatable; default: the first)")
    bands.add_options(s)
    parallel_options(s)
    s.set_defaults(func=cmd_sweep)

    r = sub.add_parser("runup", help="slow linear run-up with continuous speed input, "
                                     "order-tracked in the crank-angle domain")
    common(r)
    case_option(r)
    runup_options(r)
    r.add_argument("--plot", action="append",
                   help="analysed signal to plot (repeatable; default: every --signal)")
    bands.add_options(r)
    r.set_defaults(func=cmd_runup)

    c = sub.add_parser("campbell", help="Campbell diagram: engine orders against the model's "
                                        "natural frequencies, crossings listed")
    common(c)
    case_option(c)
    c.set_defaults(func=cmd_campbell)

    studies = [("study-mounts", "paper §7.1: 4 mounts vs 3 mounts + stiffening bar (scene 2; "
                                "--each: every change alone and all three)", cmd_study_mounts),
               ("study-engines", "inline-3 (M13) vs the inline-4 it replaced, with and without Lanchester "
                                 "shafts (scene 2)", cmd_study_engines)]
    for name, help_text, func in studies:
        m = sub.add_parser(name, help=help_text)
        common(m)
        m.add_argument("--count", type=int, default=18, help="speed points per case (default 18)")
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
    b.add_argument("--scene", type=int, action="append",
                   help="scene(s) to measure (repeatable; default 2)")
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

    from .accuracy import add_parser as add_accuracy
    from .doe import add_parser as add_doe
    from .optimise import add_parser as add_optimise

    add_accuracy(sub)
    add_doe(sub)
    add_optimise(sub)
    from .why import add_parsers as add_why

    add_why(sub)
    # --- issue 46 (test data): registered here until the lead moves it -------------------------
    from .testbench.calibrate import register as register_calibrate
    from .testbench.correlate import register as register_correlate

    register_correlate(sub)
    register_calibrate(sub)
    # --- end issue 46 ------------------------------------------------------------------------
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs one command; expected failures (a refused option, a failed point) end with the cause
    on stderr and a non-zero exit code, without a Python traceback."""
    args = build_parser().parse_args(argv)
    args.command_line = ["emc"] + list(sys.argv[1:] if argv is None else argv)
    keep_freed_memory()
    if args.command == "bench-effects" and args.scene is None:
        args.scene = [DEFAULT_PARAMETERS["scene"]]
    try:
        return args.func(args)
    except UsageError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except PointFailed as failure:
        print(failure.report(), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
