"""Writes the SYNTHETIC example measurement of this folder: the model's own order cuts of a car
whose parameters differ from the nominal (below), with 3 % noise and noise floors, as a test
system would export them (UFF 58 over rpm; the steering wheel in g RMS), and its mapping file.

    PYTHONPATH=python python examples/measurement/regenerate.py
"""

import pathlib

import numpy as np

from emc.testbench.synthetic import twin_measurement

# The "car": what a calibration of this measurement should find.
HIDDEN = {"mount[1].stiffnessScale": 1.2, "mount[3].stiffnessScale": 0.9,
          **{f"mount[{i}].dampingScale": 1.25 for i in range(1, 5)},
          "chassis.modalDampingScale": 0.8}

if __name__ == "__main__":
    here = pathlib.Path(__file__).parent
    twin_measurement(
        "dist/EngineMountChassis.fmu", here, HIDDEN,
        ["steeringWheel.a[3]", "seat.a[3]", "mount[1].F[3]"], [1.5, 2.0, 3.0],
        np.linspace(800.0, 2500.0, 18),
        {"steeringWheel.a[3]": "g", "seat.a[3]": "m/s^2", "mount[1].F[3]": "N"}, 0.03,
        {"steeringWheel.a[3]": 0.005, "seat.a[3]": 0.005, "mount[1].F[3]": 0.1},
        seed=2026, revolutions=4, amplitude="rms", name="runup_synthetic")
