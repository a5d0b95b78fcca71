"""What each effect costs: CPU time per simulated second for each scene and effect set.

Each case runs a constant-speed point (fade-in, then a fixed simulated time) in this process
through fmpy; the CPU time covers the stepping only (not the instantiation, which may reduce the
chassis), including fmpy's per-step call overhead. The integrator counters come from the FMU's
``solver.*`` outputs.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from .runner import OperatingPoint, Runner

EFFECTS = ("gasForces", "massForces", "balanceShaft", "gyroscopic", "ringCarrier", "mountNonlinearity")


def effect_sets(scene: int) -> list[tuple[str, dict]]:
    """All effects on, then each switched off alone, then everything but gas and mass forces off;
    in scene 2 also the rigid chassis and explicit chassis mode cut-offs."""
    cases = [("all effects", {})]
    for e in EFFECTS:
        cases.append((f"without {e}", {f"effects.{e}": False}))
    cases.append(("gas + mass forces only", {f"effects.{e}": False for e in EFFECTS[2:]}))
    if scene == 2:
        cases.append(("without chassisFlexibility", {"effects.chassisFlexibility": False}))
        for cutoff in (60.0, 120.0, 400.0):
            cases.append((f"chassis cut-off {cutoff:g} Hz", {"chassis.modeCutoff": cutoff}))
    return cases


def measure(runner: Runner, rpm: float, seconds: float, parameters: dict, signal: str) -> dict:
    revolutions = max(2, int(round(seconds * rpm / 60 / 2)) * 2)
    # The stepping cost alone: a fade-in start (no periodic initialisation), 4 revolutions.
    point = OperatingPoint(rpm=rpm, revolutions=revolutions, settle_revolutions=4, periodic=False,
                           parameters=tuple(parameters.items()))
    result = runner.run_point(point, [signal])
    cpu, wall, simulated = result["cpu"], result["wall"], result["simulated"]
    counters = runner.slave.getInteger([runner.vr[n] for n in (
        "solver.steps", "solver.rhsEvaluations", "solver.jacobianEvaluations", "solver.factorizations")])
    x = result["samples"][:, 0]
    return {"cpu_s_per_s": cpu / simulated, "realtime_factor": simulated / wall,
            "steps_per_s": counters[0] / simulated, "rhs_per_s": counters[1] / simulated,
            "jac": counters[2], "lu": counters[3], "rms": float(np.std(x))}


def effects_table(fmu_path: str, scenes=(1,), rpm: float = 2000.0, seconds: float = 1.0,
                  signal: str = "mount[1].F[3]") -> pd.DataFrame:
    rows = []
    with Runner(fmu_path) as runner:
        for scene in scenes:
            for name, params in effect_sets(scene):
                row = measure(runner, rpm, seconds, {"scene": scene, **params}, signal)
                rows.append({"scene": scene, "effects": name, **row})
    return pd.DataFrame(rows)


REALTIME_CASES = (
    ("scene 1 (ground)", {"scene": 1}),
    ("scene 2 (body, automatic cut-off)", {"scene": 2}),
    ("scene 2, 1 kHz body", {"scene": 2, "chassis.modeCutoff": 1000.0}),
)


def realtime_table(fmu_path: str, rpm: float = 2000.0, seconds: float = 1.0, repeats: int = 3,
                   step: float = 1e-3) -> pd.DataFrame:
    """The FMU's own speed as a host sees it: after a 0.2 s settling phase, ``repeats`` windows of
    ``seconds`` of fmpy's low-level ``doStep`` + ``getReal`` (every Real output, every step) at a
    fixed communication step; the wall time of that loop only (no ``simulate_fmu`` overhead).
    Reports the range over the windows."""
    rows = []
    with Runner(fmu_path) as runner:
        outputs = [runner.vr[n] for n in runner.outputs()]
        for name, params in REALTIME_CASES:
            runner._start({"rpm": rpm, **params})
            t = 0.0
            n_settle, n_window = int(round(0.2 / step)), int(round(seconds / step))
            for k in range(n_settle):
                runner.slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
                t = (k + 1) * step
            factors = []
            for _ in range(repeats):
                started = time.perf_counter()
                for _ in range(n_window):
                    runner.slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
                    t += step
                    runner.slave.getReal(outputs)
                factors.append(seconds / (time.perf_counter() - started))
            steps = runner.slave.getInteger([runner.vr["solver.steps"]])[0]
            rows.append({"case": name, "rpm": rpm, "outputs read": len(outputs),
                         "x realtime min": min(factors), "x realtime max": max(factors),
                         "us per doStep+getReal": 1e6 / max(factors) * step,
                         "integrator steps per s": steps / t})
    return pd.DataFrame(rows)
