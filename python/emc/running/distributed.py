"""Many FMU evaluations on a Dask cluster (``--scheduler``; :mod:`.batches` says how any pool
keeps its instances and batches its items).

A cluster's workers need not share this machine's file system or software:

- **The FMU's bytes reach each worker once**, in a worker plugin (workers that join the cluster
  later get it too); the worker writes them to its temporary directory under their checksum.
- **Every worker is checked before anything runs**: the same emc, fmpy and numpy as this process,
  and the same content of every file the settings make the FMU read (:class:`ClusterMismatch`).
- **A worker may have any number of threads**: each running task has an instance of its own.

    with FmuPool("dist/EngineMountChassis.fmu", scheduler="tcp://host:8786") as pool:
        results = pool.map(evaluate, items)      # evaluate(runner, item) on the workers

Without a scheduler it starts a local Dask cluster (the scaling benchmark compares its threads
and processes); the commands' local pools are :class:`emc.running.local_pool.LocalPool`.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import os
from importlib import metadata
from typing import Callable, Iterable

import dask
import fmpy
import numpy
from dask.distributed import Client, LocalCluster, as_completed, get_worker
from distributed.diagnostics.plugin import WorkerPlugin

from ..base.errors import ClusterMismatch
from ..base.fmu import file_sha256
from .batches import (START_METHOD, BatchPool, forget_idle, serve_fmu, sigint_ignored,
                      warm_instances)
from .runner import MALLOC_SETTINGS, fmu_from_content, keep_freed_memory

# Local workers: Dask's nanny starts them with MALLOC_TRIM_THRESHOLD_=65536 so that they hand
# memory back to the system; glibc then trims the FMU's short-lived allocations at every free, and
# a worker needed 15-20 % more CPU time per point than the same loop in the caller (thread CPU
# time of 8 scene-2 points, 0.63-0.69 s against 0.54-0.58 s). With the large trim threshold and
# top pad of emc.running.runner.MALLOC_SETTINGS (which the command-line tools set in their own process
# too) it needs the same. Without the sampling profiler a worker runs only the study. Dask's
# periodic housekeeping (an event-loop tick every 20 ms, system and memory monitors every
# 0.5 s and 0.1 s, work stealing every 0.1 s) cost the caller 4 % and each worker 2 % of a core
# while a study runs; at 1-5 s they cost a tenth of that (2 workers, 48 scene-2 points: all
# processes together within 1-4 % of the serial loop's CPU time instead of 22 % above it).
# Local workers are forked where the system allows it (batches.START_METHOD), on Dask's event-loop
# thread while the calling thread waits for the cluster.
WORKER_CONFIG = {
    "distributed.worker.multiprocessing-method": START_METHOD,
    "distributed.nanny.pre-spawn-environ": {
        **MALLOC_SETTINGS, "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1},
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "2s",
    "distributed.scheduler.work-stealing-interval": "1s",
}


class FmuPlugin(WorkerPlugin):
    """Puts the FMU's bytes on every worker once (also on workers that join later)."""

    def __init__(self, content: bytes, sha256: str):
        self.content = content
        self.sha256 = sha256
        self.name = f"emc-fmu-{sha256[:16]}"

    def setup(self, worker):
        serve_fmu(self.sha256, fmu_from_content(self.content, self.sha256))
        # The FMU's short-lived workspaces stay with the worker (as in emc's own process).
        keep_freed_memory()

    def teardown(self, worker):
        # The files stay extracted for the next pool here.
        forget_idle(self.sha256)


@functools.cache
def software_identity() -> dict:
    """What decides a worker's numbers besides the FMU (which travels by content): emc's version
    and a checksum of its source files (two checkouts of one version differ there), fmpy's and
    numpy's versions."""

    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # emc/
    digest = hashlib.sha256()
    for folder, dirs, files in sorted(os.walk(package)):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(f for f in files if f.endswith(".py")):
            path = os.path.join(folder, name)
            digest.update(os.path.relpath(path, package).encode())
            with open(path, "rb") as f:
                digest.update(f.read())
    try:
        version = metadata.version("emc")
    except metadata.PackageNotFoundError:
        version = "unknown"
    return {"emc": f"{version} (source {digest.hexdigest()[:12]})", "fmpy": fmpy.__version__,
            "numpy": numpy.__version__}


def describe_identity(identity: dict) -> str:
    return ", ".join(f"{name} {value}" for name, value in identity.items())


def identity_mismatches(local: dict, workers: dict[str, dict]) -> list[str]:
    """One line per worker whose software differs from ``local``, naming both."""
    return [f"worker {address} runs {describe_identity(theirs)}; this process runs "
            f"{describe_identity(local)}"
            for address, theirs in sorted(workers.items()) if theirs != local]


def file_digest(path: str) -> str | None:
    """The SHA-256 of the file at ``path``, None if there is none."""
    try:
        return file_sha256(path)
    except OSError:
        return None


def _file_digests(paths: list[str]) -> dict[str, str | None]:
    return {path: file_digest(path) for path in paths}


def settings_files(parameters: dict) -> list[str]:
    """The files an absolute ``configFile`` among ``parameters`` makes the FMU read: the
    configuration itself and the body file it names (a deck, a DMIG punch or a reduced body;
    relative to the configuration's folder). INCLUDE files of a deck are not followed. A
    configuration that does not read as JSON is left to the FMU's own message."""
    name = str(parameters.get("configFile", "") or "")
    if not name or not os.path.isabs(name):
        return []
    files = [name]
    try:
        with open(name, encoding="utf-8") as f:
            body = json.load(f).get("body", {})
        path = body.get("path") if isinstance(body, dict) else None
    except (OSError, ValueError, AttributeError):
        path = None
    if isinstance(path, str) and path:
        files.append(os.path.normpath(os.path.join(os.path.dirname(name), path)))
    return files


def file_mismatches(local: dict[str, str | None], workers: dict[str, dict]) -> list[str]:
    """One line per file a worker lacks, or holds with other content than this process (where
    this process has it) or than the other workers (where it does not)."""
    lines = []
    for path in sorted({p for digests in workers.values() for p in digests} | set(local)):
        seen = {address: digests.get(path) for address, digests in sorted(workers.items())}
        reference = local.get(path) or next((d for d in seen.values() if d), None)
        for address, digest in seen.items():
            if digest is None:
                lines.append(f"{path} is missing on worker {address}")
            elif reference is not None and digest != reference:
                whose = "this process's" if local.get(path) else "another worker's"
                lines.append(f"{path} differs on worker {address} (sha256 {digest[:12]}… "
                             f"against {whose} {reference[:12]}…)")
    return lines


def _warm_up(sha256: str, evaluate: Callable | None, item, dask_worker=None):
    """Run on each worker by :meth:`FmuPool.warm`: as many idle instances as the worker has
    threads, each through ``evaluate(runner, item)`` once."""
    if dask_worker is None:
        try:
            dask_worker = get_worker()  # as a task (warm_soon) rather than through client.run
        except ValueError:
            dask_worker = None
    threads = dask_worker.state.nthreads if dask_worker is not None else 1
    warm_instances(sha256, threads, evaluate, item)


def _quiet_teardown():
    """Run on a local pool's workers before it closes: errors while closing are not logged."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


class FmuPool(BatchPool):
    """A Dask cluster whose workers each hold a warm instance of one FMU.

    ``scheduler``: the address of a running Dask scheduler (its workers get the FMU by content:
    they need not share the caller's file system, and may have any number of threads: each
    running task has an instance of its own); else a local Dask cluster of ``workers`` processes
    with ``threads_per_worker`` threads each. ``batches_per_worker``: ``None`` for shrinking
    (guided) batches, a number for that many equal batches per worker.
    """

    def __init__(self, fmu_path: str, workers: int = 2, scheduler: str | None = None,
                 batches_per_worker: int | None = None, files: Iterable[str] = (),
                 threads_per_worker: int = 1):
        """``threads_per_worker``: of a local cluster (one by default: processes keep the
        instances' memory apart, and need not share the GIL). ``files``: files the settings make the FMU read by absolute path (see
        :func:`settings_files`); every worker must see each with the same content as this
        process, checked before anything runs like the workers' software
        (:class:`ClusterMismatch`)."""

        with open(fmu_path, "rb") as f:
            self.content = f.read()
        self.sha256 = hashlib.sha256(self.content).hexdigest()
        self.batches_per_worker = batches_per_worker
        self.cluster = None
        self._warming: list = []
        if scheduler:
            self.client = Client(scheduler)
        else:
            # Worker logs below ERROR (cancelled tasks after a failure, …) would bury the cause.
            with dask.config.set(WORKER_CONFIG), sigint_ignored():
                self.cluster = LocalCluster(n_workers=workers,
                                            threads_per_worker=threads_per_worker,
                                            processes=True, dashboard_address=None,
                                            silence_logs=logging.ERROR)
            self.client = Client(self.cluster)
        try:
            self.check_workers(list(files))
            self.client.register_plugin(FmuPlugin(self.content, self.sha256))
        except BaseException:
            self.close()
            raise

    def check_workers(self, files: list[str]):
        """Refuses workers whose software differs from this process's, or that lack one of
        ``files`` or hold another copy (:class:`ClusterMismatch`, one line per defect)."""
        try:
            identities = self.client.run(software_identity)
        except (ImportError, AttributeError) as error:
            # Its functions are sent by reference: a worker without this emc cannot run them.
            raise ClusterMismatch(f"a worker cannot run emc's functions ({error}): install the "
                                  "same emc on every worker (pip install ./python)") from None
        software = identity_mismatches(software_identity(), identities)
        files = file_mismatches(_file_digests(files), self.client.run(_file_digests, files)) \
            if files else []
        problems = software + files
        if problems:
            more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
            remedy = []
            if software:
                remedy.append("install the same emc, fmpy and numpy on every worker as here "
                              "(pip install the same ./python)")
            if files:
                remedy.append("a worker reads the files the settings name from its own file "
                              "system: give it them at the same path with the same content (a "
                              "shared file system or a copy)")
            raise ClusterMismatch("; ".join(problems[:3]) + more + ": " + "; ".join(remedy))

    @property
    def workers(self) -> int:
        """The task slots: the threads of all workers (each runs one evaluation at a time)."""
        workers = self.client.scheduler_info()["workers"].values()
        return max(1, sum(w.get("nthreads", 1) for w in workers))

    def warm(self, evaluate: Callable | None = None, item=None):
        """Creates every worker's instances now, one per thread (and runs ``evaluate(runner,
        item)`` once on each, e.g. a point that reads the reduced body from the cache), so that a
        timed study that follows pays for neither."""
        self.client.run(_warm_up, self.sha256, evaluate, item)

    def warm_soon(self):
        """Has every worker make its instances in the background, as a task pinned to it, while
        the caller goes on (its own checks, its questions to the FMU): a map that follows finds
        them made, or queues behind their making on that worker. A failure there is the first
        map's to report: its points make an instance again and fail with the FMU's message."""
        # A worker of several threads is left to make its instances as its tasks come: a task
        # beside the warming one would make one more than the worker has threads.
        self._warming = [self.client.submit(_warm_up, self.sha256, None, None, pure=False,
                                            workers=[address], allow_other_workers=False)
                         for address, worker in self.client.scheduler_info()["workers"].items()
                         if worker.get("nthreads", 1) == 1]

    def _submit(self, function: Callable, *args):
        return self.client.submit(function, *args, pure=False)

    def _completed(self, futures: Iterable):
        return as_completed(futures)

    def _cancel(self, futures: list):
        self.client.cancel(futures)

    def close(self):
        self._warming = []
        if self.cluster is not None:
            # A worker whose heartbeat meets the closing scheduler logs the closed connection as
            # an error with its traceback (seen with 16 workers on 2 cores): noise after the
            # study's results, not a failure of it.
            try:
                self.client.run(_quiet_teardown)
            except Exception:  # noqa: BLE001 - a worker already gone needs no quieting
                pass
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()
