"""The packaged FMU as other tools see it: fmpy (validation, simulate_fmu) and DNV's libcosim."""

import json
import pathlib
import re
import shutil
import subprocess
import tempfile
import zipfile

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from emc.signals.spectra import order_amplitudes

ROOT = pathlib.Path(__file__).resolve().parents[2]

FMI2_FUNCTIONS = {
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate",
    "fmi2FreeInstance", "fmi2SetupExperiment", "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset", "fmi2GetReal", "fmi2GetInteger",
    "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean",
    "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative", "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives",
    "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus", "fmi2GetRealStatus", "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus", "fmi2GetStringStatus",
}

# The same library serves the FMI 3.0 FMU: build.rs exports the functions listed there too.
FMI3_FUNCTIONS = set(re.findall(r'"(fmi3\w+)"', (ROOT / "build" / "fmi3_description.rs").read_text()))

MOUNT_FORCES = [f"mount[{i}].F[{j}]" for i in range(1, 5) for j in range(1, 4)]


def test_fmpy_validation_reports_no_problems(fmu_path):
    assert validate_fmu(str(fmu_path)) == []


def test_library_exports_exactly_the_fmi2_and_fmi3_functions(fmu_path):
    with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(fmu_path) as z:
        so = z.extract("binaries/linux64/EngineMountChassis.so", tmp)
        out = subprocess.run(["nm", "-D", "--defined-only", so], capture_output=True, text=True, check=True)
    exported = {line.split()[-1] for line in out.stdout.splitlines() if line.strip()}
    assert exported == FMI2_FUNCTIONS | FMI3_FUNCTIONS


def test_windows_dll_exports_exactly_the_fmi2_and_fmi3_functions_and_needs_system_dlls_only(fmu_path):
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    if objdump is None:
        pytest.skip("mingw-w64 binutils are not installed (scripts/setup.sh installs them)")
    with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(fmu_path) as z:
        dll = z.extract("binaries/win64/EngineMountChassis.dll", tmp)
        out = subprocess.run([objdump, "-p", dll], capture_output=True, text=True, check=True).stdout
    table = out.split("[Ordinal/Name Pointer] Table", 1)[1]
    exported = set(re.findall(r"^\s*\[\s*\d+\]\s+(\S+)$", table, re.MULTILINE))
    assert exported == FMI2_FUNCTIONS | FMI3_FUNCTIONS
    imported = {name.lower() for name in re.findall(r"DLL Name: (\S+)", out)}
    system = {"kernel32.dll", "ntdll.dll", "msvcrt.dll", "ws2_32.dll", "userenv.dll", "bcrypt.dll",
              "bcryptprimitives.dll", "advapi32.dll", "ole32.dll", "combase.dll", "shell32.dll",
              "dbghelp.dll", "api-ms-win-core-synch-l1-2-0.dll"}
    assert imported <= system, imported - system


def test_package_layout(fmu_path):
    with zipfile.ZipFile(fmu_path) as z:
        names = set(z.namelist())
    assert {"modelDescription.xml", "binaries/linux64/EngineMountChassis.so",
            "binaries/win64/EngineMountChassis.dll",
            "documentation/index.html", "resources/vehicle.json"} <= names
    md = read_model_description(str(fmu_path))
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.coSimulation.canInterpolateInputs
    rpm = next(v for v in md.modelVariables if v.name == "rpm")
    assert rpm.declaredType is None and rpm.unit == "rpm"
    unit = next(u for u in md.unitDefinitions if u.name == "rpm")
    assert unit.baseUnit.rad == 1 and unit.baseUnit.s == -1
    assert unit.baseUnit.factor == pytest.approx(np.pi / 30)


# DESIGN §8: the default powertrain (engine + gearbox) weighs 180 kg; the default configuration is
# tuned to exactly that budget, and its gravity is standard gravity.
POWERTRAIN_MASS = 180.0


def config_gravity() -> float:
    return json.loads((ROOT / "resources" / "vehicle.json").read_text())["gravity"]


def test_simulate_rpm_ramp_ground_scene(fmu_path):
    signals = np.array([(0.0, 800.0), (2.0, 2500.0)], dtype=[("time", np.float64), ("rpm", np.float64)])
    result = simulate_fmu(str(fmu_path), stop_time=2.0, output_interval=1e-3, input=signals,
                          output=MOUNT_FORCES + ["crankAngle", "powertrain.r[3]"])
    assert len(result) == 2001
    for name in result.dtype.names:
        assert np.all(np.isfinite(result[name])), name
    vertical = sum(result[f"mount[{i}].F[3]"][0] for i in range(1, 5))
    # static equilibrium at t = 0: the mounts carry the powertrain's weight (force on the ground side)
    assert vertical == pytest.approx(-POWERTRAIN_MASS * config_gravity(), rel=1e-3)
    # the engine really runs: crank angle integrates the ramp
    omega = np.interp(result["time"], signals["time"], signals["rpm"]) * np.pi / 30
    expected = np.trapezoid(omega, result["time"])
    assert result["crankAngle"][-1] == pytest.approx(expected, rel=1e-3)
    # and the mount forces vibrate
    assert np.std(result["mount[1].F[3]"][500:]) > 1.0


def test_libcosim_gets_the_same_outputs_as_fmpy(fmu_path):
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    md = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    names = MOUNT_FORCES + ["crankAngle"]
    steps, h = 100, 1e-3

    execution = CosimExecution.from_step_size(step_size=int(h * 1e9))
    slave = CosimLocalSlave(fmu_path=str(fmu_path), instance_name="engine")
    index = execution.add_local_slave(local_slave=slave)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    execution.real_initial_value(slave_index=index, variable_reference=vr["rpm"], value=1500.0)
    cosim = []
    for _ in range(steps):
        assert execution.step()
        cosim.append(observer.last_real_values(slave_index=index, variable_references=[vr[n] for n in names]))
    cosim = np.array(cosim)

    result = simulate_fmu(str(fmu_path), stop_time=steps * h, output_interval=h,
                          start_values={"rpm": 1500.0}, output=names)
    fmpy_values = np.array([[row[n] for n in names] for row in result[1:]])
    scale = np.max(np.abs(fmpy_values))
    np.testing.assert_allclose(cosim, fmpy_values, rtol=0, atol=1e-9 * scale)
    assert CosimVariableType.REAL is not None


COMFORT = [f"steeringWheel.a[{i}]" for i in range(1, 4)] + [f"seat.a[{i}]" for i in range(1, 4)]


def test_simulate_hybrid_scene_with_fmpy(fmu_path, tmp_path):
    """Scene 2: engine in the elastic chassis, the reduced chassis cached in a directory of its own."""
    start = {"scene": 2, "rpm": 1800.0, "chassis.cacheDir": str(tmp_path / "cache")}
    result = simulate_fmu(str(fmu_path), stop_time=0.2, output_interval=1e-3, start_values=start,
                          output=MOUNT_FORCES + COMFORT)
    assert len(result) == 201
    for name in result.dtype.names:
        assert np.all(np.isfinite(result[name])), name
    # static equilibrium of engine and chassis together: the mounts carry the powertrain's weight
    vertical = sum(result[f"mount[{i}].F[3]"][0] for i in range(1, 5))
    assert vertical == pytest.approx(-POWERTRAIN_MASS * config_gravity(), rel=1e-3)
    # at rest the body does not accelerate; running, the steering wheel and the seat vibrate
    for name in COMFORT:
        assert abs(result[name][0]) < 1e-6, name
    assert np.std(result["steeringWheel.a[3]"][100:]) > 1e-3
    assert np.std(result["seat.a[3]"][100:]) > 1e-4
    # the reduction was cached for the next instantiation
    assert list((tmp_path / "cache").glob("cms-*.json"))


def test_comfort_outputs_are_declared_in_g_display_units(fmu_path):
    md = read_model_description(str(fmu_path))
    by_name = {v.name: v for v in md.modelVariables}
    for name in COMFORT:
        v = by_name[name]
        assert v.causality == "output" and v.unit == "m/s2" and v.displayUnit == "g"
    scene = by_name["scene"]
    assert scene.max == "3" or scene.max == 3
    for name in ["chassis.modeCutoff", "chassis.maxModes", "chassis.stiffeningBar",
                 "chassis.cacheEnabled", "chassis.cacheDir"]:
        assert by_name[name].causality == "parameter", name


@pytest.mark.parametrize("config", ["vehicle.json", "vehicle_i4.json"])
def test_inline_three_and_inline_four_through_the_fmu(fmu_path, config):
    """The shipped inline-4 runs through the packaged FMU: its mount forces carry the even orders
    of a four-cylinder four-stroke (2nd dominant, no 1.5), the inline-3's the 1.5 order."""
    rpm, spr, revs = 2000.0, 72, 8
    t_rev = 60.0 / rpm
    settle = 0.3
    result = simulate_fmu(str(fmu_path), stop_time=settle + revs * t_rev, output_interval=t_rev / spr,
                          start_values={"rpm": rpm, "configFile": config, "engine.load": 1.0},
                          output=["mount[1].F[3]"])
    force = result["mount[1].F[3]"]
    window = force[-revs * spr:]
    amp = order_amplitudes(window, revs, [1.5, 2.0])
    if config == "vehicle_i4.json":
        assert amp[2.0] > 20 * amp[1.5], amp
    else:
        assert amp[1.5] > 5 * amp[2.0], amp


def test_libcosim_run_up_with_rpm_set_at_every_step(fmu_path):
    """libcosim has no input derivatives: a master that computes the engine speed sets rpm at
    every communication step. The FMU holds the first two values and then continues their slope
    (user guide, "Inputs between communication points"): the crank angle integrates the ramp up to
    the analytic lag of those two held steps and of the speed follower, a (h² + 4 h τ + τ²)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    md = read_model_description(str(fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    tau = next(float(v.start) for v in md.modelVariables if v.name == "crank.speedTimeConstant")
    h, steps = 1e-3, 500
    rpm0, slope = 800.0, 2000.0  # rpm, rpm/s
    execution = CosimExecution.from_step_size(step_size=int(h * 1e9))
    index = execution.add_local_slave(local_slave=CosimLocalSlave(fmu_path=str(fmu_path), instance_name="engine"))
    manipulator = CosimManipulator.create_override()
    execution.add_manipulator(manipulator=manipulator)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    execution.real_initial_value(slave_index=index, variable_reference=vr["rpm"], value=rpm0)
    execution.boolean_initial_value(slave_index=index, variable_reference=vr["effects.ringCarrier"], value=False)
    for k in range(steps):
        manipulator.slave_real_values(index, [vr["rpm"]], [rpm0 + slope * k * h])
        assert execution.step()
    angle, roll = observer.last_real_values(slave_index=index,
                                            variable_references=[vr["crankAngle"], vr["powertrain.phi[2]"]])
    t = steps * h
    a = slope * np.pi / 30
    expected = (rpm0 * t + 0.5 * slope * t * t) * np.pi / 30 - a * (h * h + 4 * h * tau + tau * tau)
    assert angle + roll == pytest.approx(expected, rel=1e-6)
