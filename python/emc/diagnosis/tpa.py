"""Transfer path analysis per engine order: which mount, in which direction, carries the
vibration to a body point.

The body is linear and only the mount forces act on it, so every order of a body point's
acceleration is the sum over the paths (mount i, direction j) of

    contribution_ij = H_ij(ω) · F_ij,    ω = 2π · order · rpm / 60,

with ``F_ij`` the order's complex amplitude of the operational mount force ``mount[i].F[j]`` (from
the simulation, with the nonlinear mounts) and ``H_ij`` the body's accelerance from a force at the
mount's body point along j to the response, from the modal data the FMU exports (the same modes
and damping it simulates; :mod:`emc.running.modal`). On a periodic steady state the contributions add up
to the simulated response (the closure), up to the integrator's error and the aliasing of the
sampling.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..base.orders import ORDERS
from ..figures.plots import draw_band, plt
from ..running.band import wide
from ..running.modal import Export, body_point_of
from ..signals.spectra import order_components

AXES = "xyz"


def path_label(mount: int, direction: int, names: dict | None = None) -> str:
    """``mount[2] z (front right)``."""
    name = f" ({names[mount]})" if names and mount in names else ""
    return f"mount[{mount}] {AXES[direction - 1]}{name}"


def force_signals(export: Export) -> list[str]:
    return [f"mount[{i}].F[{j}]" for i, j, _ in export.paths()]


def contributions(export: Export, response: str, samples: dict, revolutions: int, rpm: float,
                  orders=ORDERS, case: str = "") -> pd.DataFrame:
    """Path contributions of each order to ``response`` (an acceleration output such as
    ``steeringWheel.a[3]``, or ``<body point>.a[j]``) from a stationary window of
    ``revolutions`` revolutions: one row per order and path, then the row ``sum`` and, if the
    response was recorded (``samples`` has it), ``simulated``; complex values as real and
    imaginary parts, amplitude and phase (deg)."""
    if export.body is None:
        raise ValueError("the export has no elastic body (scene 2 or the body FMU)")
    point, dof = body_point_of(response)
    export.body.point(point)  # a clear error for an unknown point
    paths = export.paths()
    forces = np.column_stack([samples[s] for s in force_signals(export)])
    f = order_components(forces, revolutions, orders)                       # (orders, paths)
    frequencies = np.asarray(orders, float) * rpm / 60.0
    h = export.body.accelerance(point, dof, [(p, j - 1) for _, j, p in paths], frequencies)
    simulated = (order_components(samples[response], revolutions, orders)
                 if response in samples else None)
    return expand_complex(pd.DataFrame(order_rows(paths, orders, frequencies, h * f, f, h,
                                                  simulated, case=case, rpm=rpm,
                                                  response=response)))


def order_rows(paths, orders, frequencies, c, f, h, simulated=None, quasi_static=None,
               **labels) -> list[dict]:
    """Table rows of one speed and response: per order, each path's contribution ``c``, force
    ``f`` and transfer function ``h`` (orders × paths, complex), then the row ``sum`` and, if
    given, ``simulated`` (per order); ``quasi_static`` (orders × paths): each path's force
    times its transfer function where ``c`` is something else (a run-up's contribution),
    summed in the row ``sum`` alike. ``labels``: the columns every row carries (case, rpm,
    response)."""
    rows = []
    for o, order in enumerate(orders):
        base = {**labels, "order": float(order), "frequency": frequencies[o]}
        for k, (i, j, p) in enumerate(paths):
            row = {**base, "path": path_label(i, j), "mount": i, "direction": AXES[j - 1],
                   "body_point": p, "value": c[o, k], "force": f[o, k], "transfer": h[o, k]}
            if quasi_static is not None:
                row["quasi_static"] = quasi_static[o, k]
            rows.append(row)
        none = {"mount": 0, "direction": "", "body_point": "", "force": np.nan,
                "transfer": np.nan}
        total = {} if quasi_static is None else {"quasi_static": quasi_static[o].sum()}
        rows.append({**base, "path": "sum", **none, "value": c[o].sum(), **total})
        if simulated is not None:
            missing = {} if quasi_static is None else {"quasi_static": np.nan}
            rows.append({**base, "path": "simulated", **none, "value": simulated[o], **missing})
    return rows


def expand_complex(table: pd.DataFrame) -> pd.DataFrame:
    """Complex columns as amplitude, phase (deg), real and imaginary parts (CSV-friendly)."""
    out = table.copy()
    for column in [c for c in ("value", "force", "transfer", "quasi_static") if c in out]:
        z = out.pop(column).to_numpy(dtype=complex)
        prefix = "" if column == "value" else f"{column}_"
        out[f"{prefix}amplitude"] = np.abs(z)
        out[f"{prefix}phase_deg"] = np.degrees(np.angle(z))
        out[f"{prefix}re"] = z.real
        out[f"{prefix}im"] = z.imag
    return out


def complex_values(table: pd.DataFrame, prefix: str = "") -> np.ndarray:
    return table[f"{prefix}re"].to_numpy() + 1j * table[f"{prefix}im"].to_numpy()


def closure(table: pd.DataFrame, significant: float = 0.01, prefix: str = "") -> pd.DataFrame:
    """Per case, rpm, response and order: the simulated amplitude, the sum of the paths and
    their difference relative to the simulated order, for the orders above ``significant`` of
    the response's largest order at that speed (``prefix`` ``quasi_static_``: the sum of the
    products of force and transfer function instead of the contributions)."""
    keys = ["case", "rpm", "response", "order"]
    sim = table[table.path == "simulated"].set_index(keys)
    total = table[table.path == "sum"].set_index(keys)
    if sim.empty:
        raise ValueError("the response was not simulated: no closure to check")
    z_sim = complex_values(sim)
    z_sum = complex_values(total.loc[sim.index], prefix)
    out = pd.DataFrame({"simulated": np.abs(z_sim), "sum_of_paths": np.abs(z_sum),
                        "relative_error": np.abs(z_sum - z_sim) / np.maximum(np.abs(z_sim), 1e-300)},
                       index=sim.index).reset_index()
    largest = out.groupby(["case", "rpm", "response"]).simulated.transform("max")
    out["significant"] = out.simulated > significant * largest
    return out


def ranked(table: pd.DataFrame, rpm: float, order: float, response: str,
           case: str = "") -> pd.DataFrame:
    """The paths at one speed and order, largest first, with each path's share of the response
    along the total's phase (``in_phase``: the projection, which adds up to the total's
    amplitude)."""
    at = table[(table.case == case) & (table.response == response) & (table.order == order)
               & np.isclose(table.rpm, rpm)]
    if at.empty:
        raise ValueError(f"no contributions at {rpm:g} rpm, order {order:g} for {response}")
    paths = at[~at.path.isin(["sum", "simulated"])].copy()
    total = complex_values(at[at.path == "sum"])[0]
    z = complex_values(paths)
    paths["in_phase"] = (z * np.conj(total)).real / max(abs(total), 1e-300)
    paths["share"] = paths["in_phase"] / max(abs(total), 1e-300)
    return paths.sort_values("amplitude", ascending=False).reset_index(drop=True)


def dominant_path(table: pd.DataFrame, rpm: float, order: float, response: str,
                  case: str = "") -> pd.Series:
    """The path with the largest in-phase share of the response at one speed and order."""
    r = ranked(table, rpm, order, response, case)
    return r.loc[r.in_phase.idxmax()]



def plot_ranked(table: pd.DataFrame, rpm: float, order: float, response: str, path: str,
                names: dict | None = None, case: str = "", top: int = 12):
    """Ranked path contributions at one speed and order: amplitude bars (the part in phase
    with the total darker), each path's phase beside it, and the sum of the paths against the
    simulated response."""
    r = ranked(table, rpm, order, response, case).head(top)
    at = table[(table.case == case) & (table.response == response) & (table.order == order)
               & np.isclose(table.rpm, rpm)]
    total = at[at.path == "sum"].amplitude.iloc[0]
    simulated = at[at.path == "simulated"].amplitude
    labels = [path_label(int(m), AXES.index(d) + 1, names) for m, d in zip(r.mount, r.direction)]
    fig, (ax, ax_phase) = plt.subplots(1, 2, figsize=(10, 0.42 * len(r) + 2.4), sharey=True,
                                       gridspec_kw={"width_ratios": [3, 1]})
    y = np.arange(len(r))[::-1]
    ax.barh(y, r.amplitude, color="tab:blue", alpha=0.35, label="|contribution|")
    ax.barh(y, r.in_phase, color="tab:blue", label="part in phase with the total")
    ax.axvline(total, color="tab:red", lw=1.5, label=f"sum of paths {total:.3g}")
    if len(simulated):
        ax.axvline(simulated.iloc[0], color="k", ls="--", lw=1.0,
                   label=f"simulated {simulated.iloc[0]:.3g}")
    ax.axvline(0, color="0.3", lw=0.6)
    ax.set_yticks(y, labels, fontsize=8)
    ax.set_xlabel(f"{response} order {order:g} [m/s²]")
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(True, axis="x", alpha=0.3)
    ax_phase.scatter(r.phase_deg, y, color="tab:blue")
    total_phase = at[at.path == "sum"].phase_deg.iloc[0]
    ax_phase.axvline(total_phase, color="tab:red", lw=1.5)
    ax_phase.set_xlim(-180, 180)
    ax_phase.set_xticks([-180, -90, 0, 90, 180])
    ax_phase.set_xlabel("phase [deg]")
    ax_phase.grid(True, alpha=0.3)
    fig.suptitle(f"Transfer paths to {response}, order {order:g} at {rpm:g} rpm "
                 f"({order * rpm / 60:.1f} Hz){': ' + case if case else ''}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_over_speed(table: pd.DataFrame, order: float, response: str, path: str,
                    names: dict | None = None, case: str = "", top: int = 6):
    """The largest path contributions of one order over engine speed, with their sum and the
    simulated response. A table with the bounds of a damping band (``bound``: low, nominal,
    high) draws each path and the sum as its band with the nominal line over it."""
    data = table[(table.case == case) & (table.response == response) & (table.order == order)]
    banded = "bound" in data and data.bound.nunique() > 1
    if banded:
        data = wide(data, ["rpm", "path", "mount", "direction"], ["amplitude"]).rename(
            columns={"amplitude_nominal": "amplitude"})

    def curve(d: pd.DataFrame, **style):
        if banded:
            draw_band(ax, d.rpm, d.amplitude_low, d.amplitude, d.amplitude_high, **style)
        else:
            ax.plot(d.rpm, d.amplitude, **style)

    paths = data[~data.path.isin(["sum", "simulated"])]
    biggest = paths.groupby("path").amplitude.max().sort_values(ascending=False).head(top).index
    fig, ax = plt.subplots(figsize=(9, 5.5))
    for k, p in enumerate(biggest):
        d = paths[paths.path == p].sort_values("rpm")
        m, direction = int(d.mount.iloc[0]), d.direction.iloc[0]
        curve(d, color=f"C{k}", marker="o" if len(d) < 60 else None, ms=3, lw=1.2,
              label=path_label(m, AXES.index(direction) + 1, names))
    curve(data[data.path == "sum"].sort_values("rpm"), color="k", lw=2.2,
          label="sum of the 12 paths")
    total = data[data.path == "sum"].sort_values("rpm")
    if "quasi_static_amplitude" in total:
        ax.plot(total.rpm, total.quasi_static_amplitude, color="0.45", lw=1.0, ls=":",
                label="sum of force × transfer function (quasi-stationary)")
    simulated = data[data.path == "simulated"].sort_values("rpm")
    if len(simulated) and not banded:
        ax.plot(simulated.rpm, simulated.amplitude, color="w", ls="--", lw=1.0,
                label="simulated (dashed over the sum)")
    ax.set_yscale("log")
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel(f"{response}, order {order:g} [m/s²]")
    ax.set_title(f"Path contributions of order {order:g} to {response}"
                 + (", damping band shaded" if banded else "")
                 + f"{': ' + case if case else ''}", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_cases(table: pd.DataFrame, order: float, response: str, path_name: str,
               cases: list[str], path: str, names: dict | None = None, at: float | None = None):
    """One path and the whole response of one order over speed, case beside case: what a change
    does to the path it aims at and to the response."""
    fig, ax = plt.subplots(figsize=(9, 5.5))
    data = table[(table.response == response) & (table.order == order)]
    for k, case in enumerate(cases):
        d = data[data.case == case]
        total = d[d.path == "sum"].sort_values("rpm")
        one = d[d.path == path_name].sort_values("rpm")
        label = case or "model"
        ax.plot(total.rpm, total.amplitude, color=f"C{k}", lw=2.0, label=f"{label}: {response}")
        ax.plot(one.rpm, one.amplitude, color=f"C{k}", lw=1.2, ls="--",
                label=f"{label}: path {path_name}")
    if at is not None:
        ax.axvline(at, color="0.5", lw=0.8, ls=":")
    ax.set_yscale("log")
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel(f"order {order:g} [m/s²]")
    ax.set_title(f"Order {order:g} of {response} and its path {path_name}, per case", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)

