"""The FMI 3.0 FMU (dist/EngineMountChassis-fmi3.fmu) beside the 2.0 one: fmpy's 3.0 validation,
the terminals, the exports, and both FMUs driven side by side through fmpy's low-level API
(scene 1 and 2, rpm set every step, an FMU state round trip): one library and one instance type
underneath, so their outputs must agree to 1e-12."""

import pathlib
import re
import subprocess
import tempfile
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

ROOT = pathlib.Path(__file__).resolve().parents[2]

# The 3.0 arrays and the 2.0 scalars they stand for (row-major).
ARRAYS = {
    "mount.F": [f"mount[{i}].F[{j}]" for i in range(1, 5) for j in range(1, 4)],
    "crankAngle": ["crankAngle"],
    "powertrain.r": [f"powertrain.r[{j}]" for j in range(1, 4)],
    "powertrain.phi": [f"powertrain.phi[{j}]" for j in range(1, 4)],
    "powertrain.a": [f"powertrain.a[{j}]" for j in range(1, 4)],
    "steeringWheel.a": [f"steeringWheel.a[{j}]" for j in range(1, 4)],
    "seat.a": [f"seat.a[{j}]" for j in range(1, 4)],
}
COUNTERS = ["solver.steps", "solver.rhsEvaluations", "solver.jacobianEvaluations", "solver.factorizations"]


def test_fmpy_validates_the_fmi3_fmu_without_problems(fmu3_path):
    assert validate_fmu(str(fmu3_path)) == []
    body3 = fmu3_path.parent / "EngineMountBody-fmi3.fmu"
    assert validate_fmu(str(body3)) == []
    assert read_model_description(str(body3)).coSimulation.modelIdentifier == "EngineMountBody"
    md = read_model_description(str(fmu3_path))
    assert md.fmiVersion == "3.0"
    assert md.coSimulation.modelIdentifier == "EngineMountChassis"
    assert md.guid == read_model_description(str(ROOT / "dist" / "EngineMountChassis.fmu")).guid


def test_arrays_units_and_descriptions_follow_the_2_0_variables(fmu3_path, fmu_path):
    md3 = read_model_description(str(fmu3_path))
    md2 = read_model_description(str(fmu_path))
    v3 = {v.name: v for v in md3.modelVariables}
    v2 = {v.name: v for v in md2.modelVariables}
    force = v3["mount.F"]
    assert [d.start for d in force.dimensions] == [4, 3]
    assert force.valueReference == v2["mount[1].F[1]"].valueReference
    # 3.0 variables carry their units through declared types (as the Reference-FMUs do).
    assert (force.declaredType.unit, force.causality) == ("N", "output")
    for name in ["steeringWheel.a", "seat.a", "powertrain.r"]:
        assert [d.start for d in v3[name].dimensions] == [3]
        assert v3[name].declaredType.unit == v2[f"{name}[1]"].unit
        assert v3[name].declaredType.displayUnit == v2[f"{name}[1]"].displayUnit
    size = v3["modes.size"]
    assert (size.type, size.causality, size.variability) == ("UInt64", "structuralParameter", "fixed")
    for name in ["mode.frequency", "mode.damping", "mode.powertrainShare"]:
        assert [d.valueReference for d in v3[name].dimensions] == [size.valueReference]
    # The 3.0 variables (but time and modes.size) have as many elements as the 2.0 FMU variables.
    slots = size.start
    elements = sum(int(np.prod([d.start if d.start is not None else int(slots) for d in v.dimensions]))
                   for n, v in v3.items() if n not in ("time", "modes.size"))
    assert elements == len(v2)
    assert v3["rpm"].declaredType.unit == "rpm" and v3["rpm"].start == v2["rpm"].start


def test_terminals_name_existing_variables_and_match_the_schema(fmu3_path):
    import fmpy
    from lxml import etree
    schema_dir = pathlib.Path(fmpy.__file__).parent / "schema" / "fmi3"
    with zipfile.ZipFile(fmu3_path) as z:
        xml = z.read("terminalsAndIcons/terminalsAndIcons.xml")
    root = etree.fromstring(xml)
    schema = etree.XMLSchema(file=str(schema_dir / "fmi3TerminalsAndIcons.xsd"))
    assert schema.validate(root), schema.error_log
    names = {v.name for v in read_model_description(str(fmu3_path)).modelVariables}
    terminals = {t.get("name"): [m.get("variableName") for m in t] for t in root.iter("Terminal")}
    assert terminals["engine"] == ["rpm", "loadTorque"]
    assert terminals["bodyPort"] == ["mount.body.r", "mount.body.v", "mount.F"]
    assert "mount.stiffnessScale" in terminals["mounts"]
    assert terminals["comfort"] == ["steeringWheel.a", "seat.a"]
    assert all(m in names for members in terminals.values() for m in members)


def test_library_exports_the_fmi2_and_fmi3_functions_only(fmu3_path):
    listed = set(re.findall(r'"(fmi3\w+)"', (ROOT / "build" / "fmi3_description.rs").read_text()))
    with tempfile.TemporaryDirectory() as tmp, zipfile.ZipFile(fmu3_path) as z:
        so = z.extract("binaries/x86_64-linux/EngineMountChassis.so", tmp)
        out = subprocess.run(["nm", "-D", "--defined-only", so], capture_output=True, text=True, check=True)
    exported = {line.split()[-1] for line in out.stdout.splitlines() if line.strip()}
    assert {f for f in exported if f.startswith("fmi3")} == listed
    assert all(f.startswith(("fmi2", "fmi3")) for f in exported)


class Pair:
    """The 2.0 and the 3.0 FMU instantiated side by side, set and stepped alike."""

    def __init__(self, fmu2, fmu3, scene, cache_dir):
        self.md2 = read_model_description(str(fmu2))
        self.md3 = read_model_description(str(fmu3))
        self.vr2 = {v.name: v.valueReference for v in self.md2.modelVariables}
        self.vr3 = {v.name: v.valueReference for v in self.md3.modelVariables}
        self.dirs = [extract(str(fmu2)), extract(str(fmu3))]
        self.a = FMU2Slave(guid=self.md2.guid, unzipDirectory=self.dirs[0],
                           modelIdentifier="EngineMountChassis", instanceName="two")
        self.b = FMU3Slave(guid=self.md3.guid, unzipDirectory=self.dirs[1],
                           modelIdentifier="EngineMountChassis", instanceName="three")
        self.a.instantiate()
        self.b.instantiate()
        self.a.setInteger([self.vr2["scene"]], [scene])
        self.b.setInt32([self.vr3["scene"]], [scene])
        self.a.setString([self.vr2["chassis.cacheDir"]], [str(cache_dir)])
        self.b.setString([self.vr3["chassis.cacheDir"]], [str(cache_dir)])
        self.a.setupExperiment(startTime=0.0)
        self.a.enterInitializationMode()
        self.b.enterInitializationMode(startTime=0.0)
        self.a.exitInitializationMode()
        self.b.exitInitializationMode()

    def set_rpm(self, rpm):
        self.a.setReal([self.vr2["rpm"]], [rpm])
        self.b.setFloat64([self.vr3["rpm"]], [rpm])

    def step(self, t, h):
        self.a.doStep(t, h)
        event, terminate, early, last = self.b.doStep(t, h)
        assert not (event or terminate or early)
        assert abs(last - (t + h)) < 1e-12

    def outputs(self):
        """(2.0 values, 3.0 values) of the Float64 outputs and the Int32 counters."""
        x = self.a.getReal([self.vr2[n] for names in ARRAYS.values() for n in names])
        y = self.b.getFloat64([self.vr3[n] for n in ARRAYS], nValues=len(x))
        c2 = self.a.getInteger([self.vr2[n] for n in COUNTERS])
        c3 = self.b.getInt32([self.vr3[n] for n in COUNTERS])
        return np.array(x + c2, dtype=float), np.array(y + c3, dtype=float)

    def free(self):
        for f in (self.a, self.b):
            f.terminate()
            f.freeInstance()


def _agree(x, y):
    scale = max(1.0, float(np.max(np.abs(x))))
    d = float(np.max(np.abs(x - y))) / scale
    assert d <= 1e-12, f"2.0 and 3.0 outputs differ by {d:.1e} (relative)"
    return d


@pytest.mark.parametrize("scene,duration", [(1, 0.3), (2, 0.06)])
def test_both_fmus_agree_side_by_side_with_rpm_set_every_step_and_a_state_round_trip(
        fmu_path, fmu3_path, tmp_path, scene, duration):
    pair = Pair(fmu_path, fmu3_path, scene, tmp_path / "cache")
    h = 1e-3
    steps = int(round(duration / h))
    half = steps // 2
    first, worst = [], 0.0
    try:
        for k in range(steps):
            t = k * h
            pair.set_rpm(1500.0 + 2000.0 * t)
            if k == half:
                states = pair.a.getFMUstate(), pair.b.getFMUState()
            pair.step(t, h)
            x, y = pair.outputs()
            worst = max(worst, _agree(x, y))
            if k >= half:
                first.append(y)
        assert np.max(np.abs(first[-1][:12])) > 0, "the mount forces stayed zero"
        # Back to the state before step `half` on both; the replay repeats the 3.0 run exactly and
        # the two FMUs still agree.
        pair.a.setFMUstate(states[0])
        pair.b.setFMUState(states[1])
        for k in range(half, steps):
            t = k * h
            pair.set_rpm(1500.0 + 2000.0 * t)
            pair.step(t, h)
            x, y = pair.outputs()
            worst = max(worst, _agree(x, y))
            np.testing.assert_array_equal(y, first[k - half])
        # A serialized 3.0 state restores in both FMUs (one format, one GUID), and they go on alike.
        blob = pair.b.serializeFMUState(states[1])
        copies = pair.a.deSerializeFMUstate(blob), pair.b.deserializeFMUState(blob)
        pair.a.setFMUstate(copies[0])
        pair.b.setFMUState(copies[1])
        for k in range(half, half + 5):
            pair.set_rpm(1500.0 + 2000.0 * k * h)
            pair.step(k * h, h)
            x, y = pair.outputs()
            worst = max(worst, _agree(x, y))
            np.testing.assert_array_equal(y, first[k - half])
        pair.a.freeFMUstate(copies[0])
        pair.b.freeFMUState(copies[1])
        pair.a.freeFMUstate(states[0])
        pair.b.freeFMUState(states[1])
        print(f"scene {scene}: largest relative 2.0/3.0 difference {worst:.1e}")
    finally:
        pair.free()


def test_natural_mode_arrays_follow_the_structural_parameter(fmu3_path, tmp_path):
    md = read_model_description(str(fmu3_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(str(fmu3_path)),
                    modelIdentifier="EngineMountChassis", instanceName="modes")
    fmu.instantiate()
    try:
        fmu.enterConfigurationMode()
        fmu.setUInt64([vr["modes.size"]], [6])
        fmu.exitConfigurationMode()
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        assert fmu.getUInt64([vr["modes.size"]]) == [6]
        frequencies = fmu.getFloat64([vr["mode.frequency"]], nValues=6)
        count = fmu.getInt32([vr["modes.count"]])[0]
        assert count >= 6
        assert all(0 < a <= b for a, b in zip(frequencies, frequencies[1:]))
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_output_derivatives_through_fmpy_follow_the_crank_angle(fmu3_path):
    """fmi3GetOutputDerivatives as fmpy calls it: the crank angle's rate is its slope over a step."""
    md = read_model_description(str(fmu3_path))
    assert md.coSimulation.maxOutputDerivativeOrder == 1
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=extract(str(fmu3_path)),
                    modelIdentifier="EngineMountChassis", instanceName="derivatives")
    fmu.instantiate()
    try:
        fmu.setFloat64([vr["rpm"]], [1200.0])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        t, h, angles, rates = 0.0, 1e-5, [], []
        for _ in range(2000):
            fmu.doStep(t, h)
            t += h
            angles.append(fmu.getFloat64([vr["crankAngle"]])[0])
            rates.append(fmu.getOutputDerivatives([vr["crankAngle"]], [1])[0])
        slope = (angles[-1] - angles[-3]) / (2 * h)
        assert abs(rates[-2] - slope) < 1e-4 * abs(slope), (rates[-2], slope)
        assert abs(rates[-2] - 1200.0 * np.pi / 30.0) < 0.01 * 1200.0 * np.pi / 30.0
    finally:
        fmu.terminate()
        fmu.freeInstance()
