"""The fmpy co-simulation master of emc.running.coupling (engine FMU in scene 3 + body FMU) against the
monolithic scene 2: where plain Jacobi and Gauss-Seidel exchange break down, the linearly
implicit interface-Jacobian step stays stable and accurate; at a fine step all three agree."""

import pathlib
import subprocess
import sys

import numpy as np
import pytest

from emc.running.coupling import (ALGORITHMS, CoupledPair, Run, coupled, growth, largest_deviation,
                                  monolithic)

ROOT = pathlib.Path(__file__).resolve().parents[2]
STIFF = {f"mount[{i}].stiffnessScale": 20.0 for i in range(1, 5)}


@pytest.fixture(scope="module")
def fmus(fmu_path):
    body = ROOT / "dist" / "EngineMountBody.fmu"
    if not body.exists():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return fmu_path, body


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("coupling-cache")


def test_the_partial_derivatives_describe_the_interface(fmus, cache):
    """K is the mounts' tangent stiffness (block diagonal, one 3×3 block per mount, the
    configured rates at the static point), A = ∂a/∂F is symmetric positive definite (a mobility),
    and the measured ramp response of the linear body is the same at another time."""
    with CoupledPair(*fmus, 2000.0, t_end=0.02, cache_dir=cache) as pair:
        K, C = pair.mount_stiffness()
        A = pair.interface_compliance()
        S_r, S_v = pair.body_response(0.0, 1e-3)
        pair.run("gauss_seidel", 1e-3)
        S_r2, S_v2 = pair.body_response(0.02, 1e-3)
    for i in range(4):
        block = K[3 * i:3 * i + 3, 3 * i:3 * i + 3]
        np.testing.assert_allclose(np.diag(block), [-51.5e3, -36.6e3, -48.3e3], rtol=0.02)
        K[3 * i:3 * i + 3, 3 * i:3 * i + 3] = 0.0
    assert np.abs(K).max() == 0.0
    assert np.all(np.diag(C) < 0)
    np.testing.assert_allclose(A, A.T, atol=1e-12 * np.abs(A).max())
    assert np.linalg.eigvalsh(A).min() > 0
    np.testing.assert_allclose(S_r2, S_r, atol=1e-9 * np.abs(S_r).max())
    np.testing.assert_allclose(S_v2, S_v, atol=1e-9 * np.abs(S_v).max())


def test_stiff_mounts_at_1_ms_only_the_interface_jacobian_master_holds(fmus, cache):
    """Mounts 20 times stiffer (about 1000 N/mm), coupling step 1 ms, 2000 rpm: Jacobi and
    Gauss-Seidel are beyond the explicit interface limit 2c/k = 0.24 ms (see the user guide)
    and fail (the engine's integrator gives up on the grown jumps of its held inputs; were it
    to carry on, they would be off by far more than 20 %: 532 % and 357 % at 1100 rpm); the
    interface-Jacobian step stays stable and within 8 % of scene 2 in every order above 1 % of
    its group's largest (measured: 4.2 %)."""
    rpm = 2000.0
    reference = monolithic(fmus[0], rpm, 1e-4, 1.0, cache_dir=cache, engine_parameters=STIFF)
    for algorithm in ("jacobi", "gauss_seidel"):
        run = coupled(*fmus, rpm, algorithm, 1e-3, 1.0, cache_dir=cache, engine_parameters=STIFF)
        if run.ok:
            deviation, where = largest_deviation(reference, run, rpm, floor="group")
            assert growth(reference, run, rpm) > 5.0 or deviation > 0.2, f"{algorithm}: {where}"
    run = coupled(*fmus, rpm, "interface_jacobian", 1e-3, 1.0, cache_dir=cache,
                  engine_parameters=STIFF)
    assert run.ok, run.status
    assert growth(reference, run, rpm) < 1.1
    deviation, where = largest_deviation(reference, run, rpm, floor="group")
    assert deviation < 0.08, f"{where}: {deviation * 100:.2f} %"


def test_at_1_ms_the_interface_jacobian_master_is_within_2_percent(fmus, cache):
    """Production mounts, 1100 rpm, coupling step 1 ms, the default body damping: Jacobi off by
    more than 3 % (measured 4.0 %), Gauss-Seidel between (1.5 %), the interface-Jacobian step the
    closest and within 2 % (1.04 %), orders above 1 % of their group's largest. (With the body
    damped by the Adams table: 13 %, 8 % and 0.75 %.)"""
    rpm = 1100.0
    reference = monolithic(fmus[0], rpm, 1e-4, 1.0, cache_dir=cache)
    deviations = {}
    for algorithm in ALGORITHMS:
        run = coupled(*fmus, rpm, algorithm, 1e-3, 1.0, cache_dir=cache)
        assert run.ok, f"{algorithm}: {run.status}"
        deviations[algorithm], _ = largest_deviation(reference, run, rpm, floor="group")
    assert deviations["jacobi"] > 0.03, deviations
    assert deviations["interface_jacobian"] < deviations["gauss_seidel"] < deviations["jacobi"]
    assert deviations["interface_jacobian"] < 0.02, deviations


def test_at_0_1_ms_all_three_reproduce_scene_2(fmus, cache):
    """1100 rpm, coupling step 0.1 ms: every algorithm within 2 % of scene 2 in every order
    above 1 % of each signal's own largest (mount forces, steering-wheel acceleration)."""
    rpm = 1100.0
    reference = monolithic(fmus[0], rpm, 1e-4, 1.0, cache_dir=cache)
    for algorithm in ALGORITHMS:
        run = coupled(*fmus, rpm, algorithm, 1e-4, 1.0, cache_dir=cache)
        assert run.ok, f"{algorithm}: {run.status}"
        deviation, where = largest_deviation(reference, run, rpm)
        assert deviation < 0.02, f"{algorithm}, {where}: {deviation * 100:.2f} %"


def test_values_only_the_order_of_the_exchange_decides(fmus, cache):
    """Values only (no input derivatives: the FMUs continue them by their first-order hold),
    0.1 ms, 2000 rpm, 1 s from the coupled equilibrium. The engine's forces depend directly on the
    body motion it is given: setting the body's motion first and then reading the forces stays
    within 2 % of scene 2 (measured 0.75 %, like the FMI 3.0 pair); reading the forces first, as
    libcosim's fixed-step master does, passes forces of the engine's extrapolated motion (measured
    2.89 %, libcosim's own 2.82 %)."""
    rpm, H, t_end = 2000.0, 1e-4, 1.0
    reference = monolithic(fmus[0], rpm, H, t_end, cache_dir=cache)
    deviation = {}
    for motion_first in (True, False):
        with CoupledPair(*fmus, rpm, t_end=t_end, cache_dir=cache) as pair:
            e, b, vr, nf = pair.engine.slave, pair.body.slave, pair.vr, pair.n
            steps = int(round(t_end / H))
            samples = np.full((steps, len(pair.signals)), np.nan)
            for k in range(steps):
                e.doStep(k * H, H)
                b.doStep(k * H, H)
                if not motion_first:
                    forces = e.getReal(vr["F"])
                e.setReal(vr["re"], b.getReal(vr["r"]))
                e.setReal(vr["ve"], b.getReal(vr["v"]))
                if motion_first:
                    forces = e.getReal(vr["F"])
                b.setReal(vr["Fb"], list(forces))
                samples[k, :nf] = forces
                samples[k, nf:] = b.getReal(vr["sw"])
        run = Run(h=H, signals=dict(zip(pair.signals, samples.T)), wall=0.0, status="ok",
                  t_reached=t_end)
        deviation[motion_first], _ = largest_deviation(reference, run, rpm)
    print(f"motion first {deviation[True] * 100:.2f} %, forces first {deviation[False] * 100:.2f} %")
    assert deviation[True] < 0.02, deviation
    assert deviation[False] > 2 * deviation[True], deviation
