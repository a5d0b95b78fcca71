"""Many FMU evaluations on Dask, with one warm FMU instance per worker.

A study (a sweep, a design of experiments, an optimisation) evaluates the same FMU hundreds or
thousands of times. What each evaluation may cost besides its own simulation is kept small:

- **The FMU's bytes reach each worker once**, in a worker plugin (workers that join the cluster
  later get it too); the worker writes them to its temporary directory under their checksum.
- **Each worker keeps one instance per task it runs at once** (:class:`emc.running.runner.Runner`) for its
  life and reuses it from evaluation to evaluation: ``fmi2Reset`` brings it back to the
  instantiated state. A worker started with several threads (Dask's default: one per core) runs
  that many tasks at once; each task takes an instance no other task holds (FMI allows one call
  at a time per instance), so the threads compute in parallel (the FMU releases the GIL). Restoring an
  FMU state saved right after instantiation does the same and gives the same numbers to the bit;
  both cost well under a millisecond against 100–400 ms for a point (most of it the periodic
  start), so the plain reset is kept: there is no state to hold.
- **Evaluations go in batches**, several per task, so that scheduling is a small part of each
  task. By default the batches shrink as the study goes (guided self-scheduling): the first
  round gives each worker a batch of a ``2 × workers``-th of the items, each later round a
  ``2 × workers``-th of what is left, down to single items. Big batches at the start keep the
  scheduling cost small; single items at the end leave a worker idle for at most about one
  evaluation while the others finish. Each batch spreads over the items (a sweep's slow
  low-speed points over all batches). ``batches_per_worker=B`` gives the older scheme instead:
  ``B × workers`` equal interleaved batches.
- **Results come back in the order of the items**, and every evaluation starts from the reset
  instance: a study gives the same numbers to the bit, serially or on any number of workers.

    with FmuPool("dist/EngineMountChassis.fmu", workers=4) as pool:
        results = pool.map(evaluate, items)      # evaluate(runner, item) on the workers

``evaluate`` must be picklable (a module-level function, or a ``functools.partial`` of one) and
may raise :class:`emc.running.runner.PointFailed`; the first failure cancels the rest and is raised with
the FMU's log.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import logging
import math
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from importlib import metadata
from typing import Callable, Iterable

import dask
import fmpy
import numpy
from dask.distributed import Client, LocalCluster, as_completed, get_worker
from distributed.diagnostics.plugin import WorkerPlugin

from ..base.errors import ClusterMismatch
from .runner import (MALLOC_SETTINGS, PointFailed, Runner, extracted, fmu_from_content,
                     keep_freed_memory)

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
# Local workers are forked from the calling process where the system allows it (Linux): they
# start with its modules imported, a pool of 2 in 0.27-0.35 s against 1.8-2.4 s spawned (each
# worker importing dask, fmpy and emc anew; /tmp/poolstart-like timing of FmuPool and warm(),
# machine F under load, 2026-12-04). The fork happens on Dask's event-loop thread while the
# calling thread waits for the cluster, holding no lock a worker needs.
START_METHOD = "fork" if sys.platform.startswith("linux") else "spawn"
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

# The warm instances of this worker process that no task holds now, by the FMU's checksum. A
# worker with several threads runs several tasks at once: each takes an idle instance (or makes
# one) and gives it back when done, so no instance is ever called from two threads at once and a
# worker holds as many instances as it ran tasks at once. Every evaluation starts from a reset, so
# which instance runs which item does not change a number.
_IDLE_RUNNERS: dict[str, list[Runner]] = {}
_RUNNERS_LOCK = threading.Lock()
# The FMU files the plugin wrote on this worker, by checksum.
_FMU_FILES: dict[str, str] = {}


class FmuPlugin(WorkerPlugin):
    """Puts the FMU's bytes on every worker once (also on workers that join later)."""

    def __init__(self, content: bytes, sha256: str):
        self.content = content
        self.sha256 = sha256
        self.name = f"emc-fmu-{sha256[:16]}"

    def setup(self, worker):
        _FMU_FILES[self.sha256] = fmu_from_content(self.content, self.sha256)
        # The FMU's short-lived workspaces stay with the worker (as in emc's own process).
        keep_freed_memory()

    def teardown(self, worker):
        # Idle instances are dropped, not freed: freeing is cheap to skip, the worker process
        # ends next and takes them along; an instance a task still holds (a study interrupted)
        # must not be freed under its step. The files stay extracted for the next pool here.
        with _RUNNERS_LOCK:
            _IDLE_RUNNERS.pop(self.sha256, None)


def _new_runner(sha256: str) -> Runner:
    path = _FMU_FILES.get(sha256)
    if path is None:
        raise RuntimeError(f"the FMU {sha256[:12]}… never reached this worker")
    name = f"emc-worker-{os.getpid()}-{threading.get_ident()}"
    return Runner(path, instance_name=name, unzipdir=extracted(path, sha256))


@contextlib.contextmanager
def worker_runner(sha256: str):
    """An instance of the FMU with this checksum that no other task of this worker holds, for
    the length of the ``with`` block: an idle one, else a new one."""
    with _RUNNERS_LOCK:
        idle = _IDLE_RUNNERS.get(sha256)
        runner = idle.pop() if idle else None
    if runner is None:
        runner = _new_runner(sha256)
    try:
        yield runner
    finally:
        with _RUNNERS_LOCK:
            _IDLE_RUNNERS.setdefault(sha256, []).append(runner)


@dataclass(frozen=True)
class BatchRecord:
    """Where and when a batch ran: the worker's process and thread, its wall-clock start and end
    (``time.time()``, comparable between the processes of one machine) and the CPU time of the
    worker thread that ran it (the evaluations alone, without the worker's housekeeping)."""
    pid: int
    thread: int
    items: int
    start: float
    end: float
    cpu: float


def evaluate_batch(sha256: str, evaluate: Callable,
                   items: list) -> tuple[list, PointFailed | None, BatchRecord]:
    """A task: ``evaluate(runner, item)`` for each item on this worker's warm instance. A failure
    comes back as a value with the results before it, so the worker logs nothing of its own and
    the caller reports the FMU's cause."""
    start, cpu = time.time(), time.thread_time()
    results: list = []
    failure = None
    with worker_runner(sha256) as runner:
        for item in items:
            try:
                results.append(evaluate(runner, item))
            except PointFailed as failed:
                failure = failed
                break
    record = BatchRecord(os.getpid(), threading.get_ident(), len(items), start, time.time(),
                         time.thread_time() - cpu)
    return results, failure, record


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
        with open(path, "rb") as f:
            return hashlib.sha256(f.read()).hexdigest()
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
    with _RUNNERS_LOCK:
        runners = _IDLE_RUNNERS.pop(sha256, [])
    runners += [_new_runner(sha256) for _ in range(threads - len(runners))]
    if evaluate is not None:
        for runner in runners:
            evaluate(runner, item)
    with _RUNNERS_LOCK:
        _IDLE_RUNNERS.setdefault(sha256, []).extend(runners)


@contextlib.contextmanager
def _sigint_ignored():
    """SIGINT ignored while child processes are started from this (main) thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _quiet_teardown():
    """Run on a local pool's workers before it closes: errors while closing are not logged."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


def interleaved_batches(count: int, batches: int) -> list[list[int]]:
    """Item indices ``0 … count-1`` in ``batches`` equal interleaved batches (none empty):
    batch ``b`` holds items ``b, b + B, b + 2B, …``."""
    batches = max(1, min(batches, count))
    return spread_batches([count // batches + (b < count % batches) for b in range(batches)])


def spread_batches(sizes: list[int]) -> list[list[int]]:
    """Item indices ``0 … sum(sizes)-1`` in batches of these sizes, each spread evenly over the
    index range: the ``j``-th of a batch's ``k`` slots belongs at the middle of the ``j``-th
    ``k``-th of the range, and the slots of all batches, sorted by that place (the first batch on
    a tie), take the items in order. Equal sizes give :func:`interleaved_batches`."""
    slots = sorted(((2 * j + 1) / (2 * size), b) for b, size in enumerate(sizes)
                   for j in range(size))
    batches: list[list[int]] = [[] for _ in sizes]
    for i, (_, b) in enumerate(slots):
        batches[b].append(i)
    return batches


def guided_sizes(count: int, workers: int) -> list[int]:
    """Batch sizes of guided self-scheduling: rounds of ``workers`` batches, each of a
    ``2 × workers``-th of the items still left (rounded up), the last rounds single items."""
    sizes: list[int] = []
    left = count
    while left > 0:
        size = max(1, math.ceil(left / (2 * workers)))
        for _ in range(workers):
            take = min(size, left)
            if take == 0:
                break
            sizes.append(take)
            left -= take
    return sizes


def guided_batches(count: int, workers: int) -> list[list[int]]:
    """Item indices ``0 … count-1`` in shrinking batches (:func:`guided_sizes`), each spread over
    the items, the largest first."""
    return spread_batches(guided_sizes(count, workers))


@dataclass
class MapRecord:
    """A :meth:`FmuPool.map`: its wall-clock start and end (``time.time()``) and every batch."""
    start: float
    end: float = 0.0
    batches: list[BatchRecord] = field(default_factory=list)

    def anatomy(self, workers: int) -> dict:
        """Where the workers' time went (``workers``: the task slots, the threads of all
        workers): ``busy``, the share of ``workers × wall time`` spent in batches; ``first_s``,
        how long a slot waited for its first batch (mean); ``tail_s``, how long a slot sat idle
        between its last batch and the map's end (mean); ``cpu_s``, the CPU time of the
        evaluations alone (the worker threads that ran them)."""
        wall = self.end - self.start
        by_worker: dict[tuple[int, int], list[BatchRecord]] = {}
        for batch in self.batches:
            by_worker.setdefault((batch.pid, batch.thread), []).append(batch)
        # Workers that got no batch wait the whole map.
        idle = max(0, workers - len(by_worker))
        first = [min(b.start for b in runs) - self.start for runs in by_worker.values()]
        tail = [self.end - max(b.end for b in runs) for runs in by_worker.values()]
        return {"busy": sum(b.end - b.start for b in self.batches) / (workers * wall),
                "first_s": (sum(first) + idle * wall) / workers,
                "tail_s": (sum(tail) + idle * wall) / workers,
                "cpu_s": sum(b.cpu for b in self.batches),
                "batches": len(self.batches)}


class FmuPool:
    """A Dask cluster whose workers each hold a warm instance of one FMU.

    ``scheduler``: the address of a running Dask scheduler (its workers get the FMU by content:
    they need not share the caller's file system, and may have any number of threads: each
    running task has an instance of its own); else a local cluster of ``workers`` processes with
    one thread each (the FMU runs single-threaded; processes keep the instances' memory apart). ``batches_per_worker``: ``None`` for
    shrinking (guided) batches, a number for that many equal batches per worker.
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
        # The last map's timings (see MapRecord.anatomy).
        self.last_map: MapRecord | None = None
        self.cluster = None
        self._warming: list = []
        if scheduler:
            self.client = Client(scheduler)
        else:
            # Worker logs below ERROR (cancelled tasks after a failure, …) would bury the cause.
            # The worker processes start with Ctrl-C ignored (a Python process keeps an
            # ignored SIGINT): the terminal's interrupt reaches them too, and each would print
            # its own KeyboardInterrupt traceback before the command's one-line message; the
            # command stops them itself.
            with dask.config.set(WORKER_CONFIG), _sigint_ignored():
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

    def map(self, evaluate: Callable, items: Iterable, progress: Callable[[int], None] | None = None,
            batches: int | None = None) -> list:
        """``evaluate(runner, item)`` for every item on the workers; the results in the order of
        ``items``. ``progress(n)`` is called with the number of items each finished batch held.
        ``batches``: that many equal batches for this map (else as the pool was made)."""

        items = list(items)
        if not items:
            return []
        record = MapRecord(time.time())
        workers = self.workers
        if batches or self.batches_per_worker:
            groups = interleaved_batches(len(items), batches or self.batches_per_worker * workers)
        else:
            groups = guided_batches(len(items), workers)
        # Submitted largest first: the scheduler hands out tasks in the order they came.
        futures = {self.client.submit(evaluate_batch, self.sha256, evaluate,
                                      [items[i] for i in group], pure=False): group
                   for group in groups}
        results: list = [None] * len(items)
        for future in as_completed(futures):
            values, failure, batch = future.result()
            record.batches.append(batch)
            if failure is not None:
                self.client.cancel(list(futures))
                raise failure
            for i, value in zip(futures[future], values):
                results[i] = value
            if progress is not None:
                progress(len(values))
        record.end = time.time()
        self.last_map = record
        return results

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

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
