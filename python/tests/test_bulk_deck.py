"""A user's body from a Nastran bulk data deck through the packaged FMU: a small steel ladder frame
on four suspension springs, written here in small field, carries the engine in scene 2 by the
vehicle configuration's `"body": {"kind": "nastran", ...}` with its points named by GRID id."""

import json
import pathlib
import subprocess
import textwrap

import numpy as np
import pytest
from fmpy import simulate_fmu

STEEL = "MAT1    1       2.1+11          .3      7850.\n"
# 80 x 80 x 3 mm steel tube: A, I1, I2, J
TUBE = "PBAR    1       1       9.24-4  9.2-7   9.2-7   1.4-6\n"


def field(x) -> str:
    """One small-field field (8 columns); reals carry a point, as Nastran requires."""
    if isinstance(x, (int, str)):
        text = str(x)
    else:
        text = f"{x:.6g}"
        if "." not in text and "e" not in text:
            text += "."
    return f"{text:<8}"


def card(name, *fields) -> str:
    return f"{name:<8}" + "".join(field(f) for f in fields) + "\n"


def ladder_frame():
    """Two rails at y = +-0.4 m, z = 0.55 m, cross members, a steering column and four corner
    masses on springs; returns the deck and the GRID ids of the named points."""
    grids, lines = {}, [STEEL, TUBE]

    def grid(key, x, y, z):
        grids[key] = len(grids) + 1
        lines.append(card("GRID", grids[key], "", x, y, z))

    xs = [0.8, 0.5, -0.1, -0.6, -1.2, -2.0]
    for side, y in (("l", 0.4), ("r", -0.4)):
        for i, x in enumerate(xs):
            grid((side, i), x, y, 0.55)
    grid("seat", -1.2, 0.0, 0.55)
    grid("wheel", -0.6, 0.35, 1.0)
    eid = 0

    def bar(a, b, v=(0.0, 0.0, 1.0)):
        nonlocal eid
        eid += 1
        lines.append(card("CBAR", eid, 1, grids[a], grids[b], *v))

    for side in ("l", "r"):
        for i in range(len(xs) - 1):
            bar((side, i), (side, i + 1))
    for i in (0, 3, 5):
        bar(("l", i), ("r", i))
    bar(("l", 4), "seat")
    bar("seat", ("r", 4))
    bar(("l", 3), "wheel", (1.0, 0.0, 0.0))
    for corner in (("l", 0), ("r", 0), ("l", 5), ("r", 5)):
        eid += 1
        lines.append(card("CONM2", eid, grids[corner], "", 150.0))
        lines.append(card("", 1.0, 0.0, 1.0, 0.0, 0.0, 1.0))
        for dof in (1, 2, 3):
            eid += 1
            lines.append(card("CELAS2", eid, 6.0e4, grids[corner], dof))
    points = {"mount_front_left": grids[("l", 1)], "mount_front_right": grids[("r", 1)],
              "mount_rear_left": grids[("l", 2)], "mount_rear_right": grids[("r", 2)],
              "steering_wheel": grids["wheel"], "seat_rail": grids["seat"]}
    return "BEGIN BULK\n" + "".join(lines) + "ENDDATA\n", points


def test_a_ladder_frame_from_a_bulk_deck_carries_the_engine_in_scene_2(fmu_path, tmp_path):
    deck, points = ladder_frame()
    (tmp_path / "frame.bdf").write_text(deck)
    config = {"extends": "default", "body": {"kind": "nastran", "path": "frame.bdf", "points": points}}
    (tmp_path / "vehicle.json").write_text(json.dumps(config))
    r = simulate_fmu(str(fmu_path), stop_time=0.2, output_interval=1e-3,
                     start_values={"scene": 2, "rpm": 2000.0, "configFile": str(tmp_path / "vehicle.json"),
                                   "chassis.cacheDir": str(tmp_path / "cache")},
                     output=["mount[1].F[3]", "mount[2].F[3]", "mount[3].F[3]", "mount[4].F[3]",
                             "steeringWheel.a[3]", "seat.a[3]"])
    for name in r.dtype.names:
        assert np.all(np.isfinite(r[name])), name
    weight = 180.0 * 9.81
    vertical = sum(r[f"mount[{i}].F[3]"][0] for i in range(1, 5))
    assert vertical == pytest.approx(-weight, rel=1e-6)
    # the frame moves: the engine's excitation reaches the steering column
    assert np.std(r["steeringWheel.a[3]"][100:]) > 1e-3


ROOT = pathlib.Path(__file__).resolve().parents[2]
PYNASTRAN = ROOT / ".venv" / "pynastran" / "bin" / "python"

# pyNastran (an independent writer and reader) writes the frame's bulk data with a TABDMP1 and a
# case control naming it (SDAMPING), reads the deck back and reports the table as it reads it.
WITH_DAMPING = textwrap.dedent("""
    import json, sys
    from pyNastran.bdf.bdf import BDF
    from pyNastran.bdf.case_control_deck import CaseControlDeck

    model = BDF(debug=None, log=None)
    model.read_bdf(sys.argv[1], punch=True, xref=False)
    model.punch = False  # written as a whole deck: executive, case control, bulk data
    model.sol = 103
    # G 0.02 at 0 Hz to 0.04 at 20 Hz, a step to 0.12 there, 2.4 at 225 Hz and above.
    model.add_tabdmp1(7, [0.0, 20.0, 20.0, 225.0], [0.02, 0.04, 0.12, 2.4], Type="G")
    model.case_control_deck = CaseControlDeck(["SUBCASE 1", "  SDAMPING = 7", "BEGIN BULK"])
    model.write_bdf(sys.argv[2])
    back = BDF(debug=None, log=None)
    back.read_bdf(sys.argv[2], xref=False)
    table = back.tables_sdamping[7]
    json.dump({"type": table.Type, "x": [float(v) for v in table.x],
               "y": [float(v) for v in table.y],
               "sdamping": back.case_control_deck.subcases[1].get_parameter("SDAMPING")[0]},
              sys.stdout)
""")


def tabdmp1_ratio(table: dict, f: float) -> float:
    """The damping ratio TABDMP1 gives a mode of frequency f, written out from the card's
    definition: linear between the points, the end values held, a step between two points at
    one frequency; G = 2 zeta, Q = 1 / (2 zeta)."""
    x, y = table["x"], table["y"]
    if f <= x[0]:
        value = y[0]
    elif f >= x[-1]:
        value = y[-1]
    else:
        i = max(k for k in range(len(x) - 1) if x[k] < f)
        value = y[i] + (f - x[i]) / (x[i + 1] - x[i]) * (y[i + 1] - y[i])
    return {"G": value / 2, "CRIT": value, "Q": 1 / (2 * value)}[table["type"]]


def test_a_tabdmp1_written_by_pynastran_gives_every_mode_its_ratio(tmp_path):
    """The body FMU reports the reduced body's modes (frequency, damping ratio): each ratio is
    the table's at the mode's frequency (1e-12), on both sides of the step and beyond the last
    point, where the table is held."""
    assert PYNASTRAN.exists(), "scripts/setup.sh installs pyNastran in .venv/pynastran"
    deck, points = ladder_frame()
    bulk = "".join(line + "\n" for line in deck.splitlines()
                   if line not in ("BEGIN BULK", "ENDDATA"))
    (tmp_path / "bulk.bdf").write_text(bulk)
    table = json.loads(subprocess.run(
        [str(PYNASTRAN), "-c", WITH_DAMPING, str(tmp_path / "bulk.bdf"), str(tmp_path / "frame.bdf")],
        check=True, capture_output=True, text=True).stdout)
    assert table["sdamping"] == 7 and table["type"] == "G"
    config = {"extends": "default", "body": {"kind": "nastran", "path": "frame.bdf", "points": points}}
    (tmp_path / "vehicle.json").write_text(json.dumps(config))
    body = ROOT / "dist" / "EngineMountBody.fmu"
    names = ["modes.count"] + [f"mode[{k}].{q}" for k in range(1, 129)
                               for q in ("frequency", "damping")]
    r = simulate_fmu(str(body), stop_time=1e-3, output=names,
                     start_values={"configFile": str(tmp_path / "vehicle.json"),
                                   "chassis.cacheEnabled": False})
    count = int(r["modes.count"][0])
    hz = np.array([r[f"mode[{k}].frequency"][0] for k in range(1, count + 1)])
    zeta = np.array([r[f"mode[{k}].damping"][0] for k in range(1, count + 1)])
    expected = np.array([tabdmp1_ratio(table, f) for f in hz])
    assert count > 20 and hz.min() < 20.0 < hz.max() and hz.max() > 225.0, hz
    np.testing.assert_allclose(zeta, expected, rtol=0, atol=1e-12)
