"""Many FMU evaluations on worker processes of this machine: the pool of ``--workers N``.

A local pool needs none of what a Dask cluster is for (:mod:`.distributed`): its workers are
forked from this process (:data:`emc.running.batches.START_METHOD`), so they run this emc,
fmpy and numpy and read this file system, and the FMU need not travel. Python's own process pool
(:class:`concurrent.futures.ProcessPoolExecutor`) starts them in milliseconds, where importing
Dask's distributed scheduler alone takes 0.25-0.35 s and its local cluster another 0.15-0.2 s
(a 48-point sweep on two workers: 3.2-3.3 s for the whole command against 3.75-3.9 s on Dask,
5.1 s serial; machine F, 2026-12-04). Each worker has one thread; instances and batches are
kept as in every pool (:mod:`.batches`), so the numbers equal the serial ones to the bit.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import connection
from typing import Callable, Iterable

from ..base.errors import WorkerLost
from ..base.fmu import file_sha256
from .batches import START_METHOD, BatchPool, serve_fmu, sigint_ignored, warm_instances
from .runner import extracted, keep_freed_memory


def _start_worker(sha256: str, path: str, warm_with: tuple | None, started):
    """A worker's first act: its FMU, its memory settings, and its instance made now (and put
    through ``evaluate(runner, item)`` once, ``warm_with``), before the first task asks for it;
    then ``started`` is released. A failure to make the instance is left to the first task,
    which makes one again and reports the FMU's own message (a failure here would break the
    pool)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    keep_freed_memory()
    serve_fmu(sha256, path)
    try:
        warm_instances(sha256, 1, *(warm_with or ()))
    except Exception:  # noqa: BLE001 - the first task reports the cause (see above)
        pass
    finally:
        started.release()


class LocalPool(BatchPool):
    """``workers`` processes of this machine, one thread each, each holding a warm instance of
    one FMU. The processes start (and make their instances) as the pool is made; ``warm_with``,
    ``(evaluate, item)``: each instance runs ``evaluate(runner, item)`` once then (e.g. a point
    that reads the reduced body from the cache). ``batches_per_worker``: ``None`` for shrinking
    (guided) batches, a number for that many equal batches per worker."""

    def __init__(self, fmu_path: str, workers: int = 2, batches_per_worker: int | None = None,
                 warm_with: tuple[Callable, object] | None = None):
        path = os.path.abspath(fmu_path)
        self.sha256 = file_sha256(path)
        self.batches_per_worker = batches_per_worker
        self.count = max(1, int(workers))
        # Extracted once here, before the workers start, rather than by both at once.
        extracted(path, self.sha256)
        context = multiprocessing.get_context(START_METHOD)
        # Released by each worker once its instance is made (inherited, not sent: see warm).
        self._started = context.Semaphore(0)
        self._warm = False
        self.executor = ProcessPoolExecutor(
            self.count, mp_context=context, initializer=_start_worker,
            initargs=(self.sha256, path, warm_with, self._started))
        self._futures: list = []
        self._workers: dict = {}
        # The first task starts every worker now, from this thread (a forked pool starts them
        # all at once); each makes its instance while this process goes on.
        with sigint_ignored():
            self._futures.append(self.executor.submit(os.getpid))
        self._know_workers()

    @property
    def workers(self) -> int:
        return self.count

    def warm_soon(self):
        """Nothing more to do: the workers make their instances as they start."""

    def warm(self):
        """Returns once every worker has made its instance (and run ``warm_with``): a timed map
        that follows pays for neither. A task cannot be sent to a given worker of this pool, so
        the workers say so themselves, through a semaphore they inherit."""
        if not self._warm:
            for _ in range(self.count):
                self._started.acquire()
            self._warm = True

    def _submit(self, function: Callable, *args):
        future = self.executor.submit(function, *args)
        self._futures = [f for f in self._futures if not f.done()] + [future]
        self._know_workers()
        return future

    def _know_workers(self):
        """Keeps a hand on every worker process the executor started: it forgets them when a
        worker dies (the pool is then broken), and they say how it ended. The executor's own
        record (Python 3.11 has no public one; 3.14's terminate_workers stops them)."""
        for pid, process in (getattr(self.executor, "_processes", None) or {}).items():
            self._workers.setdefault(pid, process)

    def _completed(self, futures: Iterable):
        """The futures as they finish; those found finished together in the order they were
        submitted (the first failure reported is then the first point's)."""
        order = {future: i for i, future in enumerate(futures)}
        pending = set(order)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=order.__getitem__):
                if isinstance(future.exception(), BrokenProcessPool):
                    self._cancel(list(pending))
                    raise WorkerLost(
                        f"a worker process of the local pool ended in the middle of its work "
                        f"({self._exit_codes()}): nothing of this map is kept") from None
                yield future

    def _cancel(self, futures: list):
        for future in futures:
            future.cancel()

    def _exit_codes(self) -> str:
        """How the lost worker ended. Once one is lost the executor terminates the others
        (SIGTERM): those are named only where nothing else is known."""
        codes = [code for code in map(_exit_code, self._workers.values()) if code is not None]
        codes = sorted(set(c for c in codes if c != -signal.SIGTERM) or set(codes))
        return ", ".join(f"exit code {c}" if c >= 0 else f"signal {-c}" for c in codes) or \
            "exit code unknown"

    def close(self):
        """Stops the workers: idle ones end at once; one still in a batch (a map that failed or
        was interrupted) is terminated rather than waited for, as its results have no reader."""
        if all(future.done() for future in self._futures):
            self.executor.shutdown(wait=True)
            return
        processes = list(self._workers.values())
        self.executor.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            process.terminate()  # nothing where it has ended
        # Ended once their sentinels say so (the executor's thread reaps them).
        running = [process.sentinel for process in processes]
        deadline = time.monotonic() + 5
        while running and time.monotonic() < deadline:
            ended = connection.wait(running, timeout=deadline - time.monotonic())
            running = [sentinel for sentinel in running if sentinel not in ended]


def _exit_code(process) -> int | None:
    """A worker's exit code (negative: the signal that ended it), None while it runs. The
    executor's own thread reaps its workers too: a poll between its reaping and its recording
    the code finds none, so a process that has ended is asked again for a while."""
    if not connection.wait([process.sentinel], timeout=1):
        return None
    for _ in range(100):
        if process.exitcode is not None:
            return process.exitcode
        time.sleep(0.01)
    return None
