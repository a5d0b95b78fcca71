"""Where a command's points run: a pool of worker processes of this machine (:mod:`.local_pool`),
the workers of a Dask cluster (:mod:`.distributed`, imported only when one is used) or one FMU
instance in this process, chosen from the command's options and its number of runs
(:func:`emc.base.checks.pool_workers`)."""

from __future__ import annotations

import contextlib
import dataclasses
import time
from typing import Callable, Iterable

from ..base.checks import pool_workers
from .batches import BatchPool
from .local_pool import LocalPool
from .runner import Runner, cutoffs_in_use, cutoffs_on, serial_map


def start_pool(fmu: str, workers: int, scheduler: str | None = None,
               settings: list[dict] = ()) -> BatchPool:
    """A pool of ``workers`` processes of this machine (:class:`LocalPool`), or the workers of the
    Dask cluster at ``scheduler`` (:class:`emc.running.distributed.FmuPool`), each of which must
    see the files the ``settings`` (each run's start values) make the FMU read, with the content
    this process sees (checked before anything runs)."""
    if not scheduler:
        return LocalPool(fmu, workers)
    # Deferred: Dask is imported only where the points run on a cluster (start-up time).
    from .distributed import FmuPool, settings_files

    files = sorted({f for parameters in settings for f in settings_files(parameters)})
    return FmuPool(fmu, workers, scheduler, files=files)


def open_pool(args, runs: int, settings: list[dict]) -> BatchPool | None:
    """The pool for a command's ``runs`` runs (:func:`start_pool`), or None where they run in
    this process."""
    workers = pool_workers(args, runs)
    if workers is None:
        return None
    return start_pool(args.fmu, workers, args.scheduler, settings)


@dataclasses.dataclass
class PointEngine:
    """Where a command's points run: a pool of workers, or one instance in this process. Counts
    the points it ran and the CPU time of their evaluations (the worker threads' on a pool, this
    process's here)."""

    runner: Runner | None = None
    pool: BatchPool | None = None
    points: int = 0
    cpu_s: float = 0.0

    @classmethod
    def on(cls, fmu: str, pool: BatchPool | None = None) -> PointEngine:
        """An engine on ``pool`` (which stays the caller's to close), or, without one, on a new
        instance of the FMU here (:meth:`close` frees it)."""
        return cls(pool=pool) if pool is not None else cls(runner=Runner(fmu))

    def map(self, evaluate: Callable, items: Iterable,
            progress: Callable[[int], None] | None = None) -> list:
        """``evaluate(runner, item)`` for every item, the results in the order of ``items``;
        ``progress(n)`` after every ``n`` items done."""
        items = list(items)
        if not items:
            return []
        if self.pool is not None:
            results = self.pool.map(evaluate, items, progress)
            self.cpu_s += self.pool.last_map.anatomy(self.pool.workers)["cpu_s"]
        else:
            started = time.process_time()
            results = serial_map(None, evaluate, items, progress, runner=self.runner)
            self.cpu_s += time.process_time() - started
        self.points += len(items)
        return results

    def cutoffs(self, fmu: str, cases: list[tuple[str, dict]]) -> list[float | None]:
        """:func:`cutoffs_in_use`, asked of the instance the points run on next (a worker's
        warm one on a pool): no instance is made for the question alone."""
        if self.pool is not None:
            return self.pool.map(cutoffs_on, [cases])[0]
        return cutoffs_in_use(fmu, cases, self.runner)

    def close(self):
        """Frees the instance here, if any (a pool is closed by whoever opened it)."""
        if self.runner is not None:
            self.runner.close()
            self.runner = None


@contextlib.contextmanager
def point_engine(args, cases: list[tuple[str, dict]], runs: int):
    """The :class:`PointEngine` for a command's ``runs`` points: a pool of local workers (or the
    given scheduler's), whose instances are made in the background while this process checks and
    prepares, or one instance in this process (few points, or --serial)."""
    pool = open_pool(args, runs, [parameters for _, parameters in cases])
    try:
        if pool is not None:
            pool.warm_soon()
        engine = PointEngine.on(args.fmu, pool)
        try:
            yield engine
        finally:
            engine.close()
    finally:
        if pool is not None:
            pool.close()
