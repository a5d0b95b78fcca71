"""``emc doe``: a design of experiments over mount variables with the variance-based
sensitivity of the comfort objective (and of the static travel) to each variable, so that the
engineer sees which mounts matter before optimising (:mod:`emc.studies.mount_study`).

Two plans, both from SALib (the field's library for global sensitivity analysis), seeded:

- ``sobol`` (default): Saltelli's extension of a scrambled Sobol' sequence, N (n + 2) designs for
  n variables; Sobol' first-order and total indices (S1: the share of the objective's variance
  each variable explains alone; ST: with all its interactions) with bootstrap confidence
  intervals.
- ``lhs``: a Latin hypercube of N designs; first-order indices by RBD-FAST (random balance
  designs), which works on any such sample.

Every design runs its speed band and its static equilibria (all designs' runs spread over the
pool, stored as they finish). The designs' table, the indices and plots go to the study folder.
"""

from __future__ import annotations

import json
import pathlib
import time

import numpy as np
import pandas as pd
from SALib.analyze import rbd_fast
from SALib.analyze import sobol as sobol_analysis
from SALib.sample import latin
from SALib.sample import sobol as sobol_sampling

from ..base.checks import check_range
from ..base.errors import UsageError
from ..base.outputs import reduction_notice, warn, write_metadata
from ..figures.plots import plt
from ..running.runner import progress_bar
from .mount_study import Problem, design_table, open_study, problem_from_args

# The responses whose sensitivities are reported: the objective and the limits' quantities.
RESPONSES = {"objective": "objective", "max_deflection_mm": "largest mount deflection",
             "max_rotation_deg": "largest powertrain rotation"}


def salib_problem(names: list[str], bounds: list[tuple[float, float]]) -> dict:
    return {"num_vars": len(names), "names": list(names), "bounds": [list(b) for b in bounds]}


def sample(problem: dict, method: str, n: int, seed: int) -> np.ndarray:
    """The designs of the plan (rows: designs, columns: variables in their units)."""
    if method == "sobol":
        return sobol_sampling.sample(problem, n, calc_second_order=False, seed=seed)
    return latin.sample(problem, n, seed=seed)


# Resamples of the bootstrap (confidence) and of the permutation test (the index of a response
# that does not depend on a variable at all), each a few milliseconds on a study's sample.
RESAMPLES = 200
# An index whose confidence half-width exceeds this, or an RBD-FAST index below which no
# sensitivity can be told from none, makes the sample too small for the table: said so.
PRECISION = 0.1


def _rbd_fast_s1(problem: dict, X: np.ndarray, Y: np.ndarray, seed: int) -> np.ndarray:
    """RBD-FAST's first-order indices. SALib also bootstraps a confidence of its own with each
    (100 resamples by default) from draws that do not touch S1; the bootstrap and the
    permutation test here call this 2 × RESAMPLES times, so SALib's is cut to the 2 it needs
    to run at all: the same S1 to the bit, and the indices of a study in a fiftieth of the time
    (an RBD-FAST table of 3 responses: 30 s before)."""
    return np.asarray(rbd_fast.analyze(problem, X, Y, num_resamples=2, seed=seed)["S1"],
                      dtype=float)


def indices(problem: dict, method: str, X: np.ndarray, Y: np.ndarray, seed: int) -> pd.DataFrame:
    """Sensitivity indices of response ``Y`` (one value per row of ``X``, the plan's order):
    S1 and ST (``sobol``) or S1 (``lhs``, RBD-FAST), each with its 95 % confidence half-width
    from a bootstrap of the designs (SALib's for Sobol', ours for RBD-FAST, whose SALib
    estimate has none), and whether it can be told from zero: Sobol' indices whose intervals
    reach zero, RBD-FAST's not above the 95th percentile of the same estimate on responses
    shuffled against the variable (``S1_null``: the estimator's floor for this sample, its
    small-sample bias included)."""
    Y = np.asarray(Y, dtype=float)
    X = np.asarray(X, dtype=float)
    if method == "sobol":
        s = sobol_analysis.analyze(problem, Y, calc_second_order=False, seed=seed,
                                   num_resamples=RESAMPLES)
        table = pd.DataFrame({"variable": problem["names"], "S1": s["S1"],
                              "S1_conf": s["S1_conf"], "ST": s["ST"], "ST_conf": s["ST_conf"]})
        table["zero"] = ((table.S1.abs() <= table.S1_conf) & (table.ST.abs() <= table.ST_conf))
        return table
    rng = np.random.default_rng(seed)
    s1 = _rbd_fast_s1(problem, X, Y, seed)
    rows = rng.integers(0, len(Y), size=(RESAMPLES, len(Y)))
    boot = np.array([_rbd_fast_s1(problem, X[r], Y[r], seed) for r in rows])
    null = np.array([_rbd_fast_s1(problem, X, rng.permutation(Y), seed)
                     for _ in range(RESAMPLES)])
    table = pd.DataFrame({"variable": problem["names"], "S1": s1,
                          "S1_conf": 1.96 * boot.std(axis=0),
                          "S1_null": np.percentile(null, 95, axis=0)})
    table["zero"] = table.S1 <= table.S1_null
    return table


def precision_warnings(table: pd.DataFrame, method: str, samples: int) -> list[str]:
    """What the sample cannot resolve: confidence half-widths above :data:`PRECISION`, an
    RBD-FAST floor above it; each with the sample that would bring it down."""
    lines = []
    widest = table[[c for c in ("S1_conf", "ST_conf") if c in table]].max().max()
    if widest > PRECISION:
        # The half-width falls as 1 / sqrt(N).
        needed = int(np.ceil(samples * (widest / PRECISION) ** 2))
        lines.append(f"the indices' 95 % confidence half-widths reach {widest:.2f} with "
                     f"--samples {samples}: about --samples {needed} bring them to "
                     f"{PRECISION:g}")
    if method == "lhs" and table.S1_null.max() > PRECISION:
        floor = table.S1_null.max()
        needed = int(np.ceil(samples * floor / PRECISION))
        lines.append(f"with --samples {samples} RBD-FAST reports up to {floor:.2f} for a "
                     f"variable the response does not depend on (its small-sample bias): "
                     f"first-order indices below that cannot be told from zero; about "
                     f"--samples {needed} bring the floor to {PRECISION:g}")
    return lines


def plot_indices(table: pd.DataFrame, path: str, title: str):
    responses = list(dict.fromkeys(table.response))
    fig, axes = plt.subplots(1, len(responses), figsize=(4.2 * len(responses), 0.45 *
                             table.variable.nunique() + 1.8), sharey=True, squeeze=False)
    for ax, response in zip(axes[0], responses):
        t = table[table.response == response]
        y = np.arange(len(t))
        ax.barh(y - 0.18, t.S1, 0.36, xerr=t.S1_conf, label="first order S1", color="C0")
        if "ST" in t and t.ST.notna().any():
            ax.barh(y + 0.18, t.ST, 0.36, xerr=t.ST_conf, label="total ST", color="C1")
        ax.set_yticks(y, t.variable)
        ax.invert_yaxis()
        ax.set_xlim(0, 1.05)
        ax.set_title(RESPONSES.get(response, response), fontsize=9)
        ax.grid(True, axis="x", alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_scatter(designs: pd.DataFrame, names: list[str], path: str):
    cols = min(4, len(names))
    rows = -(-len(names) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.3 * cols, 2.8 * rows), sharey=True,
                             squeeze=False)
    ok = designs.feasible
    for ax, name in zip(axes.flat, names):
        ax.plot(designs[name][ok], designs.objective[ok], ".", ms=4, color="C0", label="feasible")
        ax.plot(designs[name][~ok], designs.objective[~ok], "x", ms=4, color="C3",
                label="beyond a limit")
        ax.set_xlabel(name, fontsize=8)
        ax.grid(True, alpha=0.3)
    for ax in axes.flat[len(names):]:
        ax.axis("off")
    axes[0][0].set_ylabel("objective [m/s²]")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cmd_doe(args) -> int:
    problem, variables, mounts = problem_from_args(args)
    # RBD-FAST reads 10 harmonics of each variable's ordering of the sample: it needs more
    # designs than 2 x 10.
    check_range("--samples", args.samples, 21 if args.method == "lhs" else 2)
    out = pathlib.Path(args.out)
    names = [v.name for v in problem.variables]
    salib = salib_problem(names, [(v.low, v.high) for v in problem.variables])
    X = sample(salib, args.method, args.samples, args.seed)
    reduction_notice({"scene": 2}, variables)
    started = time.perf_counter()
    store, evaluator, pool = open_study(args, problem, mounts)
    # The current design first: the reference of the table.

    bar = progress_bar(len(X) + 1, "designs", not args.quiet, unit="design")
    evaluator.progress = None if bar is None else (lambda record: bar.update(1))
    try:
        baseline = evaluator([problem.baseline()])[0]
        records = evaluator(list(X))
    finally:
        if bar is not None:
            bar.close()
        evaluator.close()
        if pool is not None:
            pool.close()
    elapsed = time.perf_counter() - started
    designs = design_table(problem, records)
    designs.to_csv(out / "designs.csv", index=False)
    tables = []
    for response in RESPONSES:
        values = designs[response].to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            raise UsageError(f"design {k + 1} of the plan ("
                             + ", ".join(f"{n}={designs[n].iloc[k]:.4g}" for n in names)
                             + f") has {RESPONSES[response]} {values[k]}: the indices need a "
                             "finite value of every design")
        t = indices(salib, args.method, X, values, args.seed)
        t.insert(0, "response", response)
        tables.append(t)
    table = pd.concat(tables, ignore_index=True)
    table.to_csv(out / "sensitivity.csv", index=False)
    warnings = precision_warnings(table, args.method, args.samples)
    warn(warnings)
    what = ("Sobol' indices (Saltelli)" if args.method == "sobol" else
            "first-order indices (RBD-FAST on a Latin hypercube)")
    plot_indices(table, str(out / "sensitivity.png"),
                 f"{what}, {len(X)} designs, {problem.objective} over "
                 f"{problem.rpm_from:g}-{problem.rpm_to:g} rpm")
    plot_scatter(designs, names, str(out / "scatter.png"))
    best = designs[designs.feasible].sort_values("objective").head(1)
    current = design_table(problem, [baseline]).iloc[0].to_dict()
    summary = {"designs": len(X), "evaluated_now": evaluator.evaluated, "seconds": elapsed,
               "current_design": current, "baseline_objective": baseline["objective"],
               "best_feasible": best.to_dict("records"),
               "current_is_best": bool(baseline["feasible"] and (
                   best.empty or baseline["objective"] <= best.objective.iloc[0])),
               "warnings": warnings}
    (out / "doe.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    write_metadata(out, args, variables, [("", dict(problem.parameters))],
                       {"problem": problem.settings(), "plan": {"method": args.method,
                                                                "samples": args.samples,
                                                                "seed": args.seed}})
    print_summary(problem, table, designs, baseline, len(X), evaluator.evaluated, elapsed)
    print(f"-> {out}")
    return 0


def print_summary(problem: Problem, table: pd.DataFrame, designs: pd.DataFrame, baseline: dict,
                  count: int, evaluated: int, elapsed: float):
    shown = table.pivot(index="variable", columns="response",
                        values=[c for c in ("S1", "ST") if c in table]).reindex(
        [v.name for v in problem.variables])
    print(f"{count} designs ({evaluated} run now) in {elapsed:.1f} s; objective "
          f"({problem.objective}, m/s²) of the current design {baseline['objective']:.4g}, "
          f"{designs.feasible.sum()} designs within the limits")
    print(shown.to_string(float_format=lambda v: f"{v:.3f}"))
    print(f"current design: objective {baseline['objective']:.4g}, "
          + ("within the limits" if baseline["feasible"] else "beyond a limit") + ": "
          + ", ".join(f"{v.name}={x:.3g}" for v, x in zip(problem.variables, baseline["x"])))
    zero = table[table.zero]
    if not zero.empty:
        print("indistinguishable from zero (95 %): " + "; ".join(
            f"{RESPONSES.get(r, r)}: " + ", ".join(g.variable)
            for r, g in zero.groupby("response", sort=False)))
    if designs.feasible.any():
        best = designs[designs.feasible].sort_values("objective").iloc[0]
        print(f"best feasible design of the plan: objective {best.objective:.4g} "
              f"({best.objective / baseline['objective'] - 1:+.1%} against the current): "
              + ", ".join(f"{v.name}={best[v.name]:.3g}" for v in problem.variables))
        if baseline["feasible"] and baseline["objective"] <= best.objective:
            print("no design of the plan beats the current design")
