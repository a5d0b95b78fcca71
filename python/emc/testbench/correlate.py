"""``emc correlate``: does the model match the measured car?

For each mapped order cut the model runs at the measured speeds, at the nominal damping and at
the two bounds of the damping band (the default band of :mod:`emc.band`, or the calibrated one
with ``--band-from``). Written to ``--out``:

- ``correlation.csv``: per channel the metrics of :mod:`.metrics` (level error mean, RMS and
  largest in dB, peak speed and level differences, share inside the band, the score);
- ``order_cuts.csv``: measured and simulated amplitudes (0-peak, SI) at every speed;
- ``correlate_<output>.png``: the measured order cuts over the simulated ones with the band;
- FRF channels: ``frf_correlation.csv`` (FRAC, level error) and ``frf_<output>.png``;
- measured modes: ``modes.csv`` (measured and paired model frequencies, MAC) and ``mac.csv`` /
  ``mac.png`` (the full MAC matrix against the body's modes at the measured points);
- ``metadata.json``: the FMU (checksum), the files and their checksums, the mapping.
"""

from __future__ import annotations

import argparse
import hashlib
import pathlib
import re
import sys
import time

import numpy as np
import pandas as pd
from matplotlib import ticker

from ..base.checks import (case_parameters, check_pool, check_range, check_revolutions,
                           parse_settings)
from ..base.errors import UsageError
from ..base.fmu import check_config_file, highest_speed, model_variables, units_of
from ..base.options import POOL_FROM
from ..base.outputs import claim, reduction_notice, safe_name, write_metadata
from ..figures import plots
from ..running import band as bands
from ..running.band import band_metadata
from ..running.engine import PointEngine
from ..running.engine import open_pool as open_command_pool
from ..running.modal import body_point_of, export_from_fmu
from ..running.runner import progress_bar
from . import metrics
from .mapping import Mapping, MeasurementError, load
from .simulate import Grid, evaluate, grid_of, points

# The most speeds simulated without --speeds (each costs one point per parameter set).
MAX_SPEEDS = 120


# ----- shared by emc correlate and emc calibrate ------------------------------------------------

class Setup:
    """What both commands check before anything runs: the FMU, the settings, the mapping and
    the measurement, the speeds."""

    def __init__(self, args):
        self.variables = model_variables(args.fmu)
        outputs = {n: v.unit for n, v in self.variables.items() if v.causality == "output"}
        check_pool(args)
        check_revolutions(args.revolutions)
        if args.speeds is not None:
            check_range("--speeds", args.speeds, 3)
        fixed = parse_settings(args.set, self.variables)
        self.parameters = case_parameters(fixed, {})
        if int(self.parameters.get("scene", 1)) != 2:
            print("warning: correlating outside the elastic body (scene 2): the comfort points "
                  "do not move there", file=sys.stderr)
        check_config_file(args.fmu, self.parameters, remote=bool(args.scheduler))
        try:
            self.mapping: Mapping = load(args.mapping, outputs)
        except MeasurementError as error:
            raise UsageError(str(error)) from None
        self.grid: Grid | None = None
        self.channels = []
        if self.mapping.order_channels():
            self.grid, self.channels = grid_of(self.mapping, args.speeds)
            if args.speeds is None and len(self.grid.speeds) > MAX_SPEEDS:
                raise UsageError(f"{args.mapping}: the channels hold {len(self.grid.speeds)} "
                                     f"different speeds; simulate fewer with --speeds N "
                                     f"(at most {MAX_SPEEDS} without it)")
            highest = highest_speed(self.variables)
            if self.grid.speeds[-1] > highest:
                raise UsageError(f"{args.mapping}: measured up to {self.grid.speeds[-1]:g} "
                                     f"rpm, the FMU runs up to {highest:g} rpm")
        reduction_notice(self.parameters, self.variables)

    def files(self) -> dict:
        """The mapping and every measurement file with their checksums (metadata)."""
        folder = self.mapping.path.parent
        out = {}
        for path in [self.mapping.path] + [folder / f for f in self.mapping.files]:
            out[str(path.resolve())] = hashlib.sha256(path.read_bytes()).hexdigest()
        return out


def open_pool(args, parameters: dict):
    """The pool of a correlation or calibration (a study of many points), or None: serial."""
    return open_command_pool(args, POOL_FROM, [parameters])


def run_sets(engine: PointEngine, grid: Grid, sets: list[tuple[dict, str | None]],
             revolutions: int, quiet: bool, what: str) -> list[np.ndarray]:
    """Each (start values, configuration) over the grid's speeds, every point of every set in
    one map; per set an array (speeds, orders, signals)."""
    items = [p for parameters, config in sets for p in points(grid, parameters, config,
                                                               revolutions)]
    bar = progress_bar(len(items), what, not quiet, unit="point")
    try:
        done = engine.map(evaluate, items, None if bar is None else bar.update)
    finally:
        if bar is not None:
            bar.close()
    n = len(grid.speeds)
    return [np.array(done[k * n:(k + 1) * n]) for k in range(len(sets))]


def channel_values(grid: Grid, channel, simulated: np.ndarray) -> np.ndarray:
    idx, order, signal = grid.index(channel)
    return simulated[idx, order, signal]


def metrics_table(grid: Grid, channels, simulated: np.ndarray, low: np.ndarray | None = None,
                  high: np.ndarray | None = None) -> pd.DataFrame:
    rows = []
    for c in channels:
        s = channel_values(grid, c, simulated)
        lo = None if low is None else channel_values(grid, c, low)
        hi = None if high is None else channel_values(grid, c, high)
        rows.append({"channel": c.label, "output": c.map.output, "order": c.map.order,
                     **metrics.order_cut_metrics(c.x, c.values, s, c.floor, lo, hi)})
    return pd.DataFrame(rows)


def cuts_table(grid: Grid, channels, curves: dict[str, np.ndarray]) -> pd.DataFrame:
    """Measured and simulated amplitudes (one column per curve) at every measured speed."""
    parts = []
    for c in channels:
        part = pd.DataFrame({"channel": c.label, "output": c.map.output, "order": c.map.order,
                             "rpm": c.x, "measured": np.abs(c.values),
                             "noise_floor": c.floor})
        for name, sim in curves.items():
            part[name] = np.abs(channel_values(grid, c, sim))
        parts.append(part)
    return pd.concat(parts, ignore_index=True)


def overlay_figure(grid: Grid, channels, output: str, unit: str | None, lines: dict,
                   band: tuple[np.ndarray, np.ndarray, str] | None, title: str):
    """The measured order cuts of ``output`` (markers) over the simulated ``lines`` (label →
    array), the band (low, high, label) shaded around the first line."""
    mine = [c for c in channels if c.map.output == output]
    # Placed by hand, minor ticks at 2 and 5 only, no minor grid: constrained layout measures
    # every log axis's ticks again and again, and every minor tick is an object of its own;
    # drawing the figures was half of a correlation's time (cProfile of emc correlate).
    columns = min(3, len(mine))
    rows = -(-len(mine) // columns)
    fig, axes = plots.plt.subplots(rows, columns, figsize=(4.3 * columns, 3.3 * rows + 1.2),
                                   sharex=True, sharey=True, squeeze=False)
    for ax in axes.flat[len(mine):]:
        ax.set_visible(False)
    ylabel = f"amplitude (0-peak) [{plots.level_reference(unit)[2]}]"
    for k, (ax, c) in enumerate(zip(axes.flat, mine)):
        rpm = c.x
        every = [np.abs(c.values)]
        for j, (label, sim) in enumerate(lines.items()):
            values = np.abs(channel_values(grid, c, sim))
            every.append(values)
            if j == 0 and band is not None:
                low, high = (np.abs(channel_values(grid, c, b)) for b in band[:2])
                plots.draw_band(ax, rpm, low, values, high, label=f"{label} ({band[2]})",
                                color=f"C{j}", lw=1.4)
            else:
                ax.plot(rpm, values, color=f"C{j}", lw=1.4, label=label)
        ax.plot(rpm, np.abs(c.values), "o", color="k", ms=3.5, label="measured")
        if np.any(c.floor > 0):
            ax.plot(rpm, c.floor, ":", color="0.5", lw=1.0, label="noise floor")
        ax.set_yscale("log")
        ax.yaxis.set_minor_locator(ticker.LogLocator(subs=(2.0, 5.0)))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())
        ax.grid(True, which="major", lw=0.5, alpha=0.6)
        ax.set_title(f"order {c.map.order:g}", fontsize=10)
        ax.set_xlabel("engine speed [rpm]")
        ax.tick_params(labelbottom=True)
        if k % columns == 0:
            ax.set_ylabel(ylabel)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 4), fontsize=9,
               frameon=False)
    fig.suptitle(title, fontsize=10)
    height = fig.get_figheight()
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.9 / height, top=1.0 - 0.75 / height,
                        hspace=0.35, wspace=0.06)
    return fig


def safe(name: str) -> str:
    return safe_name(name)


# ----- FRFs and modes ---------------------------------------------------------------------------

def frf_correlation(fmu: str, parameters: dict, mapping: Mapping, out: pathlib.Path,
                    units: dict) -> pd.DataFrame:
    """FRAC and level error of every FRF channel against the body's accelerance from the
    force at the input mount's body point (the body the FMU simulates, :mod:`emc.modal`)."""
    export = export_from_fmu(fmu, parameters)
    if export.body is None:
        raise UsageError("FRF channels need the elastic body (scene 2)")
    at = {i: p for i, _, p in export.paths()}
    rows = []
    for c in mapping.frf_channels():
        i, j = (int(v) for v in re.match(r"mount\[(\d+)\]\.F\[(\d)\]", c.map.input).groups())
        if i not in at:
            raise UsageError(f"{mapping.path}, channel {c.map.number} ({c.label}), input: "
                                 f"mount[{i}] acts on no body point")
        point, dof = body_point_of(c.map.output)
        model = export.body.accelerance(point, dof, [(at[i], j - 1)], c.x)[:, 0]
        m = metrics.order_cut_metrics(c.x, c.values, model, c.floor)
        rows.append({"channel": c.label, "output": c.map.output, "input": c.map.input,
                     "frac": metrics.frac(c.values, model),
                     **{k: m[k] for k in ("points_used", "mean_db", "rms_db", "max_db",
                                          "score")},
                     "peak_hz_measured": m["peak_rpm_measured"],
                     "peak_hz_simulated": m["peak_rpm_simulated"]})
        fig, ax = plots.plt.subplots(figsize=(7, 4), layout="constrained")
        ax.semilogy(c.x, np.abs(c.values), "k.", ms=3, label="measured")
        ax.semilogy(c.x, np.abs(model), "C0", lw=1.3, label="model (body)")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"accelerance [{plots.level_reference(units.get(c.map.output))[2]}/N]")
        ax.set_title(f"{c.label}: FRAC {rows[-1]['frac']:.3f}", fontsize=10)
        ax.grid(True, which="both", alpha=0.4)
        ax.legend(fontsize=8)
        plots._save(fig, str(out / f"frf_{safe(c.label)}.png"))
    table = pd.DataFrame(rows)
    table.to_csv(out / "frf_correlation.csv", index=False)
    return table


def mode_correlation(fmu: str, parameters: dict, mapping: Mapping,
                     out: pathlib.Path) -> pd.DataFrame:
    """The measured modes against the body's modes at the measured points (nearest body node
    within the mapping's tolerance): MAC matrix, pairs, frequency table."""
    measured = mapping.modes
    export = export_from_fmu(fmu, parameters, full_recovery=True)
    mesh, shapes = export.full_recovery()
    nodes = np.asarray(mesh["nodes"], dtype=float)
    where = measured.positions * mapping.modes_length_unit
    distance = np.linalg.norm(where[:, None, :] - nodes[None, :, :], axis=2)
    nearest = np.argmin(distance, axis=1)
    far = np.flatnonzero(distance[np.arange(len(where)), nearest] > mapping.modes_tolerance)
    if far.size:
        k = far[0]
        raise UsageError(
            f"{measured.file}, node {measured.nodes[k]}, coordinates: the nearest body node is "
            f"{distance[k, nearest[k]] * 1e3:.0f} mm away (tolerance "
            f"{mapping.modes_tolerance * 1e3:.0f} mm in {mapping.path.name}): wrong frame or "
            "length_unit?")
    model = np.transpose(shapes[nearest, :3, :], (2, 0, 1)).reshape(shapes.shape[2], -1)
    test = measured.shapes.reshape(len(measured.frequencies), -1)
    mac = metrics.mac_matrix(test, model)
    model_hz = export.body.omega / (2.0 * np.pi)
    pd.DataFrame(mac, index=[f"test {k + 1}" for k in range(len(test))],
                 columns=[f"model {k + 1}" for k in range(len(model))]).to_csv(out / "mac.csv")
    rows = []
    for r, c in metrics.pair_modes(mac):
        rows.append({"test_mode": r + 1, "test_hz": measured.frequencies[r],
                     "model_mode": c + 1, "model_hz": model_hz[c],
                     "difference_pct": 100.0 * (model_hz[c] / measured.frequencies[r] - 1.0),
                     "mac": mac[r, c], "paired": bool(mac[r, c] >= metrics.PAIRED_MAC)})
    table = pd.DataFrame(rows).sort_values("test_mode")
    table.to_csv(out / "modes.csv", index=False)
    shown = min(model.shape[0], max(c for _, c in metrics.pair_modes(mac)) + 4)
    fig, ax = plots.plt.subplots(figsize=(0.35 * shown + 2.5, 0.35 * len(test) + 2),
                                 layout="constrained")
    image = ax.imshow(mac[:, :shown], vmin=0, vmax=1, cmap="viridis", aspect="auto")
    ax.set_xticks(range(shown), [f"{f:.0f}" for f in model_hz[:shown]], rotation=90,
                  fontsize=7)
    ax.set_yticks(range(len(test)), [f"{f:.1f}" for f in measured.frequencies], fontsize=7)
    ax.set_xlabel("model mode [Hz]")
    ax.set_ylabel("test mode [Hz]")
    fig.colorbar(image, ax=ax, label="MAC")
    plots._save(fig, str(out / "mac.png"))
    return table


# ----- the command ------------------------------------------------------------------------------

def band_for(args, variables: dict) -> bands.Band | None:
    """The band of the comparison: none, a calibration's (``--band-from``) or the default
    damping band (``emc sweep --band`` without bounds of its own)."""
    if args.no_band:
        return None
    try:
        if args.band_from:
            return bands.from_file(args.band_from, variables)
        default = argparse.Namespace(band=True, band_body=None, band_mounts=None)
        return bands.from_options(default, variables)
    except ValueError as error:
        raise UsageError(str(error)) from None


def cmd_correlate(args) -> int:
    setup = Setup(args)
    out = claim(args)
    band = band_for(args, setup.variables)
    units = units_of(setup.variables)
    started = time.perf_counter()
    seconds = {}
    table = pd.DataFrame()
    if setup.grid is not None:
        bounds = bands.bounds_of(band)
        sets = [(bands.settings_at(band, setup.parameters, b), None) for b in bounds]
        pool = open_pool(args, setup.parameters)
        engine = PointEngine.on(args.fmu, pool)
        seconds["start"] = time.perf_counter() - started
        try:
            sims = dict(zip(bounds, run_sets(engine, setup.grid, sets, args.revolutions,
                                             args.quiet, "correlate")))
        finally:
            engine.close()
            if pool is not None:
                pool.close()
        seconds["simulation"] = time.perf_counter() - started - seconds["start"]
        table = metrics_table(setup.grid, setup.channels, sims["nominal"], sims.get("low"),
                              sims.get("high"))
        table.to_csv(out / "correlation.csv", index=False)
        cuts_table(setup.grid, setup.channels, {f"simulated_{b}": s for b, s in sims.items()}
                   ).to_csv(out / "order_cuts.csv", index=False)
        seconds["metrics"] = time.perf_counter() - started - sum(seconds.values())
        what = "" if band is None else band.description
        for output in dict.fromkeys(c.map.output for c in setup.channels):
            fig = overlay_figure(setup.grid, setup.channels, output, units.get(output),
                                 {"model": sims["nominal"]},
                                 None if band is None else (sims["low"], sims["high"],
                                                            "band shaded"),
                                 f"{output}: measured against the model"
                                 + (f" with the damping band ({what})" if what else ""))
            plots._save(fig, str(out / f"correlate_{safe(output)}.png"))
        seconds["plots"] = time.perf_counter() - started - sum(seconds.values())
    frf = (frf_correlation(args.fmu, setup.parameters, setup.mapping, out, units)
           if setup.mapping.frf_channels() else pd.DataFrame())
    modes = (mode_correlation(args.fmu, setup.parameters, setup.mapping, out)
             if setup.mapping.modes is not None else pd.DataFrame())
    elapsed = time.perf_counter() - started
    write_metadata(out, args, setup.variables, [("", setup.parameters)],
                       {"files": setup.files(), "mapping": setup.mapping.describe(),
                        "speeds": list(setup.grid.speeds) if setup.grid else [],
                        "revolutions": args.revolutions, "seconds": {**seconds,
                                                                     "total": elapsed},
                        **band_metadata(band)})
    print_correlation(table, frf, modes)
    print(f"correlation in {elapsed:.1f} s -> {out}")
    return 0


def print_correlation(table: pd.DataFrame, frf: pd.DataFrame, modes: pd.DataFrame):
    if not table.empty:
        shown = table[["channel", "points_used", "mean_db", "rms_db", "max_db", "peak_rpm_diff",
                       "peak_db_diff", "inside_band", "score"]]
        print("order cuts (dB: model over measurement; score: % of speeds within ±3 dB):")
        print(shown.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    if not frf.empty:
        print(frf[["channel", "frac", "mean_db", "rms_db", "score"]].to_string(
            index=False, float_format=lambda v: f"{v:.3g}"))
    if not modes.empty:
        print(modes.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
