"""The engine FMU (scene 3) and the body FMU in a larger model: the SSP system both FMUs form,
loaded and run by libcosim, against the monolithic scene 2."""

import pathlib
import subprocess
import sys

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from emc.ssp import connections, write_ssp

ROOT = pathlib.Path(__file__).resolve().parents[2]
SIGNALS = [f"mount[{i}].F[{j}]" for i in range(1, 5) for j in range(1, 4)]
COMFORT = [f"steeringWheel.a[{j}]" for j in range(1, 4)]


@pytest.fixture(scope="session")
def body_fmu_path(fmu_path) -> pathlib.Path:
    path = ROOT / "dist" / "EngineMountBody.fmu"
    if not path.exists():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return path


def order_amplitudes(x, h, rpm, revolutions, orders):
    """Amplitude of each engine order over the last ``revolutions`` of ``x`` (sampled every ``h``
    s), by a DFT at the order's frequency over the samples spanning those revolutions."""
    n = int(round(revolutions * 60.0 / rpm / h))
    t = np.arange(n) * h
    tail = np.asarray(x)[-n:]
    return np.array([2.0 / n * abs(np.sum(tail * np.exp(-2j * np.pi * o * rpm / 60.0 * t)))
                     for o in orders])


ORDERS = np.arange(1, 13) * 0.5


def scene_2(fmu_path, rpm, h, t_end, cache, rel_tol):
    start = {"scene": 2, "rpm": rpm, "chassis.cacheDir": str(cache), "solver.relTol": rel_tol}
    r = simulate_fmu(str(fmu_path), stop_time=t_end, output_interval=h, start_values=start,
                     output=SIGNALS + COMFORT)
    return {name: r[name][1:] for name in SIGNALS + COMFORT}


def split_in_libcosim(ssp, rpm, h, t_end):
    from libcosimpy.CosimEnums import CosimLogLevel
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp), step_size=int(round(h * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    engine = execution.slave_index_from_instance_name("engine")
    body = execution.slave_index_from_instance_name("body")
    vr_engine = {v.name.decode(): v.reference for v in execution.slave_variables(engine)}
    vr_body = {v.name.decode(): v.reference for v in execution.slave_variables(body)}
    execution.real_initial_value(engine, vr_engine["rpm"], rpm)
    forces, comfort = [], []
    for _ in range(int(round(t_end / h))):
        assert execution.step()
        forces.append(observer.last_real_values(engine, [vr_engine[n] for n in SIGNALS]))
        comfort.append(observer.last_real_values(body, [vr_body[n] for n in COMFORT]))
    out = dict(zip(SIGNALS, np.array(forces).T))
    out.update(zip(COMFORT, np.array(comfort).T))
    return out


def test_the_ssp_connects_every_mount_both_ways(fmu_path, body_fmu_path):
    engine = {v.name: v for v in read_model_description(str(fmu_path)).modelVariables}
    body = {v.name: v for v in read_model_description(str(body_fmu_path)).modelVariables}
    models = {"engine": engine, "body": body}
    links = connections()
    assert len(links) == 36
    for a, ca, b, cb in links:
        assert models[a][ca].causality == "output" and models[b][cb].causality == "input"
        assert models[a][ca].unit == models[b][cb].unit


@pytest.mark.parametrize("rpm", [1100.0, 2000.0])
def test_two_fmus_from_the_ssp_in_libcosim_reproduce_scene_2(fmu_path, body_fmu_path, tmp_path, rpm):
    """Order amplitudes of the mount forces and the steering-wheel acceleration (orders above 1 %
    of each signal's largest) within 2 % of scene 2, at a 0.1 ms coupling step."""
    h, t_end, revolutions, rel_tol = 1e-4, 1.2, 8, 1e-8
    cache = tmp_path / "cache"
    parameters = {"chassis.cacheDir": str(cache), "solver.relTol": rel_tol}
    ssp = write_ssp(fmu_path, body_fmu_path, tmp_path / "EngineInBody.ssp",
                    engine_parameters=parameters, body_parameters={"chassis.cacheDir": str(cache)},
                    step_size=h, stop_time=t_end)
    split = split_in_libcosim(ssp, rpm, h, t_end)
    mono = scene_2(fmu_path, rpm, h, t_end, cache, rel_tol)
    worst = 0.0
    for name in SIGNALS + COMFORT:
        a = order_amplitudes(mono[name], h, rpm, revolutions, ORDERS)
        b = order_amplitudes(split[name], h, rpm, revolutions, ORDERS)
        for o, x, y in zip(ORDERS, a, b):
            if x < 0.01 * a.max():
                continue
            rel = abs(y - x) / x
            worst = max(worst, rel)
            assert rel < 0.02, f"{name} order {o}: split {y:.5g} vs scene 2 {x:.5g}"
    print(f"{rpm} rpm: largest order deviation {worst * 100:.2f} %")
