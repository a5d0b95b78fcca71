"""Human exposure to the vibration the model computes: frequency-weighted accelerations.

- Seat (whole-body vibration, ISO 2631-1:1997, seated person): weighting Wk for the vertical axis,
  Wd for the horizontal ones, and the vibration total value a_v = sqrt(sum (k a_w)^2) with the
  comfort multiplying factors k = 1 for the three seat-surface axes (§8.2.2; for health §7.2.3
  uses 1.4 on x and y, given too).
- Steering wheel (hand-transmitted vibration, ISO 5349-1:2001): weighting Wh on each axis and
  the vibration total value a_hv = sqrt(a_hwx^2 + a_hwy^2 + a_hwz^2).

The weightings are the standards' analogue filters (ISO 2631-1 Annex A, ISO 5349-1 Annex A,
ISO 8041): band limiting (2nd-order Butterworth high and low pass, Q = 1/sqrt 2), a-v transition
and upward step, evaluated as |H(j 2 pi f)|. They act on the amplitude spectrum of a stationary
window (periodic over whole revolutions, so Parseval is exact): a_w^2 = sum (|W(f)| a_f)^2 / 2,
over the analysed band (up to 6.5 engine orders).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

# f1, f2 (band limits), f3, f4, Q4 (a-v transition), f5, Q5, f6, Q6 (upward step; None: none)
WEIGHTINGS = {
    "Wk": (0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": (0.4, 100.0, 2.0, 2.0, 0.63, None, None, None, None),
    "Wh": (6.310, 1258.9, 15.915, 15.915, 0.64, None, None, None, None),
}


def weighting(name: str, f) -> np.ndarray:
    """|W(j 2 pi f)| of weighting ``name`` at frequencies ``f`` (Hz)."""
    f1, f2, f3, f4, q4, f5, q5, f6, q6 = WEIGHTINGS[name]
    s = 2j * np.pi * np.asarray(f, dtype=float)
    w1, w2, w3, w4 = (2 * np.pi * x for x in (f1, f2, f3, f4))
    q1 = 1 / math.sqrt(2)
    high = s * s / (s * s + w1 * s / q1 + w1 * w1)
    low = w2 * w2 / (s * s + w2 * s / q1 + w2 * w2)
    transition = (1 + s / w3) / (1 + s / (q4 * w4) + (s / w4) ** 2)
    h = high * low * transition
    if f5 is not None:
        w5, w6 = 2 * np.pi * f5, 2 * np.pi * f6
        h = h * (1 + s / (q5 * w5) + (s / w5) ** 2) / (1 + s / (q6 * w6) + (s / w6) ** 2) * (w5 / w6) ** 2
    return np.abs(h)


def weighted_rms(frequency, amplitude, name: str) -> float:
    """Weighted RMS of a signal given by its one-sided amplitude spectrum (mean excluded)."""
    f = np.asarray(frequency, dtype=float)
    a = np.asarray(amplitude, dtype=float)
    keep = f > 0
    return float(np.sqrt(np.sum((weighting(name, f[keep]) * a[keep]) ** 2) / 2))


SEAT = ["seat.a[1]", "seat.a[2]", "seat.a[3]"]
WHEEL = ["steeringWheel.a[1]", "steeringWheel.a[2]", "steeringWheel.a[3]"]


def comfort_table(spectra: pd.DataFrame) -> pd.DataFrame:
    """Per case and speed point: weighted seat and steering-wheel accelerations (m/s^2 RMS) and
    their vibration total values, for the signals the sweep recorded (missing ones are left out)."""
    rows = []
    for (case, rpm), point in spectra.groupby(["case", "rpm"]):
        row = {"case": case, "rpm": rpm}
        spectra_of = {s: g for s, g in point.groupby("signal")}
        if all(s in spectra_of for s in SEAT):
            for axis, s, w in zip("xyz", SEAT, ("Wd", "Wd", "Wk")):
                row[f"seat_aw{axis}"] = weighted_rms(spectra_of[s].frequency, spectra_of[s].amplitude, w)
            row["seat_av_comfort"] = math.sqrt(sum(row[f"seat_aw{a}"] ** 2 for a in "xyz"))
            row["seat_av_health"] = math.sqrt((1.4 * row["seat_awx"]) ** 2 + (1.4 * row["seat_awy"]) ** 2
                                              + row["seat_awz"] ** 2)
        if all(s in spectra_of for s in WHEEL):
            for axis, s in zip("xyz", WHEEL):
                row[f"wheel_ahw{axis}"] = weighted_rms(spectra_of[s].frequency, spectra_of[s].amplitude, "Wh")
            row["wheel_ahv"] = math.sqrt(sum(row[f"wheel_ahw{a}"] ** 2 for a in "xyz"))
        if len(row) > 2:
            rows.append(row)
    return pd.DataFrame(rows)
