"""The sweep tool: exact order analysis, and Dask sweeps equal to serial ones."""

import numpy as np
import pandas as pd
import pytest

from emc.runner import OperatingPoint, Runner
from emc.spectra import amplitude_spectrum, order_amplitudes
from emc.sweep import run_sweep, speed_points


def test_order_amplitudes_of_a_synthetic_signal_are_exact():
    rpm, revolutions, steps = 1500.0, 8, 72
    t = np.arange(revolutions * steps) * (60 / rpm) / steps
    f1 = rpm / 60
    x = 3.0 + 2.0 * np.sin(2 * np.pi * 1.5 * f1 * t + 0.3) + 0.5 * np.cos(2 * np.pi * 2.0 * f1 * t)
    amplitudes = order_amplitudes(x, revolutions, [0.5, 1.0, 1.5, 2.0, 3.0])
    assert abs(amplitudes[1.5] - 2.0) < 1e-12
    assert abs(amplitudes[2.0] - 0.5) < 1e-12
    assert max(amplitudes[o] for o in (0.5, 1.0, 3.0)) < 1e-12
    f, a = amplitude_spectrum(x, t[1] - t[0])
    assert abs(f[np.argmax(a)] - 1.5 * f1) < 1e-9


def test_operating_points_reject_windows_without_half_orders():
    for bad in ({"rpm": 1000.0, "revolutions": 5}, {"rpm": -1.0}):
        try:
            OperatingPoint(**bad)
        except ValueError:
            continue
        raise AssertionError(f"{bad} accepted")


def test_dask_sweep_equals_serial_sweep(fmu_path):
    points = speed_points(900, 2100, 3, revolutions=4)
    signals = ["mount[1].F[3]", "mount[3].F[1]"]
    serial = run_sweep(str(fmu_path), points, signals, parallel=False, progress=False)
    parallel = run_sweep(str(fmu_path), points, signals, parallel=True, workers=2, progress=False)
    for a, b in zip(serial, parallel):
        pd.testing.assert_frame_equal(a, b, check_exact=True)
    orders = serial[0]
    assert set(orders.rpm) == {900.0, 1500.0, 2100.0}
    # the 1.5 order of the gas torque dominates the vertical mount force
    main = orders[(orders.signal == "mount[1].F[3]") & (orders.order == 1.5)].amplitude
    other = orders[(orders.signal == "mount[1].F[3]") & (orders.order.isin([2.5, 3.5]))].amplitude
    assert main.min() > 10 * other.max()


def test_study_engines_compares_the_inline_three_with_the_inline_four(fmu_path, tmp_path):
    """emc study-engines: in the same body, the inline-3's mount force carries the 1.5 order, the
    inline-4's the 2nd and 4th; every case gets its side-by-side plots."""
    from emc.cli import main

    assert main(["study-engines", "--fmu", str(fmu_path), "--rpm", "1500", "2000", "--count", "2",
                 "--revolutions", "4", "--serial", "--quiet",
                 "--signal", "mount[1].F[3]", "--out", str(tmp_path)]) == 0
    orders = pd.read_csv(tmp_path / "orders.csv")
    force = orders[orders.signal == "mount[1].F[3]"]
    peak = force.groupby(["case", "order"]).amplitude.max().unstack("order")
    assert peak.loc["inline-3 (M13)", 1.5] > 3 * peak.loc["inline-3 (M13)", 2.0]
    assert peak.loc["inline-4", 2.0] > 10 * peak.loc["inline-4", 1.5]
    assert (tmp_path / "study_waterfall_mount1.F3.png").exists()


def test_a_periodic_start_gives_the_orders_of_a_long_settled_run(fmu_path):
    """Through the FMU (initialization.periodic): a window right after initialisation has the
    order amplitudes of a window after 300 settling revolutions (scene 1, 1800 rpm)."""
    signals = ["mount[1].F[3]", "mount[3].F[1]"]
    solver = (("solver.relTol", 1e-7), ("solver.absTol", 1e-10))
    periodic = OperatingPoint(rpm=1800.0, revolutions=8, parameters=solver)
    settled = OperatingPoint(rpm=1800.0, revolutions=8, periodic=False, settle_revolutions=300,
                             parameters=solver)
    with Runner(str(fmu_path)) as runner:
        a = runner.run_point(periodic, signals)["samples"]
        b = runner.run_point(settled, signals)["samples"]
    for j, signal in enumerate(signals):
        oa = order_amplitudes(a[:, j], 8, [1.5, 3.0, 4.5])
        ob = order_amplitudes(b[:, j], 8, [1.5, 3.0, 4.5])
        for order in oa:
            assert abs(oa[order] - ob[order]) <= 1e-3 * ob[order], (signal, order, oa[order], ob[order])


def test_settle_options_are_checked(fmu_path, tmp_path, capsys):
    from emc.cli import main

    base = ["sweep", "--fmu", str(fmu_path), "--rpm", "1500", "2000", "--count", "2",
            "--revolutions", "4", "--serial", "--quiet", "--out", str(tmp_path)]
    assert main(base + ["--settle", "6"]) == 2
    assert "--start settle" in capsys.readouterr().err
    assert main(base + ["--start", "settle", "--settle", "-5"]) == 2
    assert ">= 0" in capsys.readouterr().err
    assert main(base + ["--start", "settle", "--settle", "6"]) == 0
