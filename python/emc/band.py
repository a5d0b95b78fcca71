"""Every result with its band: a study run at a low and a high damping bound beside the nominal.

Levels at a resonance scale with 1/damping, and nobody measured the damping of your body or
mounts: a result is therefore given as a band between two damping bounds, with the nominal line
inside it. The API is small, for any study:

- :class:`Band` — the FMU start values of the two bounds (and of the nominal, usually none), on
  top of a case's own settings. ``Band.damping()`` is the default: the body's modal damping and
  the mounts' damping scaled to the ends of their published ranges.
- :func:`run_band` — runs ``run(settings, bound)`` for ``low``, ``nominal`` and ``high`` and holds
  the three results (:class:`BandResult`); ``result.stack()`` puts tables into one with a
  ``bound`` column, :func:`wide` turns such a table into ``<value>_low``, ``_nominal``,
  ``_high`` columns.
- :func:`draw_band` — the one plotting helper: the band between the bounds filled, the nominal
  line drawn over it.

Example (any study that maps FMU start values to a table)::

    from emc.band import Band, run_band, draw_band
    result = run_band(lambda settings, bound: my_study(settings), Band.damping(), base={"scene": 2})
    table = result.stack()                       # column "bound": low / nominal / high
    draw_band(ax, x, result.low.y, result.nominal.y, result.high.y, label="steering wheel")

``emc sweep --band`` and ``emc runup --band`` use it for sweeps, run-ups, order cuts and comfort
values.
"""

from __future__ import annotations

import dataclasses
import json
import pathlib
from typing import Callable

import numpy as np
import pandas as pd

BOUNDS = ("low", "nominal", "high")

# The default band. The body: 5 % of critical nominal, 3–7 % (Adams & Askenazi's range for metal
# structures with joints) as modalDampingScale 0.6–1.4. The mounts: a loss factor of 0.15 at
# 10 Hz nominal, 0.10–0.20 (rubber engine mounts) as dampingScale 2/3–4/3 — paired the other way
# round: above the powertrain's own modes on its mounts a mount's damping transmits force to the
# body, so the least damped body with the most damped mounts gives the highest levels at the
# body's resonances (and the other pair the lowest).
BODY_SCALE = (0.6, 1.4)
MOUNT_SCALE = (4.0 / 3.0, 2.0 / 3.0)
MOUNTS = 4


@dataclasses.dataclass(frozen=True)
class Band:
    """The FMU start values of each bound, applied on top of a case's own settings. ``low`` is
    the bound with the least damped body (the higher levels at its resonances)."""

    low: dict
    high: dict
    nominal: dict = dataclasses.field(default_factory=dict)
    description: str = ""
    # The bounds' values multiply what the settings they are applied to already have (1 where
    # those have none): a band of scale factors around a case's own scale.
    multiplies: bool = False

    def settings(self, bound: str) -> dict:
        if bound not in BOUNDS:
            raise ValueError(f"bound {bound!r} is none of {', '.join(BOUNDS)}")
        return dict(getattr(self, bound))

    def applied(self, parameters: dict, bound: str) -> dict:
        """``parameters`` with the bound's settings on top."""
        own = self.settings(bound)
        if self.multiplies:
            own = {name: float(parameters.get(name, 1.0)) * value for name, value in own.items()}
        return {**parameters, **own}

    @classmethod
    def damping(cls, body: tuple[float, float] | None = BODY_SCALE,
                mounts: tuple[float, float] | None = MOUNT_SCALE,
                mount_count: int = MOUNTS) -> "Band":
        """The body's modal damping (``chassis.modalDampingScale``) and the mounts' damping
        (``mount[i].dampingScale``) at the scales ``(at the low bound, at the high bound)``, each
        pair enclosing 1 (the nominal); ``None`` leaves one nominal."""
        if body is None and mounts is None:
            raise ValueError("a damping band needs the body's or the mounts' bounds")
        low, high, parts = {}, {}, []
        for pair, names, what in (
                (body, ["chassis.modalDampingScale"], "body modal damping"),
                (mounts, [f"mount[{i}].dampingScale" for i in range(1, mount_count + 1)],
                 "mount damping")):
            if pair is None:
                continue
            a, b = (float(v) for v in pair)
            if not (np.isfinite(a) and np.isfinite(b) and min(a, b) >= 0.0
                    and min(a, b) <= 1.0 <= max(a, b)):
                raise ValueError(f"{what} bounds must be >= 0 and enclose 1 (scales of the "
                                 f"nominal), got {a:g} {b:g}")
            low.update({n: a for n in names})
            high.update({n: b for n in names})
            parts.append(f"{what} x{a:.3g}..x{b:.3g}")
        return cls(low=low, high=high, description=", ".join(parts), multiplies=True)


@dataclasses.dataclass
class BandResult:
    """The results of one study at the three bounds."""

    band: Band
    results: dict

    def __getitem__(self, bound: str):
        return self.results[bound]

    @property
    def low(self):
        return self.results["low"]

    @property
    def nominal(self):
        return self.results["nominal"]

    @property
    def high(self):
        return self.results["high"]

    def stack(self, part: int | None = None) -> pd.DataFrame:
        """The three results as one table with a ``bound`` column (``part``: which table of
        results that are tuples of tables)."""
        tables = []
        for bound in BOUNDS:
            table = self.results[bound] if part is None else self.results[bound][part]
            tables.append(with_bound(table, bound))
        return pd.concat(tables, ignore_index=True)


def run_band(run: Callable[[dict, str], object], band: Band,
             base: dict | None = None) -> BandResult:
    """``run(settings, bound)`` for the low bound, the nominal and the high bound, the settings
    being ``base`` with the bound's on top (:meth:`Band.applied`)."""
    results = {}
    for bound in BOUNDS:
        results[bound] = run(band.applied(base or {}, bound), bound)
    return BandResult(band, results)


def with_bound(table: pd.DataFrame, bound: str) -> pd.DataFrame:
    out = table.copy()
    out["bound"] = bound
    return out


def wide(table: pd.DataFrame, keys: list[str], values: list[str]) -> pd.DataFrame:
    """A table with a ``bound`` column as one row per ``keys`` with ``<value>_low``,
    ``<value>_nominal`` and ``<value>_high`` columns."""
    pivot = table.pivot_table(index=keys, columns="bound", values=values, sort=False)
    pivot.columns = [f"{value}_{bound}" for value, bound in pivot.columns]
    ordered = [f"{v}_{b}" for v in values for b in BOUNDS if f"{v}_{b}" in pivot.columns]
    return pivot[ordered].reset_index()


def draw_band(ax, x, low, nominal, high, label: str | None = None, color=None,
              alpha: float = 0.25, **line):
    """Fills the band between the ``low`` and ``high`` results over ``x`` and draws the
    ``nominal`` line over it in the same colour; returns the line. Whichever bound is higher at
    a point is the band's top there."""
    x = np.asarray(x, dtype=float)
    low, nominal, high = (np.asarray(v, dtype=float) for v in (low, nominal, high))
    (handle,) = ax.plot(x, nominal, label=label, color=color, **line)
    ax.fill_between(x, np.minimum(low, high), np.maximum(low, high), color=handle.get_color(),
                    alpha=alpha, lw=0, label=None)
    return handle


def _cases(table: pd.DataFrame) -> list[str]:
    return list(dict.fromkeys(table.case.fillna(""))) if "case" in table else [""]


def _curves(table: pd.DataFrame, x: str, y: str):
    """(x, low, nominal, high) of a table with one row per x and bound."""
    grid = table.pivot_table(index=x, columns="bound", values=y).sort_index()
    missing = [b for b in BOUNDS if b not in grid]
    if missing:
        raise ValueError(f"no {', '.join(missing)} bound in the table")
    return grid.index.to_numpy(), grid["low"], grid["nominal"], grid["high"]


def order_cuts_figure(orders: pd.DataFrame, signal: str, unit: str | None = None,
                      cut_orders=None, title: str | None = None, band: Band | None = None):
    """Order amplitudes over engine speed with their bands: one panel per order (three to a
    row), every case a band and its nominal line."""
    from . import plots

    cut_orders = cut_orders or plots.MAIN_ORDERS
    data = orders[orders.signal == signal]
    if data.empty:
        raise ValueError(f"no order amplitudes for {signal}")
    fig, axes = plots.order_panels(len(cut_orders), extra_height=1.0)
    cases = _cases(data)
    ylabel = f"amplitude (peak) [{plots.level_reference(unit)[2]}]"
    for k, (ax, order) in enumerate(zip(axes.flat, cut_orders)):
        for j, case in enumerate(cases):
            d = data[(data.case.fillna("") == case) & np.isclose(data.order, order)]
            x, low, nominal, high = _curves(d, "rpm", "amplitude")
            draw_band(ax, x, low, nominal, high, label=plots.case_label(case), color=f"C{j}",
                      lw=1.4, marker="o", ms=3)
        plots.order_panel_axes(ax, k, order, axes.shape[1], ylabel, data.amplitude)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, [f"{lab}: nominal, band shaded" for lab in labels],
               loc="outside lower center", ncol=min(len(cases), 3), fontsize=9, frameon=False)
    what = f" ({band.description})" if band is not None and band.description else ""
    fig.suptitle(title or f"{signal}: order cuts with the damping band{what}", fontsize=10)
    return fig


def comfort_figure(table: pd.DataFrame, band: Band | None = None):
    """Weighted seat and steering-wheel accelerations over engine speed: every case a band and
    its nominal line."""
    from . import plots

    panels = [(c, label) for c, label in (
        ("seat_av_comfort", "seat, vibration total value a_v (ISO 2631-1, Wk/Wd, comfort)"),
        ("wheel_ahv", "steering wheel, a_hv (ISO 5349-1, Wh)")) if c in table]
    fig, axes = plots.plt.subplots(1, len(panels), figsize=(7 * len(panels), 4.8),
                                   squeeze=False, layout="constrained")
    for ax, (column, label) in zip(axes[0], panels):
        for j, case in enumerate(_cases(table)):
            d = table[table.case.fillna("") == case]
            x, low, nominal, high = _curves(d, "rpm", column)
            draw_band(ax, x, low, nominal, high, label=f"{plots.case_label(case)}: nominal",
                      color=f"C{j}", lw=1.4, marker="o", ms=3)
        ax.set_xlabel("engine speed [rpm]")
        ax.set_ylabel("weighted RMS acceleration [m/s²]")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.4)
        ax.legend(title="shaded: damping band", fontsize=8, title_fontsize=8)
    if band is not None and band.description:
        fig.suptitle(f"comfort values with the damping band ({band.description})", fontsize=10)
    return fig


def comfort_table(spectra: pd.DataFrame) -> pd.DataFrame:
    """Comfort values (``emc.comfort``) per bound, with a ``bound`` column."""
    from .comfort import comfort_table as per_case

    tables = [with_bound(per_case(spectra[spectra.bound == b]), b) for b in BOUNDS
              if (spectra.bound == b).any()]
    table = pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
    return table if "rpm" in table else pd.DataFrame()


def save_figure(fig, path: str):
    from . import plots

    plots._save(fig, path)


# --- the emc commands' side: options and reports --------------------------------------------


def add_options(parser):
    """``--band`` and the bounds' options of ``emc sweep`` and ``emc runup``."""
    parser.add_argument("--band", action="store_true",
                        help="run at two damping bounds beside the nominal and draw the band: "
                             f"body modal damping x{BODY_SCALE[0]:g}..x{BODY_SCALE[1]:g} "
                             f"(5 %% nominal: 3-7 %%) with mount damping x{MOUNT_SCALE[0]:.3g}.."
                             f"x{MOUNT_SCALE[1]:.3g} (loss factor 0.15: 0.20-0.10)")
    parser.add_argument("--band-body", nargs=2, type=float, metavar=("LOW", "HIGH"),
                        help="the band's chassis.modalDampingScale at the low and the high bound "
                             "(implies --band)")
    parser.add_argument("--band-mounts", nargs=2, type=float, metavar=("LOW", "HIGH"),
                        help="the band's mount[i].dampingScale at the low and the high bound, "
                             "every mount (implies --band; 1 1 leaves the mounts nominal)")
    parser.add_argument("--band-from", metavar="BAND_JSON",
                        help="the band's bounds from a calibration (the band.json emc calibrate "
                             "writes: the calibrated damping's 95 %% intervals; implies --band)")


def from_options(args, variables: dict) -> Band | None:
    """The band the options ask for (None: no band), checked against the FMU's variables."""
    if getattr(args, "band_from", None):
        if getattr(args, "band_body", None) or getattr(args, "band_mounts", None):
            raise ValueError("--band-from gives the bounds: drop --band-body/--band-mounts")
        return from_file(args.band_from, variables)
    if not (getattr(args, "band", False) or getattr(args, "band_body", None)
            or getattr(args, "band_mounts", None)):
        return None
    body = tuple(args.band_body) if args.band_body else BODY_SCALE
    mounts = tuple(args.band_mounts) if args.band_mounts else MOUNT_SCALE
    count = sum(1 for i in range(1, 65) if f"mount[{i}].dampingScale" in variables)
    band = Band.damping(body=None if body == (1.0, 1.0) else body,
                        mounts=None if mounts == (1.0, 1.0) or count == 0 else mounts,
                        mount_count=count)
    for bound in ("low", "high"):
        for name in band.settings(bound):
            if name not in variables:
                raise ValueError(f"--band: this FMU has no {name}")
    return band


def from_file(path, variables: dict) -> Band:
    """The band a calibration wrote (``band.json`` of ``emc calibrate``: ``low`` and ``high``,
    factors on the FMU's damping scales, and a ``description``), checked against the FMU's
    variables."""
    path = pathlib.Path(path)
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ValueError(f"--band-from {path}: not a band file ({error})") from None
    if not isinstance(data, dict) or not all(isinstance(data.get(k), dict)
                                             for k in ("low", "high")):
        raise ValueError(f"--band-from {path}: a band file holds \"low\" and \"high\" "
                         "settings")
    for bound in ("low", "high"):
        for name, value in data[bound].items():
            if name not in variables:
                raise ValueError(f"--band-from {path}, {bound}: this FMU has no {name}")
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value >= 0.0):
                raise ValueError(f"--band-from {path}, {bound}, {name}: a factor >= 0, "
                                 f"got {value!r}")
    return Band(low=dict(data["low"]), high=dict(data["high"]),
                description=str(data.get("description", f"from {path.name}")), multiplies=True)


def report_sweep(out, band: Band, orders: pd.DataFrame, spectra: pd.DataFrame, signals,
                 plot_signals, units: dict, suffix: str) -> pd.DataFrame:
    """Writes the band's tables (all three bounds side by side) and plots of a sweep; returns
    the comfort table (with its ``bound`` column)."""
    from . import plots
    from .sweep import save

    keys = ["case", "signal", "order", "rpm"]
    main = orders[orders.order.isin(plots.MAIN_ORDERS)]
    save(wide(main, keys, ["amplitude"]), str(out / f"order_band{suffix}"))
    for signal in plot_signals:
        name = _safe(signal)
        nominal = spectra[(spectra.bound == "nominal")]
        plots.waterfall(nominal, signal, str(out / f"waterfall_{name}.png"),
                        unit=units.get(signal),
                        title=f"{signal}: waterfall at the nominal damping")
        save_figure(order_cuts_figure(orders, signal, unit=units.get(signal), band=band),
                    str(out / f"order_cuts_{name}.png"))
    exposure = comfort_table(spectra)
    if not exposure.empty:
        columns = [c for c in exposure.columns if c not in ("case", "rpm", "bound")]
        save(exposure, str(out / f"comfort{suffix}"))
        save(wide(exposure, ["case", "rpm"], columns), str(out / f"comfort_band{suffix}"))
        save_figure(comfort_figure(exposure, band), str(out / "comfort.png"))
    return exposure


def report_runup(out, band: Band, orders: pd.DataFrame, plot_signals, units: dict, what: str,
                 suffix: str):
    """Writes the band's table and plots of a run-up's tracked orders."""
    from . import plots
    from .sweep import save

    main = orders[orders.order.isin(plots.MAIN_ORDERS)]
    save(wide(main, ["case", "signal", "order", "rpm"], ["amplitude"]),
         str(out / f"runup_order_band{suffix}"))
    for signal in plot_signals:
        name = _safe(signal)
        plots.order_map(orders[orders.bound == "nominal"], signal,
                        str(out / f"runup_order_map_{name}.png"), unit=units.get(signal),
                        title=f"{signal}: order map at the nominal damping, {what}")
        save_figure(order_cuts_figure(orders, signal, unit=units.get(signal), band=band,
                                      title=f"{signal}: order cuts of a {what}\nwith the "
                                            f"damping band ({band.description})"),
                    str(out / f"runup_order_cuts_{name}.png"))


def _safe(signal: str) -> str:
    from .cli import safe_name

    return safe_name(signal)
