"""What the field reads: waterfalls as dB colour maps with a labelled colour bar (re 1 µm/s² for
accelerations, re 1 N for forces, 60 dB below the peak), order cuts in physical units stating
peak amplitude, cases overlaid on common axes with styles that keep coinciding curves visible,
order maps of run-ups. Built from synthetic tables, so the checks do not depend on the FMU."""

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.collections import QuadMesh

from emc.figures import plots
from emc.signals.spectra import ORDERS

SPEEDS = (1000.0, 1500.0, 2000.0)


def spectra_table(signal: str, peak: float, cases=("",)) -> pd.DataFrame:
    rows = []
    for case in cases:
        for rpm in SPEEDS:
            f1 = rpm / 60.0
            for k in range(0, 53):  # 8-revolution window: bins every 1/8 order, to 6.5 orders
                order = k / 8
                amplitude = peak if order == 1.5 else (peak / 100 if order % 0.5 == 0 else 0.0)
                rows.append({"case": case, "rpm": rpm, "signal": signal,
                             "frequency": order * f1, "amplitude": amplitude})
    return pd.DataFrame(rows)


def orders_table(signal: str, cases=("",), scale=None) -> pd.DataFrame:
    rows = []
    for j, case in enumerate(cases):
        for rpm in SPEEDS:
            for order in ORDERS:
                amplitude = (1.0 + order) * rpm / 1000 * ((scale or {}).get(case, 1.0)
                                                          if order == 1.0 else 1.0)
                rows.append({"case": case, "rpm": rpm, "signal": signal, "order": order,
                             "frequency": order * rpm / 60, "amplitude": amplitude})
    return pd.DataFrame(rows)


def colour_bar_axes(fig):
    return [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]


@pytest.mark.parametrize("unit,reference,peak", [("m/s2", "dB re 1 µm/s²", 2.0),
                                                 ("N", "dB re 1 N", 40.0)])
def test_waterfall_is_a_db_colour_map_with_a_labelled_colour_bar(unit, reference, peak):
    fig = plots.waterfall_figure(spectra_table("x", peak), "x", unit=unit)
    try:
        (bar,) = colour_bar_axes(fig)
        assert bar.get_ylabel() == f"peak amplitude [{reference}]"
        meshes = [c for c in fig.axes[0].collections if isinstance(c, QuadMesh)]
        assert len(meshes) == len(SPEEDS), "one strip per speed point"
        low, high = meshes[0].get_clim()
        peak_db = 20 * np.log10(peak / plots.level_reference(unit)[0])
        assert high - low == plots.DYNAMIC_RANGE_DB == 60.0
        assert peak_db <= high < peak_db + 5.0
        # The 1 % lines (-40 dB) are inside the colour range, not dropped.
        assert peak_db - 40.0 > low
        ax = fig.axes[0]
        assert ax.get_xlabel() == "engine speed [rpm]" and ax.get_ylabel() == "frequency [Hz]"
        labels = {t.get_text().strip() for t in ax.texts}
        assert {"1", "1.5", "3", "4.5"} <= labels, "order lines are labelled"
    finally:
        plt.close(fig)


def test_order_cuts_state_peak_amplitude_in_physical_units():
    fig = plots.order_cuts_figure(orders_table("F"), "F", unit="N")
    try:
        ax = fig.axes[0]
        assert ax.get_ylabel() == "amplitude (peak) [N]"
        assert ax.get_yscale() == "log"
        assert [t.get_text() for t in ax.get_legend().get_texts()] == [
            f"order {o:g}" for o in plots.MAIN_ORDERS]
    finally:
        plt.close(fig)


def test_cases_overlay_on_common_axes_in_the_given_order():
    cases = ["original", "no shaft", "stiffer plate"]
    table = orders_table("a", cases, scale={"no shaft": 30.0})
    fig = plots.order_cuts_figure(table, "a", unit="m/s2", cases=cases)
    try:
        panels = [ax for ax in fig.axes if ax.get_visible() and ax.lines]
        assert [ax.get_title() for ax in panels] == [f"order {o:g}" for o in plots.MAIN_ORDERS]
        for ax in panels:
            assert [line.get_label() for line in ax.lines] == cases
            # Coinciding curves (every order but the 1st here) stay distinguishable.
            assert len({line.get_linestyle() for line in ax.lines}) == len(cases)
            assert len({line.get_marker() for line in ax.lines}) == len(cases)
        assert len({ax.get_ylim() for ax in panels}) == 1, "common axes"
        assert panels[0].get_ylabel() == "amplitude (peak) [m/s²]"
        (legend,) = fig.legends
        assert [t.get_text() for t in legend.get_texts()] == cases
        first = panels[0]
        assert max(first.lines[1].get_ydata()) > 10 * max(first.lines[0].get_ydata())
    finally:
        plt.close(fig)


def test_side_by_side_waterfalls_share_one_colour_scale():
    cases = ["4 mounts", "3 mounts"]
    table = pd.concat([spectra_table("a", 2.0, cases[:1]), spectra_table("a", 0.5, cases[1:])])
    fig = plots.side_by_side_figure(table, "a", cases, unit="m/s2")
    try:
        panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
        assert [ax.get_title() for ax in panels] == cases
        clims = {c.get_clim() for ax in panels for c in ax.collections if isinstance(c, QuadMesh)}
        assert len(clims) == 1
        (bar,) = colour_bar_axes(fig)
        assert bar.get_ylabel() == "peak amplitude [dB re 1 µm/s²]"
    finally:
        plt.close(fig)


def test_order_map_of_run_up_cases():
    cases = ["a", "b"]
    fig = plots.order_map_figure(orders_table("F", cases), "F", unit="N", cases=cases)
    try:
        panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
        assert [ax.get_title() for ax in panels] == cases
        assert panels[0].get_ylabel() == "engine order"
        ticks = panels[0].get_yticks()
        assert np.allclose(ticks, ORDERS)
        (bar,) = colour_bar_axes(fig)
        assert bar.get_ylabel() == "peak amplitude [dB re 1 N]"
    finally:
        plt.close(fig)


def test_all_zero_order_cuts_do_not_break_the_log_axis():
    table = orders_table("wheel")
    table["amplitude"] = 0.0
    fig = plots.order_cuts_figure(table, "wheel", unit="m/s2")
    try:
        assert fig.axes[0].get_yscale() == "linear"
    finally:
        plt.close(fig)


def test_comfort_lines_follow_the_case_order():
    """The comfort plot colours the cases as the order cuts do (the order the cases were given,
    not the alphabet)."""
    table = pd.DataFrame({"case": ["b", "b", "a", "a"], "rpm": [1000, 2000, 1000, 2000],
                          "seat_av_comfort": [0.1, 0.2, 0.3, 0.4], "wheel_ahv": [1, 2, 3, 4]})
    fig = plots.comfort_figure(table, cases=["b", "a"])
    try:
        for ax in fig.axes:
            assert [line.get_label() for line in ax.lines] == ["b", "a"]
            assert [line.get_color() for line in ax.lines] == ["C0", "C1"]
            assert ax.get_ylabel() == "weighted RMS acceleration [m/s²]"
        assert list(fig.axes[1].lines[0].get_ydata()) == [1, 2]
    finally:
        plt.close(fig)


def _write(path, text):
    path.write_text(text)


def _fail(message):
    raise ValueError(message)


def test_figures_drawn_side_by_side_write_every_file_and_report_a_failure(tmp_path):
    """draw_all forks processes for the jobs beyond the first: every job's file is written, and
    a job that fails, here or in a child process, comes back as an error naming its cause."""
    import functools

    from emc.figures import draw_all

    jobs = [functools.partial(_write, tmp_path / f"{k}.txt", str(k)) for k in range(3)]
    draw_all(jobs)
    assert [(tmp_path / f"{k}.txt").read_text() for k in range(3)] == ["0", "1", "2"]
    with pytest.raises(RuntimeError, match="ValueError: the third figure"):
        draw_all([jobs[0], jobs[1], functools.partial(_fail, "the third figure")])
    with pytest.raises(RuntimeError, match="ValueError: the first figure"):  # this process's
        draw_all([functools.partial(_fail, "the first figure"), jobs[1]])
    # More jobs than processes: a failed job does not keep the others of its process from
    # writing, and every failure is named.
    many = [functools.partial(_write, tmp_path / f"m{k}.txt", str(k)) for k in range(8)]
    many[1] = functools.partial(_fail, "job one")
    many[0] = functools.partial(_fail, "job zero")
    with pytest.raises(RuntimeError) as failed:
        draw_all(many)
    assert "ValueError: job zero" in str(failed.value) and "ValueError: job one" in str(failed.value)
    assert all((tmp_path / f"m{k}.txt").read_text() == str(k) for k in range(2, 8))
