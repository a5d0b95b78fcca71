"""Settings, cases and option values, checked against the FMU before anything runs."""

from __future__ import annotations

import difflib
import math

from .errors import UsageError
from .fmu import check_config_file, check_outputs, model_variables, start_value
from .options import DEFAULT_WORKERS, POOL_FROM
from .orders import HIGHEST_ORDER

# The default of every command: the engine in the elastic body (scene 1 has no steering wheel).
DEFAULT_PARAMETERS = {"scene": 2}
BOOLEAN_SPELLINGS = {"true": True, "1": True, "yes": True, "on": True,
                     "false": False, "0": False, "no": False, "off": False}
# The largest requests the commands take: beyond them a run would last hours on one machine
# (a scene-2 speed point costs 0.1-0.4 s, a frequency of a transfer function about 1 ms, a
# verifying sine a few seconds) for no resolution a plot or a table can show.
MAX_SPEED_POINTS = 2000
MAX_FREQUENCIES = 20000
MAX_VERIFY_FREQUENCIES = 20
# A verifying sine above the body's modes (its cut-off is 225 Hz by default) checks nothing the
# modal model keeps; its sampling at 32 steps a cycle would make every step tiny.
MAX_VERIFY_HZ = 1000.0
# The load torque's sine amplitude: beyond several times the engine's full-load torque
# (about 300 N·m) the mounts leave their measured curves.
MAX_TORQUE = 5000.0
# Inputs and parameters each point's speed, load and start come from: set by the command's own
# options, never by --set (a --set rpm would run every point at that speed, labelled otherwise).
CONTROLLED = {"rpm": "--rpm", "loadTorque": "--load-torque", "initialization.periodic": "--start"}


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


def name_and_bounds(text: str, option: str, error: type[Exception] = UsageError
                    ) -> tuple[str, tuple[float, float] | None]:
    """``NAME`` or ``NAME=LOW:HIGH`` (a design variable, a calibration parameter): the name and
    the bounds if given (``error`` names ``option`` and the text when they are not two numbers)."""
    name, _, bounds = text.partition("=")
    if not bounds:
        return name.strip(), None
    try:
        low, high = (float(v) for v in bounds.split(":"))
    except ValueError:
        raise error(f"{option} {text}: bounds are LOW:HIGH") from None
    return name.strip(), (low, high)


def check_pool(args):
    """--workers, if given, at least one."""
    if args.workers is not None:
        check_range("--workers", args.workers, 1)


def pool_workers(args, runs: int) -> int | None:
    """How many local workers a command's ``runs`` get: ``None`` to run in this process (with
    --serial, or without --workers and --scheduler for fewer than :data:`POOL_FROM` runs)."""
    check_pool(args)
    if args.serial or (args.workers is None and args.scheduler is None and runs < POOL_FROM):
        return None
    return args.workers or DEFAULT_WORKERS


def check_range(name: str, value, low=None, high=None, strict_low=False):
    bad = ((low is not None and (value <= low if strict_low else value < low))
           or (high is not None and value > high) or not math.isfinite(value))
    if bad:
        bound = (f"> {low}" if strict_low else f">= {low}") if low is not None else ""
        bound += (" and " if bound and high is not None else "") + (f"<= {high}" if high is not None else "")
        raise UsageError(f"{name} must be {bound or 'finite'}, got {value}")


def check_count(value: int, option: str = "--count", largest: int = MAX_SPEED_POINTS):
    """A number of points: at least 1, at most ``largest`` (module constants say why)."""
    check_range(option, value, 1, largest)


def check_revolutions(value: int, option: str = "--revolutions"):
    """A window of whole working cycles (two revolutions each) puts every half order on a bin."""
    if value < 2 or value % 2:
        raise UsageError(f"{option} must be even and >= 2, got {value}")


def check_speeds(rpm: list[float], increasing: bool = False, highest: float = 6000.0):
    """FROM and TO positive and at most the FMU's highest speed; TO above FROM where the command
    needs a range (a run-up, a sweep of several points)."""
    check_range("--rpm FROM", rpm[0], 0.0, highest, strict_low=True)
    check_range("--rpm TO", rpm[1], 0.0, highest, strict_low=True)
    if rpm[1] < rpm[0] or (increasing and rpm[1] == rpm[0]):
        need = "increase" if increasing else "not decrease"
        raise UsageError(f"--rpm FROM TO must {need}, got {rpm[0]:g} {rpm[1]:g}")


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


def analysed_signals(args, variables: dict, default: list[str]) -> list[str]:
    """--signal (checked), else ``default``; --plot (checked) must be among them."""
    signals = list(dict.fromkeys(getattr(args, "signal", None) or []))
    check_outputs("--signal", signals, variables)
    signals = signals or default
    check_outputs("--plot", getattr(args, "plot", None) or [], variables, among=signals)
    return signals


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
        check_revolutions(args.revolutions)
        options["revolutions"] = args.revolutions
    return options


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
