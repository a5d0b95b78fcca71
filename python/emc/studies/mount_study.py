"""A mount design problem: design variables, the comfort objective over a speed band, the limits
a mount engineer sets, and a store of the evaluations that lets an interrupted study continue.

Variables (each with bounds ``LOW:HIGH``):

- ``mount[i].stiffnessScale``, ``mount[i].dampingScale``: the FMU's own inputs (a factor on the
  mount's force-deflection curve about its static operating point, and on its damping);
- ``mount[i].rate[j]``: a factor on the stiffness of mount ``i``'s curve along its axis ``j``,
  written into a copy of the vehicle configuration (the FMU's own, or the ``configFile`` given),
  which the worker that needs it writes to its temporary directory under its checksum.

Mount positions are not variables: in the elastic body a mount's bracket must sit on its body
node (within 1 mm), and the body's nodes are not parameters of the configuration.

A design is evaluated by

- a sweep of the speed band (periodic start) recording the steering wheel's and the seat's
  accelerations; per speed the weighted steering-wheel a_hv (ISO 5349-1) and seat a_v
  (ISO 2631-1, comfort) of :mod:`emc.signals.comfort`; the **objective** is their mean or largest value
  over the band (or a weighted sum of both);
- the **static equilibrium on rigid ground** (scene 1, where the engine's motion is its motion
  relative to the body) under the weight and under the full-load torque in both senses (drive and
  reverse): each mount's deflection (the FMU's ``mount[i].staticDeflection[j]``) and the
  powertrain's translation and rotation (``powertrain.r``, ``powertrain.phi``). The **limits**:
  the largest deflection, translation and rotation; a design violating one is infeasible.

Every evaluation is stored (``evaluations.jsonl``, one line per design) with the FMU's checksum
and the settings that decide its numbers; a study started again in the same folder reads what
it finds and evaluates only what is missing.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import os
import pathlib
import re
import sys
import tempfile
import time
import zipfile

import numpy as np
import pandas as pd

from ..base.checks import (check_count, check_pool, check_range, check_revolutions, check_speeds,
                           name_and_bounds, parse_settings)
from ..base.errors import UsageError
from ..base.fmu import (check_config_file, file_sha256, highest_speed, model_variables,
                        mount_count)
from ..base.options import POOL_FROM
from ..base.outputs import claim
from ..running.engine import PointEngine, open_pool
from ..running.runner import OperatingPoint, PointFailed, Runner
from ..running.sweep import analyse, speed_points, tables
from ..signals.comfort import SEAT, WHEEL, comfort_table
from .defaults import BASELINE, DEFAULT_BOUNDS, Limits

VARIABLE = re.compile(r"^mount\[(\d+)\]\.(stiffnessScale|dampingScale|rate\[([123])\])$")
SIGNALS = WHEEL + SEAT
STATIC_OUTPUTS = ([f"powertrain.r[{j}]" for j in (1, 2, 3)]
                  + [f"powertrain.phi[{j}]" for j in (1, 2, 3)])


class StudyError(Exception):
    """A bad variable, limit or study folder: reported as one line before anything runs."""


@dataclasses.dataclass(frozen=True)
class Variable:
    """One design variable: an FMU input (``kind`` stiffnessScale or dampingScale) or a change of
    the vehicle configuration (a rate, along the mount's ``axis`` 1-3) of mount ``mount``
    (1-based)."""

    name: str
    mount: int
    kind: str
    axis: int | None
    low: float
    high: float

    @property
    def baseline(self) -> float:
        return BASELINE[self.kind]

    @property
    def in_configuration(self) -> bool:
        return self.kind == "rate"


def parse_variable(text: str, mounts: int) -> Variable:
    """``NAME`` or ``NAME=LOW:HIGH``, e.g. ``mount[2].stiffnessScale=0.5:2``."""
    name, bounds = name_and_bounds(text, "--var", StudyError)
    match = VARIABLE.match(name)
    if not match:
        raise StudyError(f"--var {text}: not a design variable (mount[i].stiffnessScale, "
                         "mount[i].dampingScale, mount[i].rate[j])")
    mount = int(match.group(1))
    if not 1 <= mount <= mounts:
        raise StudyError(f"--var {text}: the FMU has mounts 1 to {mounts}")
    kind = match.group(2).split("[")[0]
    axis = match.group(3)
    low, high = bounds or DEFAULT_BOUNDS[kind]
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise StudyError(f"--var {text}: need finite bounds LOW < HIGH")
    if low < 0.0:
        raise StudyError(f"--var {text}: a factor cannot be negative")
    if not low <= BASELINE[kind] <= high:
        raise StudyError(f"--var {text}: the bounds must contain the current design "
                         f"({BASELINE[kind]:g})")
    return Variable(name, mount, kind, None if axis is None else int(axis), low, high)


@dataclasses.dataclass(frozen=True)
class Problem:
    """Everything that decides a design's numbers besides the design itself."""

    variables: tuple[Variable, ...]
    rpm_from: float = 800.0
    rpm_to: float = 2000.0
    count: int = 12
    revolutions: int = 8
    objective: str = "wheel-mean"
    seat_weight: float = 1.0
    limits: Limits = Limits()
    parameters: tuple = ()              # fixed FMU start values (name, value), e.g. configFile
    base_configuration: str | None = None  # vehicle JSON the rate variables change

    def settings(self) -> dict:
        """The study's settings as stored beside each evaluation."""
        record = dataclasses.asdict(self)
        if self.base_configuration is not None:
            record["base_configuration"] = hashlib.sha256(
                self.base_configuration.encode()).hexdigest()
        return record

    def unit(self, x) -> np.ndarray:
        """``x`` (in the variables' units) in the unit cube of the bounds."""
        low = np.array([v.low for v in self.variables])
        high = np.array([v.high for v in self.variables])
        return (np.asarray(x, dtype=float) - low) / (high - low)

    def from_unit(self, u) -> np.ndarray:
        low = np.array([v.low for v in self.variables])
        high = np.array([v.high for v in self.variables])
        return low + np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * (high - low)

    def baseline(self) -> np.ndarray:
        return np.array([v.baseline for v in self.variables])

    def objective_of(self, comfort: pd.DataFrame) -> float:
        """The objective from the per-speed comfort values (m/s²)."""
        wheel = comfort.wheel_ahv.to_numpy()
        if self.objective == "wheel-mean":
            return float(np.mean(wheel))
        if self.objective == "wheel-max":
            return float(np.max(wheel))
        return float(np.mean(wheel + self.seat_weight * comfort.seat_av_comfort.to_numpy()))

    # ----- what a design runs -------------------------------------------------------------------

    def start_values(self, x) -> tuple[tuple, str | None]:
        """The FMU start values of design ``x`` and the vehicle configuration it needs (None:
        the problem's own)."""
        values = dict(self.parameters)
        config = None
        if any(v.in_configuration for v in self.variables):
            config = json.loads(self.base_configuration)
        for v, value in zip(self.variables, x):
            if v.in_configuration:
                for knot in config["mounts"][v.mount - 1]["curves"][v.axis - 1]["knots"]:
                    knot["stiffness"] *= float(value)
            else:
                values[v.name] = float(value)
        text = None if config is None else json.dumps(config, sort_keys=True)
        return tuple(values.items()), text

    def evaluations(self, x) -> list:
        """The FMU runs of design ``x``: the speed points, then the three static equilibria."""
        values, config = self.start_values(x)
        points = speed_points(self.rpm_from, self.rpm_to, self.count, revolutions=self.revolutions,
                              periodic=True, parameters=(("scene", 2),) + values)
        runs = [Run("point", point=p, configuration=config) for p in points]
        statics = dict(values, scene=1, rpm=800.0)
        for torque in (0.0, self.limits.full_load_torque, -self.limits.full_load_torque):
            runs.append(Run("static", start=tuple(dict(statics, loadTorque=torque).items()),
                            configuration=config))
        return runs

    def assess(self, x, results: list, mounts: int) -> dict:
        """A design's record from the results of :meth:`evaluations`."""
        points, statics = results[:self.count], results[self.count:]
        spectra = tables([analysis for analysis, _ in points])[1]
        comfort = comfort_table(spectra).sort_values("rpm")
        deflections = [v[len(STATIC_OUTPUTS):] for v in statics]
        static = {"deflection": float(np.max(np.abs(deflections))),
                  "translation": float(np.max(np.abs([v[:3] for v in statics]))),
                  "rotation": float(np.max(np.abs([v[3:6] for v in statics])))}
        violations = self.limits.violations(static)
        return {"x": [float(v) for v in x], "objective": self.objective_of(comfort),
                "feasible": all(g <= 0.0 for g in violations.values()),
                "static": static, "violations": violations,
                "comfort": comfort[["rpm", "wheel_ahv", "seat_av_comfort"]].to_dict("list"),
                "warnings": sorted({w for _, warnings in points for w in warnings})}


@dataclasses.dataclass(frozen=True)
class Run:
    """One FMU run of a design: a speed ``point``, or a static equilibrium for ``start``."""

    kind: str
    point: OperatingPoint | None = None
    start: tuple = ()
    configuration: str | None = None


def configuration_file(text: str) -> str:
    """The vehicle configuration ``text`` as a file of this machine's temporary directory, named
    by its checksum (written once)."""
    digest = hashlib.sha256(text.encode()).hexdigest()
    path = os.path.join(tempfile.gettempdir(), f"emc-vehicle-{digest}.json")
    if not os.path.exists(path):
        fd, partial = tempfile.mkstemp(prefix="emc-vehicle-", suffix=".part")
        with os.fdopen(fd, "w") as out:
            out.write(text)
        os.replace(partial, path)
    return path


def run(runner: Runner, item: Run, mounts: int):
    """One run on ``runner`` (on a worker or here)."""
    extra = () if item.configuration is None else (("configFile",
                                                    configuration_file(item.configuration)),)
    if item.kind == "point":
        point = dataclasses.replace(item.point, parameters=item.point.parameters + extra)
        result = runner.run_point(point, SIGNALS)
        return analyse(result), result["warnings"]
    names = STATIC_OUTPUTS + [f"mount[{i}].staticDeflection[{j}]"
                              for i in range(1, mounts + 1) for j in (1, 2, 3)]
    start = dict(item.start + extra)
    try:
        return runner.initial_values(start, names)
    except PointFailed as failure:
        raise PointFailed(f"static equilibrium, load torque {start.get('loadTorque', 0):g} N·m: "
                          f"{failure.cause}", failure.log) from None


def base_configuration(fmu_path: str, parameters: dict) -> str:
    """The vehicle configuration the rate variables change: ``configFile`` if set (a complete
    configuration, not a patch), else the FMU's own."""
    name = str(parameters.get("configFile") or "")
    if name and os.path.isabs(name):
        text = pathlib.Path(name).read_text()
    else:
        with zipfile.ZipFile(fmu_path) as z:
            text = z.read(f"resources/{name or 'vehicle.json'}").decode()
    config = json.loads(text)
    if "mounts" not in config or "extends" in config:
        raise StudyError("rate variables need a complete vehicle configuration "
                         "with its mounts (not an \"extends\" patch)")
    return text


# What every stored design carries (Problem.assess writes them).
RECORD_FIELDS = ("key", "x", "objective", "feasible", "static", "violations")


def read_store(path: pathlib.Path, fields=RECORD_FIELDS) -> tuple[dict | None, list[dict], bool]:
    """A study's ``evaluations.jsonl``: its header (None for a missing or empty file), its
    designs, and whether lines were dropped. A line that is not JSON (cut short by an
    interruption) is dropped: that design runs again. A damaged header, or a design without the
    ``fields`` a study reads or (where it has one) with an objective that is not a finite number,
    is a StudyError that names the file and the line."""
    lines = path.read_text().splitlines() if path.exists() else []
    if not lines:
        return None, [], False
    try:
        header = json.loads(lines[0])
    except json.JSONDecodeError as error:
        raise StudyError(f"{path}, line 1 (the study's header) is damaged ({error.msg}): delete "
                         "the file to start the study again") from None
    if not isinstance(header, dict) or "settings" not in header:
        raise StudyError(f"{path}, line 1 is not a study's header: delete the file to start "
                         "the study again")
    records, torn = [], not path.read_text().endswith("\n")
    for number, line in enumerate(lines[1:], start=2):
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            torn = True
            continue
        missing = [k for k in fields if not isinstance(record, dict) or k not in record]
        if missing:
            raise StudyError(f"{path}, line {number}: a design without {', '.join(missing)}; "
                             "delete that line to run the design again")
        objective = record.get("objective", 0.0)
        if isinstance(objective, bool) or not isinstance(objective, (int, float)) \
                or not math.isfinite(objective):
            raise StudyError(f"{path}, line {number}: design {record['x']} has the objective "
                             f"{objective!r}, not a finite number; delete that line to run the "
                             "design again")
        records.append(record)
    return header, records, torn


class Store:
    """The evaluations of a study folder: ``evaluations.jsonl``, a header line (the FMU's checksum
    and the settings) and one line per design, appended as each is done."""

    def __init__(self, folder: pathlib.Path, fmu_sha256: str, settings: dict,
                 fields=RECORD_FIELDS):
        """``fields``: what every stored evaluation carries (a design of a tuning study by
        default)."""
        self.path = pathlib.Path(folder) / "evaluations.jsonl"
        self.header = {"fmu_sha256": fmu_sha256, "settings": settings}
        self.records: dict[str, dict] = {}
        self.order: list[str] = []
        stored, records, torn = read_store(self.path, fields)
        if stored is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.write_text(json.dumps(self.header) + "\n")
            return
        if stored != json.loads(json.dumps(self.header)):
            raise StudyError(f"{self.path} holds the evaluations of another FMU or other "
                             "settings: use another --out folder (or delete it)")
        for record in records:
            self.records[record["key"]] = record
            self.order.append(record["key"])
        if torn:
            self.path.write_text("".join(json.dumps(r) + "\n" for r in [stored] + records))

    @staticmethod
    def key(x) -> str:
        return json.dumps([float(f"{v:.12g}") for v in x])

    def get(self, x) -> dict | None:
        return self.records.get(self.key(x))

    def put(self, x, record: dict):
        key = self.key(x)
        record = {"key": key, **record}
        with open(self.path, "a") as out:
            out.write(json.dumps(record) + "\n")
        self.records[key] = record
        self.order.append(key)

    def history(self) -> list[dict]:
        return [self.records[k] for k in self.order]


class Evaluator:
    """Evaluates designs of ``problem`` on a pool (or here), through the store."""

    def __init__(self, problem: Problem, fmu_path: str, store: Store, mounts: int, pool=None,
                 progress=None):
        self.problem, self.fmu_path, self.store = problem, fmu_path, store
        self.mounts, self.pool, self.progress = mounts, pool, progress
        self.engine = PointEngine.on(fmu_path, pool)
        self.evaluated = 0  # designs run by this evaluator (not read from the store)

    def close(self):
        self.engine.close()

    def run_all(self, items: list, progress=None) -> list:
        """The results of FMU runs (:class:`Run`), on the pool or here, in order."""
        return self.engine.map(functools.partial(run, mounts=self.mounts), items, progress)

    def __call__(self, designs, chunk: int | None = None) -> list[dict]:
        """The records of ``designs`` (rows of the variables' values), stored ones read, the
        others run ``chunk`` designs at a time (stored after each chunk)."""
        designs = [np.asarray(x, dtype=float) for x in designs]
        missing = list(dict.fromkeys(Store.key(x) for x in designs
                                     if self.store.get(x) is None))
        by_key = {Store.key(x): x for x in designs}
        workers = self.pool.workers if self.pool is not None else 1
        chunk = chunk or max(1, 2 * workers)
        for start in range(0, len(missing), chunk):
            todo = [by_key[k] for k in missing[start:start + chunk]]
            items = [item for x in todo for item in self.problem.evaluations(x)]
            began = time.perf_counter()
            results = self.run_all(items)
            seconds = (time.perf_counter() - began) / len(todo)
            per = len(items) // len(todo)
            for k, x in enumerate(todo):
                record = self.problem.assess(x, results[k * per:(k + 1) * per], self.mounts)
                record["seconds"] = seconds
                self.store.put(x, record)
                self.evaluated += 1
                if self.progress is not None:
                    self.progress(record)
        return [self.store.get(x) for x in designs]


def problem_from_args(args) -> tuple[Problem, dict, int]:
    """The problem the options describe, checked against the FMU's model description; returns
    (problem, variables of the FMU, mount count)."""

    variables = model_variables(args.fmu)
    mounts = mount_count(variables)
    check_speeds(args.rpm, increasing=args.count > 1, highest=highest_speed(variables))
    check_count(args.count)
    check_pool(args)
    check_revolutions(args.revolutions)
    for option, value in (("--max-deflection", args.max_deflection),
                          ("--max-translation", args.max_translation),
                          ("--max-rotation", args.max_rotation)):
        check_range(option, value, 0.0, strict_low=True)
    check_range("--full-load-torque", args.full_load_torque, 0.0)
    check_range("--seat-weight", args.seat_weight, 0.0)
    fixed = parse_settings(args.set, variables)
    check_config_file(args.fmu, fixed, remote=bool(args.scheduler))
    texts = args.var or [f"mount[{i}].{kind}" for kind in ("stiffnessScale", "dampingScale")
                         for i in range(1, mounts + 1)]
    try:
        chosen = tuple(parse_variable(t, mounts) for t in texts)
    except StudyError as error:
        raise UsageError(str(error)) from None
    names = [v.name for v in chosen]
    if len(set(names)) != len(names):
        raise UsageError("a design variable is given twice")
    for v in chosen:
        if not v.in_configuration and v.name not in variables:
            raise UsageError(f"--var {v.name}: the FMU has no such input")
        if v.name in fixed:
            raise UsageError(f"--set {v.name}: it is a design variable")
    base = None
    if any(v.in_configuration for v in chosen):
        try:
            base = base_configuration(args.fmu, fixed)
        except (StudyError, OSError, KeyError) as error:
            raise UsageError(str(error)) from None
        fixed.pop("configFile", None)
    limits = Limits(full_load_torque=args.full_load_torque, deflection=args.max_deflection * 1e-3,
                    translation=args.max_translation * 1e-3,
                    rotation=math.radians(args.max_rotation))
    problem = Problem(variables=chosen, rpm_from=args.rpm[0], rpm_to=args.rpm[1],
                      count=args.count, revolutions=args.revolutions, objective=args.objective,
                      seat_weight=args.seat_weight, limits=limits,
                      parameters=tuple(fixed.items()), base_configuration=base)
    return problem, variables, mounts


def open_study(args, problem: Problem, mounts: int):
    """(store, evaluator, pool or None, progress bar or None) for the command's options; the
    caller closes the evaluator and the pool."""

    digest = file_sha256(args.fmu)
    try:
        store = Store(claim(args), digest, problem.settings())
    except StudyError as error:
        raise UsageError(str(error)) from None
    if store.records:
        print(f"note: {len(store.records)} evaluations found in {store.path}: the study "
              "continues from them", file=sys.stderr)
    pool = open_pool(args, POOL_FROM, [dict(problem.parameters)])  # a study runs many designs
    evaluator = Evaluator(problem, args.fmu, store, mounts, pool)
    return store, evaluator, pool


def design_table(problem: Problem, records: list[dict]) -> pd.DataFrame:
    """One row per evaluated design: the variables, the objective, the limits' use."""
    rows = []
    for k, r in enumerate(records):
        row = {"evaluation": k + 1}
        row.update({v.name: x for v, x in zip(problem.variables, r["x"])})
        row.update({"objective": r["objective"], "feasible": r["feasible"],
                    "max_deflection_mm": r["static"]["deflection"] * 1e3,
                    "max_translation_mm": r["static"]["translation"] * 1e3,
                    "max_rotation_deg": math.degrees(r["static"]["rotation"]),
                    "seconds": r.get("seconds", float("nan"))})
        rows.append(row)
    return pd.DataFrame(rows)
