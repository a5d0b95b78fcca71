"""``emc tpa``, ``emc frf``, ``emc ods``, ``emc decoupling``: why the body vibrates.

Each command instantiates the FMU with ``analysis.exportFolder`` so that the modal data and the
linearised model it analyses are the ones the FMU simulates (:mod:`emc.running.modal`), runs what it
needs (speed points on their periodic steady state, sine excitations), writes tables (CSV),
plots and ``metadata.json`` (the FMU by checksum, the settings, the command) into ``--out``.
"""

from __future__ import annotations

import pathlib
import sys
import time

import numpy as np
import pandas as pd
from tqdm import tqdm

from ..base.checks import (MAX_FREQUENCIES, MAX_TORQUE, MAX_VERIFY_FREQUENCIES, MAX_VERIFY_HZ,
                           check_count, check_range, check_revolutions, check_speeds, prepare)
from ..base.errors import UsageError
from ..base.fmu import BODY, check_fmu, highest_speed
from ..base.orders import HIGHEST_ORDER, ORDERS
from ..base.outputs import (claim, fmu_warnings_summary, reduction_notice, safe_name, save,
                            write_metadata)
from ..running import band as bands
from ..running.band import band_metadata, band_of
from ..running.coupling import ALGORITHMS, CoupledPair
from ..running.modal import OUTPUT_POINTS, body_point_of, export_from_fmu
from ..running.runner import OperatingPoint, PointFailed, Runner
from ..running.runup import run_up
from ..running.synthesis import static_state
from ..signals.spectra import order_components
from . import decoupling, frf, ods, tpa, tpa_time


def _progress(total: int, what: str, unit: str, quiet: bool):
    if quiet:
        return None

    return tqdm(total=total, desc=what, unit=unit, file=sys.stderr)


def _mount_names(export) -> dict:
    return {m["mount"]: m["name"] for m in (export.powertrain or {}).get("mounts", [])}


def check_responses(responses: list[str], export, variables: dict) -> list[str]:
    """Each response an acceleration of a body point the export recovers: an FMU output
    (``steeringWheel.a[3]``) or ``<point>.a[j]`` for any recovered point."""
    points = list(export.body.shapes) if export.body is not None else []
    for r in responses:
        try:
            point, _ = body_point_of(r)
        except ValueError as error:
            raise UsageError(f"--response {r}: {error}") from None
        if point not in points:
            fmu_names = [f"{k}.a[1..3]" for k, v in OUTPUT_POINTS.items() if v in points]
            raise UsageError(
                f"--response {r}: unknown output point {point!r}; the body recovers "
                f"{', '.join(points) or 'no point (is scene=2 set?)'} (FMU outputs "
                f"{', '.join(fmu_names)}; any point as <point>.a[1..3])")
    return responses


def export_for(args, parameters: dict, full_recovery: bool = False):
    try:
        return export_from_fmu(args.fmu, parameters, full_recovery=full_recovery)
    except ValueError as error:
        raise UsageError(str(error)) from None


def run_points(args, parameters: dict, speeds: list[float], signals: list[str],
               revolutions: int, steps: int, case: str = "") -> dict:
    """Each speed on its periodic steady state: the samples of ``signals`` per speed."""
    bar = _progress(len(speeds), case or "speeds", "point", args.quiet)
    out = {}
    try:
        with Runner(args.fmu) as runner:
            for rpm in speeds:
                point = OperatingPoint(rpm=rpm, revolutions=revolutions,
                                       steps_per_revolution=steps,
                                       load_torque=getattr(args, "load_torque", 0.0),
                                       parameters=tuple(parameters.items()))
                result = runner.run_point(point, signals, case)
                out[rpm] = {s: result["samples"][:, k] for k, s in enumerate(signals)}
                if bar is not None:
                    bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out


# The paths add up to the simulated response only as well as the integrator solved it: at the
# FMU's default 1e-5 the weak orders of a sweep (1 % of the largest) close within 1.5e-2, at 1e-7
# within 5.3e-4 (800–2500 rpm, 18 points, the default car).
CLOSING_TOLERANCE = 1e-7


def with_closing_tolerance(parameters: dict) -> dict:
    """``parameters`` with solver.relTol tightened to :data:`CLOSING_TOLERANCE` unless set."""
    return {"solver.relTol": CLOSING_TOLERANCE, **parameters}


def parse_responses(args) -> list[str]:
    """``--response`` (default the steering wheel's vertical acceleration), each an
    acceleration output."""
    responses = args.response or ["steeringWheel.a[3]"]
    for r in responses:
        try:
            body_point_of(r)
        except ValueError as error:
            raise UsageError(f"--response {r}: {error}") from None
    return responses


def check_order(order: float):
    if order not in ORDERS:
        raise UsageError(f"--order {order:g}: one of 0.5, 1, 1.5 … 6 (the half orders a "
                                "window of whole working cycles resolves)")


# ----- emc tpa ---------------------------------------------------------------------------------

def tpa_case(args, variables: dict, label: str, parameters: dict, speeds: list[float],
             responses: list[str]) -> tuple[pd.DataFrame, object]:
    """One case: its export, its speed points, its path contributions."""
    export = export_for(args, parameters)
    if export.body is None:
        raise UsageError("transfer paths need the elastic body: --set scene=2")
    check_responses(responses, export, variables)
    recorded = [r for r in responses if r in variables]
    samples = run_points(args, parameters, speeds, tpa.force_signals(export) + recorded,
                         args.revolutions, args.steps_per_rev, case=label)
    table = pd.concat([tpa.contributions(export, r, samples[rpm], args.revolutions, rpm,
                                         case=label)
                       for rpm in speeds for r in responses], ignore_index=True)
    return table, export


def report_paths(table: pd.DataFrame, names: dict, responses: list[str], labels: list[str],
                 at_of, order: float, recorded: list[str], out: pathlib.Path) -> dict:
    """What ``emc tpa`` and its run-up and coupled forms write and print from the table of path
    contributions: closure.csv, the ranked paths at the speed ``at_of(case)`` and the paths over
    speed per response and case, the cases compared; returns the summary for metadata.json."""
    summary = {}
    if recorded:
        closure = tpa.closure(table[table.response.isin(recorded)])
        save(closure, str(out / "closure.csv"))
        significant = closure[closure.significant]
        summary["closure_max_relative_error"] = float(significant.relative_error.max())
        if "quasi_static_re" in table:
            quasi = tpa.closure(table[table.response.isin(recorded)], prefix="quasi_static_")
            significant = quasi[quasi.significant]
            summary["quasi_static_closure"] = {
                "median_relative_error": float(significant.relative_error.median()),
                "max_relative_error": float(significant.relative_error.max())}
    for r in responses:
        name = safe_name(r)
        for label in labels:
            at = at_of(label)
            suffix = f"_{safe_name(label)}" if label else ""
            tpa.plot_ranked(table, at, order, r, str(out / f"tpa_ranked_{name}{suffix}.png"),
                            names, case=label)
            if table[table.case == label].rpm.nunique() > 1:
                tpa.plot_over_speed(table, order, r,
                                    str(out / f"tpa_over_speed_{name}{suffix}.png"), names,
                                    case=label)
            ranked = tpa.ranked(table, at, order, r, case=label)
            print(f"{r}, order {order:g} at {at:g} rpm ({order * at / 60:.1f} Hz)"
                  f"{', case ' + repr(label) if label else ''}:")
            shown = ranked[["amplitude", "phase_deg", "in_phase", "share"]].head(6).copy()
            shown.insert(0, "path", [tpa.path_label(int(m), tpa.AXES.index(d) + 1, names)
                                     for m, d in zip(ranked.mount[:6], ranked.direction[:6])])
            print(shown.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
            dominant = tpa.dominant_path(table, at, order, r, case=label)
            total = tpa.complex_values(table[(table.case == label) & (table.response == r)
                                             & (table.order == order)
                                             & np.isclose(table.rpm, at)
                                             & (table.path == "sum")])[0]
            summary.setdefault(r, {})[label] = {"at": at, "dominant_path": str(dominant.path),
                                                "share": float(dominant.share),
                                                "dominant_amplitude": float(dominant.amplitude),
                                                "total_amplitude": float(abs(total))}
        if len(labels) > 1:
            first = summary[r][labels[0]]["dominant_path"]
            tpa.plot_cases(table, order, r, first, labels,
                           str(out / f"tpa_cases_{name}.png"), names, at=at_of(labels[0]))
            print(f"{r}, order {order:g}, {first} and the total per case:")
            for label in labels:
                one = tpa.ranked(table, at_of(label), order, r, case=label).set_index("path")
                print(f"  {label or 'model'} at {at_of(label):g} rpm: {first} "
                      f"{one.amplitude[first]:.4g}, total "
                      f"{summary[r][label]['total_amplitude']:.4g}")
    if "closure_max_relative_error" in summary:
        print(f"closure: the 12 paths add up to the simulated response within "
              f"{summary['closure_max_relative_error']:.2e} (every order above 1 % of the "
              "largest)")
    if "quasi_static_closure" in summary:
        q = summary["quasi_static_closure"]
        print(f"force × transfer function (quasi-stationary) against the simulated response: "
              f"median {q['median_relative_error']:.2e}, largest "
              f"{q['max_relative_error']:.2e}")
    return summary


def per_bound(band, parameters: dict, analyse) -> tuple[pd.DataFrame, object]:
    """``analyse(parameters)`` → (table, export) once, or at the band's three bounds with the
    tables stacked (column ``bound``) and the nominal export."""
    if band is None:
        return analyse(parameters)
    result = bands.run_band(lambda settings, _bound: analyse(settings), band, parameters)
    return result.stack(part=0), result.nominal[1]


def report_band(table: pd.DataFrame, names: dict, responses: list[str], labels: list[str],
                at_of, order: float, out: pathlib.Path, summary: dict):
    """The damping band of the path contributions: tpa_band.csv (every path's and the sum's
    amplitude at the three bounds), the paths over speed with their bands, and at the speed
    ``at_of(case)`` the dominant path and the total at each bound (into ``summary``)."""
    keys = ["case", "response", "order", "rpm", "path"]
    save(bands.wide(table, keys, ["amplitude", "phase_deg"]), str(out / "tpa_band.csv"))
    for r in responses:
        for label in labels:
            at = at_of(label)
            suffix = f"_{safe_name(label)}" if label else ""
            if table[table.case == label].rpm.nunique() > 1:
                tpa.plot_over_speed(table, order, r, str(
                    out / f"tpa_band_{safe_name(r)}{suffix}.png"), names, case=label, top=4)
            dominant = summary[r][label]["dominant_path"]
            record = {}
            for bound in bands.BOUNDS:
                ranked = tpa.ranked(table[table.bound == bound], at, order, r,
                                    case=label).set_index("path")
                total = ranked.in_phase.sum()
                top = tpa.dominant_path(table[table.bound == bound], at, order, r, case=label)
                record[bound] = {"total_amplitude": float(total),
                                 "path_amplitude": float(ranked.amplitude[dominant]),
                                 "path_share": float(ranked.share[dominant]),
                                 "dominant_path": str(top.path)}
            summary[r][label]["band"] = record
            print(f"{r}, order {order:g} at {at:g} rpm{', case ' + repr(label) if label else ''}"
                  f", damping band (low / nominal / high): total "
                  + " / ".join(f"{record[b]['total_amplitude']:.3g}" for b in bands.BOUNDS)
                  + f"; {dominant} "
                  + " / ".join(f"{record[b]['path_amplitude']:.3g}" for b in bands.BOUNDS)
                  + " (share " + " / ".join(f"{100 * record[b]['path_share']:.0f} %"
                                             for b in bands.BOUNDS)
                  + "); dominant path at each bound: "
                  + ", ".join(dict.fromkeys(record[b]["dominant_path"] for b in bands.BOUNDS)))


def cmd_tpa(args) -> int:
    check_count(args.count)
    check_range("--steps-per-rev", args.steps_per_rev, 14, 10000)
    check_revolutions(args.revolutions)
    check_order(args.order)
    variables, cases = prepare(args)
    check_speeds(args.rpm, increasing=args.count > 1, highest=highest_speed(variables))
    cases = [(label, with_closing_tolerance(parameters)) for label, parameters in cases]
    band = band_of(args, variables, cases)
    at = args.at if args.at is not None else args.rpm[0]
    if not args.rpm[0] <= at <= args.rpm[1]:
        raise UsageError(f"--at {at:g} rpm is outside the sweep --rpm {args.rpm[0]:g} "
                             f"{args.rpm[1]:g}")
    responses = parse_responses(args)
    reduction_notice(cases[0][1], variables)
    speeds = sorted(set(np.round(np.linspace(args.rpm[0], args.rpm[1], args.count), 6)) | {at})
    out = claim(args)
    started = time.perf_counter()
    tables, exports = [], {}
    for label, parameters in cases:
        table, exports[label] = per_bound(
            band, parameters, lambda settings, label=label: tpa_case(
                args, variables, label, settings, speeds, responses))
        tables.append(table)
    table = pd.concat(tables, ignore_index=True)
    save(table, str(out / "tpa.csv"))
    nominal = bands.nominal_rows(table)
    names = _mount_names(exports[cases[0][0]])
    labels = [label for label, _ in cases]
    summary = report_paths(nominal, names, responses, labels, lambda label: at, args.order,
                           [r for r in responses if r in variables], out)
    if band is not None:
        report_band(table, names, responses, labels, lambda label: at, args.order, out,
                    summary)
    write_metadata(out, args, variables, cases,
                       {"tpa": {"speeds": speeds, "at": at, "order": args.order,
                                "responses": responses, "revolutions": args.revolutions,
                                "steps_per_revolution": args.steps_per_rev, **summary},
                        "export": exports[cases[0][0]].manifest, **band_metadata(band)})
    runs = bands.run_count(band, len(cases) * len(speeds))
    print(f"{runs} points in {time.perf_counter() - started:.1f} s -> {out}")
    return 0


# ----- emc tpa-runup ---------------------------------------------------------------------------

def start_cycle(args, parameters: dict, export, initial: np.ndarray) -> tuple[np.ndarray, float]:
    """One working cycle of the mount forces on the periodic steady state at the run-up's start
    speed, from the start's crank angle on (the run-up's modal state at its start), checked
    against the run-up's first forces."""
    rpm = args.rpm[0]
    point = OperatingPoint(rpm=rpm, revolutions=2,
                           steps_per_revolution=tpa_time.CYCLE_STEPS_PER_REVOLUTION,
                           load_torque=args.load_torque, parameters=tuple(parameters.items()))
    with Runner(args.fmu) as runner:
        samples = runner.run_point(point, tpa.force_signals(export))["samples"]
    cycle = np.roll(samples, 1, axis=0)  # the last sample closes the cycle: t = 0
    mismatch = np.max(np.abs(cycle[0] - initial[:cycle.shape[1]]))
    if mismatch > 1e-4 * np.max(np.abs(cycle)):
        print(f"warning: the run-up's start is {mismatch:.3g} N off the periodic cycle at "
              f"{rpm:g} rpm: its paths start with a transient", file=sys.stderr)
    return cycle, 2 * 60.0 / rpm


def cmd_tpa_runup(args) -> int:
    check_range("--duration", args.duration, 0.0, strict_low=True)
    check_range("--step", args.step, 0.0, 0.01, strict_low=True)
    check_revolutions(args.block_revolutions, "--block-revolutions")
    check_order(args.order)
    variables, cases = prepare(args)
    check_speeds(args.rpm, increasing=True, highest=highest_speed(variables))
    revolutions = (args.rpm[0] + args.rpm[1]) / 2.0 / 60.0 * args.duration
    if revolutions < 2 * args.block_revolutions:
        raise UsageError(f"a run-up of {args.duration:g} s turns the crank "
                             f"{revolutions:.1f} times: too few for blocks of "
                             f"{args.block_revolutions} revolutions (lengthen --duration)")
    at = args.at if args.at is not None else args.rpm[0]
    if not args.rpm[0] <= at <= args.rpm[1]:
        raise UsageError(f"--at {at:g} rpm is outside the run-up --rpm {args.rpm[0]:g} "
                             f"{args.rpm[1]:g}")
    responses = parse_responses(args)
    periodic = args.start == "periodic"
    cases = [(label, with_closing_tolerance(parameters)) for label, parameters in cases]
    reduction_notice(cases[0][1], variables)
    out = claim(args)
    started = time.perf_counter()
    tables, exports, warnings = [], {}, []
    band = band_of(args, variables, cases)

    def analyse(label: str, parameters: dict):
        export = export_for(args, parameters)
        if export.body is None:
            raise UsageError("transfer paths need the elastic body: --set scene=2")
        check_responses(responses, export, variables)
        recorded = [r for r in responses if r in variables]
        start_values = {**parameters, "loadTorque": args.load_torque}
        if periodic:
            start_values["initialization.periodic"] = True
        run = run_up(args, tpa.force_signals(export) + recorded, start_values, label)
        warnings.extend(run["warnings"])
        cycle = start_cycle(args, parameters, export, run["initial"]) if periodic else None
        return tpa_time.runup_paths(export, run, responses, cycle, args.block_revolutions,
                                    case=label), export

    for label, parameters in cases:
        table, exports[label] = per_bound(
            band, parameters, lambda settings, label=label: analyse(label, settings))
        tables.append(table)
    table = pd.concat(tables, ignore_index=True)
    fmu_warnings_summary(warnings)
    save(table, str(out / "tpa_runup.csv"))
    labels = [label for label, _ in cases]
    nominal = bands.nominal_rows(table)
    speeds = {label: np.sort(nominal[nominal.case == label].rpm.unique()) for label in labels}
    at_of = {label: float(v[np.argmin(np.abs(v - at))]) for label, v in speeds.items()}
    names = _mount_names(exports[labels[0]])
    summary = report_paths(nominal, names, responses, labels, at_of.__getitem__, args.order,
                           [r for r in responses if r in variables], out)
    if band is not None:
        report_band(table, names, responses, labels, at_of.__getitem__, args.order, out,
                    summary)
    write_metadata(out, args, variables, cases,
                       {"tpa_runup": {"from": args.rpm[0], "to": args.rpm[1],
                                      "duration": args.duration, "step": args.step,
                                      "block_revolutions": args.block_revolutions,
                                      "start": args.start, "at": at, "order": args.order,
                                      "responses": responses, **summary},
                        "export": exports[labels[0]].manifest, **band_metadata(band)},
                       warnings)
    print(f"{len(cases)} run-up(s), {sum(len(v) for v in speeds.values())} blocks in "
          f"{time.perf_counter() - started:.1f} s -> {out}")
    return 0


# ----- emc tpa-coupled -------------------------------------------------------------------------

def cmd_tpa_coupled(args) -> int:
    check_order(args.order)
    check_revolutions(args.revolutions)
    check_range("--settle", args.settle, 0.0)
    check_range("--coupling-step", args.coupling_step, 0.0, 0.05, strict_low=True)
    if args.algorithm not in ALGORITHMS:
        raise UsageError(f"--algorithm: one of {', '.join(ALGORITHMS)}")
    variables, cases = prepare(args, cases_wanted=False)
    check_range("--rpm-point", args.rpm_point, 0.0, highest_speed(variables),
                strict_low=True)
    check_fmu(args.body_fmu, "--body-fmu", BODY)
    engine = {k: v for k, v in cases[0][1].items() if k != "scene"}  # the pair sets scene 3
    if args.start == "periodic":
        engine["initialization.periodic"] = True
    try:
        export = export_from_fmu(args.body_fmu, {})
    except ValueError as error:
        raise UsageError(str(error)) from None
    if export.body is None:
        raise UsageError(f"{args.body_fmu} exports no elastic body")
    responses = parse_responses(args)
    check_responses(responses, export, variables)
    window = args.revolutions * 60.0 / args.rpm_point
    out = claim(args)
    started = time.perf_counter()
    if not args.quiet:
        print(f"coupling the engine and the body at {args.rpm_point:g} rpm for "
              f"{args.settle + window:.3g} s ({args.algorithm}, step {args.coupling_step:g} s)",
              file=sys.stderr)
    with CoupledPair(args.fmu, args.body_fmu, args.rpm_point, args.settle + window,
                     engine_parameters=engine) as pair:
        initial = static_state(export.body, pair.F_static)
        run = pair.run(args.algorithm, args.coupling_step)
    if not run.ok:
        raise PointFailed(f"coupled run at {args.rpm_point:g} rpm: {run.status}")
    recorded = {r: run.signals.get(r) for r in responses}
    table = tpa_time.window_paths(export, run.body_forces, recorded, args.revolutions,
                                  args.rpm_point, run.t_reached - window, initial)
    save(table, str(out / "tpa_coupled.csv"))
    summary = report_paths(table, {}, responses, [""], lambda _label: args.rpm_point,
                           args.order, [r for r in responses if recorded[r] is not None], out)
    write_metadata(out, args, variables, [("", engine)],
                       {"tpa_coupled": {"rpm": args.rpm_point, "settle": args.settle,
                                        "revolutions": args.revolutions,
                                        "coupling_step": args.coupling_step,
                                        "algorithm": args.algorithm, "start": args.start,
                                        "order": args.order, "responses": responses,
                                        "stepping_wall_s": run.wall, **summary},
                        "export": export.manifest})
    print(f"{args.settle + window:.3g} s coupled in {time.perf_counter() - started:.1f} s "
          f"-> {out}")
    return 0


# ----- emc frf ---------------------------------------------------------------------------------

def cmd_frf(args) -> int:
    check_range("--freq FROM", args.freq[0], 0.0, strict_low=True)
    check_range("--freq TO", args.freq[1], args.freq[0], strict_low=True)
    check_range("--points", args.points, 2, MAX_FREQUENCIES)
    check_range("the number of --verify frequencies", len(args.verify or []), 0,
                MAX_VERIFY_FREQUENCIES)
    for f in args.verify or []:
        check_range("--verify", f, args.freq[0], min(args.freq[1], MAX_VERIFY_HZ))
    check_range("--verify-amplitude", args.verify_amplitude, 0.0, MAX_TORQUE, strict_low=True)
    check_range("--verify-rtol", args.verify_rtol, 0.0, 1e-2, strict_low=True)
    check_range("--top", args.top, 1)
    variables, cases = prepare(args, cases_wanted=False)
    if args.mark_order and args.mark_rpm is None:
        raise UsageError("--mark-order needs --mark-rpm (the speed its frequencies are at)")
    if args.mark_rpm is not None:
        check_range("--mark-rpm", args.mark_rpm, 0.0, highest_speed(variables), strict_low=True)
    for order in args.mark_order or []:
        check_range("--mark-order", order, 0.0, HIGHEST_ORDER, strict_low=True)
    parameters = cases[0][1]
    band = band_of(args, variables, cases)
    reduction_notice(parameters, variables)
    export = export_for(args, parameters)
    if export.body is None:
        raise UsageError("transfer functions need the elastic body: --set scene=2")
    # At the band's bounds: the body and the linearised model exported with their damping.
    exports = {}
    for bound in bands.bounds_of(band):
        settings = bands.settings_at(band, parameters, bound)
        exports[bound] = export if settings == parameters else export_for(args, settings)

    def at_bounds(table_of) -> pd.DataFrame:
        if band is None:
            return table_of(export)
        return pd.concat([bands.with_bound(table_of(e), b) for b, e in exports.items()],
                         ignore_index=True)

    responses = check_responses(args.response or ["steeringWheel.a[3]"], export, variables)
    out = claim(args)
    freqs = np.geomspace(args.freq[0], args.freq[1], args.points)
    marks = {f"order {o:g} at {args.mark_rpm:g} rpm": o * args.mark_rpm / 60.0
             for o in (args.mark_order or [])} if args.mark_rpm else {}
    summary = {}
    for r in responses:
        name = safe_name(r)
        body = at_bounds(lambda e: frf.body_frf(e, r, freqs))
        coupled = at_bounds(lambda e: frf.coupled_frf(e, [r], freqs))
        save(body, str(out / f"frf_body_{name}.csv"))
        save(coupled, str(out / f"frf_coupled_{name}.csv"))
        checks = None
        if args.verify:
            checks = verify(args, parameters, export, r)
            save(checks, str(out / f"frf_check_{name}.csv"))
            summary[r] = {"largest_relative_error": float(checks.relative_error.max())}
            print(checks[["frequency", "amplitude", "linearised_amplitude", "relative_error"]]
                  .to_string(index=False, float_format=lambda v: f"{v:.4g}"))
        frf.plot(body, str(out / f"frf_body_{name}.png"), "m/s²/N",
                 f"Body accelerance to {r} from a force at each mount point "
                 f"({len(export.body.omega)} modes as simulated)", top=args.top, marks=marks)
        frf.plot(coupled, str(out / f"frf_coupled_{name}.png"), "m/s²/(N m)",
                 f"Coupled system linearised at its static equilibrium: {r} per unit load "
                 "torque (roll moment on the housing)", checks=checks, marks=marks)
    write_metadata(out, args, variables, cases,
                       {"frf": {"frequencies": [args.freq[0], args.freq[1], args.points],
                                "responses": responses, "verify": args.verify or [], **summary},
                        "export": export.manifest, **band_metadata(band)})
    print(f"transfer functions of {', '.join(responses)} -> {out}")
    return 0


def verify(args, parameters: dict, export, response: str) -> pd.DataFrame:
    """The coupled transfer function at each --verify frequency from a sine on the FMU's load
    torque (engine at rest: rpm 0, excitation off, so the operating point is the
    linearisation's)."""
    at_rest = {**parameters, "rpm": 0.0, "effects.gasForces": False,
               "effects.massForces": False, "solver.relTol": args.verify_rtol}
    linear = frf.coupled_frf(export_for(args, at_rest), [response], args.verify)
    bar = _progress(len(args.verify), "sine excitation", "frequency", args.quiet)
    rows = []
    try:
        for f in args.verify:
            y = frf.sine_response(args.fmu, at_rest, "loadTorque", [response], f,
                                  args.verify_amplitude)[response]
            h = linear[linear.frequency == f]
            z = complex(h.re.iloc[0], h.im.iloc[0])
            rows.append({"frequency": f, "input": "loadTorque", "amplitude": abs(y),
                         "phase_deg": np.degrees(np.angle(y)), "linearised_amplitude": abs(z),
                         "linearised_phase_deg": np.degrees(np.angle(z)),
                         "relative_error": abs(y - z) / abs(z)})
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return pd.DataFrame(rows)


# ----- emc ods ---------------------------------------------------------------------------------

def operating_shape_at(args, parameters: dict, variables: dict):
    """The export with the body's modes on every node, the speed point's samples and the
    operating deflection shape of ``--order`` at ``--rpm-point``."""
    export = export_for(args, parameters, full_recovery=True)
    signals = ods.signals(export) + [s for s in args.compare if s in variables]
    check_responses(args.compare, export, variables)
    samples = run_points(args, parameters, [args.rpm_point], signals, args.revolutions,
                         args.steps_per_rev)[args.rpm_point]
    return export, samples, ods.operating_shape(export, samples, args.revolutions,
                                                args.rpm_point, args.order)


def compared_points(args, export, samples: dict, shape: dict) -> list[dict]:
    """Per ``--compare`` output: the shape's displacement at its node and the simulated one."""

    rows = []
    w = 2 * np.pi * shape["frequency"]
    for r in args.compare:
        point, dof = body_point_of(r)
        node = export.body.nodes[point]
        u = shape["body"][node, dof]
        row = {"response": r, "node": node, "ods_displacement": abs(u),
               "ods_phase_deg": np.degrees(np.angle(u))}
        if r in samples:
            a = order_components(samples[r], args.revolutions, [args.order])[0]
            row.update({"simulated_displacement": abs(a / -w**2),
                        "relative_difference": abs(u - a / -w**2) / abs(a / -w**2)})
        rows.append(row)
    return rows


def cmd_ods(args) -> int:
    check_order(args.order)
    check_revolutions(args.revolutions)
    check_range("--steps-per-rev", args.steps_per_rev, 14, 10000)
    check_range("--load-torque", args.load_torque)
    variables, cases = prepare(args, cases_wanted=False)
    check_range("--rpm-point", args.rpm_point, 0.0, highest_speed(variables),
                    strict_low=True)
    parameters = with_closing_tolerance(cases[0][1])
    band = band_of(args, variables, [("", parameters)])
    reduction_notice(parameters, variables)
    print("note: recovering the body's modes on every node (the reduction is run once more)",
          file=sys.stderr)
    export, samples, shape = operating_shape_at(args, parameters, variables)
    out = claim(args)
    stem = f"ods_{args.rpm_point:g}rpm_order{args.order:g}"
    ods.write_vtu(shape, str(out / f"{stem}.vtu"))
    labels = {p: export.body.nodes[p] for p in export.body.shapes if not p.startswith("mount_")}
    ods.plot(shape, str(out / f"{stem}.png"), point_labels=labels)
    rows = compared_points(args, export, samples, shape)
    for r in args.compare:
        point, dof = body_point_of(r)
        modes = ods.modal_contributions(shape, export, point, dof)
        save(modes, str(out / f"{stem}_modes_{safe_name(r)}.csv"))
        print(f"body modes carrying {r} (displacement, share in phase with the whole):")
        print(modes.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    points = pd.DataFrame(rows)
    if band is not None and args.compare:
        # The shape at the band's bounds, point by point (the file and the picture: nominal).
        tables = [bands.with_bound(points, "nominal")]
        for bound in ("low", "high"):
            e, x, sh = operating_shape_at(args, band.applied(parameters, bound), variables)
            tables.append(bands.with_bound(pd.DataFrame(compared_points(args, e, x, sh)),
                                           bound))
        stacked = pd.concat(tables, ignore_index=True)
        points = bands.wide(stacked, ["response", "node"],
                            [c for c in ("ods_displacement", "simulated_displacement",
                                                   "relative_difference") if c in stacked])
    if len(points):
        save(points, str(out / f"{stem}_points.csv"))
        print(points.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    write_metadata(out, args, variables, [("", parameters)],
                       {"ods": {"rpm": args.rpm_point, "order": args.order,
                                "frequency": shape["frequency"], "nodes": len(shape["nodes"]),
                                "revolutions": args.revolutions},
                        "export": export.manifest, **band_metadata(band)})
    print(f"operating deflection shape, order {args.order:g} at {args.rpm_point:g} rpm "
          f"({shape['frequency']:.1f} Hz) -> {out / (stem + '.vtu')}")
    return 0


# ----- emc decoupling --------------------------------------------------------------------------

def cmd_decoupling(args) -> int:
    variables, cases = prepare(args, cases_wanted=False)
    parameters = cases[0][1]
    out = claim(args)
    record = {}
    for scene, where in ((1, "on ground"), (2, "in the body")):
        if scene == 2:
            reduction_notice({**parameters, "scene": 2}, variables)
        export = export_for(args, {**parameters, "scene": scene})
        rows = decoupling.table(export)
        check = (decoupling.rigid_modes_6x6(export.powertrain) if scene == 1
                 else decoupling.rigid_modes_in_body(export.powertrain, export))
        axis = decoupling.axes(export.powertrain)
        name = "ground" if scene == 1 else "body"
        save(rows, str(out / f"decoupling_{name}.csv"))
        save(check, str(out / f"decoupling_{name}_independent.csv"))
        decoupling.plot(rows, str(out / f"decoupling_{name}.png"), axis=axis,
                        title=f"Decoupling table, powertrain on its mounts {where} "
                              f"(scene {scene})")
        print(f"powertrain on its mounts {where}: the FMU's rigid modes, kinetic energy [%] at "
              "the centre of mass")
        print(rows.drop(columns=["kind", "powertrain_share"])
              .to_string(index=False, formatters={c: "{:.1f}".format for c in rows.columns
                                                  if c.startswith("KE_")},
                         float_format=lambda v: f"{v:.3g}"))
        print(f"  independent {'6x6' if scene == 1 else '(6 + body modes)'} computation from "
              "the exported mass and stiffness (undamped): "
              + ", ".join(f"{f:.2f}" for f in check.frequency_hz) + " Hz")
        print(f"  torque-roll axis vs the mounts' elastic axis: {axis['angle_deg']:.2f}° apart, "
              f"elastic axis {1e3 * axis['offset_m']:.1f} mm from the centre of mass")
        record[name] = {"frequencies_hz": rows.frequency_hz.tolist(),
                        "independent_hz": check.frequency_hz.tolist(),
                        "axis_angle_deg": axis["angle_deg"], "axis_offset_m": axis["offset_m"]}
    write_metadata(out, args, variables, cases, {"decoupling": record})
    print(f"decoupling tables -> {out}")
    return 0
