"""Spectra and order amplitudes of stationary windows.

A window of an even number N of crank revolutions at constant speed is periodic for every half
order, so order k/2 falls exactly on DFT bin k N / 2: no leakage, no window function needed.
"""

from __future__ import annotations

import numpy as np

# The engine orders every analysis reports (0.5 … 6.0) and those its plots single out.
ORDERS = tuple(k / 2 for k in range(1, 13))
MAIN_ORDERS = (1.0, 1.5, 2.0, 3.0, 4.5)


def amplitude_spectrum(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of ``x`` (mean removed): frequencies (Hz), amplitudes."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    spectrum = np.fft.rfft(x)
    amplitude = 2.0 * np.abs(spectrum) / n
    amplitude[0] /= 2.0
    return np.fft.rfftfreq(n, dt), amplitude


def order_amplitudes(x: np.ndarray, revolutions: int | None, orders=ORDERS,
                     samples_per_revolution: float | None = None) -> dict[float, float]:
    """Amplitude of each engine order over the last ``revolutions`` crank revolutions of ``x``
    (None: the longest whole number of working cycles, two revolutions each; NaN if there is
    none).

    ``x`` is sampled at equal steps of time at constant speed (or of crank angle): one signal, or
    one column per signal (each order's amplitude is then an array over the columns).
    ``samples_per_revolution`` (``60 / (rpm × step)``, need not be whole) defaults to
    ``len(x) / revolutions``: ``x`` is the window. The window's mean is removed. Where the window
    is a whole number of samples and every order a whole number of cycles in it, the order is its
    DFT bin (no leakage); otherwise the DFT is evaluated at the order's own frequency.
    """
    x = np.asarray(x, dtype=float)
    if revolutions is None:
        if samples_per_revolution is None:
            raise ValueError("the window needs revolutions or samples_per_revolution")
        revolutions = 2 * int(len(x) / samples_per_revolution // 2)
        if revolutions == 0:
            return {float(order): np.full(x.shape[1:], np.nan)[()] for order in orders}
    per_revolution = len(x) / revolutions if samples_per_revolution is None else samples_per_revolution
    n = int(round(revolutions * per_revolution))
    if not 0 < n <= len(x):
        raise ValueError(f"a window of {revolutions} revolutions needs {n} samples, "
                         f"{len(x)} given")
    window = x[len(x) - n:]
    window = window - np.mean(window, axis=0)
    cycles = [order * revolutions for order in orders]
    on_bins = (abs(revolutions * per_revolution - n) < 1e-9 * n
               and all(abs(c - round(c)) < 1e-9 for c in cycles))
    if on_bins:
        spectrum = np.fft.rfft(window, axis=0)
        result = {}
        for order, c in zip(orders, cycles):
            k = int(round(c))
            result[float(order)] = (2.0 * abs(spectrum[k]) / n if 0 < k < len(spectrum)
                                    else np.full(np.shape(spectrum[0]), np.nan)[()])
        return result
    phase = 2.0 * np.pi * np.arange(n) / per_revolution
    return {float(order): 2.0 * np.abs(np.exp(-1j * order * phase) @ window) / n
            for order in orders}
