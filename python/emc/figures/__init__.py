"""Figures of the results: waterfalls, order cuts, overlays, bands (:mod:`.plots`) and the
accuracy study's plot (:mod:`.accuracy_plot`)."""

import importlib
import multiprocessing
import os
import sys
import threading
from typing import Callable


_PRELOAD: list[threading.Thread] = []


def _load_plots():
    try:
        importlib.import_module(__name__ + ".plots")
    except Exception:  # noqa: BLE001 - the command's own import of the module says what failed
        pass


def preload_figures() -> None:
    """Starts loading matplotlib and :mod:`.plots` (0.3 s) in a background thread, for a command
    that computes first and draws last: the FMU releases the GIL while it steps, so the loading
    runs beside the computation on the second core. Not for free: the points of a 2-point sweep
    took 0.3–0.4 s beside it against 0.2 s alone (the loading holds the GIL between the FMU's
    calls), so the whole command gained 0.1–0.15 s; a figure drawn in the loading thread as well,
    to load the fonts early, lost more than it saved. :func:`draw_all` waits for it
    (matplotlib draws from one thread at a time); an import of :mod:`.plots` meanwhile waits for
    the module."""
    thread = threading.Thread(target=_load_plots, name="emc-preload-figures", daemon=True)
    thread.start()
    _PRELOAD.append(thread)


def _run(jobs, catch=Exception) -> list[str]:
    """Runs every job of a group, also after one failed (each writes files of its own); returns
    the failures (``catch``: what counts as one; anything else is raised)."""
    errors = []
    for job in jobs:
        try:
            job()
        except catch as error:  # noqa: BLE001 - reported with the others' failures
            errors.append(f"{type(error).__name__}: {error}")
    return errors


def _run_in_child(jobs, report):
    """A forked process's group: every failure, an interrupt included, goes to the parent."""
    report.send("; ".join(_run(jobs, BaseException)) or None)


def draw_all(jobs: list[Callable[[], None]]) -> None:
    """Runs ``jobs`` that write a command's results (figures, tables; each writes files of its
    own) side by side: a figure costs 0.15–0.5 s of one core (laying out and rasterising), a
    48-point sweep's spectrum table 0.15 s, so on Linux this process runs the first job (give
    it the costliest) while forked processes run the others; serially where there is one core,
    one job, or no fork. Every job runs even where another fails; the failures are raised here
    with their messages."""
    while _PRELOAD:
        _PRELOAD.pop().join()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
    errors = []
    if cores == 1 or len(jobs) < 2 or not sys.platform.startswith("linux"):
        errors = _run(jobs)
    else:
        # The other jobs in processes of their own, up to two per core: jobs differ in cost,
        # and more processes than cores share the cores out among them. A sweep's three
        # figures on two cores, five runs each: 0.35-0.51 s in three processes, 0.35-0.54 s in
        # two, 0.54-0.67 s in this one alone.
        others = jobs[1:]
        shares = min(len(others), 2 * cores - 1)
        fork = multiprocessing.get_context("fork")
        children = []
        for group in (others[k::shares] for k in range(shares)):
            reader, writer = fork.Pipe(duplex=False)
            child = fork.Process(target=_run_in_child, args=(group, writer), daemon=True)
            child.start()
            writer.close()
            children.append((child, reader))
        try:
            errors = _run(jobs[:1])
        finally:
            for child, reader in children:
                try:
                    error = reader.recv()
                except EOFError:
                    error = "a process writing results ended without a word"
                child.join()
                if error is not None:
                    errors.append(error)
    if errors:
        raise RuntimeError("writing the results failed: " + "; ".join(errors))
