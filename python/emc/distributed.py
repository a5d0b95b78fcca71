"""Many FMU evaluations on Dask, with one warm FMU instance per worker.

A study (a sweep, a design of experiments, an optimisation) evaluates the same FMU hundreds or
thousands of times. What each evaluation may cost besides its own simulation is kept small:

- **The FMU's bytes reach each worker once**, in a worker plugin (workers that join the cluster
  later get it too); the worker writes them to its temporary directory under their checksum.
- **Each worker keeps one instance** (:class:`emc.runner.Runner`) for its life and reuses it from
  evaluation to evaluation: ``fmi2Reset`` brings it back to the instantiated state. Restoring an
  FMU state saved right after instantiation does the same and gives the same numbers to the bit;
  both cost well under a millisecond against 100–400 ms for a point (most of it the periodic
  start), so the plain reset is kept: there is no state to hold.
- **Evaluations go in batches**, several per task, so that scheduling is a small part of each
  task. The batches interleave the items (batch ``b`` holds items ``b, b + B, b + 2B, …``): a
  sweep's slow low-speed points spread over all batches. There are a few batches per worker, so a
  worker slowed by another job on its core does not hold the study back by more than a batch.
- **Results come back in the order of the items**, and every evaluation starts from the reset
  instance: a study gives the same numbers to the bit, serially or on any number of workers.

    with FmuPool("dist/EngineMountChassis.fmu", workers=4) as pool:
        results = pool.map(evaluate, items)      # evaluate(runner, item) on the workers

``evaluate`` must be picklable (a module-level function, or a ``functools.partial`` of one) and
may raise :class:`emc.runner.PointFailed`; the first failure cancels the rest and is raised with
the FMU's log.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
from typing import Callable, Iterable

import dask
from distributed.diagnostics.plugin import WorkerPlugin

from .runner import PointFailed, Runner, extracted, fmu_from_content

# Local workers: Dask's nanny starts them with MALLOC_TRIM_THRESHOLD_=65536 so that they hand
# memory back to the system; glibc then trims the FMU's short-lived allocations at every free, and
# a worker needed 15-20 % more CPU time per point than the same loop in the caller (thread CPU
# time of 8 scene-2 points, 0.63-0.69 s against 0.54-0.58 s). With a large trim threshold and top
# pad it needs the same. Without the sampling profiler a worker runs only the study. Dask's
# periodic housekeeping (an event-loop tick every 20 ms, system and memory monitors every
# 0.5 s and 0.1 s, work stealing every 0.1 s) cost the caller 4 % and each worker 2 % of a core
# while a study runs; at 1-5 s they cost a tenth of that (2 workers, 48 scene-2 points: all
# processes together within 1-4 % of the serial loop's CPU time instead of 22 % above it).
WORKER_CONFIG = {
    "distributed.nanny.pre-spawn-environ": {
        "MALLOC_TRIM_THRESHOLD_": 1 << 28, "MALLOC_TOP_PAD_": 1 << 26,
        "OMP_NUM_THREADS": 1, "MKL_NUM_THREADS": 1, "OPENBLAS_NUM_THREADS": 1},
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "2s",
    "distributed.scheduler.work-stealing-interval": "1s",
}

# The warm instances of this worker process, by the FMU's checksum (one process per worker, one
# thread: never used concurrently).
_RUNNERS: dict[str, Runner] = {}
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

    def teardown(self, worker):
        # The instance is dropped, not freed: a task may still be stepping it in the worker's
        # thread (a study interrupted), and freeing it under that step corrupts the heap. The
        # worker process ends next and takes it along; its files stay extracted for the next
        # pool on this machine.
        _RUNNERS.pop(self.sha256, None)


def worker_runner(sha256: str) -> Runner:
    """This worker's instance of the FMU with this checksum, created at its first use."""
    runner = _RUNNERS.get(sha256)
    if runner is None:
        path = _FMU_FILES.get(sha256)
        if path is None:
            raise RuntimeError(f"the FMU {sha256[:12]}… never reached this worker")
        runner = _RUNNERS[sha256] = Runner(path, instance_name=f"emc-worker-{os.getpid()}",
                                           unzipdir=extracted(path, sha256))
    return runner


def evaluate_batch(sha256: str, evaluate: Callable, items: list) -> tuple[list, PointFailed | None]:
    """A task: ``evaluate(runner, item)`` for each item on this worker's warm instance. A failure
    comes back as a value with the results before it, so the worker logs nothing of its own and
    the caller reports the FMU's cause."""
    runner = worker_runner(sha256)
    results = []
    for item in items:
        try:
            results.append(evaluate(runner, item))
        except PointFailed as failure:
            return results, failure
    return results, None


def interleaved_batches(count: int, batches: int) -> list[list[int]]:
    """Item indices ``0 … count-1`` in ``batches`` interleaved batches (none empty)."""
    batches = max(1, min(batches, count))
    return [list(range(b, count, batches)) for b in range(batches)]


class FmuPool:
    """A Dask cluster whose workers each hold a warm instance of one FMU.

    ``scheduler``: the address of a running Dask scheduler (its workers get the FMU by content:
    they need not share the caller's file system); else a local cluster of ``workers`` processes
    with one thread each (the FMU runs single-threaded).
    """

    def __init__(self, fmu_path: str, workers: int = 2, scheduler: str | None = None,
                 batches_per_worker: int = 4):
        from dask.distributed import Client, LocalCluster

        with open(fmu_path, "rb") as f:
            self.content = f.read()
        self.sha256 = hashlib.sha256(self.content).hexdigest()
        self.batches_per_worker = batches_per_worker
        self.cluster = None
        if scheduler:
            self.client = Client(scheduler)
        else:
            # Worker logs below ERROR (cancelled tasks after a failure, …) would bury the cause.
            with dask.config.set(WORKER_CONFIG):
                self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                            processes=True, dashboard_address=None,
                                            silence_logs=logging.ERROR)
            self.client = Client(self.cluster)
        try:
            self.client.register_plugin(FmuPlugin(self.content, self.sha256))
        except BaseException:
            self.close()
            raise

    @property
    def workers(self) -> int:
        return max(1, len(self.client.scheduler_info()["workers"]))

    def warm(self, evaluate: Callable | None = None, item=None):
        """Creates every worker's instance now (and runs ``evaluate(runner, item)`` once on each,
        e.g. a point that reads the reduced body from the cache), so that a timed study that
        follows pays for neither."""
        def warm_up(sha256, evaluate, item):
            runner = worker_runner(sha256)
            if evaluate is not None:
                evaluate(runner, item)

        self.client.run(warm_up, self.sha256, evaluate, item)

    def map(self, evaluate: Callable, items: Iterable, progress: Callable[[int], None] | None = None,
            batches: int | None = None) -> list:
        """``evaluate(runner, item)`` for every item on the workers; the results in the order of
        ``items``. ``progress(n)`` is called with the number of items each finished batch held."""
        from dask.distributed import as_completed

        items = list(items)
        if not items:
            return []
        count = batches or self.batches_per_worker * self.workers
        groups = interleaved_batches(len(items), count)
        futures = {self.client.submit(evaluate_batch, self.sha256, evaluate,
                                      [items[i] for i in group], pure=False): group
                   for group in groups}
        results: list = [None] * len(items)
        for future in as_completed(futures):
            values, failure = future.result()
            if failure is not None:
                self.client.cancel(list(futures))
                raise failure
            for i, value in zip(futures[future], values):
                results[i] = value
            if progress is not None:
                progress(len(values))
        return results

    def close(self):
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def serial_map(fmu_path: str, evaluate: Callable, items: Iterable,
               progress: Callable[[int], None] | None = None,
               runner: Runner | None = None) -> list:
    """The same evaluations in this process, one instance reused (``runner`` if given)."""
    own = runner is None
    runner = Runner(fmu_path) if own else runner
    try:
        results = []
        for item in items:
            results.append(evaluate(runner, item))
            if progress is not None:
                progress(1)
        return results
    finally:
        if own:
            runner.close()


def progress_bar(total: int, description: str, enabled: bool = True, unit: str = "eval"):
    """A tqdm bar on stderr if wanted and tqdm is installed (else None); ``bar.update`` fits
    :meth:`FmuPool.map`'s ``progress``."""
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, desc=description, unit=unit, file=sys.stderr)
