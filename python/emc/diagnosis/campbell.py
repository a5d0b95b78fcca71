"""Campbell diagram: engine orders over engine speed against the coupled natural frequencies.

The natural frequencies come from the FMU itself: its calculated parameters ``modes.count``,
``mode[k].frequency``, ``mode[k].damping`` and ``mode[k].powertrainShare`` hold the modes of the
model linearised at its static equilibrium (engine at rest, mounts at their operating points)
for the parameters it was started with. A mode is excited resonantly where an order line
``f = n · rpm / 60`` crosses it; the diagram marks those crossings inside the speed range.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..base.checks import check_speeds, prepare
from ..base.orders import MAIN_ORDERS, ORDERS
from ..base.outputs import claim, reduction_notice, safe_name, save, write_metadata
from ..figures.plots import plt
from ..running.runner import Runner

# Body modes damped at most this much are resonant enough to mark their crossings.
LIGHT_DAMPING = 0.075


def natural_modes(fmu_path: str, parameters: dict | None = None, case: str = "") -> pd.DataFrame:
    """The FMU's natural modes for ``parameters`` (start values), one row per mode."""
    with Runner(fmu_path, instance_name="campbell") as runner:
        if "modes.count" not in runner.vr:
            raise RuntimeError(f"{fmu_path} reports no natural modes (no modes.count variable)")
        count = runner.initial_values(parameters or {}, ["modes.count"])[0]

        def column(field: str) -> list[float]:
            return runner.get([f"mode[{k}].{field}" for k in range(1, count + 1)])

        return pd.DataFrame({"case": case, "mode": np.arange(1, count + 1),
                             "frequency": column("frequency"), "damping": column("damping"),
                             "powertrain_share": column("powertrainShare")})


def crossings(modes: pd.DataFrame, rpm_from: float, rpm_to: float,
              orders=MAIN_ORDERS) -> pd.DataFrame:
    """Speeds where an order line meets a natural frequency: ``rpm = 60 f / n`` in the range."""
    rows = []
    for order in orders:
        for mode in modes.itertuples():
            rpm = 60.0 * mode.frequency / order
            if rpm_from <= rpm <= rpm_to:
                rows.append({"case": mode.case, "order": order, "mode": mode.mode,
                             "frequency": mode.frequency, "rpm": rpm,
                             "powertrain_share": mode.powertrain_share})
    columns = ["case", "order", "mode", "frequency", "rpm", "powertrain_share"]
    return pd.DataFrame(rows, columns=columns).sort_values(["order", "rpm"]).reset_index(drop=True)


def plot(modes: pd.DataFrame, rpm_from: float, rpm_to: float, path: str, title: str = ""):
    """Frequency over engine speed: order lines, natural frequencies (powertrain modes bold,
    body modes thin), crossings with the main orders marked."""
    top = max(ORDERS) * rpm_to / 60.0 * 1.02
    fig, ax = plt.subplots(figsize=(9, 6.5))
    rpm = np.array([0.0, rpm_to])
    for order in ORDERS:
        main = order in MAIN_ORDERS
        ax.plot(rpm, order * rpm / 60.0, "-" if main else ":", color="0.35" if main else "0.6",
                lw=1.0 if main else 0.7)
        f_end = order * rpm_to / 60.0
        if f_end <= top:
            ax.text(rpm_to, f_end, f" {order:g}", fontsize=8, va="center", color="0.3")
    shown = modes[modes.frequency <= top]
    for mode in shown.itertuples():
        powertrain = mode.powertrain_share >= 0.5
        ax.axhline(mode.frequency, color="tab:red" if powertrain else "tab:blue",
                   lw=1.6 if powertrain else 0.5,
                   alpha=0.9 if powertrain else (0.6 if mode.damping <= LIGHT_DAMPING else 0.2))
    # Crossings that matter: every powertrain mode's, and the body modes' that are lightly
    # damped (resonant amplification 1/(2ζ) ≥ 6.7: the body's physical modes at the default
    # 5 %); the interface modes above the cut-off (10 % and more) barely amplify.
    cross = crossings(shown, rpm_from, rpm_to)
    damping = shown.set_index("mode").damping
    resonant = cross["mode"].map(damping) <= LIGHT_DAMPING
    for powertrain, marker, colour in ((True, "o", "tab:red"), (False, "x", "tab:blue")):
        d = cross[((cross.powertrain_share >= 0.5) == powertrain) & (powertrain | resonant)]
        ax.scatter(d.rpm, d.frequency, marker=marker, s=28, color=colour, zorder=3)
    ax.axvspan(rpm_from, rpm_to, color="tab:green", alpha=0.06, lw=0)
    handles = [
        plt.Line2D([], [], color="tab:red", lw=1.6, marker="o",
                   label="powertrain mode (≥ 50 % of kinetic energy in the engine) and crossing"),
        plt.Line2D([], [], color="tab:blue", lw=0.8, marker="x",
                   label=f"body mode; crossing marked where damping ≤ {LIGHT_DAMPING:.1%}"),
        plt.Line2D([], [], color="0.35", lw=1.0,
                   label="engine orders " + ", ".join(f"{o:g}" for o in MAIN_ORDERS)
                   + " (others dotted)"),
        plt.Rectangle((0, 0), 1, 1, color="tab:green", alpha=0.15, label="speed range analysed"),
    ]
    ax.legend(handles=handles, loc="upper left", fontsize=8)
    ax.set_xlim(0, rpm_to * 1.08)
    ax.set_ylim(0, top)
    ax.set_xlabel("engine speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(title or f"Campbell diagram: {len(shown)} natural modes below {top:.0f} Hz, "
                          "crossings with the main orders marked", fontsize=10)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def cmd_campbell(args) -> int:
    """Campbell diagram: the engine orders against the model's coupled natural frequencies."""

    check_speeds(args.rpm)
    variables, cases = prepare(args)
    out = claim(args)
    reduction_notice(cases[0][1], variables)
    tables = [natural_modes(args.fmu, parameters, case=label)
              for label, parameters in cases]
    modes = pd.concat(tables, ignore_index=True)
    save(modes, str(out / "natural_modes.csv"))
    crossing = pd.concat([crossings(t, args.rpm[0], args.rpm[1]) for t in tables],
                          ignore_index=True)
    save(crossing, str(out / "crossings.csv"))
    for label, table in zip([c[0] for c in cases], tables):
        suffix = f"_{safe_name(label)}" if label else ""
        plot(table, args.rpm[0], args.rpm[1], str(out / f"campbell{suffix}.png"),
                      title=f"Campbell diagram{': ' + label if label else ''} "
                            f"({len(table)} natural modes of the linearised model)")
    write_metadata(out, args, variables, cases)
    powertrain = crossing[crossing.powertrain_share >= 0.5]
    print(powertrain.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(f"Campbell diagram -> {out}")
    return 0
