"""Log-log plot of the work-precision table written by `examples/accuracy_cost.rs`.

Usage: emc accuracy-plot accuracy.csv accuracy.png
"""

from __future__ import annotations


import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402


def family(knob: str) -> str:
    if knob.startswith("rtol"):
        return "tolerance"
    if knob.startswith("max order"):
        return "max order (rtol 1e-5)"
    if knob.startswith("comm") and knob.endswith("interp"):
        return "comm step, inputs interpolated"
    if knob.startswith("comm"):
        return "comm step, inputs held"
    if knob.startswith("chassis cut-off"):
        return "chassis cut-off (vs 2 kHz reference)"
    return "other (rtol 1e-5)"


def plot(csv: str, png: str) -> None:
    table = pd.read_csv(csv)
    cases = list(dict.fromkeys(table.case))
    metrics = [("rel_l2", "relative L2 error of the mount forces")]
    if "rel_l2_wheel" in table and table.rel_l2_wheel.notna().any():
        metrics.append(("rel_l2_wheel", "relative L2 error of the steering-wheel acceleration"))
    fig, axes = plt.subplots(len(metrics), len(cases), figsize=(6 * len(cases), 5 * len(metrics)),
                             squeeze=False)
    for row, (column, label) in enumerate(metrics):
        for ax, case in zip(axes[row], cases):
            data = table[table.case == case].copy()
            data["family"] = data.knob.map(family)
            for name, group in data.groupby("family", sort=False):
                style = "o" if name.startswith("other") else "o-"
                ax.loglog(group.cpu_s, group[column], style, label=name)
                for _, r in group.iterrows():
                    ax.annotate(r.knob.split(" (")[0].replace("comm ", ""), (r.cpu_s, r[column]),
                                fontsize=6, xytext=(3, 3), textcoords="offset points")
            ax.set_xlabel("CPU time [s]")
            ax.set_ylabel(label)
            ax.set_title(f"scene {data.scene.iloc[0]}: {case}")
            ax.grid(True, which="both", lw=0.3)
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def cmd_accuracy_plot(args) -> int:
    """``emc accuracy-plot``: the plot of a table written by ``examples/accuracy_cost.rs``."""
    plot(args.table, args.png)
    return 0
