"""What accuracy costs for a configuration: the work-precision table of ``emc accuracy``.

For each case (the common ``--set`` values with the case's own on top: a deck, an engine, a
vehicle JSON) and each scenario (a constant-speed run, a linear run-up with the speed given by
its derivative), the packaged FMU runs once at a tight reference tolerance and once per
tolerance of the list, the tolerance passed as a master passes it: through
``fmi2SetupExperiment``. Every run starts the same way (the FMU's start: the static equilibrium
with the excitation faded in, or ``--start periodic``), may settle at the first speed for a
while, and is sampled at every communication step of the compared window that follows. Against
the reference of its case and scenario each run gets

- the relative L2 error of each signal group: ``sqrt(Σ (x − x_ref)² / Σ (x_ref − mean)²)`` over
  all samples and the group's signals (groups: the name up to its first ``[``, so the twelve
  ``mount[i].F[j]`` are one group and ``steeringWheel.a[j]`` another);
- the error of the order amplitudes (constant speed only): per order, the L2 norm over the
  group's signals of the amplitude error relative to that of the reference amplitudes, on the
  longest window of whole working cycles at the end of the run; the largest over the orders;
- its cost: CPU time of the stepping per simulated second (the chassis reduction and the FMU's
  initialisation are not counted), the real-time factor and the integrator steps.

The FMU's absolute tolerance follows the relative one (``solver.absTol`` = 0, the start value),
so the tolerance of the list controls the whole error; a ``--set solver.absTol=…`` fixes it for
the measured runs (the reference keeps following its own tolerance), and the table then shows
where that absolute tolerance takes over.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time

import numpy as np
import pandas as pd

from ..base.checks import check_range, check_speeds, prepare
from ..base.errors import UsageError
from ..base.fmu import check_outputs, highest_speed
from ..base.outputs import claim, reduction_notice, write_metadata
from ..figures.plots import plt
from ..running.runner import Runner
from ..signals.spectra import order_amplitudes
from .defaults import COMPARED_ORDERS, DEFAULT_TOLERANCES, REFERENCE_TOLERANCE


@dataclasses.dataclass(frozen=True)
class Scenario:
    """``settle`` seconds at ``rpm_from`` (not compared), then the compared window of
    ``duration`` seconds: at constant speed (``rpm_from == rpm_to``) or a linear run-up to
    ``rpm_to``, under the drivetrain's reaction ``load_torque`` (N·m) throughout."""

    name: str
    rpm_from: float
    rpm_to: float
    duration: float
    step: float = 1e-3
    periodic: bool = False
    settle: float = 0.0
    load_torque: float = 0.0

    @property
    def stationary(self) -> bool:
        return self.rpm_from == self.rpm_to

    def rpm(self, t: float) -> float:
        return self.rpm_from + self.rate(t) * max(0.0, t - self.settle)

    def rate(self, t: float) -> float:
        """Speed derivative at ``t``, rpm/s (what the FMU gets as the input derivative)."""
        return (self.rpm_to - self.rpm_from) / self.duration if t >= self.settle else 0.0


def signal_group(name: str) -> str:
    return name.split("[", 1)[0]


def run(runner: Runner, scenario: Scenario, parameters: dict, signals: list[str],
        tolerance: float | None) -> dict:
    """One run; ``tolerance`` goes to ``fmi2SetupExperiment`` (``None``: undefined, the FMU's
    own ``solver.relTol``). Returns the window's samples at every communication point and the
    cost of the whole run."""
    slave = runner.slave
    if not runner.fresh:
        slave.reset()
    runner.fresh = False
    runner.log.clear()
    try:
        slave.setupExperiment(tolerance=tolerance, startTime=0.0)
        start = {"rpm": scenario.rpm_from, "loadTorque": scenario.load_torque, **parameters}
        if scenario.periodic:
            start["initialization.periodic"] = True
        for name, value in start.items():
            runner._set(name, value)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        skipped = int(round(scenario.settle / scenario.step))
        n = int(round(scenario.duration / scenario.step))
        vrs = [runner.vr[s] for s in signals]
        rpm_vr = [runner.vr["rpm"]]
        samples = np.empty((n, len(vrs)))
        cpu, wall = time.process_time(), time.perf_counter()
        t = 0.0
        for k in range(skipped + n):
            if not scenario.stationary:
                slave.setReal(rpm_vr, [scenario.rpm(t)])
                slave.setRealInputDerivatives(rpm_vr, [1], [scenario.rate(t)])
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=scenario.step)
            t = (k + 1) * scenario.step
            if k >= skipped:
                samples[k - skipped] = slave.getReal(vrs)
        cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        steps = slave.getInteger([runner.vr["solver.steps"]])[0]
    except Exception as error:  # noqa: BLE001 - fmpy raises plain exceptions for failed calls
        raise runner.failure(f"{scenario.name}, tolerance {tolerance}", error) from None
    if not np.all(np.isfinite(samples)):
        raise runner.failure(f"{scenario.name}, tolerance {tolerance}",
                             RuntimeError("non-finite outputs"))
    return {"samples": samples, "cpu": cpu, "wall": wall, "simulated": t, "steps": int(steps)}


def relative_l2(samples: np.ndarray, reference: np.ndarray) -> float:
    """``sqrt(Σ (x − x_ref)² / Σ (x_ref − mean_ref)²)`` over all samples and columns; NaN for a
    reference without variation (scene 1 has no steering wheel)."""
    spread = float(np.sum((reference - reference.mean(axis=0)) ** 2))
    if spread == 0.0:
        return math.nan
    return math.sqrt(float(np.sum((samples - reference) ** 2)) / spread)


def order_error(samples: np.ndarray, reference: np.ndarray, scenario: Scenario,
                orders) -> float:
    if not scenario.stationary:
        return math.nan
    # The longest window of whole working cycles at the end of the samples.
    per_revolution = 60.0 / scenario.rpm_from / scenario.step
    a = order_amplitudes(samples, None, orders, per_revolution)
    b = order_amplitudes(reference, None, orders, per_revolution)
    errors = [np.linalg.norm(a[o] - b[o]) / np.linalg.norm(b[o]) for o in b
              if np.linalg.norm(b[o]) > 0.0]
    return float(max(errors)) if errors else math.nan


def work_precision(fmu: str, cases: list[tuple[str, dict]], scenarios: list[Scenario],
                   signals: list[str], tolerances=DEFAULT_TOLERANCES,
                   reference_tolerance: float = REFERENCE_TOLERANCE, orders=COMPARED_ORDERS,
                   progress=None, repeat: int = 1) -> pd.DataFrame:
    """The work-precision table: one row per case, scenario and tolerance. With ``repeat`` > 1
    each run is repeated and the least CPU and wall time are kept (the runs are identical; the
    fastest is the least disturbed by the rest of the machine)."""
    groups = list(dict.fromkeys(signal_group(s) for s in signals))
    columns = {g: [i for i, s in enumerate(signals) if signal_group(s) == g] for g in groups}
    rows = []
    with Runner(fmu, instance_name="emc-accuracy") as runner:
        for label, parameters in cases:
            for scenario in scenarios:
                # The reference is the tight answer of the same configuration: an absolute
                # tolerance set for the measured runs would floor it.
                tight = {k: v for k, v in parameters.items() if k != "solver.absTol"}
                reference = run(runner, scenario, tight, signals, reference_tolerance)
                if progress is not None:
                    progress(label, scenario, reference_tolerance, reference)
                for tolerance in tolerances:
                    r = run(runner, scenario, parameters, signals, tolerance)
                    for _ in range(repeat - 1):
                        again = run(runner, scenario, parameters, signals, tolerance)
                        r["cpu"], r["wall"] = min(r["cpu"], again["cpu"]), min(r["wall"],
                                                                             again["wall"])
                    row = {"case": label, "scenario": scenario.name, "rtol": tolerance,
                           "steps": r["steps"], "cpu_s_per_s": r["cpu"] / r["simulated"],
                           "x_realtime": r["simulated"] / r["wall"]}
                    for g, cols in columns.items():
                        row[f"l2 {g}"] = relative_l2(r["samples"][:, cols],
                                                     reference["samples"][:, cols])
                        row[f"orders {g}"] = order_error(r["samples"][:, cols],
                                                         reference["samples"][:, cols], scenario,
                                                         orders)
                    row["reference_steps"] = reference["steps"]
                    rows.append(row)
                    if progress is not None:
                        progress(label, scenario, tolerance, r)
    return pd.DataFrame(rows)


def slopes(table: pd.DataFrame, column: str) -> pd.DataFrame:
    """Per case and scenario: decades of error bought per decade of tolerance between
    neighbouring tolerances (1 = the error follows the tolerance)."""
    out = []
    for (case, scenario), g in table.groupby(["case", "scenario"], sort=False):
        g = g.sort_values("rtol", ascending=False)
        e, r = np.log10(g[column].to_numpy()), np.log10(g.rtol.to_numpy())
        for k in range(1, len(g)):
            out.append({"case": case, "scenario": scenario, "from": 10 ** r[k - 1],
                        "to": 10 ** r[k],
                        "decades per decade": (e[k - 1] - e[k]) / (r[k - 1] - r[k])})
    return pd.DataFrame(out)


def plot(table: pd.DataFrame, png: str, title: str = "") -> None:
    """Log-log work-precision plot: error against CPU time per simulated second, one panel per
    scenario and signal group, one line per case (solid: relative L2 of the time signal, dashed:
    order amplitudes), each point labelled with its tolerance."""
    groups = [c[3:] for c in table.columns if c.startswith("l2 ") and table[c].notna().any()]
    scenarios = list(dict.fromkeys(table.scenario))
    fig, axes = plt.subplots(len(groups), len(scenarios), squeeze=False,
                             figsize=(5.5 * len(scenarios), 4.2 * len(groups)))
    for i, group in enumerate(groups):
        for j, scenario in enumerate(scenarios):
            ax = axes[i][j]
            for k, (case, data) in enumerate(table[table.scenario == scenario].groupby(
                    "case", sort=False)):
                colour = f"C{k}"
                name = case or "default"
                ax.loglog(data.cpu_s_per_s, data[f"l2 {group}"], "o-", color=colour,
                          label=f"{name}: L2 of the signals")
                orders = data[f"orders {group}"]
                if orders.notna().any():
                    ax.loglog(data.cpu_s_per_s, orders, "s--", color=colour, ms=4,
                              label=f"{name}: order amplitudes")
                for _, r in data.iterrows():
                    ax.annotate(f"{r.rtol:.0e}", (r.cpu_s_per_s, r[f"l2 {group}"]), fontsize=6,
                                xytext=(3, 3), textcoords="offset points")
            ax.set_xlabel("CPU time per simulated second [s]")
            ax.set_ylabel(f"relative error of {group}[…]")
            ax.set_title(f"{scenario}: {group}[…]", fontsize=9)
            ax.grid(True, which="both", lw=0.3)
            ax.legend(fontsize=6)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def default_accuracy_signals(variables: dict) -> list[str]:
    """The twelve mount forces and the steering-wheel acceleration (the README's table)."""
    return [n for n, v in variables.items() if v.causality == "output" and v.type == "Real"
            and n.startswith(("mount[", "steeringWheel.a"))]


def cmd_accuracy(args) -> int:
    """``emc accuracy``: see the module documentation."""
    variables, cases = prepare(args)
    for label, parameters in cases:
        if "solver.relTol" in parameters:
            raise UsageError(f"{'case ' + repr(label) + ': ' if label else ''}solver.relTol "
                                 "is what emc accuracy varies; give the tolerances with --rtol")
    rel = variables.get("solver.relTol")
    low = float(rel.min) if rel is not None and rel.min is not None else 1e-12
    high = float(rel.max) if rel is not None and rel.max is not None else 0.1
    for tol in args.rtol:
        check_range("--rtol", tol, low, high)
    check_range("--reference-rtol", args.reference_rtol, low, high)
    if args.reference_rtol >= min(args.rtol):
        raise UsageError(f"--reference-rtol {args.reference_rtol:g} must be below every "
                             f"--rtol (smallest {min(args.rtol):g})")
    check_range("--duration", args.duration, 0.0, strict_low=True)
    check_range("--settle", args.settle, 0.0)
    check_range("--repeat", args.repeat, 1)
    check_range("--step", args.step, 0.0, args.duration, strict_low=True)
    highest = highest_speed(variables)
    check_range("--rpm-point", args.rpm_point, 0.0, highest, strict_low=True)
    check_range("--load-torque", args.load_torque)
    load = f", {args.load_torque:g} N·m" if args.load_torque else ""
    kinds = list(dict.fromkeys(args.scenario or ["stationary", "runup"]))
    scenarios = []
    for kind in kinds:
        if kind == "stationary":
            scenarios.append(Scenario(f"{args.rpm_point:g} rpm{load}", args.rpm_point,
                                      args.rpm_point, args.duration, args.step,
                                      args.start == "periodic", args.settle, args.load_torque))
        else:
            check_speeds(args.runup, increasing=True, highest=highest)
            if args.start == "periodic":
                raise UsageError("--start periodic needs a constant speed; use "
                                     "--scenario stationary")
            scenarios.append(Scenario(f"run-up {args.runup[0]:g}-{args.runup[1]:g} rpm{load}",
                                      args.runup[0], args.runup[1], args.duration, args.step,
                                      settle=args.settle, load_torque=args.load_torque))
    signals = list(dict.fromkeys(args.signal or []))
    check_outputs("--signal", signals, variables)
    signals = signals or default_accuracy_signals(variables)
    orders = tuple(args.order or COMPARED_ORDERS)
    tolerances = sorted(set(args.rtol), reverse=True)
    reduction_notice(cases[0][1], variables)
    out = claim(args)

    def progress(label, scenario, tolerance, result):
        if not args.quiet:
            print(f"  {label + ': ' if label else ''}{scenario.name}, rtol {tolerance:.0e}: "
                  f"{result['steps']} steps, {result['cpu']:.2f} s CPU", file=sys.stderr)

    started = time.perf_counter()
    table = work_precision(args.fmu, cases, scenarios, signals, tolerances,
                           args.reference_rtol, orders, progress, args.repeat)
    table.to_csv(out / "accuracy.csv", index=False)
    title = ", ".join(f"{label or 'default'}" for label, _ in cases) + \
        f" (reference rtol {args.reference_rtol:g}, {args.step * 1e3:g} ms communication step)"
    plot(table, str(out / "accuracy.png"), title)
    write_metadata(out, args, variables, cases,
                       {"tolerances": tolerances, "reference_rtol": args.reference_rtol,
                        "scenarios": [dataclasses.asdict(s) for s in scenarios],
                        "signals": signals, "orders": list(orders)})
    shown = table.drop(columns=["reference_steps"])
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(shown.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    first = next(c for c in table.columns if c.startswith("l2 "))
    slope = slopes(table, first)
    if not slope.empty:
        worst = slope.groupby(["case", "scenario"], sort=False)["decades per decade"].min()
        print(f"decades of {first[3:]} error per decade of tolerance, worst neighbouring pair: "
              + "; ".join(f"{c + ': ' if c else ''}{s} {v:.2f}" for (c, s), v in worst.items()))
    print(f"work-precision table in {time.perf_counter() - started:.1f} s -> {out}")
    return 0
