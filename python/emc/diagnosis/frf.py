"""Transfer functions: of the body alone (accelerance from a force at a mount's body point to a
body point) and of the coupled system (engine on its mounts in the body) linearised at its static
equilibrium, from the load torque to any output.

Both come from what the FMU exports (:mod:`emc.running.modal`): the body's modes as simulated, and the
state-space model ``A, B, C, D`` the FMU forms from its own equations (engine at rest: crank
standing, mounts linearised at their operating points under the weight and the load torque).
:func:`sine_response` measures the same quantity in the time domain, by exciting the FMU with a
sine and reading the steady response: the check of both.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..figures.plots import draw_band, plt
from ..running.band import nominal_rows, wide
from ..running.modal import Export, body_point_of
from ..running.runner import Runner, set_value
from ..signals.spectra import dft_at
from .tpa import AXES, expand_complex, path_label


def linear_output_name(output: str) -> str:
    """The name of an FMU output in the linearised model: ``steeringWheel.a[3]`` →
    ``steering_wheel.a[3]``; mount forces and ``powertrain.a`` keep theirs."""
    if output.startswith(("mount[", "powertrain.")):
        return output
    point, dof = body_point_of(output)
    return f"{point}.a[{dof + 1}]"


def body_frf(export: Export, response: str, frequencies, paths=None) -> pd.DataFrame:
    """Accelerance (m/s²/N) from a force on the body at each mount point and direction (every
    path of the export, or ``paths`` = [(mount i, direction j)], 1-based) to ``response``."""
    if export.body is None:
        raise ValueError("the export has no elastic body (scene 2 or the body FMU)")
    point, dof = body_point_of(response)
    export.body.point(point)
    points = {i: p for i, j, p in export.paths()}
    chosen = list(paths) if paths else [(i, j) for i, j, _ in export.paths()]
    for i, j in chosen:
        if i not in points:
            raise ValueError(f"mount[{i}] acts on no body point (mounts: "
                             f"{', '.join(f'mount[{k}]' for k in points)})")
    f = np.asarray(frequencies, float)
    h = export.body.accelerance(point, dof, [(points[i], j - 1) for i, j in chosen], f)
    rows = [{"frequency": fk, "input": f"mount[{i}].F[{j}]", "path": path_label(i, j),
             "output": response, "value": h[k, n], "force": np.nan, "transfer": np.nan}
            for n, (i, j) in enumerate(chosen) for k, fk in enumerate(f)]
    return _tidy(rows)


def state_space(export: Export):
    if export.linear is None:
        raise ValueError("the export has no linearised model (the engine FMU writes it)")
    lin = export.linear
    return (np.asarray(lin["a"]), np.asarray(lin["b"]), np.asarray(lin["c"]),
            np.asarray(lin["d"]), lin["outputs"], lin["inputs"])


def coupled_frf(export: Export, outputs: list[str], frequencies) -> pd.DataFrame:
    """``H(ω) = C (iω I − A)⁻¹ B + D`` of the linearised coupled model, per unit load torque
    (N m), for each FMU output name in ``outputs``."""
    a, b, c, d, names, inputs = state_space(export)
    rows_of = []
    for output in outputs:
        name = linear_output_name(output)
        if name not in names:
            raise ValueError(f"{output}: not an output of the linearised model ({name!r}; "
                             f"outputs: {', '.join(names)})")
        rows_of.append(names.index(name))
    c_sel, d_sel = c[rows_of], d[rows_of]
    eye = np.eye(a.shape[0])
    f = np.asarray(frequencies, float)
    rows = []
    for fk in f:
        x = np.linalg.solve(2j * np.pi * fk * eye - a, b)
        h = c_sel @ x + d_sel
        for output, value in zip(outputs, h[:, 0]):
            rows.append({"frequency": fk, "input": inputs[0], "path": inputs[0],
                         "output": output, "value": value, "force": np.nan, "transfer": np.nan})
    return _tidy(rows)


def _tidy(rows: list[dict]) -> pd.DataFrame:
    table = expand_complex(pd.DataFrame(rows))
    return table.drop(columns=[c for c in table.columns
                               if c.startswith(("force_", "transfer_"))])


def sine_response(fmu: str, parameters: dict, input_name: str, outputs: list[str],
                  frequency: float, amplitude: float, settle: float = 3.0, ramp: float = 0.5,
                  cycles: int = 20, steps_per_cycle: int = 50) -> dict[str, complex]:
    """Steady response of ``outputs`` per unit of a sine on ``input_name`` at ``frequency``,
    from the FMU in the time domain: the sine's amplitude rises smoothly over ``ramp`` s (so
    that the modes far from the frequency are hardly excited), ``settle`` s pass, and the
    response over ``cycles`` whole periods is divided by the input's own component at the
    frequency. The input is given with its derivative at every communication point."""
    w = 2.0 * np.pi * frequency
    h = 1.0 / (frequency * steps_per_cycle)
    n_settle = int(np.ceil(settle * frequency)) * steps_per_cycle
    n_window = cycles * steps_per_cycle

    def envelope(t):
        x = np.clip(t / ramp, 0.0, 1.0)
        return x * x * (3.0 - 2.0 * x), np.where((t > 0) & (t < ramp), 6.0 * x * (1 - x) / ramp, 0.0)

    with Runner(fmu, instance_name="sine") as runner:
        runner._start(dict(parameters))
        slave, vr = runner.slave, runner.vr
        u_vr = vr[input_name]
        out_vrs = [vr[o] for o in outputs]
        samples = np.empty((n_window, len(outputs)))
        t = 0.0
        for k in range(n_settle + n_window):
            e, de = envelope(t)
            u = amplitude * e * np.sin(w * t)
            du = amplitude * (de * np.sin(w * t) + e * w * np.cos(w * t))
            set_value(slave, "Real", u_vr, u)
            slave.setRealInputDerivatives([u_vr], [1], [du])
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t = (k + 1) * h
            if k >= n_settle:
                samples[k - n_settle] = slave.getReal(out_vrs)
    times = (np.arange(n_window) + n_settle + 1) * h
    # y = Re(Y e^{iωt}) with Y = (2/N) Σ y e^{−iωt}.
    y = 2.0 / n_window * dft_at(samples - samples.mean(axis=0), w * times)
    # The input the FMU saw: within each step the value and derivative of its start, a line
    # that leaves the sine by up to ω²h²/2 of its amplitude; its own component at ω (from 16
    # points per step) is what the response answers.
    sub = (np.arange(16) + 0.5) / 16 * h
    starts = times - h
    e, de = envelope(starts)
    u0 = amplitude * e * np.sin(w * starts)
    du = amplitude * (de * np.sin(w * starts) + e * w * np.cos(w * starts))
    applied = u0[:, None] + du[:, None] * sub[None, :]
    at = starts[:, None] + sub[None, :]
    u = 2.0 / applied.size * dft_at(applied.ravel(), (w * at).ravel())
    return {o: y[k] / u for k, o in enumerate(outputs)}

def plot(table: pd.DataFrame, path: str, unit: str, title: str, top: int | None = None,
         checks: pd.DataFrame | None = None, marks: dict | None = None):
    """Magnitude (log) and phase over frequency, one line per input (the ``top`` largest at
    their peak if given; a table with a ``bound`` column: the magnitude's damping band shaded
    around the nominal line, the nominal phase); ``checks`` (frequency, input, amplitude, phase_deg) from the sine
    excitation as points; ``marks`` {label: Hz} as vertical lines (e.g. an order at a speed)."""
    banded = "bound" in table
    full, table = table, nominal_rows(table)
    inputs = list(dict.fromkeys(table.input))
    if top is not None:
        peaks = table.groupby("input").amplitude.max().sort_values(ascending=False)
        inputs = [i for i in peaks.index[:top]]
    fig, (ax, ax_phase) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                       gridspec_kw={"height_ratios": [2, 1]})
    for k, name in enumerate(inputs):
        d = table[table.input == name].sort_values("frequency")
        label = d.path.iloc[0]
        if banded:
            w = wide(full[full.input == name], ["frequency"], ["amplitude"])
            draw_band(ax, w.frequency, w.amplitude_low, w.amplitude_nominal, w.amplitude_high,
                      label=label, color=f"C{k % 10}", lw=1.3)
        else:
            ax.plot(d.frequency, d.amplitude, color=f"C{k % 10}", lw=1.3, label=label)
        ax_phase.plot(d.frequency, d.phase_deg, color=f"C{k % 10}", lw=1.0)
        if checks is not None:
            c = checks[checks.input == name]
            if len(c):
                ax.scatter(c.frequency, c.amplitude, color=f"C{k % 10}", edgecolor="k", s=40,
                           zorder=3, label="time-domain sine excitation" if k == 0 else None)
                ax_phase.scatter(c.frequency, c.phase_deg, color=f"C{k % 10}", edgecolor="k",
                                 s=30, zorder=3)
    for label, hz in (marks or {}).items():
        for a in (ax, ax_phase):
            a.axvline(hz, color="0.4", ls=":", lw=1.0)
        ax.text(hz, table.amplitude.max(), f" {label}",
                fontsize=8, va="top", color="0.3")
    ax.set_yscale("log")
    ax.set_ylabel(f"magnitude [{unit}]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    ax_phase.set_ylim(-180, 180)
    ax_phase.set_yticks([-180, -90, 0, 90, 180])
    ax_phase.set_ylabel("phase [deg]")
    ax_phase.set_xlabel("frequency [Hz]")
    ax_phase.grid(True, alpha=0.3)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


__all__ = ["AXES", "body_frf", "coupled_frf", "sine_response", "linear_output_name", "plot"]
