"""``emc calibrate``: fits the uncertain parameters (:mod:`.parameters`) to the measured order
cuts and says what the data determine.

**The fit.** Weighted least squares on log amplitudes, and on phase where the data has it (the
measured phase must refer to the crank angle the model uses: cylinder 1 at top dead centre at
``crank.startAngle``; ``--no-phase`` drops it): for every channel and speed above the channel's
noise floor the residuals ``(ln|S| − ln|M|) / σ`` and ``arg(S / M) / σ``, with
``σ² = u² + (floor / |M|)²`` (``u``: the relative uncertainty of a measured level,
``--uncertainty``; near the noise floor a level carries less information). Levels at a resonance
scale with 1/damping and with the stiffness through the resonance speed: in logarithms the
problem is close to linear, and the parameters are fitted as logarithms of their factors (they are
positive, their uncertainty relative).

The solver is SciPy's ``least_squares`` (trust-region reflective, bounds of its own): a
maintained, documented implementation of exactly this problem (bounded nonlinear least squares)
that takes the Jacobian from the caller, so that the ``n + 1`` parameter sets of each Jacobian
(forward differences, a 2 % step) run together on the Dask pool. lmfit wraps the same solver;
its extras (parameter objects, MCMC through emcee) are not needed here.

**Resumable.** Every parameter set's simulated order components are stored as they come
(``evaluations.jsonl`` in ``--out``, with the FMU's checksum and what decides the simulation: the
parameters, speeds, outputs, orders, window, fixed start values and base configuration); the
solver is deterministic, so a calibration started again in the same folder asks for the same
sets, reads them and continues where it stopped, to the same result. Another ``--uncertainty``,
``--no-phase`` or other bounds reuse the stored simulations.

**What the data determine.** At the optimum, the covariance of the log factors is ``s² (JᵀJ)⁻¹``
(``J`` the Jacobian of the weighted residuals, ``s²`` the residual variance per degree of
freedom: the scatter the fit actually left, not the one assumed); 95 % intervals use Student's t.
The problem is nearly linear in the log factors over such intervals (the twin experiment in the
tests checks their coverage), so a sampler (emcee) would add run time, not information. The
correlation matrix shows which parameters trade off; a pair with |ρ| > 0.95 cannot be told apart
by the data, a parameter whose interval spans more than a factor 2 either way is not determined.

**Written to ``--out``**: ``calibration.json`` (values, intervals, correlation matrix,
identifiability, convergence), ``parameters.csv``, ``correlation_before_after.csv``,
``vehicle_calibrated.json`` (the configuration with the factors folded in: ``--set
configFile=<it>`` makes every command use it), ``band.json`` (the calibrated damping's 95 %
intervals as a band: ``--band-from``), ``calibrate_<output>.png`` (measured, nominal and
calibrated order cuts with the calibrated band) and ``metadata.json``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import pathlib
import sys
import time

import numpy as np
import pandas as pd
from scipy.optimize import least_squares
from scipy.stats import t as student_t

from ..base.checks import check_range
from ..base.errors import UsageError
from ..base.fmu import file_sha256, mount_count, units_of
from ..base.outputs import claim, write_metadata
from ..figures import plots
from ..running import band as bands
from ..running.band import band_metadata
from ..running.engine import PointEngine
from ..studies.mount_study import Store, StudyError, base_configuration
from . import parameters as params
from .correlate import Setup, cuts_table, metrics_table, open_pool, overlay_figure, run_sets, safe
from .simulate import Grid

STEP = 0.005              # forward-difference step of the log factors
NOT_TOLD_APART = 0.95     # |correlation| above which two parameters trade off
UNDETERMINED = np.log(2.0)  # a 95 % half-width beyond a factor 2: not determined
DEFAULT_PARAMETERS = ("mount[{i}].stiffnessScale", "mount[*].dampingScale",
                      "chassis.modalDampingScale")


@dataclasses.dataclass
class Problem:
    """The calibration problem: the channels on the grid, the parameters, the fixed start values,
    the base configuration, the residual weighting."""

    grid: Grid
    channels: list
    parameters: tuple
    fixed: dict
    base: dict | None            # complete vehicle configuration (rates need it)
    revolutions: int
    uncertainty: float
    phase: bool

    def start(self, theta) -> tuple[dict, str | None]:
        values = {**self.fixed, **params.fmu_values(self.parameters, theta)}
        if any(p.in_configuration for p in self.parameters):
            config = params.apply(self.base, self.parameters, theta, fold_inputs=False)
            return values, params.configuration_text(config)
        return values, None

    def settings(self) -> dict:
        """What decides a parameter set's simulated numbers, stored with them. Not the
        measurement, the weighting or the bounds: a calibration of the same speeds with another
        --uncertainty, --no-phase or bounds reuses the stored simulations."""
        base = None if self.base is None else hashlib.sha256(
            params.configuration_text(self.base).encode()).hexdigest()
        return {"parameters": [p.name for p in self.parameters],
                "speeds": list(self.grid.speeds), "signals": list(self.grid.signals),
                "orders": list(self.grid.orders), "revolutions": self.revolutions,
                "fixed": {k: v for k, v in self.fixed.items()}, "base_configuration": base}

    def residuals(self, simulated: np.ndarray, reference: np.ndarray | None = None
                  ) -> np.ndarray:
        """The weighted residuals of ``simulated`` against the measurement; with ``reference``
        (another simulation) their change from the reference's, the phase's taken as the angle
        between the two (no jump where a residual crosses ±π)."""
        parts = []
        for c in self.channels:
            m = c.values
            valid = np.abs(m) > c.floor
            sigma = np.sqrt(self.uncertainty**2 + (c.floor[valid] / np.abs(m[valid]))**2)
            s = channel_of(self.grid, c, simulated)[valid]
            base = m[valid] if reference is None else channel_of(self.grid, c, reference)[valid]
            parts.append((np.log(np.maximum(np.abs(s), 1e-300))
                          - np.log(np.maximum(np.abs(base), 1e-300))) / sigma)
            if self.phase and c.has_phase:
                parts.append(np.angle(s / base) / sigma)
        return np.concatenate(parts)

    def channel_residuals(self, simulated: np.ndarray) -> pd.DataFrame:
        """Per channel: the RMS of its weighted residuals and its mean level error (dB)."""
        rows = []
        for c in self.channels:
            s = channel_of(self.grid, c, simulated)
            valid = np.abs(c.values) > c.floor
            err = 20 * np.log10(np.abs(s[valid]) / np.abs(c.values[valid]))
            rows.append({"channel": c.label, "mean_db": float(np.mean(err)),
                         "rms_db": float(np.sqrt(np.mean(err**2)))})
        return pd.DataFrame(rows)


def channel_of(grid: Grid, channel, simulated: np.ndarray) -> np.ndarray:
    idx, order, signal = grid.index(channel)
    return simulated[idx, order, signal]


class Evaluations:
    """The simulated order components of parameter sets, from the store or run (all missing
    sets of a call together on the pool) and stored."""

    def __init__(self, problem: Problem, engine: PointEngine, store: Store,
                 progress: bool = True):
        self.problem, self.engine, self.store = problem, engine, store
        self.progress = progress
        self.run_now = 0      # parameter sets simulated by this process
        self.calls = 0        # parameter sets asked for (the store's included)
        self.shape = (len(problem.grid.speeds), len(problem.grid.orders),
                      len(problem.grid.signals))

    def __call__(self, thetas: list[np.ndarray]) -> list[np.ndarray]:
        self.calls += len(thetas)
        missing = [theta for theta in thetas if self.store.get(theta) is None]
        missing = list({Store.key(t): t for t in missing}.values())
        if missing:
            began = time.perf_counter()
            sets = [self.problem.start(theta) for theta in missing]
            done = run_sets(self.engine, self.problem.grid, sets, self.problem.revolutions,
                            True, "calibrate")
            seconds = (time.perf_counter() - began) / len(missing)
            for theta, sim in zip(missing, done):
                flat = sim.ravel()
                self.store.put(theta, {"x": [float(v) for v in theta],
                                       "re": flat.real.tolist(), "im": flat.imag.tolist(),
                                       "seconds": seconds})
                self.run_now += 1
            if self.progress:
                print(f"{len(missing)} parameter set(s) simulated in "
                      f"{seconds * len(missing):.1f} s ({self.run_now} so far)",
                      file=sys.stderr, flush=True)
        out = []
        for theta in thetas:
            record = self.store.get(theta)
            out.append((np.array(record["re"]) + 1j * np.array(record["im"])).reshape(self.shape))
        return out


def fit(problem: Problem, evaluations: Evaluations, max_evaluations: int = 40) -> dict:
    """Runs the fit from the nominal (every factor 1); returns the solver's result and what the
    data determine (see the module's documentation)."""
    low = np.log([p.low for p in problem.parameters])
    high = np.log([p.high for p in problem.parameters])
    n = len(problem.parameters)

    def fun(u):
        return problem.residuals(evaluations([np.exp(u)])[0])

    def jac(u, *_):
        steps = np.where(u + STEP <= high, STEP, -STEP)
        sets = [np.exp(u)] + [np.exp(u + steps[k] * np.eye(n)[k]) for k in range(n)]
        sims = evaluations(sets)
        return np.column_stack([problem.residuals(s, reference=sims[0]) / steps[k]
                                for k, s in enumerate(sims[1:])])

    result = least_squares(fun, np.zeros(n), jac=jac, bounds=(low, high), method="trf",
                           x_scale=1.0, xtol=1e-4, ftol=1e-6, gtol=1e-8,
                           max_nfev=max_evaluations)
    u = result.x
    r = fun(u)
    J = jac(u)
    m = len(r)
    dof = max(m - n, 1)
    s2 = float(r @ r) / dof
    jtj = J.T @ J
    covariance = s2 * np.linalg.pinv(jtj)
    sd = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = covariance / np.outer(sd, sd)
    quantile = float(student_t.ppf(0.975, dof))
    singular = np.linalg.svd(J, compute_uv=False)
    at_bound = [p.name for p, a in zip(problem.parameters, result.active_mask) if a != 0]
    theta = np.exp(u)
    return {"theta": theta, "u": u, "sd_log": sd, "quantile": quantile,
            "low95": np.exp(u - quantile * sd), "high95": np.exp(u + quantile * sd),
            "covariance_log": covariance, "correlation": correlation, "singular": singular,
            "residual_rms": float(np.sqrt(float(r @ r) / m)), "s2": s2, "residuals": m,
            "dof": dof, "status": int(result.status), "message": str(result.message),
            "nfev": int(result.nfev), "njev": int(result.njev or 0),
            "at_bound": at_bound, "cost_start": float(0.5 * fun(np.zeros(n)) @ fun(np.zeros(n))),
            "cost": float(result.cost)}


def identifiability(problem: Problem, result: dict) -> dict:
    """Which parameters the data do not determine, and which pairs they cannot tell apart."""
    names = [p.name for p in problem.parameters]
    undetermined = [name for name, sd in zip(names, result["sd_log"])
                    if result["quantile"] * sd > UNDETERMINED or not np.isfinite(sd)]
    pairs = []
    rho = result["correlation"]
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            if abs(rho[a, b]) > NOT_TOLD_APART:
                pairs.append({"parameters": [names[a], names[b]], "correlation": rho[a, b]})
    singular = result["singular"]
    condition = float(singular[0] / singular[-1]) if singular[-1] > 0 else float("inf")
    return {"undetermined": undetermined, "not_told_apart": pairs, "condition": condition}


def calibrated_band(problem: Problem, result: dict, mounts: int) -> bands.Band:
    """The band of the calibrated damping (its 95 % intervals, as factors on the calibrated
    values); a damping not calibrated keeps the default band's bounds. Paired like the default:
    the low bound has the least damped body with the most damped mounts."""
    low, high, parts = {}, {}, []
    # The body's scale, else the widest interval of its table's ordinates.
    body = [k for k, p in enumerate(problem.parameters) if p.kind == "modalDampingScale"] or [
        k for k, p in enumerate(problem.parameters) if p.kind == "dampingTable"]
    if not body:
        a, b = bands.BODY_SCALE
        parts.append(f"body modal damping x{a:g}..x{b:g} (default, not calibrated)")
    else:
        half = result["quantile"] * max(result["sd_log"][k] for k in body)
        a, b = float(np.exp(-half)), float(np.exp(half))
        parts.append(f"body modal damping x{a:.3g}..x{b:.3g} (calibrated, 95 %)")
    low["chassis.modalDampingScale"], high["chassis.modalDampingScale"] = a, b
    for i in range(1, mounts + 1):
        k = next((k for k, p in enumerate(problem.parameters)
                  if p.kind == "dampingScale" and i in p.mounts), None)
        if k is None:
            a, b = bands.MOUNT_SCALE
        else:
            half = result["quantile"] * result["sd_log"][k]
            a, b = float(np.exp(half)), float(np.exp(-half))
        low[f"mount[{i}].dampingScale"], high[f"mount[{i}].dampingScale"] = a, b
    calibrated = [p.name for p in problem.parameters if p.kind == "dampingScale"]
    if calibrated:
        parts.append(f"mount damping calibrated ({', '.join(calibrated)}, 95 %)")
    others = [i for i in range(1, mounts + 1) if not any(
        p.kind == "dampingScale" and i in p.mounts for p in problem.parameters)]
    if others:
        a, b = bands.MOUNT_SCALE
        parts.append(f"mount damping of mount(s) {', '.join(map(str, others))} x{a:.3g}..x{b:.3g}"
                     " (default, not calibrated)")
    return bands.Band(low=low, high=high, description="; ".join(parts), multiplies=True)


def convergence_report(problem: Problem, result: dict, after: pd.DataFrame) -> list[str]:
    """Why a calibration did not converge, or what to watch: the solver's status, parameters
    at their bounds, the residual, the channels that disagree most."""
    lines = []
    if result["status"] <= 0:
        lines.append(f"the solver stopped before converging: {result['message']} "
                     f"({result['nfev']} evaluations; raise --max-evaluations)")
    for name in result["at_bound"]:
        p = next(p for p in problem.parameters if p.name == name)
        value = float(np.exp(result["u"][[q.name for q in problem.parameters].index(name)]))
        bound = p.low if abs(value - p.low) < abs(value - p.high) else p.high
        lines.append(f"{name} ends at its bound {bound:g}: the data want it beyond (widen "
                     f"--param {name}=LOW:HIGH, or the model lacks what the data show)")
    if result["status"] <= 0 or result["at_bound"] or result["s2"] > 4.0:
        worst = after.reindex(after.rms_db.sort_values(ascending=False).index).head(3)
        lines.append(f"the weighted residual is {np.sqrt(result['s2']):.2g} times the assumed "
                     f"uncertainty ({problem.uncertainty:.0%}); channels that disagree most: "
                     + ", ".join(f"{r.channel} (RMS {r.rms_db:.1f} dB, mean {r.mean_db:+.1f} dB)"
                                 for r in worst.itertuples()))
    return lines


def plot_before_after(problem: Problem, sims: dict, band: bands.Band, out: pathlib.Path,
                      units: dict):
    for output in problem.grid.signals:
        fig = overlay_figure(problem.grid, problem.channels, output, units.get(output),
                             {"calibrated": sims["calibrated"], "nominal": sims["nominal"]},
                             (sims["low"], sims["high"], "calibrated band shaded"),
                             f"{output}: measured, nominal and calibrated model\n"
                             f"band: {band.description}")
        plots._save(fig, str(out / f"calibrate_{safe(output)}.png"))


def cmd_calibrate(args) -> int:
    setup = Setup(args)
    if setup.grid is None:
        raise UsageError(f"{args.mapping}: no order cuts to calibrate against (FRFs and "
                             "modes are correlated, not fitted)")
    check_range("--uncertainty", args.uncertainty, 0.0, strict_low=True)
    check_range("--max-evaluations", args.max_evaluations, 1)
    mounts = mount_count(setup.variables)
    texts = args.param or [t.format(i=i) for t in DEFAULT_PARAMETERS
                           for i in (range(1, mounts + 1) if "{i}" in t else [0])]
    try:
        chosen = params.parse_all(texts, mounts)
    except params.ParameterError as error:
        raise UsageError(str(error)) from None
    fixed = dict(setup.parameters)
    for p in chosen:
        for name in p.fmu_values(1.0):
            if name in fixed:
                raise UsageError(f"--set {name}: it is a calibration parameter")
    try:
        base = json.loads(base_configuration(args.fmu, fixed))
    except (StudyError, OSError, KeyError, json.JSONDecodeError) as error:
        raise UsageError(f"the calibrated configuration needs a complete vehicle "
                             f"configuration: {error}") from None
    if any(p.in_configuration for p in chosen):
        fixed.pop("configFile", None)
    try:  # refused here, before the fit, rather than when the result is written
        params.apply(base, chosen, np.ones(len(chosen)), fold_inputs=True)
    except params.ParameterError as error:
        raise UsageError(str(error)) from None
    problem = Problem(grid=setup.grid, channels=setup.channels, parameters=chosen, fixed=fixed,
                      base=base, revolutions=args.revolutions, uncertainty=args.uncertainty,
                      phase=not args.no_phase)
    digest = file_sha256(args.fmu)
    used = sum(int(np.sum(np.abs(c.values) > c.floor)) for c in problem.channels)
    if used <= len(chosen):
        raise UsageError(f"{args.mapping}: {used} measured points above the noise floors "
                             f"for {len(chosen)} parameters: too few to fit")
    out = claim(args)
    try:
        store = Store(out, digest, json.loads(json.dumps(problem.settings())),
                      fields=("key", "x", "re", "im"))
    except StudyError as error:
        raise UsageError(str(error)) from None
    if store.records:
        print(f"note: {len(store.records)} evaluations found in {store.path}: the calibration "
              "continues from them", file=sys.stderr)
    started = time.perf_counter()
    pool = open_pool(args, setup.parameters)
    engine = PointEngine.on(args.fmu, pool)
    evaluations = Evaluations(problem, engine, store, not args.quiet)
    try:
        result = fit(problem, evaluations, args.max_evaluations)
        fitted = time.perf_counter() - started
        band = calibrated_band(problem, result, mounts)
        theta = result["theta"]
        nominal, calibrated = evaluations([np.ones(len(chosen)), theta])
        start, config = problem.start(theta)
        low, high = run_sets(engine, setup.grid,
                             [(band.applied(start, "low"), config),
                              (band.applied(start, "high"), config)],
                             args.revolutions, True, "band")
    finally:
        engine.close()
        if pool is not None:
            pool.close()
    elapsed = time.perf_counter() - started
    sims = {"nominal": nominal, "calibrated": calibrated, "low": low, "high": high}
    write_results(args, setup, problem, result, band, sims, base, out,
                  {"seconds_fit": fitted, "seconds_total": elapsed,
                   "parameter_sets_run_now": evaluations.run_now,
                   "points_run_now": engine.points, "cpu_seconds_points": engine.cpu_s})
    return 0


def write_results(args, setup, problem: Problem, result: dict, band: bands.Band, sims: dict,
                  base: dict, out: pathlib.Path, cost: dict):
    names = [p.name for p in problem.parameters]
    ident = identifiability(problem, result)
    table = pd.DataFrame({
        "parameter": names, "value": result["theta"], "low95": result["low95"],
        "high95": result["high95"], "sd_log": result["sd_log"],
        "bound_low": [p.low for p in problem.parameters],
        "bound_high": [p.high for p in problem.parameters],
        "at_bound": [n in result["at_bound"] for n in names],
        "determined": [n not in ident["undetermined"] for n in names]})
    table.to_csv(out / "parameters.csv", index=False)
    before = metrics_table(problem.grid, problem.channels, sims["nominal"])
    after = metrics_table(problem.grid, problem.channels, sims["calibrated"], sims["low"],
                          sims["high"])
    keys = ["channel", "output", "order"]
    shown = ["mean_db", "rms_db", "max_db", "peak_rpm_diff", "peak_db_diff", "score"]
    both = before[keys + shown].merge(after[keys + shown + ["inside_band"]], on=keys,
                                      suffixes=("_before", "_after"))
    both.to_csv(out / "correlation_before_after.csv", index=False)
    cuts_table(problem.grid, problem.channels, {"nominal": sims["nominal"],
                                                "calibrated": sims["calibrated"],
                                                "calibrated_low": sims["low"],
                                                "calibrated_high": sims["high"]}
               ).to_csv(out / "order_cuts.csv", index=False)
    config = params.apply(base, problem.parameters, result["theta"], fold_inputs=True)
    config_path = out / "vehicle_calibrated.json"
    config_path.write_text(json.dumps(config, indent=1) + "\n")
    (out / "band.json").write_text(json.dumps({"description": band.description,
                                               "low": band.low, "high": band.high},
                                              indent=2) + "\n")
    lines = convergence_report(problem, result, problem.channel_residuals(sims["calibrated"]))
    report = {
        "parameters": table.to_dict("records"),
        "correlation_matrix": {"names": names, "values": result["correlation"].tolist()},
        "identifiability": ident,
        "singular_values": result["singular"].tolist(),
        "fit": {k: result[k] for k in ("status", "message", "nfev", "njev", "residual_rms", "s2",
                                       "residuals", "dof", "cost_start", "cost", "quantile")},
        "warnings": lines, "configuration": str(config_path.resolve()),
        "phase_fitted": problem.phase and any(c.has_phase for c in problem.channels),
        "uncertainty": problem.uncertainty, **cost}
    (out / "calibration.json").write_text(json.dumps(report, indent=2, default=float) + "\n")
    plot_before_after(problem, sims, band, out, units_of(setup.variables))
    write_metadata(out, args, setup.variables, [("", dict(problem.fixed))],
                       {"files": setup.files(), "mapping": setup.mapping.describe(),
                        "speeds": list(problem.grid.speeds), "revolutions": problem.revolutions,
                        "calibration": {"parameters": names, "solver": "scipy least_squares "
                                        "(trf), forward-difference Jacobian on the pool"},
                        **band_metadata(band)})
    print_report(table, result, ident, both, lines, cost, config_path)


def print_report(table, result, ident, both, lines, cost, config_path):
    print(f"calibration: {result['message']} ({result['nfev']} evaluations, "
          f"{cost['parameter_sets_run_now']} parameter sets run now, {cost['points_run_now']} "
          f"points, {cost['seconds_total']:.1f} s)")
    print(table[["parameter", "value", "low95", "high95", "at_bound", "determined"]].to_string(
        index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"weighted residual RMS {np.sqrt(result['s2']):.3g} (1: the assumed uncertainty); "
          f"condition number {ident['condition']:.3g}")
    for pair in ident["not_told_apart"]:
        print(f"not told apart: {pair['parameters'][0]} and {pair['parameters'][1]} "
              f"(correlation {pair['correlation']:+.2f})")
    for name in ident["undetermined"]:
        print(f"not determined by the data: {name}")
    print(both[["channel", "rms_db_before", "rms_db_after", "score_before", "score_after"]]
          .to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)
    print(f"calibrated configuration -> {config_path} (--set configFile={config_path.resolve()})")
