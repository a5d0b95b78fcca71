"""Order tracking of run-ups in the crank-angle domain.

A run-up changes the speed continuously, so a fixed-length time window smears every order over a
band of frequencies. Resampled at equal increments of the crank angle (the FMU's ``crankAngle``
output), each engine order is a fixed number of cycles per revolution: a block of whole
revolutions puts every half order exactly on a bin, as in a stationary window, and the block's
mean speed labels it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .spectra import ORDERS, order_components


def resample_by_angle(crank_angle: np.ndarray, values: np.ndarray, samples_per_revolution: int):
    """``values`` (samples × signals) at equal crank-angle steps from the first sample on, over
    whole revolutions; returns (angle grid, resampled values). The crank angle must increase."""
    theta = np.asarray(crank_angle, dtype=float) - float(crank_angle[0])
    if np.any(np.diff(theta) <= 0.0):
        raise ValueError("the crank angle must increase strictly for order tracking")
    revolutions = int(np.floor(theta[-1] / (2.0 * np.pi)))
    grid = np.arange(revolutions * samples_per_revolution) * (2.0 * np.pi / samples_per_revolution)
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        return grid, np.interp(grid, theta, values)
    return grid, np.column_stack([np.interp(grid, theta, values[:, j])
                                  for j in range(values.shape[1])])


def tracked_blocks(crank_angle, rpm, samples: np.ndarray, revolutions_per_block: int = 4,
                   samples_per_revolution: int = 64, orders=ORDERS):
    """The complex order components of each signal per block of ``revolutions_per_block``
    revolutions in the crank-angle domain: (mean speed of each block, array (blocks, orders,
    signals)); the phase of a block refers to its first crank angle."""
    if revolutions_per_block < 2 or revolutions_per_block % 2:
        raise ValueError("blocks must hold an even number of revolutions (half orders on bins)")
    if samples_per_revolution < 2 * max(orders) + 2:
        raise ValueError("too few samples per revolution for the highest order")
    samples = np.asarray(samples, dtype=float)
    if samples.ndim == 1:
        samples = samples[:, None]
    grid, resampled = resample_by_angle(crank_angle, np.column_stack([samples, rpm]),
                                        samples_per_revolution)
    n = revolutions_per_block * samples_per_revolution
    starts = range(0, len(grid) - n + 1, n)
    speeds = np.array([np.mean(resampled[s:s + n, -1]) for s in starts])
    components = np.array([order_components(resampled[s:s + n, :-1], revolutions_per_block,
                                            orders) for s in starts])
    return speeds, components.reshape(len(speeds), len(orders), samples.shape[1])


def track_orders(crank_angle, rpm, samples: np.ndarray, signals: list[str],
                 revolutions_per_block: int = 4, samples_per_revolution: int = 64,
                 orders=ORDERS, case: str = "runup") -> pd.DataFrame:
    """Order amplitudes (peak) of each signal per block of ``revolutions_per_block``
    revolutions, labelled with the block's mean speed: a table like a stationary sweep's."""
    speeds, components = tracked_blocks(crank_angle, rpm, samples, revolutions_per_block,
                                        samples_per_revolution, orders)
    rows = []
    for speed, block in zip(speeds, np.abs(components)):
        for j, signal in enumerate(signals):
            for order, amplitude in zip(orders, block[:, j]):
                rows.append({"case": case, "rpm": float(speed), "signal": signal,
                             "order": float(order), "frequency": order * speed / 60.0,
                             "amplitude": float(amplitude)})
    return pd.DataFrame(rows)
