"""A cluster as the Dask page sets it up: `dask scheduler` and `dask worker` started as processes
on localhost, the worker with several threads (Dask's default is one per core), and emc's
commands on it give the serial numbers to the bit; workers that would give other numbers (other
software, other or missing configuration files) are refused before anything runs."""

import json
import os
import pathlib
import shutil
import subprocess
import sys
import time

import pandas as pd
import pytest

from emc.cli import main
from emc.running.distributed import (ClusterMismatch, FmuPool, file_mismatches, identity_mismatches,
                                     settings_files, software_identity)

DASK = str(pathlib.Path(sys.executable).with_name("dask"))


class Cluster:
    """A scheduler and workers as separate processes, as on a real cluster."""

    def __init__(self, folder: pathlib.Path):
        folder.mkdir(parents=True, exist_ok=True)
        self.folder = folder
        self.file = folder / "scheduler.json"
        self.processes: list[subprocess.Popen] = []
        self.logs = []
        self.start([DASK, "scheduler", "--scheduler-file", str(self.file), "--port", "0",
                    "--no-dashboard", "--host", "127.0.0.1"], "scheduler")
        deadline = time.monotonic() + 60
        while not self.file.exists():
            if time.monotonic() > deadline or self.processes[0].poll() is not None:
                raise RuntimeError(f"the scheduler did not start: {self.log_text()}")
            time.sleep(0.2)
        self.address = json.loads(self.file.read_text())["address"]

    def start(self, command: list[str], name: str, env: dict | None = None):
        log = open(self.folder / f"{name}.log", "w")
        self.logs.append(log)
        self.processes.append(subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT,
                                               env=env, cwd=self.folder))

    def add_worker(self, threads: int, name: str = "worker", env: dict | None = None):
        self.start([DASK, "worker", self.address, "--nthreads", str(threads), "--nworkers", "1",
                    "--no-dashboard", "--host", "127.0.0.1", "--name", name], name, env)

    def wait_for(self, threads: int):
        from dask.distributed import Client

        with Client(self.address, timeout=60) as client:
            deadline = time.monotonic() + 90
            while sum(w["nthreads"] for w in client.scheduler_info()["workers"].values()) < threads:
                if time.monotonic() > deadline:
                    raise RuntimeError(f"the workers did not join: {self.log_text()}")
                time.sleep(0.2)

    def log_text(self) -> str:
        for log in self.logs:
            log.flush()
        return "\n".join(p.read_text() for p in sorted(self.folder.glob("*.log")))

    def close(self):
        for process in reversed(self.processes):
            process.terminate()
        for process in reversed(self.processes):
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
        for log in self.logs:
            log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """One worker process with four threads (what `dask worker` gives a 4-core machine)."""
    cluster = Cluster(tmp_path_factory.mktemp("cluster"))
    try:
        cluster.add_worker(threads=4)
        cluster.wait_for(threads=4)
        yield cluster
    finally:
        cluster.close()


def test_a_sweep_on_a_worker_with_four_threads_equals_the_serial_sweep(fmu_path, tmp_path,
                                                                      cluster):
    """The crash of a worker whose threads shared one instance (3 runs of 5 failed): now each
    running task has an instance of its own, and 16 scene-2 points come back as serially."""
    common = ["sweep", "--fmu", str(fmu_path), "--set", "scene=2", "--rpm", "800", "2500",
              "--count", "16", "--revolutions", "8", "--quiet",
              "--signal", "steeringWheel.a[3]", "--signal", "mount[1].F[3]"]
    assert main(common + ["--serial", "--out", str(tmp_path / "serial")]) == 0
    for run in range(2):
        out = tmp_path / f"cluster{run}"
        assert main(common + ["--scheduler", cluster.address, "--out", str(out)]) == 0
        for table in ("orders.csv", "spectra.csv"):
            pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "serial" / table),
                                          pd.read_csv(out / table), check_exact=True)
    assert "Traceback" not in cluster.log_text() and "signal 11" not in cluster.log_text()


def test_a_doe_on_a_worker_with_four_threads_equals_the_serial_doe(fmu_path, tmp_path, cluster):
    common = ["doe", "--fmu", str(fmu_path), "--var", "mount[1].stiffnessScale",
              "--var", "mount[2].dampingScale", "--method", "sobol", "--samples", "2",
              "--rpm", "1000", "1600", "--count", "3", "--revolutions", "2", "--quiet"]
    assert main(common + ["--serial", "--out", str(tmp_path / "serial")]) == 0
    assert main(common + ["--scheduler", cluster.address, "--out", str(tmp_path / "cluster")]) == 0
    # Every column but the evaluations' wall-clock seconds.
    serial = pd.read_csv(tmp_path / "serial" / "designs.csv").drop(columns="seconds")
    parallel = pd.read_csv(tmp_path / "cluster" / "designs.csv").drop(columns="seconds")
    assert len(serial) == 8
    pd.testing.assert_frame_equal(serial, parallel, check_exact=True)


def test_the_pool_counts_every_thread_of_every_worker_and_warms_an_instance_for_each(
        fmu_path, cluster):
    with FmuPool(str(fmu_path), scheduler=cluster.address) as pool:
        assert pool.workers == 4
        pool.warm()

        from emc.running.batches import idle_count

        assert list(pool.client.run(idle_count, pool.sha256).values()) == [4]


def test_a_worker_with_other_software_is_refused_naming_both_versions(fmu_path, tmp_path,
                                                                      cluster):
    """A worker that imports another checkout of emc (here a copy with one line more) could give
    other numbers: the pool refuses the cluster, naming that worker's emc and this one's."""
    import emc

    copy = tmp_path / "other" / "emc"
    shutil.copytree(pathlib.Path(emc.__file__).parent, copy,
                    ignore=shutil.ignore_patterns("__pycache__"))
    with open(copy / "signals" / "spectra.py", "a") as f:
        f.write("\n# a change on that worker only\n")
    other = Cluster(tmp_path / "c2")
    try:
        other.add_worker(threads=1, name="other",
                         env={**os.environ, "PYTHONPATH": str(copy.parent)})
        other.wait_for(threads=1)
        with pytest.raises(ClusterMismatch) as error:
            FmuPool(str(fmu_path), scheduler=other.address)
        ours = software_identity()["emc"]
        message = str(error.value)
        assert "worker tcp://127.0.0.1:" in message and ours in message
        assert message.count("emc 0.") == 2 and "source" in message
    finally:
        other.close()


def test_comparing_identities_and_files_names_the_worker_and_both_sides():
    local = {"emc": "0.2.0 (source aaaa)", "fmpy": "0.3.32", "numpy": "2.4.6"}
    assert identity_mismatches(local, {"tcp://a:1": dict(local)}) == []
    [line] = identity_mismatches(local, {"tcp://a:1": dict(local),
                                         "tcp://b:2": {**local, "numpy": "2.3.0"}})
    assert line.startswith("worker tcp://b:2 runs") and "numpy 2.3.0" in line
    assert "this process runs emc 0.2.0 (source aaaa), fmpy 0.3.32, numpy 2.4.6" in line
    # A file: missing on one worker, another copy on a second; right on a third.
    files = {"/c/car.json": "1" * 64}
    workers = {"tcp://a:1": {"/c/car.json": "1" * 64}, "tcp://b:2": {"/c/car.json": None},
               "tcp://c:3": {"/c/car.json": "2" * 64}}
    assert file_mismatches(files, workers) == [
        "/c/car.json is missing on worker tcp://b:2",
        "/c/car.json differs on worker tcp://c:3 (sha256 222222222222… against this "
        "process's 111111111111…)"]
    # A file only the workers have: they must agree among themselves.
    assert file_mismatches({"/c/car.json": None}, workers)[1].endswith(
        "against another worker's 111111111111…)")


def test_settings_files_are_the_configuration_and_its_body(tmp_path):
    config = tmp_path / "car.json"
    config.write_text(json.dumps({"extends": "default", "body": {"kind": "nastran",
                                                                  "path": "body/main.bdf"}}))
    assert settings_files({"configFile": str(config)}) == [str(config),
                                                           str(tmp_path / "body" / "main.bdf")]
    assert settings_files({"configFile": "vehicle_i4.json"}) == []  # in the FMU's resources
    assert settings_files({}) == []


def test_a_configuration_missing_on_the_workers_is_refused_before_anything_runs(
        fmu_path, tmp_path, cluster, capsys):
    """The workers read an absolute configFile from their own file system: one they lack is a
    one-line error naming the file and the worker, before any point runs."""
    missing = tmp_path / "nowhere" / "car.json"
    status = main(["sweep", "--fmu", str(fmu_path), "--set", f"configFile={missing}",
                   "--rpm", "1000", "1200", "--count", "2", "--scheduler", cluster.address,
                   "--quiet", "--out", str(tmp_path / "out")])
    errors = [line for line in capsys.readouterr().err.splitlines() if line.startswith("error")]
    assert status == 2 and len(errors) == 1, errors
    assert errors[0].startswith(f"error: {missing} is missing on worker tcp://127.0.0.1:")
    assert "from its own file system" in errors[0]
    assert not (tmp_path / "out" / "orders.csv").exists()
