"""Waterfalls (colour maps of frequency over engine speed, in dB), order cuts, case overlays.

Amplitudes are the peak amplitudes of the spectral lines (``emc.spectra``: 2|X|/N of a window of
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

MAIN_ORDERS = (1.0, 1.5, 2.0, 3.0, 4.5)
ALL_ORDERS = tuple(k / 2 for k in range(1, 13))
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


def _draw_colour_map(ax, data: pd.DataFrame, unit: str | None, top: float, vmin: float,
                     vmax: float):
    """Each speed point is a vertical strip of its own spectral bins (their widths differ with
    the speed), coloured by level."""
    speeds = np.sort(data.rpm.unique())
    edges = _speed_edges(speeds)
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
    for order in ALL_ORDERS:
        main = order in MAIN_ORDERS
        ax.plot(rpm_line, order * rpm_line / 60.0, "--" if main else ":", color="white",
                lw=0.8 if main else 0.5, alpha=0.8 if main else 0.5)
        f_end = order * edges[-1] / 60.0
        if f_end <= top:
            ax.text(edges[-1], f_end, f" {order:g}", fontsize=7, va="center", color="0.2")
    ax.set_xlim(edges[0], edges[-1])
    ax.set_ylim(0, top)
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    return mesh


def _level_range(data: pd.DataFrame, unit: str | None) -> tuple[float, float]:
    peak = float(to_db(data.amplitude.max(), unit))
    vmax = 5.0 * np.ceil(peak / 5.0)
    return vmax - DYNAMIC_RANGE_DB, vmax


def waterfall(spectra: pd.DataFrame, signal: str, path: str, unit: str | None = None,
              title: str | None = None, max_frequency: float | None = None):
    """Colour map of the spectra of ``signal``: frequency over engine speed, level in dB."""
    data = spectra[spectra.signal == signal]
    if data.empty:
        raise ValueError(f"no spectra for {signal}")
    top = max_frequency or float(data.frequency.max())
    vmin, vmax = _level_range(data, unit)
    fig, ax = plt.subplots(figsize=(8.5, 6))
    mesh = _draw_colour_map(ax, data, unit, top, vmin, vmax)
    bar = fig.colorbar(mesh, ax=ax, pad=0.08)
    bar.set_label(f"peak amplitude [{level_reference(unit)[1]}]")
    peak = data.amplitude.max()
    ax.set_title(title or f"{signal}: waterfall (largest line {peak:.3g} "
                          f"{level_reference(unit)[2]} peak; order lines dashed)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def order_cuts(orders: pd.DataFrame, signal: str, path: str, unit: str | None = None,
               title: str | None = None, cut_orders=MAIN_ORDERS):
    """Order amplitudes over engine speed. One case: one axes, a line per order. Several cases:
    one panel per order, the cases overlaid on common axes."""
    data = orders[orders.signal == signal]
    if data.empty:
        raise ValueError(f"no order amplitudes for {signal}")
    printed = level_reference(unit)[2]
    cases = list(dict.fromkeys(data.case.fillna("")))
    if len(cases) == 1:
        fig, ax = plt.subplots(figsize=(8, 5))
        for order in cut_orders:
            d = data[np.isclose(data.order, order)].sort_values("rpm")
            ax.plot(d.rpm, d.amplitude, marker="o", ms=3, label=f"order {order:g}")
        _cut_axes(ax, printed)
        ax.legend(fontsize=8)
        ax.set_title(title or f"{signal}: order cuts", fontsize=10)
    else:
        fig, axes = plt.subplots(1, len(cut_orders), figsize=(3.6 * len(cut_orders), 4.2),
                                 sharey=True, squeeze=False)
        for ax, order in zip(axes[0], cut_orders):
            for case in cases:
                d = data[(data.case.fillna("") == case) & np.isclose(data.order, order)]
                d = d.sort_values("rpm")
                ax.plot(d.rpm, d.amplitude, marker="o", ms=3, label=case or "model")
            _cut_axes(ax, printed if ax is axes[0][0] else None)
            ax.set_title(f"order {order:g}", fontsize=10)
        axes[0][0].legend(fontsize=8)
        fig.suptitle(title or f"{signal}: order cuts, cases overlaid", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _cut_axes(ax, printed_unit: str | None):
    ax.set_xlabel("engine speed [rpm]")
    if printed_unit is not None:
        ax.set_ylabel(f"amplitude (peak) [{printed_unit}]")
    ax.set_yscale("log")
    ax.grid(True, which="both", lw=0.3)


def order_map(orders: pd.DataFrame, signal: str, path: str, unit: str | None = None,
              title: str | None = None):
    """Order-tracked run-up: order over engine speed, level in dB (each block of whole
    revolutions is one column; every half order is one row)."""
    data = orders[orders.signal == signal].sort_values(["rpm", "order"])
    if data.empty:
        raise ValueError(f"no order amplitudes for {signal}")
    speeds = np.sort(data.rpm.unique())
    order_values = np.sort(data.order.unique())
    grid = data.pivot_table(index="order", columns="rpm", values="amplitude").reindex(
        index=order_values, columns=speeds)
    levels = to_db(grid.to_numpy(), unit)
    vmax = 5.0 * np.ceil(np.nanmax(levels) / 5.0)
    step = order_values[1] - order_values[0] if len(order_values) > 1 else 0.5
    order_edges = np.concatenate([order_values - step / 2, [order_values[-1] + step / 2]])
    fig, ax = plt.subplots(figsize=(8.5, 5.5))
    mesh = ax.pcolormesh(_speed_edges(speeds), order_edges, levels, cmap="inferno",
                         vmin=vmax - DYNAMIC_RANGE_DB, vmax=vmax, shading="flat", rasterized=True)
    bar = fig.colorbar(mesh, ax=ax)
    bar.set_label(f"peak amplitude [{level_reference(unit)[1]}]")
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("engine order")
    ax.set_yticks(order_values)
    ax.set_title(title or f"{signal}: order map", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def side_by_side(spectra: pd.DataFrame, orders: pd.DataFrame, signal: str, cases: list[str],
                 waterfall_path: str, order_cut_path: str, unit: str | None = None):
    """Waterfalls of several cases next to each other on one colour scale, and their order cuts
    overlaid."""
    data = spectra[spectra.signal == signal]
    top = float(data.frequency.max())
    vmin, vmax = _level_range(data, unit)
    fig, axes = plt.subplots(1, len(cases), figsize=(6.5 * len(cases), 5.5), squeeze=False)
    mesh = None
    for ax, case in zip(axes[0], cases):
        d = data[data.case == case]
        mesh = _draw_colour_map(ax, d, unit, top, vmin, vmax) or mesh
        ax.set_title(f"{case}: {signal}", fontsize=10)
    bar = fig.colorbar(mesh, ax=list(axes[0]), pad=0.02, fraction=0.03)
    bar.set_label(f"peak amplitude [{level_reference(unit)[1]}]")
    fig.savefig(waterfall_path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    order_cuts(orders[orders.case.isin(cases)], signal, order_cut_path, unit=unit,
               title=f"{signal}: order cuts, " + " vs ".join(cases))


def comfort(table: pd.DataFrame, path: str):
    """Weighted seat and steering-wheel accelerations over engine speed, one line per case."""
    panels = [(c, label) for c, label in (
        ("seat_av_comfort", "seat, vibration total value a_v (ISO 2631-1, Wk/Wd, comfort)"),
        ("wheel_ahv", "steering wheel, a_hv (ISO 5349-1, Wh)")) if c in table]
    fig, axes = plt.subplots(1, len(panels), figsize=(7 * len(panels), 4.5), squeeze=False)
    for ax, (column, label) in zip(axes[0], panels):
        for case, d in table.groupby("case"):
            ax.plot(d.rpm, d[column], marker="o", label=case or "model")
        ax.set_xlabel("engine speed [rpm]")
        ax.set_ylabel("weighted RMS acceleration [m/s²]")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.4)
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
