"""Drives the packaged FMU with fmpy's low-level API, one instance reused via ``reset()``."""

from __future__ import annotations

import ctypes
import dataclasses
import hashlib
import itertools
import math
import os
import re
import shutil
import sys
import tempfile
import time
from ctypes import byref
from typing import Callable, Iterable

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE,
                       fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE,
                       free)
from fmpy.logging import addLoggerProxy
from tqdm import tqdm

from ..base.fmu import CUTOFF_IN_USE

STATUS_LABELS = ("info", "warning", "discard", "error", "fatal", "pending")

# glibc gives freed memory back to the system as soon as the free top of the heap exceeds a
# threshold (128 KiB to start with), and the FMU frees workspaces of that size at every point:
# the heap shrinks and grows again, and every page it regrows faults in afresh. With a large trim
# threshold and top pad a scene-2 sweep point costs 5-7 % less CPU (48 points, 2.60-2.67 s against
# 2.81 s serially, `emc bench-scaling --points 48 --workers 1`, 2026-11-27); the process
# keeps up to 256 MiB of freed memory for reuse. Dask workers get the same as environment
# variables (emc.running.distributed), this process by :func:`keep_freed_memory`.
MALLOC_SETTINGS = {"MALLOC_TRIM_THRESHOLD_": 1 << 28, "MALLOC_TOP_PAD_": 1 << 26}
_MALLOPT_PARAMETERS = {"MALLOC_TRIM_THRESHOLD_": -1, "MALLOC_TOP_PAD_": -2}  # M_TRIM_THRESHOLD, M_TOP_PAD


def keep_freed_memory() -> list[str]:
    """Applies :data:`MALLOC_SETTINGS` to this process where its C library is glibc (through
    ``mallopt``), except a setting the environment already gives. Returns the settings applied
    (none elsewhere: the tuning is only for speed)."""
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError, TypeError):
        return []
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return [name for name, value in MALLOC_SETTINGS.items()
            if name not in os.environ and mallopt(_MALLOPT_PARAMETERS[name], value) == 1]


class PointFailed(RuntimeError):
    """An FMU call failed: the FMU's own cause first, then every log line of the point.

    Picklable, so it travels back from Dask workers with its log.
    """

    def __init__(self, cause: str, log: tuple = ()):
        super().__init__(cause)
        self.cause = cause
        self.log = tuple(log)

    def __reduce__(self):
        return (PointFailed, (self.cause, self.log))

    def report(self) -> str:
        lines = [f"error: {self.cause}"]
        if self.log:
            lines.append("FMU log of the failed point:")
            lines += [f"  {line}" for line in self.log]
        return "\n".join(lines)


def set_value(slave: FMU2Slave, kind: str, vr: int, value) -> None:
    """Sets one variable of type ``kind`` ("Real", "Integer", "Boolean" or "String")."""
    if kind == "Real":
        slave.setReal([vr], [float(value)])
    elif kind == "Integer":
        slave.setInteger([vr], [int(value)])
    elif kind == "Boolean":
        slave.setBoolean([vr], [bool(value)])
    else:
        slave.setString([vr], [str(value)])


# fmpy's logger proxy (which formats the FMU's printf-style messages) keeps ONE logger for the
# whole process, the last one registered: each instance's own Python logger would receive every
# instance's messages, and once it is freed the next message from any instance calls freed memory.
# So one logger lives as long as the process and hands each message to the sink of the instance
# it came from, named by the instance's component environment.
_SINKS: dict[int, list] = {}
_NEXT_SINK = itertools.count(1)


def _dispatch(environment, _instance, status, category, message):
    sink = _SINKS.get(environment or 0)
    if sink is None:
        return
    label = STATUS_LABELS[status] if 0 <= status < len(STATUS_LABELS) else str(status)
    sink.append(f"[{label}] {category.decode('utf-8', 'replace')}: "
                f"{message.decode('utf-8', 'replace')}")


_LOGGER = fmi2CallbackLoggerTYPE(_dispatch)


def logging_callbacks(sink: list) -> fmi2CallbackFunctions:
    """FMI callbacks whose logger appends "[status] category: message" lines to ``sink`` (until
    :func:`release_logging`)."""

    key = next(_NEXT_SINK)
    _SINKS[key] = sink
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _LOGGER
    callbacks.componentEnvironment = key
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    addLoggerProxy(byref(callbacks))
    return callbacks


def release_logging(callbacks: fmi2CallbackFunctions):
    """Stops collecting the messages of the instance created with ``callbacks`` (after its
    fmi2FreeInstance)."""
    _SINKS.pop(callbacks.componentEnvironment or 0, None)


@dataclasses.dataclass(frozen=True)
class OperatingPoint:
    """One constant-speed run and its stationary window.

    ``periodic`` (the default) starts the FMU on the periodic steady state
    (``initialization.periodic``): the window follows initialisation directly. Otherwise the
    excitation fades in from the static equilibrium and ``settle_revolutions`` pass before the
    window (transients of the lightly damped body modes need hundreds at 1 % damping).
    """

    rpm: float
    load_torque: float = 0.0
    revolutions: int = 40          # stationary window (even: half orders fall on bins)
    settle_revolutions: int = 0    # after the start, before the window
    steps_per_revolution: int = 72  # communication steps (5 degrees of crank angle)
    parameters: tuple = ()          # extra (name, value) start values: effects, solver, scene …
    periodic: bool = True

    def __post_init__(self):
        if self.rpm <= 0 or not math.isfinite(self.rpm):
            raise ValueError(f"rpm must be positive, got {self.rpm}")
        if self.revolutions < 2 or self.revolutions % 2:
            raise ValueError(f"revolutions must be even and >= 2 (half orders), got {self.revolutions}")
        if self.settle_revolutions < 0:
            raise ValueError(f"settle revolutions must be >= 0, got {self.settle_revolutions}")


class Runner:
    """One FMU instance; ``run_point`` resets it, so results never depend on earlier points."""

    def __init__(self, fmu_path: str, instance_name: str = "emc", unzipdir: str | None = None):
        """``unzipdir``: the FMU already extracted there (kept on close); else it is extracted
        into a temporary directory of its own, removed on close."""
        self.md = read_model_description(fmu_path)
        self.own_unzipdir = unzipdir is None
        self.unzipdir = extract(fmu_path) if unzipdir is None else unzipdir
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.kind = {v.name: v.type for v in self.md.modelVariables}
        self.log: list[str] = []
        self.callbacks = None
        try:
            self.slave = FMU2Slave(
                guid=self.md.guid,
                unzipDirectory=self.unzipdir,
                modelIdentifier=self.md.coSimulation.modelIdentifier,
                instanceName=instance_name,
            )
            self.callbacks = logging_callbacks(self.log)
            self.slave.instantiate(callbacks=self.callbacks)
        except Exception as error:  # noqa: BLE001 - fmpy raises a bare Exception
            # Nothing of a failed start stays behind: not the extracted FMU, not its sink.
            if self.callbacks is not None:
                release_logging(self.callbacks)
            if self.own_unzipdir:
                shutil.rmtree(self.unzipdir, ignore_errors=True)
            raise self.failure(f"instantiating {self.md.modelName}", error) from None
        # Errors and warnings always reach the logger; the model set-up events (scene, chassis
        # reduction or cache, periodic start) are cheap and tell what a failed point was doing.
        categories = [c.name for c in self.md.logCategories or []]
        if "logEvents" in categories:
            self.slave.setDebugLogging(True, ["logEvents"])
        self.fresh = True

    def close(self):
        try:
            self.slave.terminate()
        except Exception:  # noqa: BLE001 - a failed point leaves the instance in an error state
            pass
        self.slave.freeInstance()
        release_logging(self.callbacks)
        if self.own_unzipdir:
            shutil.rmtree(self.unzipdir, ignore_errors=True)

    def warnings(self) -> list[str]:
        """The FMU's warnings since the log was last cleared (a successful point may have some)."""
        return [line for line in self.log if line.startswith("[warning]")]

    def failure(self, what: str, error: Exception) -> PointFailed:
        """The cause of a failed call: the FMU's error messages first, else fmpy's."""
        # The FMU names the refused function first ("fmi2DoStep: ..."); the user reads the cause.
        errors = [re.sub(r"^fmi2\w+: ", "", line.split(": ", 1)[1]) for line in self.log
                  if line.startswith(("[error]", "[fatal]")) and ": " in line]
        cause = "; ".join(errors) if errors else str(error)
        return PointFailed(f"{what}: {cause}", tuple(self.log))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def outputs(self, names: Iterable[str] | None = None) -> list[str]:
        if names:
            return list(names)
        return [v.name for v in self.md.modelVariables if v.causality == "output" and v.type == "Real"]

    def _set(self, name: str, value):
        set_value(self.slave, self.kind[name], self.vr[name], value)

    def _start(self, start_values: dict, initialise: bool = True):
        """Back to the instantiated state (reset), the start values set, initialisation mode
        entered and, if ``initialise``, left."""
        if not self.fresh:
            self.slave.reset()
        self.fresh = False
        self.slave.setupExperiment(startTime=0.0)
        for name, value in start_values.items():
            self._set(name, value)
        self.slave.enterInitializationMode()
        if initialise:
            self.slave.exitInitializationMode()

    def get(self, names: Iterable[str]) -> list:
        """The current values of the variables ``names``, each read with its type's getter."""
        names = list(names)
        getters = {"Real": self.slave.getReal, "Integer": self.slave.getInteger,
                   "Boolean": self.slave.getBoolean, "String": self.slave.getString}
        values = {}
        for kind, getter in getters.items():
            of_kind = [n for n in names if self.kind[n] == kind]
            if of_kind:
                values.update(zip(of_kind, getter([self.vr[n] for n in of_kind])))
        return [values[n] for n in names]

    def initial_values(self, start_values: dict, names: Iterable[str]) -> list:
        """The values of ``names`` in initialisation mode for ``start_values``: calculated
        parameters (outputs would build the model and give its static equilibrium)."""
        try:
            self._start(start_values, initialise=False)
            return self.get(names)
        except Exception as error:  # noqa: BLE001 - fmpy raises plain exceptions
            raise self.failure("initialisation", error) from None

    def run_point(self, point: OperatingPoint, signals: list[str], case: str = "") -> dict:
        """Runs one point; returns the stationary window of ``signals`` sampled per step.
        A failed FMU call raises :class:`PointFailed` with the FMU's cause and log."""
        self.log.clear()
        try:
            return self._run_point(point, signals)
        except PointFailed:
            raise
        except Exception as error:  # fmpy raises plain exceptions for failed calls
            where = f"{point.rpm:g} rpm" + (f", case {case!r}" if case else "")
            raise self.failure(where, error) from None

    def _run_point(self, point: OperatingPoint, signals: list[str]) -> dict:
        start = {"rpm": point.rpm, "loadTorque": point.load_torque, **dict(point.parameters)}
        if point.periodic:
            if "initialization.periodic" not in self.vr:
                raise RuntimeError(f"{self.md.modelName} has no initialization.periodic parameter: "
                                   "use a settled start (--start settle)")
            start["initialization.periodic"] = True
        self._start(start)
        t_rev = 60.0 / point.rpm
        h = t_rev / point.steps_per_revolution
        n_settle = point.settle_revolutions * point.steps_per_revolution
        n_window = point.revolutions * point.steps_per_revolution
        vrs = [self.vr[s] for s in signals]
        samples = np.empty((n_window, len(vrs)))
        t = 0.0
        # CPU time of the stepping only (instantiation may include a chassis reduction).
        cpu = time.process_time()
        wall = time.perf_counter()
        for k in range(n_settle + n_window):
            self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t = (k + 1) * h
            if k >= n_settle:
                samples[k - n_settle] = self.slave.getReal(vrs)
        cpu = time.process_time() - cpu
        wall = time.perf_counter() - wall
        if not np.all(np.isfinite(samples)):
            raise RuntimeError(f"non-finite outputs at {point.rpm} rpm")
        return {"point": point, "dt": h, "signals": signals, "samples": samples,
                "cpu": cpu, "wall": wall, "simulated": t, "warnings": self.warnings()}

    def run_up(self, rpm_from: float, rpm_to: float, duration: float, signals: list[str],
               step: float = 2e-4, start_values: dict | None = None, progress=None,
               case: str = "") -> dict:
        """A slow linear run-up, the speed given continuously by input derivatives; the crank
        angle is recorded beside ``signals`` for order tracking (``samples`` after each step,
        ``initial`` the signals at the start). ``progress(seconds)`` is called with the
        simulated time reached, every 1 % of the run."""
        self.log.clear()
        try:
            return self._run_up(rpm_from, rpm_to, duration, signals, step, start_values,
                                progress)
        except Exception as error:
            where = f"run-up {rpm_from:g}->{rpm_to:g} rpm" + (f", case {case!r}" if case else "")
            raise self.failure(where, error) from None

    def _run_up(self, rpm_from, rpm_to, duration, signals, step, start_values, progress):
        self._start({"rpm": rpm_from, **(start_values or {})})
        rate = (rpm_to - rpm_from) / duration
        n = int(round(duration / step))
        vrs = [self.vr[s] for s in signals] + [self.vr["crankAngle"]]
        samples = np.empty((n, len(vrs)))
        rpm = np.empty(n)
        initial = np.array(self.slave.getReal(vrs))
        t = 0.0
        tick = max(1, n // 100)
        for k in range(n):
            self.slave.setReal([self.vr["rpm"]], [rpm_from + rate * t])
            self.slave.setRealInputDerivatives([self.vr["rpm"]], [1], [rate])
            self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
            t = (k + 1) * step
            samples[k] = self.slave.getReal(vrs)
            rpm[k] = rpm_from + rate * t
            if progress is not None and ((k + 1) % tick == 0 or k + 1 == n):
                progress(t)
        if not np.all(np.isfinite(samples)):
            raise RuntimeError("non-finite outputs in the run-up")
        return {"dt": step, "rpm": rpm, "signals": signals, "samples": samples[:, :-1],
                "crank_angle": samples[:, -1], "initial": initial[:-1],
                "warnings": self.warnings()}


def fmu_from_content(content: bytes, sha256: str) -> str:
    """The FMU with this content as a local file: written once per machine into the temporary
    directory under its checksum (Dask workers get the FMU's bytes, not the caller's path)."""

    path = os.path.join(tempfile.gettempdir(), f"emc-fmu-{sha256}.fmu")
    if not os.path.exists(path):
        if hashlib.sha256(content).hexdigest() != sha256:
            raise ValueError("the FMU's content does not match its checksum")
        fd, partial = tempfile.mkstemp(prefix="emc-fmu-", suffix=".part")
        with os.fdopen(fd, "wb") as out:
            out.write(content)
        os.replace(partial, path)
    return path


def extracted(path: str, sha256: str) -> str:
    """The FMU at ``path`` (with this checksum) extracted once per machine into the temporary
    directory under its checksum; concurrent callers each extract into a directory of their own
    and the first to rename it into place wins."""

    target = os.path.join(tempfile.gettempdir(), f"emc-fmu-{sha256}")
    if not os.path.isdir(target):
        partial = extract(path, tempfile.mkdtemp(prefix="emc-fmu-", suffix=".part"))
        try:
            os.rename(partial, target)
        except OSError:  # another process was first
            shutil.rmtree(partial, ignore_errors=True)
    return target


def cutoffs_in_use(fmu: str, cases: list[tuple[str, dict]],
                   runner: Runner | None = None) -> list[float | None]:
    """The chassis mode cut-off (Hz) each case's body keeps, as the FMU reports it
    (``chassis.modeCutoffInUse``; None for an FMU without it); asked of ``runner`` if given (the
    instance the command's points run on next), else of an instance of its own."""
    own = runner is None
    runner = Runner(fmu) if own else runner
    try:
        if CUTOFF_IN_USE not in runner.vr:
            return [None for _ in cases]
        return [runner.initial_values(parameters, [CUTOFF_IN_USE])[0] for _, parameters in cases]
    finally:
        if own:
            runner.close()


def cutoffs_on(runner: Runner, cases: list[tuple[str, dict]]) -> list[float | None]:
    """:func:`cutoffs_in_use` of ``runner``'s FMU, as an evaluation on a pool's worker."""
    return cutoffs_in_use("", cases, runner)


def serial_map(fmu_path: str | None, evaluate: Callable, items: Iterable,
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
    """A tqdm bar on stderr if wanted (else None); ``bar.update`` fits :meth:`emc.running.batches.BatchPool.map`'s
    ``progress``."""
    if not enabled:
        return None
    return tqdm(total=total, desc=description, unit=unit, file=sys.stderr)
