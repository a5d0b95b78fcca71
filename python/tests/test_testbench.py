"""Test data against the model (emc.testbench): universal files through pyuff and back, a file
shaped like a test system's export, the mapping's conversions, every bad input, the correlation
metrics against values worked out by hand, the calibrated configuration against the FMU's own
inputs, and the twin experiment: a car with known parameter offsets, measured with noise,
calibrated from the nominal.

Sized for CI (2 cores, about 3 minutes for this file): the twin experiment simulates 11 speeds
(dense where the steering wheel's 1.5 order resonates, 1000-1200 rpm), 4 outputs × 4 orders,
2 revolutions per point on the periodic steady state. The full-size case (35 speeds) is
``emc bench-calibration``.
"""

import json
import math
import pathlib
import re

import numpy as np
import pandas as pd
import pytest
import pyuff

from emc.running import band as bands
from emc import cli
from emc.base.fmu import model_variables
from emc.running.modal import export_from_fmu
from emc.studies.mount_study import base_configuration
from emc.testbench import metrics, parameters
from emc.testbench.mapping import load
from emc.testbench.measurement import MeasurementError, read_csv, read_modes, read_uff_functions
from emc.running.engine import PointEngine
from emc.testbench.simulate import Grid, evaluate, points
from emc.testbench.synthetic import twin_measurement

OUTPUTS = {"steeringWheel.a[3]": "m/s2", "seat.a[3]": "m/s2", "mount[1].F[3]": "N",
           "mount[1].F[1]": "N", "mount[3].F[3]": "N", "mount[4].F[3]": "N"}


# --- universal files through pyuff ----------------------------------------------------------------

def uff58(**fields) -> dict:
    base = dict(func_type=0, rsp_node=101, rsp_dir=3, ref_node=0, ref_dir=0, ord_data_type=6,
                abscissa_spacing=0, abscissa_spec_data_type=19, ordinate_spec_data_type=12,
                ordinate_axis_units_lab="g", orddenom_spec_data_type=0, z_axis_spec_data_type=0,
                id1="SW:+Z order 1.5", x=np.array([800.0, 900.0, 1000.0, 1100.0]),
                data=np.array([0.1 + 0.2j, 0.3 - 0.1j, 0.5 + 0.0j, 0.0 + 0.7j]))
    base.update(fields)
    if base["ord_data_type"] in (2, 4):
        base["data"] = np.abs(base["data"])
    return pyuff.prepare_58(**base)


def write(path, sets):
    path = pathlib.Path(path)
    if path.exists():
        path.unlink()
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    return path


def test_uff58_round_trip_through_pyuff(tmp_path):
    """Order cuts (rpm, complex and real) and an FRF (Hz, complex, func type 4) written by pyuff
    come back with their abscissa, values, nodes, directions, unit labels and kinds."""
    x_hz = np.linspace(10.0, 50.0, 9)
    frf = 1.0 / (30.0**2 - x_hz**2 + 2j * 0.05 * 30.0 * x_hz)
    sets = [uff58(), uff58(ord_data_type=4, rsp_node=201, id1="seat order 2"),
            uff58(func_type=4, abscissa_spec_data_type=18, ordinate_axis_units_lab="g/N",
                  ref_node=11, ref_dir=3, x=x_hz, data=frf, id1="FRF")]
    functions = read_uff_functions(write(tmp_path / "cuts.uff", sets))
    assert [f.kind for f in functions] == ["order", "order", "frf"]
    first, second, third = functions
    np.testing.assert_array_equal(first.x, [800.0, 900.0, 1000.0, 1100.0])
    np.testing.assert_allclose(first.values, sets[0]["data"], rtol=1e-11)
    assert (first.node, first.direction, first.unit_label, first.quantity) == (
        101, 3, "g", "acceleration")
    assert not second.complex and second.node == 201
    np.testing.assert_allclose(second.values, np.abs(sets[0]["data"]), rtol=1e-11)
    np.testing.assert_allclose(third.values, frf, rtol=1e-11)
    assert (third.reference_node, third.reference_direction) == (11, 3)


def test_uff55_modes_with_their_nodes_round_trip_through_pyuff(tmp_path):
    """Two normal modes on three nodes (dataset 2411 coordinates) come back with their
    frequencies, damping, node positions and shapes."""
    nodes = np.array([1, 2, 3])
    xyz = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [2.0, 0.0, 1.0]])
    shapes = [np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.5], [0.0, 0.0, -1.0]]),
              np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])]
    sets = [pyuff.prepare_2411(node_nums=nodes, x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2],
                               def_cs=np.zeros(3, int), disp_cs=np.zeros(3, int),
                               color=np.ones(3, int))]
    for k, (f, shape) in enumerate(zip((24.5, 31.25), shapes), 1):
        sets.append(pyuff.prepare_55(
            analysis_type=2, data_ch=2, spec_data_type=8, node_nums=nodes, r1=shape[:, 0],
            r2=shape[:, 1], r3=shape[:, 2], mode_n=k, freq=f, modal_damp_vis=0.01 * k,
            model_type=1, load_case=0, data_type=2, n_data_per_node=3))
    modes = read_modes(write(tmp_path / "modes.unv", sets))
    np.testing.assert_allclose(modes.frequencies, [24.5, 31.25])
    np.testing.assert_allclose(modes.damping, [0.01, 0.02])
    np.testing.assert_array_equal(modes.nodes, nodes)
    np.testing.assert_allclose(modes.positions, xyz)
    np.testing.assert_allclose(modes.shapes, np.array(shapes))


def real_export(path, rpm, data, unit="g", func_type=12, spec=12):
    """A dataset 58 as a test system writes it, by hand from the format's definition (not through
    pyuff): spectrum over rpm, complex single precision, uneven abscissa, 6E13.5 per line."""
    lines = ["    -1", "    58", f"{'SW:+Z order 1.5':<80}", f"{'Run-up 3rd gear WOT':<80}",
             f"{'12-Mar-26 10:41:07':<80}", f"{'NONE':<80}", f"{'NONE':<80}",
             "%5i%10i%5i%10i %-10s%10i%4i %-10s%10i%4i" % (func_type, 1, 1, 0, "NONE", 101, 3,
                                                           "NONE", 0, 0),
             "%10i%10i%10i%13.5E%13.5E%13.5E" % (5, len(rpm), 0, 0.0, 0.0, 0.0),
             "%10i%5i%5i%5i %-20s %-20s" % (19, 0, 0, 0, "Tacho", "rpm"),
             "%10i%5i%5i%5i %-20s %-20s" % (spec, 0, 0, 0, "Acceleration", unit),
             "%10i%5i%5i%5i %-20s %-20s" % (0, 0, 0, 0, "NONE", "NONE"),
             "%10i%5i%5i%5i %-20s %-20s" % (0, 0, 0, 0, "NONE", "NONE")]
    triples = [v for r, d in zip(rpm, data) for v in (r, d.real, d.imag)]
    for k in range(0, len(triples), 6):
        lines.append("".join(f"{v:13.5E}" for v in triples[k:k + 6]))
    lines.append("    -1")
    pathlib.Path(path).write_text("\n".join(lines) + "\n")


def one_channel_mapping(folder, file="export.uff", **fields):
    entry = {"node": 101, "direction": 3, "output": "steeringWheel.a[3]", "order": 1.5,
             "unit": "g", "amplitude": "rms", "sign": 1, **fields}
    text = f'[measurement]\nfile = "{file}"\n\n[[channel]]\n' + "".join(
        f"{k} = {json.dumps(v)}\n" for k, v in entry.items() if v is not None)
    path = pathlib.Path(folder) / "map.toml"
    path.write_text(text)
    return path


def test_a_real_export_complex_g_rms_reads_as_si_zero_peak(tmp_path):
    """Truth by hand: a complex value V in g RMS is V · 9.80665 · √2 m/s² 0-peak, the phase kept
    (single precision: 6 digits); with sign -1 the phase turns by π."""
    rpm = np.array([800.0, 950.0, 1100.0, 1250.0, 1400.0])
    data = np.array([0.012 + 0.004j, 0.05 - 0.02j, 0.41 + 0.3j, 0.08 - 0.07j, 0.02 + 0.001j])
    real_export(tmp_path / "export.uff", rpm, data)
    channel = load(one_channel_mapping(tmp_path), OUTPUTS).channels[0]
    assert channel.has_phase
    np.testing.assert_array_equal(channel.x, rpm)
    np.testing.assert_allclose(channel.values, data * 9.80665 * math.sqrt(2.0), rtol=2e-5)
    flipped = load(one_channel_mapping(tmp_path, sign=-1), OUTPUTS).channels[0]
    np.testing.assert_allclose(flipped.values, -channel.values)


def test_velocity_and_peak_peak_convert_to_acceleration_0_peak(tmp_path):
    """Truth by hand: a harmonic velocity v (mm/s, peak-peak) at order k and n rpm is the
    acceleration i ω v / 2 · 1e-3 m/s², ω = 2π k n / 60."""
    rpm = np.array([900.0, 1000.0, 1200.0])
    data = np.array([1.0 + 0.0j, 0.0 + 2.0j, 3.0 - 1.0j])
    real_export(tmp_path / "export.uff", rpm, data, unit="mm/s", spec=11)
    channel = load(one_channel_mapping(tmp_path, unit="mm/s", amplitude="peak-peak"),
                   OUTPUTS).channels[0]
    omega = 2 * math.pi * 1.5 * rpm / 60
    np.testing.assert_allclose(channel.values, 1j * omega * data * 1e-3 / 2, rtol=2e-5)


def test_csv_with_the_documented_header(tmp_path):
    """Two channels in one CSV, amplitude and phase; the mapping picks one by its channel name
    and order; N stays N, RMS becomes 0-peak."""
    (tmp_path / "cuts.csv").write_text(
        "# run-up 3rd gear, levels RMS\nchannel,order,rpm,amplitude,phase_deg\n"
        "MNT1_Z,1.5,800,10,0\nMNT1_Z,1.5,900,20,90\nMNT1_Z,1.5,1000,30,180\n"
        "MNT1_Z,2,800,1,0\nMNT1_Z,2,900,2,0\nMNT1_Z,2,1000,3,0\n")
    path = tmp_path / "map.toml"
    path.write_text('[measurement]\nfile = "cuts.csv"\nunmapped = "ignore"\n[[channel]]\n'
                    'channel = "MNT1_Z"\noutput = "mount[1].F[3]"\norder = 1.5\nunit = "N"\n'
                    'amplitude = "rms"\n')
    channel = load(path, OUTPUTS).channels[0]
    np.testing.assert_allclose(channel.values, np.array([10, 20j, -30]) * math.sqrt(2),
                               atol=1e-12)


# --- bad input: one line naming the file, the set and the field -----------------------------------

GOOD_X = np.array([800.0, 900.0, 1000.0, 1100.0])


@pytest.mark.parametrize("change, expected", [
    (dict(x=np.array([800.0, 900.0, 850.0, 1100.0])), ["set 1", "abscissa (rpm)",
                                                      "does not increase"]),
    (dict(x=np.array([800.0, 900.0, 900.0, 1100.0])), ["set 1", "abscissa (rpm)", "duplicate"]),
    (dict(x=GOOD_X[:2], data=np.array([1.0, 2.0]) + 0j), ["set 1", "abscissa (rpm)",
                                                          "2 points, at least 3"]),
    (dict(abscissa_spec_data_type=17), ["set 1", "abscissa_spec_data_type", "17"]),
    (dict(func_type=6), ["set 1", "func_type", "6"]),
])
def test_bad_sets_are_refused_naming_file_set_and_field(tmp_path, change, expected):
    path = write(tmp_path / "bad.uff", [uff58(**change)])
    with pytest.raises(MeasurementError) as error:
        read_uff_functions(path)
    message = str(error.value)
    assert "\n" not in message and str(path) in message
    for fragment in expected:
        assert fragment in message, message


def test_a_value_that_is_not_a_number_is_refused(tmp_path):
    """pyuff writes NaN as 0, so the file is written by hand, as a test system might."""
    path = tmp_path / "nan.uff"
    real_export(path, np.array([800.0, 900.0, 1000.0]), np.array([0.1, np.nan, 0.2]) + 0j)
    with pytest.raises(MeasurementError, match=r"nan.uff, set 1, data: not a finite number at "
                                               r"point 2"):
        read_uff_functions(path)


@pytest.mark.parametrize("fields, expected", [
    (dict(node=102), ["channel 1", "node", "no function with node 102 direction 3"]),
    (dict(unit="m/s^2"), ["channel 1", "unit", "says 'g'"]),
    (dict(unit="N"), ["channel 1", "unit", "measures force", "acceleration"]),
    (dict(unit="furlong"), ["channel 1", "unit", "not a unit"]),
    (dict(amplitude="rms-ish"), ["channel 1", "amplitude", "peak, rms, peak-peak"]),
    (dict(sign=2), ["channel 1", "sign", "1 or -1"]),
    (dict(order=1.25), ["channel 1", "order", "halves"]),
    (dict(order=None), ["channel 1", "order", "missing"]),
    (dict(output="steeringWheel.a[4]"), ["channel 1", "output", "not an output"]),
    (dict(colour="red"), ["channel 1", "colour", "unknown field"]),
    (dict(noise_floor=-1), ["channel 1", "noise_floor", ">= 0"]),
    (dict(direction=None), ["channel 1", "direction", "go together"]),
])
def test_bad_mappings_are_refused_naming_file_channel_and_field(tmp_path, fields, expected):
    write(tmp_path / "export.uff", [uff58()])
    path = one_channel_mapping(tmp_path, **fields)
    with pytest.raises(MeasurementError) as error:
        load(path, OUTPUTS)
    message = str(error.value)
    assert "\n" not in message and str(path) in message
    for fragment in expected:
        assert fragment in message, message


def test_unmapped_ambiguous_and_twice_mapped_sets_are_refused(tmp_path):
    write(tmp_path / "export.uff", [uff58(), uff58(id1="SW:+Z order 2")])
    with pytest.raises(MeasurementError, match=r"export.uff, set 2, .*no channel of map.toml "
                                               r"maps it"):
        load(one_channel_mapping(tmp_path, id="SW:+Z order 1.5"), OUTPUTS)
    with pytest.raises(MeasurementError, match=r"channel 1 .*selects 2 functions .*add an id"):
        load(one_channel_mapping(tmp_path), OUTPUTS)
    path = tmp_path / "twice.toml"
    entry = ('[[channel]]\nnode = 101\ndirection = 3\nid = "SW:+Z order 1.5"\nunit = "g"\n'
             'amplitude = "peak"\n')
    path.write_text('[measurement]\nfile = "export.uff"\nunmapped = "ignore"\n'
                    + entry + 'output = "steeringWheel.a[3]"\norder = 1.5\n'
                    + entry + 'output = "steeringWheel.a[3]"\norder = 2\n')
    with pytest.raises(MeasurementError, match=r"channel 2 .*mapped twice \(channel 1 too\)"):
        load(path, OUTPUTS)


@pytest.mark.parametrize("text, expected", [
    ("channel,order,rpm\nA,1.5,800\n", ["header", "amplitude", "missing column"]),
    ("channel,order,rpm,amplitude\nA,1.5,800,1\nA,1.5,x,2\nA,1.5,1000,3\n",
     ["line 3", "rpm", "not a number"]),
    ("channel,order,rpm,amplitude\nA,1.5,800,1\nA,1.5,900,nan\nA,1.5,1000,3\n",
     ["line 3", "amplitude", "not a finite"]),
    ("channel,order,rpm,amplitude\nA,1.5,800,1\nA,1.5,800,2\nA,1.5,1000,3\n",
     ["channel 'A' order 1.5", "rpm", "duplicate"]),
    ("channel,order,rpm,amplitude,colour\nA,1.5,800,1,red\n", ["header", "colour", "unknown"]),
])
def test_bad_csv_is_refused_naming_file_line_or_channel_and_field(tmp_path, text, expected):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(MeasurementError) as error:
        read_csv(path)
    message = str(error.value)
    assert "\n" not in message and str(path) in message
    for fragment in expected:
        assert fragment in message, message


def test_the_commands_report_bad_input_in_one_line_without_traceback(tmp_path, fmu_path, capsys):
    write(tmp_path / "export.uff", [uff58()])
    mapping = one_channel_mapping(tmp_path, unit="N")
    for command in ("correlate", "calibrate"):
        code = cli.main([command, "--fmu", str(fmu_path), "--mapping", str(mapping), "--out",
                         str(tmp_path / "out"), "--serial"])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and err[-1].startswith("error: ") and "unit" in err[-1], err
    good = one_channel_mapping(tmp_path)
    for param, fragment in (("mount[9].stiffnessScale", "mounts 1 to 4"),
                            ("mount[1].stiffnessScale=2:3", "0 < LOW < 1 < HIGH"),
                            ("mount[*].stiffnessScale", "dampingScale only")):
        code = cli.main(["calibrate", "--fmu", str(fmu_path), "--mapping", str(good), "--out",
                         str(tmp_path / "out"), "--serial", "--param", param])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and fragment in err[-1], err


@pytest.mark.parametrize("text, fragment", [
    ("not json", "not a band file"),
    ('{"low": {}}', 'holds "low" and "high"'),
    ('{"low": {"mount[9].dampingScale": 1}, "high": {}}', "this FMU has no mount[9]"),
    ('{"low": {"chassis.modalDampingScale": -1}, "high": {}}', "a factor >= 0"),
])
def test_bad_band_files_are_refused(tmp_path, fmu_path, text, fragment):
    path = tmp_path / "band.json"
    path.write_text(text)
    with pytest.raises(ValueError, match=re.escape(fragment)):
        bands.from_file(path, model_variables(str(fmu_path)))


# --- correlation metrics against values worked out by hand ----------------------------------------

def test_order_cut_metrics_by_hand():
    """Measured 1, 2, 4, 2 and 0.01 (below the 0.05 floor, left out); simulated 1, 4, 2, 2, 1.
    Level errors 0, +6.0206, -6.0206, 0 dB: mean 0, RMS 6.0206/√2 = 4.2572, largest +6.0206 at
    900 rpm (the first of the two), measured peak at 1000 rpm, simulated at 900 (-100 rpm, the
    same level: 0 dB), 2 of 4 within ±3 dB: score 50 %. The band 0.5..3 at every speed holds the
    measured 1, 2 (3 of the first four: the 4 is outside): 75 %."""
    rpm = [800.0, 900.0, 1000.0, 1100.0, 1200.0]
    m = metrics.order_cut_metrics(rpm, [1, 2, 4, 2, 0.01], [1, 4, 2, 2, 1],
                                  floor=[0.05] * 5, low=[0.5] * 5, high=[3.0] * 5)
    six = 20 * math.log10(2)
    assert m["points_used"] == 4
    assert m["mean_db"] == pytest.approx(0.0, abs=1e-12)
    assert m["rms_db"] == pytest.approx(six / math.sqrt(2), rel=1e-12)
    assert (m["max_db"], m["max_db_rpm"]) == (pytest.approx(six), 900.0)
    assert (m["peak_rpm_measured"], m["peak_rpm_simulated"], m["peak_rpm_diff"]) == (
        1000.0, 900.0, -100.0)
    assert m["peak_db_diff"] == pytest.approx(0.0, abs=1e-12)
    assert m["score"] == 50.0
    assert m["inside_band"] == 75.0


def test_frac_and_mac_by_hand():
    """FRAC of [1, i] against [1, 1]: |1·1 + i·1|² / (2 · 2) = 2 / 4 = 0.5; against itself
    times 3 - 2i: 1. MAC of [1, 0] against [1, 1]: 1 / 2; against [0, 1]: 0; the pairing of
    [[0.9, 0.2, 0.1], [0.8, 0.95, 0.0]] takes (0, 0) and (1, 1) (sum 1.85), not the larger
    single entry first."""
    assert metrics.frac([1, 1j], [1 + 0j, 1]) == pytest.approx(0.5)
    h = np.array([1 + 2j, 0.5 - 1j, 3j])
    assert metrics.frac(h, (3 - 2j) * h) == pytest.approx(1.0)
    mac = metrics.mac_matrix(np.array([[1.0, 0.0]]), np.array([[1.0, 1.0], [0.0, 1.0]]))
    np.testing.assert_allclose(mac, [[0.5, 0.0]])
    assert metrics.pair_modes(np.array([[0.9, 0.2, 0.1], [0.8, 0.95, 0.0]])) == [(0, 0), (1, 1)]


# --- the calibrated configuration is what the FMU does with its own inputs ------------------------

def test_the_folded_configuration_gives_the_fmus_own_scales(tmp_path, fmu_path):
    """Second method: a scene-2 point with the scales as FMU inputs and parameter against the
    same point with the scales folded into a vehicle configuration (every scale 1): the order
    components agree to the solver's tolerance."""
    chosen = parameters.parse_all(["mount[1].stiffnessScale", "mount[3].stiffnessScale",
                                   "mount[*].dampingScale", "chassis.modalDampingScale"], 4)
    theta = [1.2, 0.85, 1.4, 0.7]
    base = json.loads(cli_base(fmu_path))
    folded = parameters.configuration_text(parameters.apply(base, chosen, theta, True))
    grid = Grid((1100.0,), ("steeringWheel.a[3]", "mount[1].F[3]", "mount[3].F[1]"),
                (1.0, 1.5, 3.0))
    engine = PointEngine.on(str(fmu_path))
    try:
        by_inputs, by_file = engine.map(
            evaluate,
            points(grid, {"scene": 2, **parameters.fmu_values(chosen, theta)}, None, 2)
            + points(grid, {"scene": 2}, folded, 2))
    finally:
        engine.close()
    assert np.max(np.abs(by_inputs)) > 0
    np.testing.assert_allclose(by_file, by_inputs, rtol=1e-4, atol=1e-6 * np.abs(by_inputs).max())


def test_rates_and_table_ordinates_are_the_fmus_own_scales(fmu_path):
    """Second method: mount 2's rates along its three axes at one factor are its stiffnessScale
    (an FMU input), and the default body table's only ordinate is chassis.modalDampingScale (an
    FMU parameter)."""
    base = json.loads(cli_base(fmu_path))
    in_file = parameters.parse_all([f"mount[2].rate[{j}]" for j in (1, 2, 3)]
                                   + ["body.damping.table[1]"], 4)
    config = parameters.apply(base, in_file, [0.8, 0.8, 0.8, 1.5], fold_inputs=False)
    grid = Grid((1100.0,), ("steeringWheel.a[3]", "mount[2].F[3]"), (1.5, 3.0))
    engine = PointEngine.on(str(fmu_path))
    try:
        by_inputs, by_file = engine.map(
            evaluate,
            points(grid, {"scene": 2, "mount[2].stiffnessScale": 0.8,
                          "chassis.modalDampingScale": 1.5}, None, 2)
            + points(grid, {"scene": 2}, parameters.configuration_text(config), 2))
    finally:
        engine.close()
    np.testing.assert_allclose(by_file, by_inputs, rtol=1e-4, atol=1e-6 * np.abs(by_inputs).max())
    with pytest.raises(parameters.ParameterError, match=r"table\[2\].*has 1 point"):
        parameters.apply(base, parameters.parse_all(["body.damping.table[2]"], 4), [1.2], False)


def cli_base(fmu_path) -> str:
    return base_configuration(str(fmu_path), {})


# --- the twin experiment --------------------------------------------------------------------------

TRUTH = {"mount[1].stiffnessScale": 1.15, "mount[2].stiffnessScale": 0.88,
         "mount[3].stiffnessScale": 1.10, "mount[4].stiffnessScale": 0.92,
         **{f"mount[{i}].dampingScale": 1.3 for i in range(1, 5)},
         "chassis.modalDampingScale": 0.75}
FITTED = {"mount[1].stiffnessScale": 1.15, "mount[2].stiffnessScale": 0.88,
          "mount[3].stiffnessScale": 1.10, "mount[4].stiffnessScale": 0.92,
          "mount[*].dampingScale": 1.3, "chassis.modalDampingScale": 0.75}
TWIN_SPEEDS = [800, 950, 1050, 1100, 1150, 1250, 1500, 1750, 2000, 2250, 2500]
TWIN_OUTPUTS = ["steeringWheel.a[3]", "seat.a[3]", "mount[3].F[3]", "mount[4].F[3]"]


@pytest.fixture(scope="module")
def twin(tmp_path_factory, fmu_path):
    """The twin measurement (3 % noise, noise floors 5 mm/s² and 0.1 N) and its calibration
    from the nominal on 2 Dask workers."""
    folder = tmp_path_factory.mktemp("twin")
    mapping = twin_measurement(
        str(fmu_path), folder, TRUTH, TWIN_OUTPUTS, [1.0, 1.5, 2.0, 3.0], TWIN_SPEEDS,
        {"steeringWheel.a[3]": "g", "seat.a[3]": "m/s^2", "mount[3].F[3]": "N",
         "mount[4].F[3]": "N"}, 0.03,
        {"steeringWheel.a[3]": 0.005, "seat.a[3]": 0.005, "mount[3].F[3]": 0.1,
         "mount[4].F[3]": 0.1}, seed=7, revolutions=2, amplitude="rms")
    out = folder / "calibration"
    args = ["calibrate", "--fmu", str(fmu_path), "--mapping", str(mapping), "--out", str(out),
            "--revolutions", "2", "--uncertainty", "0.03", "--workers", "2", "--quiet"]
    assert cli.main(args) == 0
    return {"folder": folder, "mapping": mapping, "out": out, "args": args}


def test_twin_experiment_recovers_the_hidden_parameters_inside_their_intervals(twin):
    table = pd.read_csv(twin["out"] / "parameters.csv").set_index("parameter")
    for name, truth in FITTED.items():
        row = table.loc[name]
        tolerance = 0.10 if "amping" in name else 0.05
        assert abs(row.value / truth - 1.0) <= tolerance, (name, row.value, truth)
        assert row.low95 <= truth <= row.high95, (name, row.low95, truth, row.high95)
        assert not row.at_bound and row.determined
    report = json.loads((twin["out"] / "calibration.json").read_text())
    assert report["fit"]["status"] > 0 and not report["warnings"]
    # The correlation improves: every channel's RMS level error after at most before.
    both = pd.read_csv(twin["out"] / "correlation_before_after.csv")
    assert (both.rms_db_after <= both.rms_db_before + 0.05).all()
    assert both.rms_db_after.mean() < 0.6 * both.rms_db_before.mean()


def test_twin_calibrated_configuration_and_band_are_usable(twin, fmu_path):
    """The calibrated configuration holds the fitted factors (the knots of mount 2's curves
    scaled by its stiffness factor against the FMU's own configuration); the band file is a band
    --band-from accepts, enclosing 1."""
    config = json.loads((twin["out"] / "vehicle_calibrated.json").read_text())
    base = json.loads(cli_base(fmu_path))
    value = pd.read_csv(twin["out"] / "parameters.csv").set_index("parameter").loc[
        "mount[2].stiffnessScale", "value"]
    got = config["mounts"][1]["curves"][2]["knots"][0]["stiffness"]
    want = base["mounts"][1]["curves"][2]["knots"][0]["stiffness"] * value
    assert got == pytest.approx(want, rel=1e-12)
    band = bands.from_file(twin["out"] / "band.json", model_variables(str(fmu_path)))
    body = (band.low["chassis.modalDampingScale"], band.high["chassis.modalDampingScale"])
    assert body[0] < 1.0 < body[1]


def test_twin_calibration_resumes_with_an_identical_result(twin):
    """The store cut before its last three evaluations (an interrupted run, its last line half
    written): the calibration started again runs only what is missing and ends identically."""
    store = twin["out"] / "evaluations.jsonl"
    lines = store.read_text().splitlines()
    before = (twin["out"] / "parameters.csv").read_text()
    keep = len(lines) - 3
    store.write_text("\n".join(lines[:keep]) + "\n" + lines[keep][:40])
    # Serially this time: the FMU gives the same numbers to the bit in this process as on the
    # pool's workers.
    at = twin["args"].index("--workers")
    serial = twin["args"][:at] + twin["args"][at + 2:] + ["--serial"]
    assert cli.main(serial) == 0
    report = json.loads((twin["out"] / "calibration.json").read_text())
    assert report["parameter_sets_run_now"] == len(lines) - keep
    assert (twin["out"] / "parameters.csv").read_text() == before


def test_twin_correlation_at_the_truth_is_at_the_noise_level(twin, fmu_path):
    """emc correlate with the hidden values set: the model is the car, so the level errors are
    the noise (3 % ≈ 0.26 dB) wherever the level is well above the floor."""
    out = twin["folder"] / "correlate"
    settings = [a for name, v in TRUTH.items() for a in ("--set", f"{name}={v}")]
    assert cli.main(["correlate", "--fmu", str(fmu_path), "--mapping", str(twin["mapping"]),
                     "--out", str(out), "--revolutions", "2", "--serial", "--no-band",
                     "--quiet", *settings]) == 0
    table = pd.read_csv(out / "correlation.csv").set_index("channel")
    for channel in ("steeringWheel.a[3] order 1.5", "mount[3].F[3] order 1.5",
                    "mount[4].F[3] order 2"):
        assert abs(table.loc[channel, "mean_db"]) < 0.3
        assert table.loc[channel, "rms_db"] < 0.6
        assert table.loc[channel, "score"] == 100.0
    metadata = json.loads((out / "metadata.json").read_text())
    assert str(twin["mapping"].resolve()) in metadata["files"]


def test_a_calibration_that_cannot_converge_says_why(twin, fmu_path, capsys):
    """One stiffness bounded below its true 1.15, the other hidden offsets left out: the
    parameter ends at its bound and the report names the bound, the residual and the channels
    that disagree most."""
    out = twin["folder"] / "bounded"
    code = cli.main(["calibrate", "--fmu", str(fmu_path), "--mapping", str(twin["mapping"]),
                     "--out", str(out), "--revolutions", "2", "--uncertainty", "0.03", "--serial",
                     "--quiet", "--param", "mount[1].stiffnessScale=0.8:1.05",
                     "--max-evaluations", "4", "--speeds", "6"])
    err = capsys.readouterr().err
    assert code == 0
    assert "mount[1].stiffnessScale ends at its bound 1.05" in err, err
    assert "channels that disagree most:" in err and "RMS" in err, err
    report = json.loads((out / "calibration.json").read_text())
    assert report["parameters"][0]["at_bound"] and len(report["warnings"]) >= 2


def test_sweep_takes_its_band_from_a_calibration(twin, fmu_path, tmp_path):
    """emc sweep --band-from: the three bounds run with the band file's factors."""
    out = tmp_path / "sweep"
    assert cli.main(["sweep", "--fmu", str(fmu_path), "--rpm", "1100", "1100", "--count", "1",
                     "--revolutions", "2", "--signal", "steeringWheel.a[3]", "--serial",
                     "--quiet", "--band-from", str(twin["out"] / "band.json"),
                     "--out", str(out)]) == 0
    metadata = json.loads((out / "metadata.json").read_text())
    band = json.loads((twin["out"] / "band.json").read_text())
    assert metadata["band"]["low"] == band["low"] and metadata["band"]["high"] == band["high"]


# --- FRFs and modes: the body's own, measured in other units -----------------------------------

def test_frf_and_modes_of_the_body_itself_correlate_perfectly(fmu_path, tmp_path):
    """The body's own accelerance written in g/N and its own modes at six body nodes with the
    coordinates in mm: the mapping's conversions and the node matching must give FRAC 1, level
    errors 0 and every measured mode paired with its own (MAC 1, 0 % frequency difference)."""
    export = export_from_fmu(str(fmu_path), {"scene": 2}, full_recovery=True)
    mesh, shapes = export.full_recovery()
    at = {i: p for i, _, p in export.paths()}
    f = np.linspace(15.0, 60.0, 31)
    h = export.body.accelerance("steering_wheel", 2, [(at[1], 2)], f)[:, 0]
    nodes = np.asarray(mesh["nodes"])
    chosen = np.linspace(0, len(nodes) - 1, 6).astype(int)
    model_hz = export.body.omega / (2 * np.pi)
    modes = [k for k in range(len(model_hz)) if model_hz[k] > 20.0][:3]
    sets = [uff58(func_type=4, abscissa_spec_data_type=18, ordinate_axis_units_lab="g/N",
                  ref_node=11, ref_dir=3, x=f, data=h / 9.80665, id1="FRF SW:+Z / MNT1:+Z"),
            pyuff.prepare_2411(node_nums=chosen + 1, x=nodes[chosen, 0] * 1e3,
                               y=nodes[chosen, 1] * 1e3, z=nodes[chosen, 2] * 1e3,
                               def_cs=np.zeros(6, int), disp_cs=np.zeros(6, int),
                               color=np.ones(6, int))]
    for n, k in enumerate(modes, 1):
        shape = shapes[chosen, :3, k]
        sets.append(pyuff.prepare_55(
            analysis_type=2, data_ch=2, spec_data_type=8, node_nums=chosen + 1, r1=shape[:, 0],
            r2=shape[:, 1], r3=shape[:, 2], mode_n=n, freq=model_hz[k], modal_damp_vis=0.05,
            model_type=1, load_case=0, data_type=2, n_data_per_node=3))
    write(tmp_path / "frf.uff", sets[:1])
    write(tmp_path / "modes.unv", sets[1:])
    (tmp_path / "map.toml").write_text(
        '[measurement]\nfile = "frf.uff"\n[[channel]]\nnode = 101\ndirection = 3\n'
        'output = "steeringWheel.a[3]"\ninput = "mount[1].F[3]"\nunit = "g/N"\n'
        'amplitude = "peak"\n[modes]\nfile = "modes.unv"\nlength_unit = "mm"\n'
        'tolerance = 0.001\n')
    out = tmp_path / "out"
    assert cli.main(["correlate", "--fmu", str(fmu_path), "--mapping", str(tmp_path / "map.toml"),
                     "--out", str(out), "--quiet", "--serial"]) == 0
    frf = pd.read_csv(out / "frf_correlation.csv")
    assert frf.frac[0] == pytest.approx(1.0, abs=1e-9)
    assert abs(frf.mean_db[0]) < 1e-6 and frf.rms_db[0] < 1e-6
    pairs = pd.read_csv(out / "modes.csv")
    assert list(pairs.model_mode) == [k + 1 for k in modes]
    # UFF 55 writes frequencies and shapes with 6 significant digits.
    assert (pairs.mac > 1 - 1e-6).all() and (pairs.difference_pct.abs() < 1e-3).all()
