"""The error against the tolerance for three settings of the absolute tolerance, through the
packaged FMU: 2000 rpm from the static start, 0.5 s, 1 ms communication step; relative L2 error
of the twelve mount forces (scene 2: and of the steering-wheel acceleration) against an
rtol 1e-11 / atol 1e-16 reference; the tolerance set as solver.relTol; steps in brackets.
Columns per scene: solver.absTol 1e-8 (the former default), absTol = rtol·1e-3, and absTol 0
(follows the relative tolerance, the default). Prints a Markdown table (the one in the user
guide's "What accuracy costs"); a few seconds.

Usage: PYTHONPATH=python .venv/bin/python scripts/tolerance_table.py dist/EngineMountChassis.fmu
"""
import sys

from emc.studies import accuracy
from emc.running.runner import Runner

FORCES = [f"mount[{i}].F[{j}]" for i in range(1, 5) for j in range(1, 4)]
WHEEL = [f"steeringWheel.a[{j}]" for j in range(1, 4)]
SCENARIO = accuracy.Scenario("2000 rpm", 2000.0, 2000.0, 0.5)
COLUMNS = (("1e-8 (the former default)", lambda rtol: {"solver.absTol": 1e-8}),
           ("= rtol·1e-3", lambda rtol: {"solver.absTol": rtol * 1e-3}),
           ("0 (follows, the default)", lambda rtol: {}))


def cell(run, reference, scene):
    f = accuracy.relative_l2(run["samples"][:, :12], reference["samples"][:, :12])
    if scene == 1:
        return f"{f:.1e} ({run['steps']})"
    w = accuracy.relative_l2(run["samples"][:, 12:], reference["samples"][:, 12:])
    return f"{f:.1e} / {w:.0e} ({run['steps']})"


def main(fmu):
    rows = {}
    with Runner(fmu) as runner:
        for scene in (1, 2):
            tight = {"scene": scene, "solver.relTol": 1e-11, "solver.absTol": 1e-16}
            reference = accuracy.run(runner, SCENARIO, tight, FORCES + WHEEL, None)
            for rtol in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9):
                for name, extra in COLUMNS:
                    parameters = {"scene": scene, "solver.relTol": rtol, **extra(rtol)}
                    run = accuracy.run(runner, SCENARIO, parameters, FORCES + WHEEL, None)
                    rows.setdefault(rtol, []).append(cell(run, reference, scene))
    print("| `solver.relTol` | " + " | ".join(f"scene {s}, absTol {name}" for s in (1, 2)
                                             for name, _ in COLUMNS) + " |")
    print("|---" * (2 * len(COLUMNS) + 1) + "|")
    for rtol, cells in rows.items():
        print(f"| {rtol:.0e} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1])
