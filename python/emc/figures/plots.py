"""Waterfalls (colour maps of frequency over engine speed, in dB), order cuts, case overlays.

Amplitudes are the peak amplitudes of the spectral lines (``emc.signals.spectra``: 2|X|/N of a window of
whole revolutions). Levels are in dB re 1 µm/s² for accelerations and re 1 N for forces, the
references of vehicle NVH practice; the unit of each signal comes from the FMU's model
description.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from ..base.orders import HIGHEST_ORDER, MAIN_ORDERS, ORDERS  # noqa: E402
# Colour range of a waterfall below its peak.
DYNAMIC_RANGE_DB = 60.0

# (reference amplitude, what the dB are relative to, how the unit is printed)
LEVEL_REFERENCES = {
    "m/s2": (1e-6, "dB re 1 µm/s²", "m/s²"),
    "N": (1.0, "dB re 1 N", "N"),
    "N.m": (1.0, "dB re 1 N·m", "N·m"),
    "m": (1e-12, "dB re 1 pm", "m"),
    "rad": (1e-12, "dB re 1 prad", "rad"),
}


def level_reference(unit: str | None) -> tuple[float, str, str]:
    """Reference amplitude, dB label and printed unit for a model-description unit."""
    if unit in LEVEL_REFERENCES:
        return LEVEL_REFERENCES[unit]
    return 1.0, f"dB re 1 {unit or 'unit'}", unit or "1"


def to_db(amplitude, unit: str | None) -> np.ndarray:
    reference = level_reference(unit)[0]
    return 20.0 * np.log10(np.maximum(np.asarray(amplitude, dtype=float), 1e-30) / reference)


def _speed_edges(speeds: np.ndarray) -> np.ndarray:
    """Strip edges halfway between the speed points (the outer strips as wide as their
    neighbours' half-gaps)."""
    if len(speeds) == 1:
        return np.array([speeds[0] - 25.0, speeds[0] + 25.0])
    mid = 0.5 * (speeds[1:] + speeds[:-1])
    return np.concatenate([[speeds[0] - (mid[0] - speeds[0])], mid,
                           [speeds[-1] + (speeds[-1] - mid[-1])]])


# Each case's line style in overlays: colour, dash pattern and marker all differ, so that cases
# whose curves coincide (an effect that leaves an order alone) stay visible as such.
LINE_STYLES = ("-", "--", "-.", ":")
MARKERS = ("o", "s", "^", "D", "v", "P")
# Where no spectrum was analysed (above 6.5 orders of a speed point).
NOT_ANALYSED = "0.88"


def case_style(k: int, points: int = 0, cases: int = 1) -> dict:
    """Line style of case ``k``; on dense curves (a run-up's blocks) about 12 markers, staggered
    between the cases so that coinciding curves show every case's markers."""
    style = {"color": f"C{k % 10}", "linestyle": LINE_STYLES[k % len(LINE_STYLES)],
             "marker": MARKERS[k % len(MARKERS)], "ms": 4, "lw": 1.4}
    if k % 2:
        style["markerfacecolor"] = "none"
    if points > 24:
        every = points // 12
        style["markevery"] = (k * every // max(cases, 1), every)
    return style


def case_label(case) -> str:
    return case if isinstance(case, str) and case else "model"


def _cases(data: pd.DataFrame) -> list[str]:
    return list(dict.fromkeys(data.case.fillna(""))) if "case" in data else [""]


def _save(fig, path: str):
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _draw_colour_map(ax, data: pd.DataFrame, unit: str | None, top: float, vmin: float,
                     vmax: float):
    """Each speed point is a vertical strip of its own spectral bins (their widths differ with
    the speed), coloured by level; grey where nothing was analysed."""
    speeds = np.sort(data.rpm.unique())
    edges = _speed_edges(speeds)
    ax.set_facecolor(NOT_ANALYSED)
    mesh = None
    for k, rpm in enumerate(speeds):
        d = data[data.rpm == rpm].sort_values("frequency")
        f = d.frequency.to_numpy()
        if len(f) < 2:
            continue
        df = f[1] - f[0]
        f_edges = np.concatenate([f - df / 2, [f[-1] + df / 2]]).clip(min=0.0)
        levels = to_db(d.amplitude.to_numpy(), unit)[:, None]
        mesh = ax.pcolormesh([edges[k], edges[k + 1]], f_edges, levels, cmap="inferno",
                             vmin=vmin, vmax=vmax, shading="flat", rasterized=True)
    rpm_line = np.array([0.0, edges[-1]])
    for order in ORDERS:
        main = order in MAIN_ORDERS
        ax.plot(rpm_line, order * rpm_line / 60.0, "--" if main else ":", color="white",
                lw=0.8 if main else 0.5, alpha=0.7 if main else 0.4)
        f_end = order * edges[-1] / 60.0
        if f_end <= top:
            ax.text(edges[-1], f_end, f" {order:g}", fontsize=7, va="center", color="0.2")
    ax.text(1.0, 1.01, "order", transform=ax.transAxes, fontsize=7, color="0.2", ha="left")
    ax.set_xlim(edges[0], edges[-1])
    ax.set_ylim(0, top)
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    return mesh


def _level_range(data: pd.DataFrame, unit: str | None) -> tuple[float, float]:
    peak = float(to_db(data.amplitude.max(), unit))
    vmax = 5.0 * np.ceil(peak / 5.0)
    return vmax - DYNAMIC_RANGE_DB, vmax


def _colour_bar(fig, mesh, axes, unit: str | None):
    bar = fig.colorbar(mesh, ax=axes, pad=0.06 if not isinstance(axes, list) else 0.02,
                       fraction=0.05 if not isinstance(axes, list) else 0.03, extend="min")
    bar.set_label(f"peak amplitude [{level_reference(unit)[1]}]")
    return bar


def waterfall_figure(spectra: pd.DataFrame, signal: str, unit: str | None = None,
                     title: str | None = None, max_frequency: float | None = None):
    """Colour map of the spectra of ``signal``: frequency over engine speed, level in dB."""
    data = spectra[spectra.signal == signal]
    if data.empty:
        raise ValueError(f"no spectra for {signal}")
    top = max_frequency or float(data.frequency.max())
    vmin, vmax = _level_range(data, unit)
    fig, ax = plt.subplots(figsize=(8.5, 6))
    mesh = _draw_colour_map(ax, data, unit, top, vmin, vmax)
    _colour_bar(fig, mesh, ax, unit)
    peak = data.amplitude.max()
    ax.set_title(title or f"{signal}: waterfall, largest line {peak:.3g} "
                          f"{level_reference(unit)[2]} (peak)\norder lines dashed/dotted; grey: "
                          f"above order {HIGHEST_ORDER:g}, not analysed", fontsize=10)
    fig.tight_layout()
    return fig


def waterfall(spectra: pd.DataFrame, signal: str, path: str, unit: str | None = None,
              title: str | None = None, max_frequency: float | None = None):
    _save(waterfall_figure(spectra, signal, unit, title, max_frequency), path)


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


def _band_curves(table: pd.DataFrame, x: str, y: str):
    """(x, low, nominal, high) of a table with one row per x and bound."""
    grid = table.pivot_table(index=x, columns="bound", values=y).sort_index()
    missing = [b for b in ("low", "nominal", "high") if b not in grid]
    if missing:
        raise ValueError(f"no {', '.join(missing)} bound in the table")
    return grid.index.to_numpy(), grid["low"], grid["nominal"], grid["high"]


def order_cuts_figure(orders: pd.DataFrame, signal: str, unit: str | None = None,
                      title: str | None = None, cut_orders=MAIN_ORDERS,
                      cases: list[str] | None = None, band: str | None = None):
    """Order amplitudes over engine speed. One case: one axes, a line per order. Several cases,
    or a table with a ``bound`` column (the damping band ``band`` describes): one panel per order
    (three to a row), the cases overlaid on common axes (each a band around its nominal line),
    one legend."""
    data = orders[orders.signal == signal]
    if data.empty:
        raise ValueError(f"no order amplitudes for {signal}")
    ylabel = f"amplitude (peak) [{level_reference(unit)[2]}]"
    cases = cases or _cases(data)
    banded = "bound" in data
    if banded:
        fig, axes = order_panels(len(cut_orders), extra_height=1.0)
        for k, (ax, order) in enumerate(zip(axes.flat, cut_orders)):
            for j, case in enumerate(cases):
                d = data[(data.case.fillna("") == case) & np.isclose(data.order, order)]
                x, low, nominal, high = _band_curves(d, "rpm", "amplitude")
                draw_band(ax, x, low, nominal, high, label=case_label(case), color=f"C{j}",
                          lw=1.4, marker="o", ms=3)
            order_panel_axes(ax, k, order, axes.shape[1], ylabel, data.amplitude)
        handles, labels = axes.flat[0].get_legend_handles_labels()
        fig.legend(handles, [f"{lab}: nominal, band shaded" for lab in labels],
                   loc="outside lower center", ncol=min(len(cases), 3), fontsize=9,
                   frameon=False)
        what = f" ({band})" if band else ""
        fig.suptitle(title or f"{signal}: order cuts with the damping band{what}", fontsize=10)
        return fig
    if len(cases) == 1:
        fig, ax = plt.subplots(figsize=(8, 5))
        for k, order in enumerate(cut_orders):
            d = data[np.isclose(data.order, order)].sort_values("rpm")
            ax.plot(d.rpm, d.amplitude, label=f"order {order:g}",
                    **{**case_style(k, len(d), len(cut_orders)), "linestyle": "-"})
        _cut_axes(ax, data.amplitude)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=8)
        ax.set_title(title or f"{signal}: order cuts", fontsize=10)
        fig.tight_layout()
        return fig
    fig, axes = order_panels(len(cut_orders))
    for k, (ax, order) in enumerate(zip(axes.flat, cut_orders)):
        for j, case in enumerate(cases):
            d = data[(data.case.fillna("") == case) & np.isclose(data.order, order)]
            d = d.sort_values("rpm")
            ax.plot(d.rpm, d.amplitude, label=case_label(case),
                    **case_style(j, len(d), len(cases)))
        order_panel_axes(ax, k, order, axes.shape[1], ylabel, data.amplitude)
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=min(len(cases), 4),
               fontsize=9, frameon=False)
    fig.suptitle(title or f"{signal}: order cuts, cases overlaid", fontsize=11)
    return fig


def order_cuts(orders: pd.DataFrame, signal: str, path: str, unit: str | None = None,
               title: str | None = None, cut_orders=MAIN_ORDERS, cases: list[str] | None = None,
               band: str | None = None):
    _save(order_cuts_figure(orders, signal, unit, title, cut_orders, cases, band), path)


def order_panels(count: int, extra_height: float = 0.9):
    """A figure with one panel per order, three to a row, on shared axes (unused panels
    hidden); returns (figure, axes)."""
    columns = min(3, count)
    rows = -(-count // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.3 * columns, 3.3 * rows + extra_height),
                             sharex=True, sharey=True, squeeze=False, layout="constrained")
    for ax in axes.flat[count:]:
        ax.set_visible(False)
    return fig, axes


def order_panel_axes(ax, k: int, order: float, columns: int, ylabel: str, amplitudes):
    """Scales, grid, title and (first column) label of order panel ``k``."""
    _cut_axes(ax, amplitudes)
    ax.set_title(f"order {order:g}", fontsize=10)
    if k % columns == 0:
        ax.set_ylabel(ylabel)
    ax.tick_params(labelbottom=True)


def _cut_axes(ax, amplitudes):
    ax.set_xlabel("engine speed [rpm]")
    if np.nanmax(np.asarray(amplitudes, dtype=float), initial=0.0) > 0.0:
        ax.set_yscale("log")  # else all zero (the steering wheel in scene 1): a linear axis
    ax.grid(True, which="major", lw=0.5, alpha=0.6)
    ax.grid(True, which="minor", lw=0.3, alpha=0.3)


def order_map_figure(orders: pd.DataFrame, signal: str, unit: str | None = None,
                     cases: list[str] | None = None, title: str | None = None):
    """Order-tracked run-up: engine order over engine speed, level in dB (each block of whole
    revolutions is one column, every half order one row); one panel per case, one colour
    scale."""
    data = orders[orders.signal == signal]
    if data.empty:
        raise ValueError(f"no order amplitudes for {signal}")
    cases = cases or _cases(data)
    vmax = 5.0 * np.ceil(float(to_db(data.amplitude.max(), unit)) / 5.0)
    fig, axes = plt.subplots(1, len(cases), figsize=(3.0 + 5.5 * len(cases), 5.5),
                             squeeze=False, sharey=True, layout="constrained")
    mesh = None
    for ax, case in zip(axes[0], cases):
        d = data[data.case.fillna("") == case].sort_values(["rpm", "order"])
        speeds = np.sort(d.rpm.unique())
        order_values = np.sort(d.order.unique())
        grid = d.pivot_table(index="order", columns="rpm", values="amplitude").reindex(
            index=order_values, columns=speeds)
        step = order_values[1] - order_values[0] if len(order_values) > 1 else 0.5
        order_edges = np.concatenate([order_values - step / 2, [order_values[-1] + step / 2]])
        mesh = ax.pcolormesh(_speed_edges(speeds), order_edges, to_db(grid.to_numpy(), unit),
                             cmap="inferno", vmin=vmax - DYNAMIC_RANGE_DB, vmax=vmax,
                             shading="flat", rasterized=True)
        ax.set_xlabel("engine speed [rpm]")
        ax.set_yticks(order_values)
        if len(cases) > 1:
            ax.set_title(case_label(case), fontsize=10)
    axes[0][0].set_ylabel("engine order")
    _colour_bar(fig, mesh, list(axes[0]), unit)
    fig.suptitle(title or f"{signal}: order map", fontsize=10)
    return fig


def order_map(orders: pd.DataFrame, signal: str, path: str, unit: str | None = None,
              cases: list[str] | None = None, title: str | None = None):
    _save(order_map_figure(orders, signal, unit, cases, title), path)


def side_by_side_figure(spectra: pd.DataFrame, signal: str, cases: list[str],
                        unit: str | None = None):
    """Waterfalls of several cases next to each other on one colour scale."""
    data = spectra[spectra.signal == signal]
    if data.empty:
        raise ValueError(f"no spectra for {signal}")
    top = float(data.frequency.max())
    vmin, vmax = _level_range(data, unit)
    fig, axes = plt.subplots(1, len(cases), figsize=(1.5 + 5.5 * len(cases), 5.5),
                             squeeze=False, sharey=True, layout="constrained")
    mesh = None
    for ax, case in zip(axes[0], cases):
        d = data[data.case == case]
        mesh = _draw_colour_map(ax, d, unit, top, vmin, vmax) or mesh
        ax.set_title(case_label(case), fontsize=10)
    for ax in axes[0][1:]:
        ax.set_ylabel("")
    _colour_bar(fig, mesh, list(axes[0]), unit)
    fig.suptitle(f"{signal}: waterfalls on one colour scale (order lines dashed/dotted; grey: "
                 f"above order {HIGHEST_ORDER:g}, not analysed)", fontsize=11)
    return fig


def side_by_side(spectra: pd.DataFrame, orders: pd.DataFrame, signal: str, cases: list[str],
                 waterfall_path: str, order_cut_path: str, unit: str | None = None):
    """Waterfalls of several cases next to each other on one colour scale, and their order cuts
    overlaid."""
    _save(side_by_side_figure(spectra, signal, cases, unit), waterfall_path)
    order_cuts(orders[orders.case.isin(cases)], signal, order_cut_path, unit=unit,
               title=f"{signal}: order cuts, " + " vs ".join(case_label(c) for c in cases),
               cases=cases)


def comfort_figure(table: pd.DataFrame, cases: list[str] | None = None, band: str | None = None):
    """Weighted seat and steering-wheel accelerations over engine speed, one line per case (in
    the order of ``cases``: the same colours as the order cuts); with a ``bound`` column each
    case a band around its nominal line (the damping band ``band`` describes)."""
    cases = cases or _cases(table)
    banded = "bound" in table
    panels = [(c, label) for c, label in (
        ("seat_av_comfort", "seat, vibration total value a_v (ISO 2631-1, Wk/Wd, comfort)"),
        ("wheel_ahv", "steering wheel, a_hv (ISO 5349-1, Wh)")) if c in table]
    fig, axes = plt.subplots(1, len(panels), figsize=(7 * len(panels), 4.8 if banded else 4.5),
                             squeeze=False, layout="constrained" if banded else None)
    for ax, (column, label) in zip(axes[0], panels):
        for k, case in enumerate(cases):
            d = table[table.case.fillna("") == case]
            if banded:
                x, low, nominal, high = _band_curves(d, "rpm", column)
                draw_band(ax, x, low, nominal, high, label=f"{case_label(case)}: nominal",
                          color=f"C{k}", lw=1.4, marker="o", ms=3)
            else:
                d = d.sort_values("rpm")
                ax.plot(d.rpm, d[column], label=case_label(case), **case_style(k))
        ax.set_xlabel("engine speed [rpm]")
        ax.set_ylabel("weighted RMS acceleration [m/s²]")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.4)
        if banded:
            ax.legend(title="shaded: damping band", fontsize=8, title_fontsize=8)
        else:
            ax.legend()
    if banded and band:
        fig.suptitle(f"comfort values with the damping band ({band})", fontsize=10)
    elif not banded:
        fig.tight_layout()
    return fig


def comfort(table: pd.DataFrame, path: str, cases: list[str] | None = None,
            band: str | None = None):
    _save(comfort_figure(table, cases, band), path)


# A Campbell diagram (engine orders against the model's natural frequencies) lives in
# emc.diagnosis.campbell, beside the code that reads the modes from the FMU.
