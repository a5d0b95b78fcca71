"""Frequency weightings against the standards' tabulated factors, weighted RMS against Parseval,
and comfort values from a sweep of the FMU."""

import numpy as np
import pandas as pd
import pytest

from emc.signals.comfort import comfort_table, weighted_rms, weighting

# ISO 2631-1:1997 Table 3 (Wk, Wd) and ISO 5349-1:2001 Table A.2 (Wh): factors x 1000 at
# one-third-octave centre frequencies (Hz), the ranges the model's spectra cover.
TABLES = {
    "Wk": {0.5: 418, 1.0: 482, 2.0: 531, 4.0: 967, 5.0: 1039, 6.3: 1054, 8.0: 1036, 10.0: 988,
           16.0: 768, 31.5: 405, 63.0: 186, 80.0: 132},
    "Wd": {0.5: 853, 1.0: 1011, 2.0: 890, 4.0: 512, 5.0: 409, 6.3: 323, 8.0: 253, 16.0: 125,
           31.5: 63.2, 63.0: 29.5, 80.0: 21.1},
    "Wh": {6.3: 727, 8.0: 873, 10.0: 951, 12.5: 958, 16.0: 896, 31.5: 519, 63.0: 256, 125.0: 127},
}


@pytest.mark.parametrize("name", sorted(TABLES))
def test_weightings_match_the_standards_tables(name):
    nominal = sorted(TABLES[name])
    expected = np.array([TABLES[name][x] for x in nominal]) / 1000
    # ISO 2631-1 tabulates at the nominal band centres, ISO 5349-1 at the exact ones 10^(n/10) Hz;
    # both give three digits
    f = 10 ** (np.round(10 * np.log10(nominal)) / 10) if name == "Wh" else np.array(nominal)
    np.testing.assert_allclose(weighting(name, f), expected, rtol=4e-3)  # half a unit of 3 digits


def test_weighted_rms_of_a_sinusoid_is_the_weighted_amplitude_over_root_two():
    f = np.array([0.0, 5.0, 31.5])
    a = np.array([9.0, 0.0, 2.0])  # the mean (0 Hz) does not count
    assert weighted_rms(f, a, "Wk") == pytest.approx(weighting("Wk", 31.5) * 2 / np.sqrt(2), rel=1e-12)


def test_comfort_table_from_spectra():
    rows = []
    for s, amp in [("seat.a[1]", 0.1), ("seat.a[2]", 0.2), ("seat.a[3]", 0.3),
                   ("steeringWheel.a[1]", 1.0), ("steeringWheel.a[2]", 0.0), ("steeringWheel.a[3]", 2.0)]:
        rows.append({"case": "", "rpm": 1800.0, "signal": s, "frequency": 45.0, "amplitude": amp})
    t = comfort_table(pd.DataFrame(rows))
    wd, wk, wh = (float(weighting(n, 45.0)) for n in ("Wd", "Wk", "Wh"))
    r = t.iloc[0]
    assert r.seat_awz == pytest.approx(wk * 0.3 / np.sqrt(2))
    assert r.seat_av_comfort == pytest.approx(np.sqrt((wd * 0.1) ** 2 + (wd * 0.2) ** 2 + (wk * 0.3) ** 2) / np.sqrt(2))
    assert r.seat_av_health == pytest.approx(
        np.sqrt((1.4 * wd * 0.1) ** 2 + (1.4 * wd * 0.2) ** 2 + (wk * 0.3) ** 2) / np.sqrt(2))
    assert r.wheel_ahv == pytest.approx(wh * np.sqrt(1.0 + 4.0) / np.sqrt(2))


def test_a_sweep_writes_comfort_values(fmu_path, tmp_path):
    from emc.cli import main

    signals = [f"seat.a[{i}]" for i in (1, 2, 3)] + [f"steeringWheel.a[{i}]" for i in (1, 2, 3)]
    args = ["sweep", "--fmu", str(fmu_path), "--rpm", "1500", "2000", "--count", "2", "--revolutions", "4",
            "--serial", "--quiet", "--set", "scene=2", "--out", str(tmp_path)]
    for s in signals:
        args += ["--signal", s]
    assert main(args) == 0
    table = pd.read_csv(tmp_path / "comfort.csv")
    assert len(table) == 2
    assert (table.seat_av_comfort > 0).all() and (table.wheel_ahv > 0).all()
    assert np.isfinite(table.drop(columns="case").to_numpy(dtype=float)).all()
    assert (tmp_path / "comfort.png").exists()
