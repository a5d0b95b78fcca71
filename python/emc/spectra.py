"""Spectra and order amplitudes of stationary windows.

A window of an even number N of crank revolutions at constant speed is periodic for every half
order, so order k/2 falls exactly on DFT bin k N / 2: no leakage, no window function needed.
"""

from __future__ import annotations

import numpy as np


def amplitude_spectrum(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of ``x`` (mean removed): frequencies (Hz), amplitudes."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    spectrum = np.fft.rfft(x)
    amplitude = 2.0 * np.abs(spectrum) / n
    amplitude[0] /= 2.0
    return np.fft.rfftfreq(n, dt), amplitude


def order_components(x: np.ndarray, revolutions: int, orders) -> np.ndarray:
    """Complex amplitude ``X`` of each engine order in a window of exactly ``revolutions`` crank
    revolutions, ``x(t) ≈ Re(X e^{iωt})`` with t from the first sample: (orders,) for one signal,
    (orders, signals) for samples × signals."""
    x = np.asarray(x, dtype=float)
    x = x - np.mean(x, axis=0)
    n = len(x)
    spectrum = np.fft.rfft(x, axis=0)
    bins = []
    for order in orders:
        k = order * revolutions
        if abs(k - round(k)) > 1e-9:
            raise ValueError(f"order {order} does not fall on a bin of a {revolutions}-revolution window")
        bins.append(int(round(k)))
    out = np.full((len(bins),) + spectrum.shape[1:], np.nan + 0j)
    for row, k in enumerate(bins):
        if 0 < k < len(spectrum):
            out[row] = 2.0 * spectrum[k] / n
    return out


def order_amplitudes(x: np.ndarray, revolutions: int, orders) -> dict[float, float]:
    """Amplitude of each engine order in a window of exactly ``revolutions`` crank revolutions."""
    amplitudes = np.abs(order_components(x, revolutions, orders))
    return {float(order): float(a) for order, a in zip(orders, amplitudes)}
