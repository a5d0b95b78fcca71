"""Every result with its band: the damping bounds as FMU settings, a study run at low, nominal
and high, tables with all three, plots that fill the band and draw the nominal line; and emc's
sweep and run-up with --band on the packaged FMU (a lower damping scale must raise the response
at a body resonance, which the bounds' order must show)."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import PolyCollection

from emc import cli
from emc.figures import plots
from emc.running import band


def test_the_default_band_scales_body_and_mounts_to_the_ends_of_their_ranges():
    b = band.Band.damping()
    assert b.low["chassis.modalDampingScale"] == 0.6
    assert b.high["chassis.modalDampingScale"] == 1.4
    # The mounts paired the other way round: their damping transmits force to the body.
    assert [b.low[f"mount[{i}].dampingScale"] for i in range(1, 5)] == [4 / 3] * 4
    assert b.high["mount[2].dampingScale"] == 2 / 3
    assert b.nominal == {}
    # Scales multiply a case's own scale; the nominal leaves it alone.
    case = {"scene": 2, "chassis.modalDampingScale": 2.0}
    assert b.applied(case, "high")["chassis.modalDampingScale"] == pytest.approx(2.8)
    assert b.applied(case, "low")["mount[3].dampingScale"] == pytest.approx(4 / 3)
    assert b.applied(case, "nominal") == case
    only_body = band.Band.damping(mounts=None)
    assert set(only_body.low) == {"chassis.modalDampingScale"}


@pytest.mark.parametrize("body", [(1.2, 1.4), (0.5, 0.9), (-0.1, 2.0), (np.nan, 2.0)])
def test_bounds_must_enclose_the_nominal(body):
    with pytest.raises(ValueError, match="enclose 1"):
        band.Band.damping(body=body)


def test_run_band_holds_three_results_and_stacks_them():
    calls = []

    def study(settings, bound):
        calls.append((bound, settings))
        return pd.DataFrame({"rpm": [1000.0, 2000.0],
                             "level": [1.0 / settings.get("chassis.modalDampingScale", 1.0),
                                       0.5]})

    result = band.run_band(study, band.Band.damping(mounts=None), base={"scene": 2})
    assert [c[0] for c in calls] == ["low", "nominal", "high"]
    assert all(c[1]["scene"] == 2 for c in calls)
    assert result.low.level[0] == pytest.approx(1 / 0.6)
    table = result.stack()
    assert list(table.bound.unique()) == ["low", "nominal", "high"]
    wide = band.wide(table, ["rpm"], ["level"])
    assert list(wide.columns) == ["rpm", "level_low", "level_nominal", "level_high"]
    assert wide.level_high[0] == pytest.approx(1 / 1.4)
    assert wide.level_nominal[1] == 0.5


def test_draw_band_fills_between_the_bounds_and_draws_the_nominal():
    x = np.array([1.0, 2.0, 3.0])
    low, nominal, high = np.array([4.0, 1.0, 3.0]), np.array([3.0, 1.5, 2.0]), np.array(
        [2.0, 2.0, 1.0])
    fig, ax = plt.subplots()
    try:
        line = plots.draw_band(ax, x, low, nominal, high, label="wheel")
        assert np.allclose(line.get_ydata(), nominal) and line.get_label() == "wheel"
        (fill,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
        ys = fill.get_paths()[0].vertices[:, 1]
        # The filled region spans, at each x, from the lower to the higher bound.
        assert ys.min() == 1.0 and ys.max() == 4.0
        assert np.allclose(fill.get_facecolor()[0][:3],
                           plt.matplotlib.colors.to_rgb(line.get_color()))
    finally:
        plt.close(fig)


def synthetic_orders():
    rows = []
    for bound, scale in (("low", 2.0), ("nominal", 1.0), ("high", 0.7)):
        for case in ("", "stiff"):
            for rpm in (1000.0, 1500.0, 2000.0):
                for order in (1.0, 1.5, 2.0, 3.0, 4.5):
                    rows.append({"case": case, "rpm": rpm, "signal": "x", "order": order,
                                 "frequency": order * rpm / 60, "amplitude": scale * order,
                                 "bound": bound})
    return pd.DataFrame(rows)


def test_order_cuts_and_comfort_draw_a_band_per_case():
    fig = plots.order_cuts_figure(synthetic_orders(), "x", unit="m/s2")
    try:
        panels = [ax for ax in fig.axes if ax.get_visible()]
        assert len(panels) == 5
        for ax in panels:
            assert len([c for c in ax.collections if isinstance(c, PolyCollection)]) == 2
            assert len(ax.lines) == 2
    finally:
        plt.close(fig)
    comfort = pd.DataFrame([{"case": "", "rpm": r, "bound": b, "wheel_ahv": s * r / 1000,
                             "seat_av_comfort": s} for r in (1000.0, 2000.0)
                            for b, s in (("low", 2.0), ("nominal", 1.0), ("high", 0.5))])
    fig = plots.comfort_figure(comfort)
    try:
        assert len(fig.axes) == 2
        for ax in fig.axes:
            assert len([c for c in ax.collections if isinstance(c, PolyCollection)]) == 1
    finally:
        plt.close(fig)


def test_a_sweep_with_its_band_on_the_fmu(fmu_path, tmp_path, capsys):
    """The steering wheel's 1.5 order at 1250 rpm (31 Hz: the steering-column modes): the low
    bound above the nominal above the high bound; tables carry all three."""
    out = tmp_path / "band"
    code = cli.main(["sweep", "--fmu", str(fmu_path), "--out", str(out), "--serial", "--quiet",
                     "--count", "1", "--rpm", "1250", "1250", "--revolutions", "4",
                     "--signal", "steeringWheel.a[3]", "--band"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    orders = pd.read_csv(out / "orders.csv")
    assert sorted(orders.bound.unique()) == ["high", "low", "nominal"]
    wide = pd.read_csv(out / "order_band.csv")
    row = wide[np.isclose(wide.order, 1.5)].iloc[0]
    assert row.amplitude_low > row.amplitude_nominal > row.amplitude_high > 0.0
    assert (out / "order_cuts_steeringWheel.a3.png").exists()
    metadata = json.loads((out / "metadata.json").read_text())
    assert metadata["band"]["low"]["chassis.modalDampingScale"] == 0.6
    assert "3 points" in captured.out


def test_band_options_are_checked(fmu_path, tmp_path, capsys):
    code = cli.main(["sweep", "--fmu", str(fmu_path), "--out", str(tmp_path / "x"), "--serial",
                     "--count", "1", "--rpm", "1250", "1250", "--band-body", "1.2", "2"])
    err = capsys.readouterr().err
    assert code == 2 and "enclose 1" in err, err
    assert not (tmp_path / "x").exists()
