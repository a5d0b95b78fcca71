"""Spectra and order amplitudes of stationary windows.

A window of an even number N of crank revolutions at constant speed is periodic for every half
order, so order k/2 falls exactly on DFT bin k N / 2: no leakage, no window function needed.
"""

from __future__ import annotations

import numpy as np

from ..base.orders import ORDERS


def amplitude_spectrum(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of ``x`` (mean removed): frequencies (Hz), amplitudes."""
    x = np.asarray(x, dtype=float) - np.mean(x)
    n = len(x)
    spectrum = np.fft.rfft(x)
    amplitude = 2.0 * np.abs(spectrum) / n
    amplitude[0] /= 2.0
    return np.fft.rfftfreq(n, dt), amplitude


def dft_at(x: np.ndarray, angle: np.ndarray):
    """The discrete Fourier sum ``Σ x e^{-i angle}`` at one frequency, ``angle`` = ω t at each
    sample (along the first axis of ``x``: one signal, or one column per signal). Over whole
    periods ``x(t) ≈ Re(X e^{iωt})`` with ``X = 2 / N × dft_at(x - mean, ω t)``."""
    return np.exp(-1j * np.asarray(angle, dtype=float)) @ np.asarray(x)


def _order_sums(x: np.ndarray, revolutions: int | None, orders,
                samples_per_revolution: float | None) -> tuple[np.ndarray, int]:
    """The DFT sums ``Σ x e^{-iωt}`` of each order over the window (one row per order) and the
    window's length; see :func:`order_components` for the window rules."""
    x = np.asarray(x, dtype=float)
    if revolutions is None:
        if samples_per_revolution is None:
            raise ValueError("the window needs revolutions or samples_per_revolution")
        revolutions = 2 * int(len(x) / samples_per_revolution // 2)
        if revolutions == 0:
            return np.full((len(orders),) + x.shape[1:], np.nan + 0j), 1
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
    sums = np.full((len(orders),) + window.shape[1:], np.nan + 0j)
    if on_bins:
        spectrum = np.fft.rfft(window, axis=0)
        for row, c in enumerate(cycles):
            k = int(round(c))
            if 0 < k < len(spectrum):
                sums[row] = spectrum[k]
        return sums, n
    phase = 2.0 * np.pi * np.arange(n) / per_revolution
    for row, order in enumerate(orders):
        sums[row] = dft_at(window, order * phase)
    return sums, n


def order_components(x: np.ndarray, revolutions: int | None, orders=ORDERS,
                     samples_per_revolution: float | None = None) -> np.ndarray:
    """Complex amplitude ``X`` of each engine order over the last ``revolutions`` crank
    revolutions of ``x``, ``x(t) ≈ Re(X e^{iωt})`` with t from the window's first sample
    (``revolutions`` None: the longest whole number of working cycles, two revolutions each; NaN
    if there is none).

    ``x`` is sampled at equal steps of time at constant speed (or of crank angle): one signal, or
    one column per signal. The result has one row per order: shape (orders,) or (orders,
    signals). ``samples_per_revolution`` (``60 / (rpm × step)``, need not be whole) defaults to
    ``len(x) / revolutions``: ``x`` is the window. The window's mean is removed. Where the window
    is a whole number of samples and every order a whole number of cycles in it, the order is its
    DFT bin (no leakage); otherwise the DFT is evaluated at the order's own frequency.
    """
    sums, n = _order_sums(x, revolutions, list(orders), samples_per_revolution)
    return 2.0 * sums / n


def order_amplitudes(x: np.ndarray, revolutions: int | None, orders=ORDERS,
                     samples_per_revolution: float | None = None) -> dict[float, float]:
    """Amplitude ``|X|`` of each engine order, by order, with the window rules of
    :func:`order_components`; for several signals each order's amplitude is an array over the
    columns."""
    orders = list(orders)
    sums, n = _order_sums(x, revolutions, orders, samples_per_revolution)
    return {float(order): (2.0 * np.abs(s) / n)[()] for order, s in zip(orders, sums)}