"""Waterfall diagrams (rpm × frequency, bubble size = amplitude, order lines) and order cuts."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

MAIN_ORDERS = (1.0, 1.5, 2.0, 3.0, 4.5)


def waterfall(spectra: pd.DataFrame, signal: str, path: str, title: str | None = None,
              max_frequency: float | None = None, ax=None):
    """Bubbles at the spectral lines of each rpm; order lines 0.5 … 6 for orientation."""
    data = spectra[spectra.signal == signal]
    if data.empty:
        raise ValueError(f"no spectra for {signal}")
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(8, 6))
    peak = data.amplitude.max()
    shown = data[data.amplitude > 0.02 * peak]
    ax.scatter(shown.rpm, shown.frequency, s=400 * shown.amplitude / peak, alpha=0.6,
               color="tab:blue", edgecolors="none")
    rpm = np.linspace(data.rpm.min(), data.rpm.max(), 2)
    top = max_frequency or data.frequency.max()
    for k in range(1, 13):
        order = k / 2
        style = "-" if order in MAIN_ORDERS else ":"
        ax.plot(rpm, order * rpm / 60, style, color="gray", lw=0.7)
        f_end = order * rpm[-1] / 60
        if f_end <= top:
            ax.text(rpm[-1], f_end, f" {order:g}", fontsize=7, va="center", color="gray")
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_ylim(0, top)
    ax.set_title(title or f"{signal}: waterfall (bubble area ∝ amplitude, max {peak:.3g})")
    if own:
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


def order_cuts(orders: pd.DataFrame, signal: str, path: str, title: str | None = None,
               cut_orders=MAIN_ORDERS, ax=None):
    data = orders[orders.signal == signal]
    own = ax is None
    if own:
        fig, ax = plt.subplots(figsize=(8, 5))
    for order in cut_orders:
        d = data[np.isclose(data.order, order)].sort_values("rpm")
        ax.plot(d.rpm, d.amplitude, marker="o", ms=3, label=f"order {order:g}")
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("amplitude")
    ax.set_yscale("log")
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    ax.set_title(title or f"{signal}: order cuts")
    if own:
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


def side_by_side(spectra: pd.DataFrame, orders: pd.DataFrame, signal: str, cases: list[str],
                 waterfall_path: str, order_cut_path: str):
    """Waterfalls and order cuts of several cases next to each other, on common scales."""
    data = spectra[spectra.signal == signal]
    top = data.frequency.max()
    fig, axes = plt.subplots(1, len(cases), figsize=(7 * len(cases), 6), squeeze=False)
    peak = data.amplitude.max()
    for ax, case in zip(axes[0], cases):
        d = data[data.case == case]
        shown = d[d.amplitude > 0.02 * peak]
        ax.scatter(shown.rpm, shown.frequency, s=400 * shown.amplitude / peak, alpha=0.6,
                   color="tab:blue", edgecolors="none")
        rpm = np.linspace(d.rpm.min(), d.rpm.max(), 2)
        for k in range(1, 13):
            order = k / 2
            ax.plot(rpm, order * rpm / 60, "-" if order in MAIN_ORDERS else ":", color="gray", lw=0.7)
        ax.set_ylim(0, top)
        ax.set_xlabel("engine speed [rpm]")
        ax.set_ylabel("frequency [Hz]")
        ax.set_title(f"{case}: {signal} (common scale, max {peak:.3g})")
    fig.tight_layout()
    fig.savefig(waterfall_path, dpi=120)
    plt.close(fig)

    fig, axes = plt.subplots(1, len(cases), figsize=(7 * len(cases), 5), squeeze=False, sharey=True)
    for ax, case in zip(axes[0], cases):
        order_cuts(orders[orders.case == case], signal, "", title=f"{case}: {signal}", ax=ax)
    fig.tight_layout()
    fig.savefig(order_cut_path, dpi=120)
    plt.close(fig)


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
