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
- :func:`emc.figures.plots.draw_band` — the one plotting helper: the band between the bounds
  filled, the nominal line drawn over it; the order cuts and comfort figures draw a table with
  a ``bound`` column as bands.

Example (any study that maps FMU start values to a table)::

    from emc.figures.plots import draw_band
    from emc.running.band import Band, run_band

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

from ..base.checks import typed_value
from ..base.errors import UsageError
from ..base.options import BAND_BODY_SCALE, BAND_MOUNT_SCALE
from ..base.orders import MAIN_ORDERS
from ..base.outputs import safe_name, save
from ..signals.comfort import comfort_table as per_case

BOUNDS = ("low", "nominal", "high")

# The default band (its bounds and why: emc.base.options).
BODY_SCALE = BAND_BODY_SCALE
MOUNT_SCALE = BAND_MOUNT_SCALE
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


def bounds_of(band: Band | None) -> tuple[str, ...]:
    """The bounds a study runs at: the band's three, or the nominal alone where there is none."""
    return ("nominal",) if band is None else BOUNDS


def settings_at(band: Band | None, parameters: dict, bound: str) -> dict:
    """A case's settings at one bound (its own settings where there is no band)."""
    return dict(parameters) if band is None else band.applied(parameters, bound)


def run_count(band: Band | None, per_bound: int) -> int:
    """The runs of a study of ``per_bound`` runs at each of its bounds."""
    return per_bound * len(bounds_of(band))


def nominal_rows(table: pd.DataFrame) -> pd.DataFrame:
    """A study's nominal results: the nominal bound's rows of a table with a ``bound`` column,
    else the whole table."""
    return table[table.bound == "nominal"] if "bound" in table else table


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


def comfort_table(spectra: pd.DataFrame) -> pd.DataFrame:
    """Comfort values (:mod:`emc.signals.comfort`) per bound, with a ``bound`` column."""
    tables = [with_bound(per_case(spectra[spectra.bound == b]), b) for b in BOUNDS
              if (spectra.bound == b).any()]
    table = pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()
    return table if "rpm" in table else pd.DataFrame()


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
    # The low bound is the one with the higher levels at the body's resonances: the less damped
    # body, with the more damped mounts (see emc.base.options).
    if body[0] > body[1]:
        raise ValueError(f"--band-body {body[0]:g} {body[1]:g}: LOW is the less damped body's "
                         "scale, so LOW <= 1 <= HIGH")
    if mounts[0] < mounts[1]:
        raise ValueError(f"--band-mounts {mounts[0]:g} {mounts[1]:g}: LOW is the more damped "
                         "mounts' scale (they pass more force to the body's resonances), so "
                         "LOW >= 1 >= HIGH")
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
    from ..figures import plots  # deferred: matplotlib only where a band is drawn (start-up time)

    keys = ["case", "signal", "order", "rpm"]
    main = orders[orders.order.isin(MAIN_ORDERS)]
    save(wide(main, keys, ["amplitude"]), str(out / f"order_band{suffix}"))
    for signal in plot_signals:
        name = safe_name(signal)
        plots.waterfall(nominal_rows(spectra), signal, str(out / f"waterfall_{name}.png"),
                        unit=units.get(signal),
                        title=f"{signal}: waterfall at the nominal damping")
        plots.order_cuts(orders, signal, str(out / f"order_cuts_{name}.png"),
                         unit=units.get(signal), band=band.description)
    exposure = comfort_table(spectra)
    if not exposure.empty:
        columns = [c for c in exposure.columns if c not in ("case", "rpm", "bound")]
        save(exposure, str(out / f"comfort{suffix}"))
        save(wide(exposure, ["case", "rpm"], columns), str(out / f"comfort_band{suffix}"))
        plots.comfort(exposure, str(out / "comfort.png"), band=band.description)
    return exposure


def report_runup(out, band: Band, orders: pd.DataFrame, plot_signals, units: dict, what: str,
                 suffix: str):
    """Writes the band's table and plots of a run-up's tracked orders."""
    from ..figures import plots  # deferred: matplotlib only where a band is drawn (start-up time)

    main = orders[orders.order.isin(MAIN_ORDERS)]
    save(wide(main, ["case", "signal", "order", "rpm"], ["amplitude"]),
         str(out / f"runup_order_band{suffix}"))
    for signal in plot_signals:
        name = safe_name(signal)
        plots.order_map(nominal_rows(orders), signal,
                        str(out / f"runup_order_map_{name}.png"), unit=units.get(signal),
                        title=f"{signal}: order map at the nominal damping, {what}")
        plots.order_cuts(orders, signal, str(out / f"runup_order_cuts_{name}.png"),
                         unit=units.get(signal), band=band.description,
                         title=f"{signal}: order cuts of a {what}\nwith the damping band "
                               f"({band.description})")


def band_of(args, variables: dict, cases: list[tuple[str, dict]]) -> Band | None:
    """The damping band the options ask for, its settings checked like --set values."""
    try:
        band = from_options(args, variables)
    except ValueError as error:
        raise UsageError(str(error)) from None
    if band is not None:
        for _, parameters in cases:
            for bound in ("low", "high"):
                for name in band.settings(bound):
                    typed_value(variables[name], repr(band.applied(parameters, bound)[name]))
    return band


def band_metadata(band: Band | None) -> dict:
    if band is None:
        return {}
    return {"band": {"description": band.description, "low": band.low,
                     "nominal": band.nominal, "high": band.high}}
