"""How slow a run-up must be to give the order amplitudes of stationary points: run-ups
1000 -> 2000 rpm in 12 s and 40 s (83 and 25 rpm/s, from the periodic steady state at 1000 rpm,
order-tracked in 4-revolution blocks) against stationary points on their periodic steady state
at 1100 ... 1900 rpm; prints the deviation of the 1.5 order in per cent, per speed, for the
vertical force of mount 1 and the steering wheel's vertical acceleration (the guide's "Run-ups
and order tracking"; python/tests/test_cli.py asserts the mount force at 83 rpm/s).

Usage: PYTHONPATH=python .venv/bin/python scripts/runup_vs_stationary.py [FMU] [--set NAME=VALUE ...]
"""

import argparse
import pathlib
import tempfile

import numpy as np
import pandas as pd

from emc.cli import main as emc
from emc.running.sweep import run_sweep, speed_points

SIGNALS = ["mount[1].F[3]", "steeringWheel.a[3]"]
SPEEDS = tuple(float(r) for r in range(1100, 2000, 100))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("fmu", nargs="?", default="dist/EngineMountChassis.fmu")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="FMU start value of every run (e.g. configFile=vehicle_adams_damping.json)")
    args = parser.parse_args()
    settings = tuple([("scene", 2)] + [tuple(s.split("=", 1)) for s in args.set])
    points = [p for r in SPEEDS for p in speed_points(r, r, 1, parameters=settings)]
    stationary, _ = run_sweep(args.fmu, points, SIGNALS, parallel=False, progress=False)
    stationary = stationary[np.isclose(stationary.order, 1.5)]
    print("run-up | rate | signal | " + " | ".join(f"{r:.0f}" for r in SPEEDS))
    for duration in (12, 40):
        with tempfile.TemporaryDirectory() as out:
            sets = [a for s in args.set for a in ("--set", s)]
            code = emc(["runup", "--fmu", args.fmu, "--rpm", "1000", "2000", "--duration",
                        str(duration), "--step", "5e-4", "--quiet", "--out", out, *sets]
                       + [a for s in SIGNALS for a in ("--signal", s)])
            if code:
                raise SystemExit(code)
            tracked = pd.read_csv(pathlib.Path(out) / "runup_orders.csv")
        tracked = tracked[np.isclose(tracked.order, 1.5)]
        for signal in SIGNALS:
            t = tracked[tracked.signal == signal].sort_values("rpm")
            s = stationary[stationary.signal == signal].set_index("rpm").amplitude
            deviation = [100 * (np.interp(r, t.rpm, t.amplitude) / s[r] - 1) for r in SPEEDS]
            print(f"{duration} s | {1000 / duration:.0f} rpm/s | {signal} | "
                  + " | ".join(f"{d:+.1f} %" for d in deviation))


if __name__ == "__main__":
    main()
