"""The simulated counterpart of a measurement: the complex order components of the mapped
outputs at the measured speeds, for given FMU start values (and vehicle configuration), on a
:class:`emc.running.engine.PointEngine` (a pool, or one instance here).

Each speed is one constant-speed point on its periodic steady state (``initialization.periodic``):
the window of whole working cycles that follows gives every half order on a DFT bin
(:mod:`emc.spectra`), its phase referred to the crank angle at the window's start (the start of
the run, crank angle ``crank.startAngle``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..running.runner import OperatingPoint, Runner
from ..signals.spectra import order_components
from ..studies.mount_study import configuration_file
from .mapping import Channel, Mapping


@dataclasses.dataclass(frozen=True)
class Grid:
    """What the simulation computes for a mapping: the speeds, the outputs and the orders; and,
    per channel, where its measured points sit on the speeds."""

    speeds: tuple[float, ...]
    signals: tuple[str, ...]
    orders: tuple[float, ...]

    def index(self, channel: Channel) -> tuple[np.ndarray, int, int]:
        """(indices of the channel's speeds in :attr:`speeds`, its order's index, its
        output's index)."""
        idx = np.searchsorted(np.asarray(self.speeds), channel.x)
        return idx, self.orders.index(channel.map.order), self.signals.index(channel.map.output)


def grid_of(mapping: Mapping, count: int | None = None) -> tuple[Grid, list[Channel]]:
    """The speeds to simulate and the order channels on them: the union of the measured speeds
    (``count`` None), or ``count`` speeds evenly over the measured range with every channel's
    measurement interpolated onto those inside its own range (amplitude in log, phase
    unwrapped)."""
    channels = mapping.order_channels()
    signals = tuple(dict.fromkeys(c.map.output for c in channels))
    orders = tuple(sorted({c.map.order for c in channels}))
    if count is None:
        speeds = np.unique(np.concatenate([np.round(c.x, 6) for c in channels]))
        resampled = [dataclasses.replace(c, x=np.round(c.x, 6)) for c in channels]
        return Grid(tuple(float(s) for s in speeds), signals, orders), resampled
    lo = min(c.x[0] for c in channels)
    hi = max(c.x[-1] for c in channels)
    speeds = np.round(np.linspace(lo, hi, count), 6)
    resampled = []
    for c in channels:
        inside = speeds[(speeds >= c.x[0] - 1e-9) & (speeds <= c.x[-1] + 1e-9)]
        amplitude = np.exp(np.interp(inside, c.x, np.log(np.maximum(np.abs(c.values), 1e-300))))
        floor = np.interp(inside, c.x, c.floor)
        if c.has_phase:
            phase = np.interp(inside, c.x, np.unwrap(np.angle(c.values)))
            values = amplitude * np.exp(1j * phase)
        else:
            values = amplitude
        resampled.append(dataclasses.replace(c, x=inside, values=values, floor=floor))
    return Grid(tuple(float(s) for s in speeds), signals, orders), resampled


@dataclasses.dataclass(frozen=True)
class Point:
    """One simulated speed: FMU start values, the vehicle configuration (JSON text, None: the
    start values' own) and what to analyse."""

    rpm: float
    parameters: tuple
    configuration: str | None
    signals: tuple[str, ...]
    orders: tuple[float, ...]
    revolutions: int


def evaluate(runner: Runner, point: Point) -> np.ndarray:
    """The complex order components (orders × signals) of one point, on ``runner``."""
    extra = () if point.configuration is None else (
        ("configFile", configuration_file(point.configuration)),)
    op = OperatingPoint(rpm=point.rpm, revolutions=point.revolutions, periodic=True,
                        parameters=tuple(point.parameters) + extra)
    result = runner.run_point(op, list(point.signals))
    return order_components(result["samples"], point.revolutions, point.orders)


def points(grid: Grid, parameters: dict, configuration: str | None,
           revolutions: int) -> list[Point]:
    return [Point(rpm, tuple(parameters.items()), configuration, grid.signals, grid.orders,
                  revolutions) for rpm in grid.speeds]
