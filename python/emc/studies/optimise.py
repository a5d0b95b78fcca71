"""``emc optimise``: tunes mount parameters for comfort over a speed band within the limits a
mount engineer sets (:mod:`emc.studies.mount_study`).

The optimiser is SciPy's COBYQA (``scipy.optimize.minimize(method="COBYQA")``, Ragonneau & Zhang):
derivative-free (each objective value is a set of simulations, no gradients), with bounds and
nonlinear inequality constraints of its own (the limits), few evaluations for a handful of
variables, and deterministic, so a study is reproducible and an interrupted one, started again,
asks for the same designs and finds them in its store. It works in the unit cube of the bounds,
starting from the current design (or the best feasible design of a DOE study). Its first
2n + 1 designs (the start and a step along each variable both ways) are evaluated together on
the pool before it asks for them; after that every design's speed points and static equilibria
run in parallel.

After the optimum, each variable is changed by ±5 % alone: the objective there (a check that no
such step improves a feasible design, and the local sensitivities: the objective's relative
change per relative change of the variable). The current design and the optimum are then swept
side by side (waterfalls, order cuts, comfort).
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import time

import numpy as np
import pandas as pd
from scipy.optimize import Bounds, NonlinearConstraint, minimize

from ..base.checks import check_range
from ..base.errors import UsageError
from ..base.fmu import units_of
from ..base.outputs import reduction_notice, save, write_metadata
from ..figures import plots
from ..figures.plots import plt
from ..running.runner import progress_bar
from ..running.sweep import tables
from ..signals.comfort import comfort_table
from .mount_study import (Problem, StudyError, design_table, open_study, problem_from_args,
                          read_store)

PERTURBATION = 0.05


def start_designs(problem: Problem, u0: np.ndarray, radius: float) -> list[np.ndarray]:
    """The start and a step of ``radius`` along each unit-cube axis both ways (inside the cube):
    the designs COBYQA's first model interpolates."""
    designs = [u0]
    for i in range(len(u0)):
        for sign in (1.0, -1.0):
            u = u0.copy()
            u[i] = min(1.0, max(0.0, u[i] + sign * radius))
            designs.append(u)
    return [problem.from_unit(u) for u in designs]


def minimise(problem: Problem, evaluator, start, evaluations: int = 60,
             radius: float = 0.25, final_radius: float = 1e-3) -> dict:
    """Runs COBYQA from design ``start``; returns the best feasible design's record (the start's
    if none is better) and the optimiser's message."""

    u0 = problem.unit(start)
    evaluator(start_designs(problem, u0, radius))
    reference = max(evaluator([start])[0]["objective"], 1e-12)

    def record(u):
        return evaluator([problem.from_unit(u)])[0]

    def objective(u):
        return record(u)["objective"] / reference

    def limits(u):
        return np.array(list(record(u)["violations"].values()))

    result = minimize(objective, u0, method="COBYQA", bounds=Bounds(0.0, 1.0),
                      constraints=[NonlinearConstraint(limits, -np.inf, 0.0)],
                      options={"maxfev": evaluations, "initial_tr_radius": radius,
                               "final_tr_radius": final_radius})
    feasible = [r for r in evaluator.store.history() if r["feasible"]]
    best = min(feasible, key=lambda r: r["objective"]) if feasible else evaluator([start])[0]
    return {"best": best, "message": str(result.message), "evaluations": int(result.nfev)}


def perturbations(problem: Problem, x) -> list[tuple[str, float, np.ndarray]]:
    """Design ``x`` with each variable changed by ±5 % alone (of its value; of its range for a
    variable at 0), kept inside the bounds: (variable, sign, design)."""
    out = []
    for i, v in enumerate(problem.variables):
        for sign in (1.0, -1.0):
            step = PERTURBATION * (abs(x[i]) if x[i] != 0.0 else v.high - v.low)
            y = np.array(x, dtype=float)
            y[i] = min(v.high, max(v.low, x[i] + sign * step))
            if y[i] != x[i]:
                out.append((v.name, sign, y))
    return out


def local_check(problem: Problem, evaluator, best: dict) -> pd.DataFrame:
    """The objective around the optimum, each variable ±5 % alone: whether a feasible step
    improves it, and the local sensitivity (relative change of the objective per relative change
    of the variable, central where both steps exist)."""
    x = np.array(best["x"])
    steps = perturbations(problem, x)
    records = evaluator([y for _, _, y in steps])
    rows = []
    for (name, sign, y), r in zip(steps, records):
        i = [v.name for v in problem.variables].index(name)
        rows.append({"variable": name, "step": f"{'+' if sign > 0 else '-'}{PERTURBATION:.0%}",
                     "value": y[i], "objective": r["objective"], "feasible": r["feasible"],
                     "change": r["objective"] / best["objective"] - 1.0,
                     "improves": bool(r["feasible"] and r["objective"] < best["objective"])})
    table = pd.DataFrame(rows)
    sensitivity = {}
    for i, v in enumerate(problem.variables):
        mine = table[table.variable == v.name]
        if mine.empty:
            continue
        dx = (mine.value.max() - mine.value.min()) if len(mine) == 2 else (
            mine.value.iloc[0] - x[i])
        df = (mine.objective.iloc[0] - mine.objective.iloc[-1]) if len(mine) == 2 else (
            mine.objective.iloc[0] - best["objective"])
        if len(mine) == 2 and mine.value.iloc[0] < mine.value.iloc[-1]:
            df = -df
        scale = abs(x[i]) if x[i] != 0.0 else (v.high - v.low)
        sensitivity[v.name] = df / best["objective"] / (dx / scale) if dx else float("nan")
    table["sensitivity"] = table.variable.map(sensitivity)
    return table


def plot_history(history: pd.DataFrame, baseline: float, path: str, title: str):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ok = history.feasible
    ax.plot(history.evaluation[ok], history.objective[ok], "o", ms=4, color="C0",
            label="feasible design")
    ax.plot(history.evaluation[~ok], history.objective[~ok], "x", ms=5, color="C3",
            label="beyond a limit")
    best = history.objective.where(ok).cummin().ffill()
    ax.step(history.evaluation, best, where="post", color="C2", lw=1.6,
            label="best feasible so far")
    ax.axhline(baseline, color="0.4", ls="--", lw=1.0, label="current design")
    ax.set_xlabel("evaluation")
    ax.set_ylabel("objective [m/s²]")
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def compare(problem: Problem, evaluator, designs: dict, out: pathlib.Path, units: dict,
            progress: bool = True):
    """Sweeps each design of ``designs`` (label → x) over the band on the study's pool (a
    configuration a design needs travels with its runs) and draws them side by side: waterfalls
    and order cuts of the steering wheel's vertical and lateral acceleration, comfort."""

    orders, spectra = [], []
    for label, x in designs.items():
        points = problem.evaluations(x)[:problem.count]
        bar = progress_bar(len(points), label, progress, unit="point")
        try:
            done = evaluator.run_all(points, None if bar is None else bar.update)
        finally:
            if bar is not None:
                bar.close()
        o, s = tables([analysis for analysis, _ in done], label)
        orders.append(o)
        spectra.append(s)
    orders, spectra = pd.concat(orders, ignore_index=True), pd.concat(spectra, ignore_index=True)
    save(orders, str(out / "orders.csv"))
    labels = list(designs)
    for signal in ("steeringWheel.a[3]", "steeringWheel.a[2]"):
        name = signal.replace("[", "").replace("]", "")
        plots.side_by_side(spectra, orders, signal, labels, str(out / f"waterfall_{name}.png"),
                           str(out / f"order_cuts_{name}.png"), unit=units.get(signal))
    exposure = comfort_table(spectra)
    save(exposure, str(out / "comfort.csv"))
    plots.comfort(exposure, str(out / "comfort.png"), cases=labels)
    return exposure


class Progress:
    """One line per design the optimiser runs: its objective, whether it is within the limits,
    the best so far."""

    def __init__(self, stored: list[dict]):
        self.count = len(stored)
        self.best = min((r["objective"] for r in stored if r["feasible"]), default=math.inf)

    def __call__(self, record: dict):
        self.count += 1
        if record["feasible"]:
            self.best = min(self.best, record["objective"])
        print(f"design {self.count}: objective {record['objective']:.4g} m/s²"
              f"{'' if record['feasible'] else ' (beyond a limit)'}, best within the limits "
              f"{self.best:.4g}, {record['seconds']:.1f} s", file=sys.stderr, flush=True)


def cmd_optimise(args) -> int:
    problem, variables, mounts = problem_from_args(args)
    check_range("--evaluations", args.evaluations, 1)
    out = pathlib.Path(args.out)
    start = problem.baseline()
    if args.start_from:
        start = best_of_study(pathlib.Path(args.start_from), problem)
    reduction_notice({"scene": 2}, variables)
    started = time.perf_counter()
    store, evaluator, pool = open_study(args, problem, mounts)
    if not args.quiet:
        evaluator.progress = Progress(store.history())
    try:
        baseline = evaluator([problem.baseline()])[0]
        result = minimise(problem, evaluator, start, args.evaluations)
        best = result["best"]
        check = local_check(problem, evaluator, best)
        optimised = time.perf_counter() - started
        history = design_table(problem, store.history())
        history.to_csv(out / "history.csv", index=False)
        check.to_csv(out / "local_check.csv", index=False)
        plot_history(history, baseline["objective"], str(out / "history.png"),
                     f"{problem.objective} over {problem.rpm_from:g}-{problem.rpm_to:g} rpm "
                     f"({problem.count} points), COBYQA: {result['message']}")
        designs = {"current design": problem.baseline(), "optimum": np.array(best["x"])}
        compare(problem, evaluator, designs, out, units_of(variables), not args.quiet)
    finally:
        evaluator.close()
        if pool is not None:
            pool.close()
    elapsed = time.perf_counter() - started
    report = {"baseline": baseline, "best": best, "message": result["message"],
              "evaluations_in_store": len(store.records), "evaluated_now": evaluator.evaluated,
              "seconds_optimisation": optimised, "seconds_total": elapsed}
    (out / "optimum.json").write_text(json.dumps(report, indent=2) + "\n")
    write_metadata(out, args, variables, [("", dict(problem.parameters))],
                       {"problem": problem.settings(), "optimiser": "scipy COBYQA",
                        "result": {k: report[k] for k in ("message", "evaluations_in_store",
                                                          "evaluated_now")}})
    print_summary(problem, baseline, best, check, report)
    print(f"optimisation in {elapsed:.1f} s -> {out}")
    return 0


def print_summary(problem: Problem, baseline: dict, best: dict, check: pd.DataFrame,
                  report: dict):
    print(f"objective ({problem.objective}, m/s²): current design {baseline['objective']:.4g}"
          f"{'' if baseline['feasible'] else ' (beyond a limit)'}, optimum "
          f"{best['objective']:.4g} ({best['objective'] / baseline['objective'] - 1:+.1%}), "
          f"{report['evaluations_in_store']} designs evaluated "
          f"({report['evaluated_now']} now), COBYQA: {report['message']}")
    design = pd.DataFrame({"variable": [v.name for v in problem.variables],
                           "current": baseline["x"], "optimum": best["x"],
                           "low": [v.low for v in problem.variables],
                           "high": [v.high for v in problem.variables]})
    print(design.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    use = {k: f"{v + 1:.0%}" for k, v in best["violations"].items()}
    print(f"limits used at the optimum: {use}")
    improving = check[check.improves]
    print("±5 % around the optimum: " + ("no feasible step improves the objective" if
                                         improving.empty else
                                         f"{len(improving)} steps improve it (not converged)"))
    sens = check.drop_duplicates("variable")[["variable", "sensitivity"]]
    print(sens.to_string(index=False, float_format=lambda v: f"{v:+.3f}"))


def best_of_study(folder: pathlib.Path, problem: Problem) -> np.ndarray:
    """The best feasible design of the study in ``folder`` (same variables)."""
    path = folder / "evaluations.jsonl"
    if not path.exists():
        raise UsageError(f"--start-from {folder}: no evaluations.jsonl there")
    try:
        header, records, _ = read_store(path)
    except StudyError as error:
        raise UsageError(f"--start-from {folder}: {error}") from None
    if header is None:
        raise UsageError(f"--start-from {folder}: {path} is empty")
    try:
        names = [v["name"] for v in header["settings"]["variables"]]
    except (KeyError, TypeError):
        raise UsageError(f"--start-from {folder}: {path} is not a study of mount variables") \
            from None
    if names != [v.name for v in problem.variables]:
        raise UsageError(f"--start-from {folder}: that study has other variables ({names})")
    feasible = [r for r in records if r["feasible"]]
    if not feasible:
        raise UsageError(f"--start-from {folder}: no feasible design there")
    best = min(feasible, key=lambda r: r["objective"])
    print(f"note: starting from the best feasible design of {path}: "
          + ", ".join(f"{n}={v:.4g}" for n, v in zip(names, best["x"]))
          + f" (objective {best['objective']:.4g} m/s²)", file=sys.stderr)
    return np.array(best["x"])
