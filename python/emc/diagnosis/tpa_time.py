"""Transfer paths where the body is not on a periodic steady state: a run-up of the engine in the
body (scene 2, ``emc tpa-runup``) and the engine FMU on the body FMU coupled by
:mod:`emc.running.coupling` (scene 3, ``emc tpa-coupled``).

Each path's contribution is the body's response to that mount force alone, synthesised in the
time domain from the modal data the FMU exports (:mod:`emc.running.synthesis`), then analysed like the
response itself: order-tracked block by block in a run-up (:mod:`emc.signals.tracking`), or per order
over a window of whole working cycles. Because the analysis is linear, the tracked paths add up
to the tracked response whatever the speed does.

The product of a block's force order with the body's transfer function at the order's frequency
(the order-based TPA of a measured run-up) is written beside it as ``quasi_static``: it is the
contribution only where the response is quasi-stationary. Passing a 1 %-damped body mode, the
response lags and rings, and that product misses the tracked response by tens of per cent at
85 rpm/s and still by a few per cent at 8.5 rpm/s (the user guide's run-up chapter).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..running.modal import Export, body_point_of
from ..running.synthesis import HeldForces, path_responses, periodic_state, static_state
from ..signals.spectra import ORDERS, order_components
from ..signals.tracking import tracked_blocks
from . import tpa

# Cubic refinement of sampled forces before the hold (emc.running.synthesis): 1.4e-4 at 125 Hz, 0.2 ms.
REFINE = 4
# Samples per revolution of the working cycle that gives a periodic start its modal state.
CYCLE_STEPS_PER_REVOLUTION = 720


def inputs_of(export: Export) -> list[tuple[str, int]]:
    return [(p, j - 1) for _, j, p in export.paths()]


def _complex_table(export: Export, responses: list[str], speeds, paths_c, forces_c,
                   simulated: dict, orders, case: str) -> pd.DataFrame:
    """Rows per speed (block or window), response and order, from the contributions
    ``paths_c`` (speeds, orders, responses, paths), the force orders ``forces_c`` (speeds,
    orders, paths) and the tracked responses ``simulated`` (name → (speeds, orders))."""
    inputs = inputs_of(export)
    rows = []
    for r, response in enumerate(responses):
        point, dof = body_point_of(response)
        for s, rpm in enumerate(speeds):
            frequencies = np.asarray(orders, float) * rpm / 60.0
            h = export.body.accelerance(point, dof, inputs, frequencies)
            tracked = simulated[response][s] if response in simulated else None
            rows += tpa.order_rows(export.paths(), orders, frequencies, paths_c[s, :, r],
                                   forces_c[s], h, tracked, quasi_static=h * forces_c[s],
                                   case=case, rpm=float(rpm), response=response)
    return tpa.expand_complex(pd.DataFrame(rows))


def angle_resolution(rpm_lowest: float, dt: float) -> int:
    """Crank-angle samples per revolution for tracking a run sampled every ``dt``: a power of two
    at least as fine as the time sampling at the lowest speed. Coarser, the resampling folds
    the high orders the time samples hold onto the low ones (at 64 per revolution and 1100 rpm
    the steering wheel's content near 1.1 kHz, order 61, lands on order 3 and takes 13 % off
    it)."""
    return max(64, 2 ** int(np.ceil(np.log2(60.0 / (rpm_lowest * dt)))))


def set_point_angle(rpm: np.ndarray, dt: float) -> np.ndarray:
    """The crank angle the speed set-point gives at the samples (``rpm`` sampled every ``dt``
    from t = dt on, linear in between, as :meth:`emc.running.runner.Runner.run_up` drives it), from 0 at
    t = 0.

    The paths are tracked on it, not on the FMU's ``crankAngle``: that angle carries the crank's
    speed fluctuation (a few mrad at the 1.5 order), which modulates a time-periodic signal
    resampled on it and moves a part of its strong 1.5 order onto orders 0 and 3; the body
    filters in time, so the force's order times the transfer function then misses the
    response's order 3 by 13 % at 1100 rpm. On the set-point angle the orders are the time
    harmonics the transfer functions act on."""
    rpm = np.asarray(rpm, float)
    start = rpm[0] - (rpm[1] - rpm[0]) if len(rpm) > 1 else rpm[0]
    speed = np.concatenate([[start], rpm]) * (2.0 * np.pi / 60.0)
    return np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)


def runup_paths(export: Export, run: dict, responses: list[str],
                cycle: tuple[np.ndarray, float] | None = None, revolutions_per_block: int = 4,
                samples_per_revolution: int | None = None, orders=ORDERS,
                case: str = "") -> pd.DataFrame:
    """Path contributions per order and block of a run-up (:meth:`emc.running.runner.Runner.run_up`
    with the mount forces first among its signals, then any recorded responses).

    ``cycle``: (samples, period in s) of one working cycle of the mount forces at the start
    speed, equally spaced from the start's crank angle on (a start on the periodic steady
    state: its modal state); None: the
    run-up started from the static equilibrium. ``samples_per_revolution``: of the tracking
    (default :func:`angle_resolution`). The table has the columns of
    :func:`emc.diagnosis.tpa.contributions`, ``rpm`` the block's mean speed, plus ``quasi_static``."""
    if export.body is None:
        raise ValueError("the export has no elastic body (scene 2)")
    n_paths = len(export.paths())
    signals = list(run["signals"])
    if signals[:n_paths] != tpa.force_signals(export):
        raise ValueError("the run-up must record the mount forces first")
    forces = np.vstack([run["initial"][None, :n_paths], run["samples"][:, :n_paths]])
    initial = (periodic_state(export.body, *cycle) if cycle is not None
               else static_state(export.body, forces[0]))
    outputs = [body_point_of(r) for r in responses]
    held = HeldForces.from_samples(forces, run["dt"], REFINE)
    paths = path_responses(export.body, held, outputs, inputs_of(export), initial)[1:]
    recorded = [r for r in responses if r in signals]
    columns = [run["samples"][:, :n_paths]] + [run["samples"][:, [signals.index(r)]]
                                               for r in recorded]
    columns.append(paths.reshape(len(paths), -1))
    per_revolution = samples_per_revolution or angle_resolution(float(np.min(run["rpm"])),
                                                                run["dt"])
    speeds, tracked = tracked_blocks(set_point_angle(run["rpm"], run["dt"]), run["rpm"],
                                     np.hstack(columns),
                                     revolutions_per_block, per_revolution, orders)
    forces_c = tracked[:, :, :n_paths]
    simulated = {r: tracked[:, :, n_paths + k] for k, r in enumerate(recorded)}
    paths_c = tracked[:, :, n_paths + len(recorded):].reshape(len(speeds), len(orders),
                                                              len(responses), n_paths)
    return _complex_table(export, responses, speeds, paths_c, forces_c, simulated, orders, case)


def window_paths(export: Export, forces: HeldForces, responses: dict, revolutions: int,
                 rpm: float, window_start: float, initial: np.ndarray | None = None,
                 orders=ORDERS, case: str = "") -> pd.DataFrame:
    """Path contributions per order over the window of ``revolutions`` revolutions from
    ``window_start`` (s) of a run at constant speed: the body driven by ``forces`` (the ramps a
    master applied, :class:`emc.running.synthesis.HeldForces`) from ``initial`` (modal state at t = 0,
    None: at rest). ``responses``: name → the body's simulated response sampled after each
    output step (t = dt, 2 dt, …), or None where it was not recorded."""
    if export.body is None:
        raise ValueError("the export has no elastic body")
    names = list(responses)
    outputs = [body_point_of(r) for r in names]
    paths = path_responses(export.body, forces, outputs, inputs_of(export), initial)
    dt = forces.dt * forces.every
    first = int(round(window_start / dt))
    n = int(round(revolutions * 60.0 / rpm / dt))
    if first < 0 or first + n >= len(paths):
        raise ValueError(f"the window {window_start:.4g} s + {revolutions} revolutions lies "
                         f"outside the run ({(len(paths) - 1) * dt:.4g} s)")
    window = slice(first + 1, first + n + 1)  # t = (first + 1) dt … (first + n) dt
    per_revolution = 60.0 / rpm / dt
    paths_c = order_components(paths[window].reshape(n, -1), revolutions, orders,
                               per_revolution).reshape(len(orders), len(names), -1)
    forces_c = order_components(forces.read[::forces.every][window], revolutions, orders,
                                per_revolution)
    simulated = {r: order_components(np.asarray(y)[first:first + n], revolutions, orders,
                                     per_revolution)[None]
                 for r, y in responses.items() if y is not None}
    return _complex_table(export, names, [rpm], paths_c[None], forces_c[None], simulated,
                          orders, case)
