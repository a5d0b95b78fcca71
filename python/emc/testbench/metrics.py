"""Correlation metrics of measured against simulated data (the guide's chapter "Does the model
match my car?" defines each).

Order cuts, per channel (one output, one order), over the speeds where the measured level is
above the channel's noise floor:

- level error ``L = 20 log10(|simulated| / |measured|)`` in dB at each speed; its mean (the bias),
  its largest magnitude (with its sign and speed) and its RMS;
- the peak: the speed and level of the largest measured and of the largest simulated amplitude;
  the differences (simulated minus measured) in rpm and dB;
- the share of measured points inside the simulated damping band;
- the **score**: the share of the speeds, in %, where the model is within ±3 dB of the
  measurement (3 dB: a factor √2, half the width of a factor-2 damping band).

FRFs: the FRAC (frequency response assurance criterion; Heylen, Lammens & Sas, *Modal Analysis
Theory and Testing*, 1998), ``|Σ H_m H_a*|² / (Σ|H_m|² Σ|H_a|²)``, on the complex FRFs, or on
their magnitudes where the measurement has none.

Modes: the MAC (modal assurance criterion; Allemang & Brown 1982), ``|φ_mᴴ φ_a|² / (φ_mᴴ φ_m
φ_aᴴ φ_a)``, every measured shape against every model mode, the pairs chosen to maximise the
summed MAC (each mode used once).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

SCORE_TOLERANCE_DB = 3.0
# A pair of modes with a MAC below this is listed but not called a match.
PAIRED_MAC = 0.6


def level_error_db(simulated, measured) -> np.ndarray:
    return 20.0 * np.log10(np.abs(simulated) / np.abs(measured))


def order_cut_metrics(rpm, measured, simulated, floor=None, low=None, high=None) -> dict:
    """The metrics of one order cut (see the module's documentation). ``measured`` and
    ``simulated`` at the speeds ``rpm`` (complex or amplitudes); ``floor``: the noise floor at
    each speed (points at or below it are left out); ``low``, ``high``: the simulated amplitudes
    at the band's bounds."""
    rpm = np.asarray(rpm, dtype=float)
    m, s = np.abs(np.asarray(measured)), np.abs(np.asarray(simulated))
    valid = m > (0.0 if floor is None else np.asarray(floor, dtype=float))
    valid &= s > 0.0
    out = {"points": int(len(rpm)), "points_used": int(valid.sum())}
    if not valid.any():
        return {**out, "mean_db": np.nan, "rms_db": np.nan, "max_db": np.nan, "max_db_rpm": np.nan,
                "peak_rpm_measured": np.nan, "peak_rpm_simulated": np.nan, "peak_rpm_diff": np.nan,
                "peak_db_diff": np.nan, "inside_band": np.nan, "score": np.nan}
    err = level_error_db(s[valid], m[valid])
    worst = int(np.argmax(np.abs(err)))
    r = rpm[valid]
    k_m, k_s = int(np.argmax(m[valid])), int(np.argmax(s[valid]))
    out.update({
        "mean_db": float(np.mean(err)), "rms_db": float(np.sqrt(np.mean(err**2))),
        "max_db": float(err[worst]), "max_db_rpm": float(r[worst]),
        "peak_rpm_measured": float(r[k_m]), "peak_rpm_simulated": float(r[k_s]),
        "peak_rpm_diff": float(r[k_s] - r[k_m]),
        "peak_db_diff": float(20.0 * np.log10(s[valid][k_s] / m[valid][k_m])),
        "score": float(100.0 * np.mean(np.abs(err) <= SCORE_TOLERANCE_DB)),
    })
    if low is not None and high is not None:
        lo, hi = np.abs(np.asarray(low))[valid], np.abs(np.asarray(high))[valid]
        inside = (m[valid] >= np.minimum(lo, hi)) & (m[valid] <= np.maximum(lo, hi))
        out["inside_band"] = float(100.0 * np.mean(inside))
    else:
        out["inside_band"] = np.nan
    return out


def frac(measured, simulated) -> float:
    """FRAC of two FRFs on the same frequencies (complex; magnitudes if either is real)."""
    a, b = np.asarray(measured), np.asarray(simulated)
    if not (np.iscomplexobj(a) and np.iscomplexobj(b)):
        a, b = np.abs(a), np.abs(b)
    return float(np.abs(np.vdot(b, a)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real))


def mac_matrix(measured: np.ndarray, model: np.ndarray) -> np.ndarray:
    """MAC of every measured shape (rows of ``measured``: modes × DOFs) against every model
    shape (rows of ``model``)."""
    a, b = np.asarray(measured), np.asarray(model)
    cross = np.abs(np.conj(a) @ b.T) ** 2
    return cross / np.outer(np.sum(np.abs(a) ** 2, axis=1), np.sum(np.abs(b) ** 2, axis=1))


def pair_modes(mac: np.ndarray) -> list[tuple[int, int]]:
    """(measured mode, model mode) pairs, 0-based, that maximise the summed MAC, each mode in
    at most one pair."""
    rows, cols = linear_sum_assignment(-np.asarray(mac))
    return [(int(r), int(c)) for r, c in zip(rows, cols)]
