"""A run-up through fmpy's simulate_fmu that prints nothing but its result: 800 -> 1400 rpm in 2 s
on rigid ground (scene 1).

fmpy warns once for every input its table lacks ("Warning: missing input for variable ..."), and
the engine FMU has many (the speed, the load torque, the mount scales, the body points of scene 3).
The table below carries every input: each at its start value, and the speed as the run-up.

    python examples/fmpy_runup.py [FMU]
"""

import sys

import numpy as np
from fmpy import read_model_description, simulate_fmu

fmu = sys.argv[1] if len(sys.argv) > 1 else "dist/EngineMountChassis.fmu"
inputs = [v for v in read_model_description(fmu).modelVariables if v.causality == "input"]
table = np.zeros(2, dtype=[("time", np.float64)] + [(v.name, np.float64) for v in inputs])
table["time"] = [0.0, 2.0]
for v in inputs:
    table[v.name] = float(v.start)
table["rpm"] = [800.0, 1400.0]

result = simulate_fmu(fmu, stop_time=2.0, output_interval=1e-3, input=table,
                      output=["crankAngle", "mount[1].F[3]"])
revolutions = result["crankAngle"][-1] / (2 * np.pi)
print(f"{revolutions:.1f} revolutions of the crank (800 -> 1400 rpm in 2 s: on average 1100 rpm)")
