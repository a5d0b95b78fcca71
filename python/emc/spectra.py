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


def order_amplitudes(x: np.ndarray, revolutions: int, orders) -> dict[float, float]:
    """Amplitude of each engine order in a window of exactly ``revolutions`` crank revolutions."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    spectrum = np.fft.rfft(x)
    result = {}
    for order in orders:
        k = order * revolutions
        if abs(k - round(k)) > 1e-9:
            raise ValueError(f"order {order} does not fall on a bin of a {revolutions}-revolution window")
        k = int(round(k))
        result[float(order)] = 2.0 * abs(spectrum[k]) / n if 0 < k < len(spectrum) else float("nan")
    return result
