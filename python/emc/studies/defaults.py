"""The studies' defaults and choices, in a module of their own so that the command line can
offer them without importing the studies' numerics (numpy, pandas, SALib, scipy)."""

from __future__ import annotations

import dataclasses
import math

# emc accuracy: the tolerances measured, one per decade, and the reference's.
DEFAULT_TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
REFERENCE_TOLERANCE = 1e-11
# The orders whose amplitudes the work-precision table compares by default (--order).
COMPARED_ORDERS = (1.5, 2.0, 3.0)

# emc doe / emc optimise: the design variables' default bounds and baselines, the objectives,
# the sampling methods.
DEFAULT_BOUNDS = {"stiffnessScale": (0.5, 2.0), "dampingScale": (0.5, 3.0), "rate": (0.5, 2.0)}
BASELINE = {"stiffnessScale": 1.0, "dampingScale": 1.0, "rate": 1.0}
OBJECTIVES = ("wheel-mean", "wheel-max", "weighted-mean")
METHODS = ("sobol", "lhs")


@dataclasses.dataclass(frozen=True)
class Limits:
    """What the engineer allows under the weight and the full-load torque (both senses)."""

    full_load_torque: float = 300.0     # N·m about the crank axis
    deflection: float = 6e-3            # m, any mount along any of its axes
    translation: float = 5e-3           # m, the powertrain's centre of gravity, any axis
    rotation: float = math.radians(1.5)  # rad, the powertrain, any Cardan angle

    def violations(self, static: dict) -> dict:
        """Each limit's use minus one (≤ 0: kept)."""
        return {"deflection": static["deflection"] / self.deflection - 1.0,
                "translation": static["translation"] / self.translation - 1.0,
                "rotation": static["rotation"] / self.rotation - 1.0}
