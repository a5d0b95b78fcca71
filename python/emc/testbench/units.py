"""Units and amplitude conventions of measured data, turned into the FMU's: SI, 0-peak.

A test system writes an order cut in g, m/s², mm/s or N, as an RMS, 0-peak or peak-peak value.
The model's outputs are accelerations in m/s² and forces in N, and its order amplitudes are
0-peak (:mod:`emc.spectra`). A velocity or displacement measured on an order is harmonic at that
order's frequency ω, so it converts to acceleration exactly: ``a = iω v = -ω² x``.
"""

from __future__ import annotations

import numpy as np

G = 9.80665  # m/s², standard gravity (ISO 80000-3)

# Each unit: (quantity, factor to SI).
UNITS = {
    "m/s^2": ("acceleration", 1.0), "mm/s^2": ("acceleration", 1e-3), "g": ("acceleration", G),
    "m/s": ("velocity", 1.0), "mm/s": ("velocity", 1e-3),
    "m": ("displacement", 1.0), "mm": ("displacement", 1e-3), "um": ("displacement", 1e-6),
    "N": ("force", 1.0), "kN": ("force", 1e3),
}
# What an FMU output's unit (model description) measures.
OUTPUT_QUANTITY = {"m/s2": "acceleration", "m/s^2": "acceleration", "N": "force"}
# How many time derivatives turn a quantity into acceleration (force stays force).
DERIVATIVES = {"acceleration": 0, "velocity": 1, "displacement": 2, "force": 0}
# UFF 58 record 9 specific data types and what they measure.
UFF_QUANTITY = {8: "displacement", 9: "force", 11: "velocity", 12: "acceleration", 13: "force"}
# To 0-peak.
CONVENTIONS = {"peak": 1.0, "0-peak": 1.0, "rms": np.sqrt(2.0), "peak-peak": 0.5}


def normalise(label: str) -> str:
    """A unit as written by people and test systems, in the spelling of :data:`UNITS`:
    ``m/s²``, ``m/s2``, ``M/S^2`` → ``m/s^2``; ``µm`` → ``um``; ``G`` → ``g``."""
    text = label.strip().replace(" ", "").replace("²", "^2").replace("µ", "u").replace("μ", "u")
    for known in UNITS:
        if text.lower() == known.lower() or text.lower() == known.lower().replace("^", ""):
            return known
    return text


def known(label: str) -> bool:
    return normalise(label) in UNITS


def quantity(label: str) -> str:
    return UNITS[normalise(label)][0]


def frf_units(label: str) -> tuple[str, str] | None:
    """``g/N``, ``m/s^2/N``, ``(m/s²)/N`` → (response unit, force unit); None if not a motion
    over a force."""
    text = label.strip().replace("(", "").replace(")", "")
    numerator, slash, denominator = text.rpartition("/")
    if not slash or not known(numerator) or not known(denominator):
        return None
    if quantity(denominator) != "force" or quantity(numerator) == "force":
        return None
    return normalise(numerator), normalise(denominator)


def to_si_acceleration(values, unit: str, omega) -> np.ndarray:
    """``values`` (complex or real) in ``unit`` as the output's quantity in SI: accelerations
    from velocities (× iω) and displacements (× -ω²) at the angular frequencies ``omega``; forces
    stay forces. Real values (amplitudes) convert by the modulus of the factor."""
    kind, factor = UNITS[normalise(unit)]
    values = np.asarray(values)
    scale = factor * (1j * np.asarray(omega, dtype=float)) ** DERIVATIVES[kind]
    if not np.iscomplexobj(values):
        scale = np.abs(scale)
    return values * scale
