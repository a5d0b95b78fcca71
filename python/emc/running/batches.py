"""Many FMU evaluations on a pool of worker processes, with warm FMU instances in each: what
every pool shares, whichever runs it (:mod:`.local_pool`, processes forked on this machine, or
:mod:`.distributed`, a Dask cluster).

- **Each worker keeps one instance per task it runs at once** (:class:`emc.running.runner.Runner`)
  for its life and reuses it from evaluation to evaluation: ``fmi2Reset`` brings it back to the
  instantiated state. A worker with several threads runs that many tasks at once; each task takes
  an instance no other task holds (FMI allows one call at a time per instance), so the threads
  compute in parallel (the FMU releases the GIL). Restoring an FMU state saved right after
  instantiation does the same and gives the same numbers to the bit; both cost well under a
  millisecond against 100–400 ms for a point (most of it the periodic start), so the plain reset
  is kept: there is no state to hold.
- **Evaluations go in batches**, several per task, so that scheduling is a small part of each
  task. By default the batches shrink as the study goes (guided self-scheduling): the first
  round gives each worker a batch of a ``2 × workers``-th of the items, each later round a
  ``2 × workers``-th of what is left, down to single items. Big batches at the start keep the
  scheduling cost small; single items at the end leave a worker idle for at most about one
  evaluation while the others finish. Each batch spreads over the items (a sweep's slow
  low-speed points over all batches). ``batches_per_worker=B`` gives the older scheme instead:
  ``B × workers`` equal interleaved batches.
- **Results come back in the order of the items**, and every evaluation starts from the reset
  instance: a study gives the same numbers to the bit, serially or on any pool.

    with LocalPool("dist/EngineMountChassis.fmu", workers=4) as pool:
        results = pool.map(evaluate, items)      # evaluate(runner, item) on the workers

``evaluate`` must be picklable (a module-level function, or a ``functools.partial`` of one) and
may raise :class:`emc.running.runner.PointFailed`; the first failure cancels the rest and is raised
with the FMU's log.

This module imports neither Dask nor anything a local pool does not need (start-up time).
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import Callable, Iterable

from .runner import PointFailed, Runner, extracted

# Workers on this machine are forked from the calling process where the system allows it
# (Linux): they start with its modules imported, a pool of 2 in 0.27-0.35 s against 1.8-2.4 s
# spawned (each worker importing fmpy and emc anew; Dask's local cluster, machine F under load,
# 2026-12-04). The fork happens while the calling thread holds no lock a worker needs.
START_METHOD = "fork" if sys.platform.startswith("linux") else "spawn"


@contextlib.contextmanager
def sigint_ignored():
    """SIGINT ignored while child processes are started from this (main) thread: they keep it
    ignored (a Python process keeps an ignored SIGINT), so the terminal's Ctrl-C, which reaches
    them too, does not make each print its own KeyboardInterrupt traceback before the command's
    one-line message; the command stops them itself."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)

# The warm instances of this worker process that no task holds now, by the FMU's checksum. A
# worker with several threads runs several tasks at once: each takes an idle instance (or makes
# one) and gives it back when done, so no instance is ever called from two threads at once and a
# worker holds as many instances as it ran tasks at once. Every evaluation starts from a reset, so
# which instance runs which item does not change a number.
_IDLE_RUNNERS: dict[str, list[Runner]] = {}
_RUNNERS_LOCK = threading.Lock()
# The FMU files this worker runs, by checksum (written by a Dask worker plugin, or the caller's
# own file for a local pool's workers).
_FMU_FILES: dict[str, str] = {}


def serve_fmu(sha256: str, path: str):
    """This worker runs the FMU with this checksum from the file at ``path``."""
    _FMU_FILES[sha256] = path


def forget_idle(sha256: str):
    """Drops this worker's idle instances of the FMU (not freed: the worker process ends next and
    takes them along; an instance a task still holds, a study interrupted, must not be freed
    under its step)."""
    with _RUNNERS_LOCK:
        _IDLE_RUNNERS.pop(sha256, None)


def idle_count(sha256: str) -> int:
    """How many instances of the FMU this worker holds that no task holds now."""
    with _RUNNERS_LOCK:
        return len(_IDLE_RUNNERS.get(sha256, []))


def warm_instances(sha256: str, count: int, evaluate: Callable | None = None, item=None):
    """At least ``count`` idle instances of the FMU on this worker, made now (each through
    ``evaluate(runner, item)`` once, if given: e.g. a point that reads the reduced body from the
    cache)."""
    with _RUNNERS_LOCK:
        runners = _IDLE_RUNNERS.pop(sha256, [])
    try:
        runners += [_new_runner(sha256) for _ in range(count - len(runners))]
        if evaluate is not None:
            for runner in runners:
                evaluate(runner, item)
    finally:
        with _RUNNERS_LOCK:
            _IDLE_RUNNERS.setdefault(sha256, []).extend(runners)


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
    """A :meth:`BatchPool.map`: its wall-clock start and end (``time.time()``) and every batch."""
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


class BatchPool:
    """What every pool of FMU workers does the same way: its maps. A pool says how it submits a
    task (:meth:`_submit`), waits for the next finished ones (:meth:`_completed`), cancels the
    rest (:meth:`_cancel`) and counts its task slots (:attr:`workers`)."""

    sha256: str
    batches_per_worker: int | None = None
    # The last map's timings (see MapRecord.anatomy).
    last_map: MapRecord | None = None

    @property
    def workers(self) -> int:
        """The task slots: the threads of all workers (each runs one evaluation at a time)."""
        raise NotImplementedError

    def _submit(self, function: Callable, *args):
        raise NotImplementedError

    def _completed(self, futures: Iterable):
        raise NotImplementedError

    def _cancel(self, futures: list):
        raise NotImplementedError

    def map(self, evaluate: Callable, items: Iterable,
            progress: Callable[[int], None] | None = None, batches: int | None = None) -> list:
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
        # Submitted largest first: both pools hand out tasks in the order they came.
        futures = {self._submit(evaluate_batch, self.sha256, evaluate,
                                [items[i] for i in group]): group
                   for group in groups}
        results: list = [None] * len(items)
        for future in self._completed(futures):
            values, failure, batch = future.result()
            record.batches.append(batch)
            if failure is not None:
                self._cancel(list(futures))
                raise failure
            for i, value in zip(futures[future], values):
                results[i] = value
            if progress is not None:
                progress(len(values))
        record.end = time.time()
        self.last_map = record
        return results

    def close(self):
        raise NotImplementedError

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
