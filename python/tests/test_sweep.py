"""The sweep tool: exact order analysis, and sweeps on pools equal to serial ones."""

import os
import time
from multiprocessing import connection

import numpy as np
import pandas as pd
import pytest

from emc.base.errors import WorkerLost
from emc.running.local_pool import LocalPool
from emc.running.runner import OperatingPoint, PointFailed, Runner
from emc.running.sweep import run_sweep, speed_points
from emc.signals.spectra import ORDERS, amplitude_spectrum, order_amplitudes


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


def test_pool_sweeps_equal_the_serial_sweep_for_any_worker_count(fmu_path):
    """Workers keep their instance from batch to batch: whatever the worker count and batching,
    the tables are the serial sweep's to the bit (scene 2, five points). The Dask cluster's
    pool is compared in the same way in test_cluster.py and by the scaling benchmark's test."""
    points = speed_points(900, 2100, 5, revolutions=4)
    signals = ["mount[1].F[3]", "mount[3].F[1]", "steeringWheel.a[3]"]
    serial = run_sweep(str(fmu_path), points, signals, parallel=False, progress=False)
    for workers in (1, 2, 3):
        with LocalPool(str(fmu_path), workers=workers, batches_per_worker=2) as pool:
            assert pool.workers == workers
            # Twice on the same pool: the second sweep runs on instances already used.
            for _ in range(2):
                parallel = run_sweep(str(fmu_path), points, signals, progress=False, pool=pool)
                for a, b in zip(serial, parallel):
                    pd.testing.assert_frame_equal(a, b, check_exact=True)
    orders = serial[0]
    assert set(orders.rpm) == {900.0, 1200.0, 1500.0, 1800.0, 2100.0}
    # the 1.5 order of the gas torque dominates the vertical mount force
    main = orders[(orders.signal == "mount[1].F[3]") & (orders.order == 1.5)].amplitude
    other = orders[(orders.signal == "mount[1].F[3]") & (orders.order.isin([2.5, 3.5]))].amplitude
    assert main.min() > 10 * other.max()


def _where(runner, item):
    return os.getpid(), id(runner)


def _exit(runner, item):
    os._exit(7)


def _fail_first_sleep_after(runner, item):
    if item == 0:
        raise PointFailed("item 0 refused", ("[error] logStatusError: item 0 refused",))
    time.sleep(60)
    return item


def test_a_local_pools_workers_each_keep_the_instance_they_made_at_start(fmu_path):
    with LocalPool(str(fmu_path), workers=2) as pool:
        first = pool.map(_where, range(8), batches=4)
        second = pool.map(_where, range(8), batches=4)
    instances = {}
    for pid, runner in first + second:
        instances.setdefault(pid, set()).add(runner)
    assert os.getpid() not in instances and len(instances) <= 2
    assert all(len(runners) == 1 for runners in instances.values()), instances


def test_a_failure_on_a_local_pool_cancels_the_rest_and_stops_its_busy_worker(fmu_path):
    pool = LocalPool(str(fmu_path), workers=2)
    processes = list(pool.executor._processes.values())
    started = time.monotonic()
    try:
        with pytest.raises(PointFailed, match="item 0 refused"):
            pool.map(_fail_first_sleep_after, [0, 1], batches=2)
    finally:
        pool.close()
    # The other worker sleeps in its batch: it is terminated, not waited for.
    assert time.monotonic() - started < 20
    ended = connection.wait([p.sentinel for p in processes], timeout=0)
    assert len(processes) == 2 and len(ended) == 2


def test_an_engine_gives_the_same_points_here_and_on_a_pool_and_counts_them(fmu_path):
    import functools

    from emc.running.engine import PointEngine
    from emc.running.sweep import sweep_point

    points = speed_points(1000, 2000, 3, revolutions=2, parameters=(("scene", 1),))
    evaluate = functools.partial(sweep_point, signals=["mount[1].F[3]"], case="")
    here = PointEngine.on(str(fmu_path))
    try:
        serial = here.map(evaluate, points)
    finally:
        here.close()
    with LocalPool(str(fmu_path), workers=2) as pool:
        on_pool = PointEngine.on(str(fmu_path), pool)
        parallel = on_pool.map(evaluate, points) + on_pool.map(evaluate, points[:1])
        on_pool.close()
        assert pool.map(_where, [0])  # the engine leaves the pool open
    assert here.runner is None and here.points == 3 and here.cpu_s > 0
    assert on_pool.points == 4 and on_pool.cpu_s > 0
    for (a, _), (b, _) in zip(serial + serial[:1], parallel):
        assert np.array_equal(a.order_amplitude, b.order_amplitude)
        assert np.array_equal(a.amplitude, b.amplitude)


def _kill(runner, item):
    os.kill(os.getpid(), 9)


def test_a_worker_that_dies_is_reported_with_how_it_ended(fmu_path):
    for _ in range(3):  # the executor forgets a lost worker at once: the cause must not race
        with LocalPool(str(fmu_path), workers=2) as pool:
            with pytest.raises(WorkerLost, match=r"\(exit code 7\)"):
                pool.map(_exit, [0, 1, 2])
    with LocalPool(str(fmu_path), workers=2) as pool:
        with pytest.raises(WorkerLost, match=r"\(signal 9\)"):
            pool.map(_kill, [0, 1, 2])


def test_batches_interleave_the_items_and_cover_each_once():
    from emc.running.batches import interleaved_batches

    assert interleaved_batches(7, 3) == [[0, 3, 6], [1, 4], [2, 5]]
    assert interleaved_batches(2, 8) == [[0], [1]]
    groups = interleaved_batches(48, 8)
    assert sorted(i for g in groups for i in g) == list(range(48))


def test_guided_batches_shrink_to_single_items_and_spread_over_the_items():
    from emc.running.batches import guided_batches, guided_sizes

    assert guided_sizes(48, 2) == [12, 12, 6, 6, 3, 3, 2, 2, 1, 1]
    sizes = guided_sizes(192, 16)
    assert sum(sizes) == 192 and sizes == sorted(sizes, reverse=True)
    assert sizes[:16] == [6] * 16 and sizes[-16:] == [1] * 16, "the last round: single items"
    assert guided_sizes(5, 8) == [1] * 5 and guided_sizes(1, 1) == [1]
    for count, workers in ((48, 2), (192, 16), (7, 3), (1000, 5)):
        batches = guided_batches(count, workers)
        assert [len(b) for b in batches] == guided_sizes(count, workers)
        assert sorted(i for b in batches for i in b) == list(range(count))
        # The j-th of a batch's k items lies within 1.5 places of the j-th k-th of the range:
        # every batch holds slow and fast points alike.
        for batch in batches:
            k = len(batch)
            assert all(abs(j - k * i / count) < 1.5 for j, i in enumerate(batch)), (count, batch)


def test_a_maps_anatomy_splits_the_workers_time():
    from emc.running.batches import BatchRecord, MapRecord

    # Two workers over 10 s: one busy 1-9 s in two batches, the other 2-6 s; a third never used.
    record = MapRecord(100.0, 110.0, [BatchRecord(1, 7, 2, 101.0, 105.0, 3.5),
                                      BatchRecord(1, 7, 1, 105.0, 109.0, 4.0),
                                      BatchRecord(2, 7, 3, 102.0, 106.0, 3.0)])
    anatomy = record.anatomy(workers=3)
    assert anatomy["busy"] == 12.0 / 30.0
    assert anatomy["first_s"] == (1.0 + 2.0 + 10.0) / 3
    assert anatomy["tail_s"] == (1.0 + 4.0 + 10.0) / 3
    assert anatomy["cpu_s"] == 10.5 and anatomy["batches"] == 3


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


def test_order_amplitudes_on_and_off_the_bins_recover_a_known_signal():
    """The one order-amplitude routine: a window of whole samples per revolution (DFT bins) and
    one of 545.45… samples per revolution (the DFT at each order's own frequency), several
    signals at once, the mean removed."""
    rpm = 1100.0
    w = 2 * np.pi * rpm / 60.0
    for h in (60.0 / rpm / 72, 1e-4):
        per_revolution = 60.0 / rpm / h
        t = np.arange(int(round(12 * per_revolution))) * h
        x = 5.0 + 2.0 * np.cos(1.5 * w * t + 0.3) + 0.7 * np.sin(3.0 * w * t)
        a = order_amplitudes(np.column_stack([x, 2 * x]), 8, ORDERS, per_revolution)
        tol = 1e-9 if per_revolution == round(per_revolution) else 2e-3
        np.testing.assert_allclose(a[1.5], [2.0, 4.0], atol=tol)
        np.testing.assert_allclose(a[3.0], [0.7, 1.4], atol=tol)
        assert max(np.max(a[o]) for o in ORDERS if o not in (1.5, 3.0)) < tol


def test_instances_log_to_their_own_sink_and_outlive_each_other(fmu_path):
    """fmpy's logger proxy keeps one logger per process: each instance's messages must still
    reach its own log, and an instance closed first must not take the logger with it (a later
    message of the other one called freed memory: a segmentation fault)."""
    from emc.running.runner import PointFailed

    broken = OperatingPoint(rpm=1500.0, revolutions=2,
                            parameters=(("scene", 1), ("configFile", "/nonexistent/a.json")))
    first = Runner(str(fmu_path), instance_name="first")
    try:
        second = Runner(str(fmu_path), instance_name="second")
        with pytest.raises(PointFailed):
            second.run_point(broken, ["mount[1].F[3]"])
        assert any("/nonexistent/a.json" in line for line in second.log)
        assert not first.log
        second.close()
        with pytest.raises(PointFailed) as failure:
            first.run_point(broken, ["mount[1].F[3]"])
        assert "/nonexistent/a.json" in failure.value.cause
        assert any(line.startswith("[error]") for line in first.log)
    finally:
        first.close()


def test_the_scaling_benchmark_checks_each_pool_run_and_splits_its_time(fmu_path):
    """The benchmark's plumbing, not its timings: every pool run is compared with the serial run
    to the bit, and a pool's time is accounted for (a share in batches, the evaluations' CPU)."""
    import io

    from emc.bench import scaling_points, scaling_table, scheduling_table

    points = scaling_points(3)
    table = scaling_table(str(fmu_path), points, workers=(2,), repeat=1,
                          batchings=("guided", "equal"), out=io.StringIO())
    assert list(table.workers) == ["serial", 2, 2, 2, 2] and table.identical.all()
    assert list(table.pool) == ["", "local", "local", "dask", "dask"]
    pools = table.iloc[1:]
    assert (pools.batches == 3).all() and ((pools.busy > 0) & (pools.busy <= 1)).all()
    assert (pools.task_cpu_s > 0).all() and (pools.tail_s >= 0).all()
    # Waits cannot overlap more than the workers do: the speed-up is at most their number.
    waits = [0.05] * 8
    scheduled = scheduling_table(str(fmu_path), waits, workers=(2,), repeat=1,
                                 batchings=("guided",), out=io.StringIO())
    assert list(scheduled.pool) == ["local", "dask"]
    assert ((0 < scheduled.speedup) & (scheduled.speedup <= 2.0)).all()
    assert (scheduled.ideal_s == sum(waits) / 2).all()


def test_the_command_line_keeps_freed_memory_for_reuse(monkeypatch):
    import platform

    from emc.running.runner import MALLOC_SETTINGS, keep_freed_memory

    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        assert keep_freed_memory() == []
        return
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    monkeypatch.setenv("MALLOC_TOP_PAD_", "0")
    # A setting the environment gives is the user's: left alone.
    assert keep_freed_memory() == ["MALLOC_TRIM_THRESHOLD_"]
    monkeypatch.delenv("MALLOC_TOP_PAD_")
    assert keep_freed_memory() == list(MALLOC_SETTINGS)
