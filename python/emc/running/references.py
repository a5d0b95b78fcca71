"""Reference experiments an FMU carries, and a run of the FMU against them.

The FMUs ship their reference experiments in the layout of the FMI layered standard for related
files, FMI-LS-REF (github.com/modelica/fmi-ls-ref, draft tagged v1.0.0-beta.1 of 2026-07-01;
not yet a release):

    extra/org.fmi-standard.fmi-ls-ref/
        fmi-ls-manifest.xml     <fmiReferences>: one <Related> per file, with its role and SHA3-256
        experiments.exp         <Experiments>: per experiment the start and stop time, the
                                communication step, the solver tolerance, and its files
        <name>.ssv              the experiment's parameter values (SSP 1.0 parameter set), if any
        <name>_in.csv           the stimulus: input values over time, linear between rows
        <name>_ref.csv          the expected outputs, computed at a much tighter tolerance
    documentation/fmi-ls-ref.html   what the experiments are and how they are compared

The experiments file follows the format of the draft's appendix "Experiments Format" (MIME type
application/x-ma-ls-experiments, suffix .exp), which the project has since moved into a
specification of its own (MA-HS-Experiments). The comparison tolerance of an experiment sits in
an annotation of its <References> element (type ``ANNOTATION``): every output must stay within
``relative`` of the reference's range plus ``absolute`` of it at every sample.

The CSV files follow the rules of the FMI cross-check (a quoted header "time", then the
variable names; numbers as C literals; at most 1 MB), so the same files serve the cross-check
tree that packaging/references.py writes. The FMI 3.0 FMUs carry the same experiments with their
array variables: a column per 3.0 variable, an array's elements in one cell separated by spaces
in row-major order (``"mount.F"`` holds ``mount[1].F[1]``, ``mount[1].F[2]``, … ``mount[4].F[3]``),
as fmpy's ``fmpy.util.write_csv`` and the Modelica Reference-FMUs write them; their outputs are
the whole arrays that hold the 2.0 experiment's outputs.

    emc check-references dist/EngineMountChassis.fmu dist/EngineMountBody.fmu
"""

from __future__ import annotations

import dataclasses
import hashlib
import pathlib
import re
import shutil
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Slave

LS_NAME = "org.fmi-standard.fmi-ls-ref"
LS_VERSION = "1.0.0-beta.1"
LS_DIR = f"extra/{LS_NAME}"
MANIFEST = f"{LS_DIR}/fmi-ls-manifest.xml"
EXPERIMENTS = "experiments.exp"
EXPERIMENTS_TYPE = "application/x-ma-ls-experiments"
ANNOTATION = "org.engine-mount-chassis.comparison"
LS_NS = "http://fmi-standard.org/fmi-ls-manifest"


@dataclasses.dataclass
class Experiment:
    """One reference experiment: what to set, what to drive the inputs with, what to read, and
    how close the outputs must come to the references."""
    name: str
    description: str
    stop: float
    step: float
    tolerance: float                      # the solver tolerance the experiment runs at
    outputs: list[str]
    parameters: dict = dataclasses.field(default_factory=dict)
    stimuli: np.ndarray | None = None     # structured: "time", then input names
    relative: float = 1e-3                # of each reference's range (max - min) ...
    absolute: float = 0.0                 # ... plus this, in the output's unit
    start: float = 0.0
    references: np.ndarray | None = None  # structured: "time", then the outputs


def simulate(fmu: pathlib.Path, experiment: Experiment, tolerance: float | None = None) -> np.ndarray:
    """The experiment run in fmpy (its solver tolerance unless ``tolerance`` is given): the
    outputs every ``step``, the inputs set from the stimulus (linear between its rows) at each
    communication point."""

    model = read_model_description(str(fmu))
    if model.fmiVersion == "3.0":
        return _simulate3(fmu, model, experiment, tolerance or experiment.tolerance)
    result = simulate_fmu(str(fmu), start_time=experiment.start, stop_time=experiment.stop,
                          output_interval=experiment.step,
                          relative_tolerance=tolerance or experiment.tolerance,
                          start_values=experiment.parameters, input=experiment.stimuli,
                          output=experiment.outputs)
    return result[["time", *experiment.outputs]]


def _simulate3(fmu: pathlib.Path, model, experiment: Experiment, tolerance: float) -> np.ndarray:
    """An FMI 3.0 co-simulation FMU through fmpy's FMU3Slave, in the order of fmpy's
    ``simulate_fmu`` (parameters, initialization at ``tolerance``, the inputs at each
    communication point before the step). ``simulate_fmu`` itself cannot take a stimulus that
    mixes scalars and arrays (its input table stacks the columns into one array)."""

    variables = {v.name: v for v in model.modelVariables}
    stimuli = experiment.stimuli
    inputs = [] if stimuli is None else list(stimuli.dtype.names[1:])

    def apply(t: float) -> None:
        for name in inputs:
            column = stimuli[name].reshape(len(stimuli), -1)
            values = [float(np.interp(t, stimuli["time"], column[:, k])) for k in range(column.shape[1])]
            slave.setFloat64([variables[name].valueReference], values)

    def sample(t: float) -> tuple:
        row = [t]
        for name in experiment.outputs:
            size = int(np.prod(_shape(variables[name])))
            values = slave.getFloat64([variables[name].valueReference], nValues=size)
            row.append(tuple(values) if variables[name].dimensions else values[0])
        return tuple(row)

    unzipped = extract(str(fmu))
    slave = FMU3Slave(guid=model.guid, unzipDirectory=unzipped,
                      modelIdentifier=model.coSimulation.modelIdentifier, instanceName=experiment.name)
    try:
        slave.instantiate()
        for name, value in experiment.parameters.items():
            getattr(slave, f"set{variables[name].type}")([variables[name].valueReference], [value])
        slave.enterInitializationMode(tolerance=tolerance, startTime=experiment.start,
                                      stopTime=experiment.stop)
        apply(experiment.start)
        slave.exitInitializationMode()
        rows = [sample(experiment.start)]
        steps = round((experiment.stop - experiment.start) / experiment.step)
        for k in range(steps):
            t, next_t = experiment.start + k * experiment.step, experiment.start + (k + 1) * experiment.step
            apply(t)
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=next_t - t)
            rows.append(sample(next_t))
        slave.terminate()
    finally:
        slave.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    dtype = [("time", np.float64)] + [
        (n, np.float64, (int(np.prod(_shape(variables[n]))),)) if variables[n].dimensions
        else (n, np.float64) for n in experiment.outputs]
    return np.array(rows, dtype=dtype)


def _shape(variable) -> tuple[int, ...]:
    """The fixed dimensions of a 3.0 variable (the experiments use no array sized by a structural
    parameter)."""
    if any(d.start is None for d in variable.dimensions):
        raise ValueError(f"{variable.name}: an array sized by a structural parameter")
    return tuple(int(d.start) for d in variable.dimensions)


# --- 2.0 scalars as 3.0 array elements -----------------------------------------------------------

def fmi3_element(name: str) -> tuple[str, tuple[int, ...]]:
    """The 3.0 variable a 2.0 scalar belongs to and its (1-based) indices in it, as build.rs maps
    them: ``mount[2].F[3]`` is element [2, 3] of ``mount.F``; a name without indices is a 3.0
    scalar of the same name."""
    return re.sub(r"\[\d+\]", "", name), tuple(int(i) for i in re.findall(r"\[(\d+)\]", name))


def fmi3_arrays(names: list[str]) -> dict[str, list[str]]:
    """The 2.0 scalar ``names`` grouped by the 3.0 variable they belong to, each group in the
    row-major order of the 3.0 array."""
    groups: dict[str, list[tuple[tuple[int, ...], str]]] = {}
    for name in names:
        name3, index = fmi3_element(name)
        groups.setdefault(name3, []).append((index, name))
    return {name3: [n for _, n in sorted(members)] for name3, members in groups.items()}


def as_fmi3(table: np.ndarray, arrays: dict[str, list[str]]) -> np.ndarray:
    """``table`` (columns: time, then 2.0 scalars) with its columns gathered into the 3.0
    variables of ``arrays`` (3.0 name -> its 2.0 elements in row-major order, as
    ``fmi3_arrays`` gives them for all variables of the 2.0 FMU); every element of each array
    must be in ``table``."""
    columns = set(table.dtype.names[1:])
    wanted = list(fmi3_arrays(list(table.dtype.names[1:])))
    out_dtype = [("time", np.float64)]
    for name3 in wanted:
        members = arrays[name3]
        missing = [n for n in members if n not in columns]
        if missing:
            raise ValueError(f"{name3}: the table lacks its elements {', '.join(missing)}")
        is_array = bool(fmi3_element(members[0])[1])
        out_dtype.append((name3, np.float64, (len(members),)) if is_array else (name3, np.float64))
    out = np.zeros(len(table), dtype=out_dtype)
    out["time"] = table["time"]
    for name3 in wanted:
        members = arrays[name3]
        if out.dtype[name3].shape:
            out[name3] = np.stack([table[n] for n in members], axis=1)
        else:
            out[name3] = table[members[0]]
    return out


def excess(result: np.ndarray, experiment: Experiment) -> dict[str, float]:
    """Per output the largest deviation from the reference as a fraction of what is allowed
    (above 1: the output leaves its band)."""
    ref = experiment.references
    if len(result) != len(ref) or not np.allclose(result["time"], ref["time"], rtol=0, atol=1e-9):
        raise ValueError(f"{experiment.name}: the run's {len(result)} samples are not the "
                         f"references' {len(ref)}")
    out = {}
    for name in experiment.outputs:
        # An array's elements each against the range of its own reference.
        expected = ref[name].reshape(len(ref), -1)
        allowed = experiment.relative * np.ptp(expected, axis=0) + experiment.absolute
        worst = np.max(np.abs(result[name].reshape(len(ref), -1) - expected), axis=0)
        ratios = np.where(allowed > 0, worst / np.where(allowed > 0, allowed, 1.0),
                          np.where(worst == 0, 0.0, np.inf))
        out[name] = float(np.max(ratios))
    return out


# --- CSV as the FMI cross-check rules have it ---------------------------------------------------

def csv_text(table: np.ndarray) -> str:
    """The table as CSV; an array column's elements in one cell, separated by spaces."""
    names = table.dtype.names

    def cell(value) -> str:
        return " ".join(repr(float(v)) for v in np.ravel(value))

    lines = [",".join(f'"{n}"' for n in names)]
    for row in table:
        lines.append(",".join(cell(row[n]) for n in names))
    return "\n".join(lines) + "\n"


def read_csv(text: str) -> np.ndarray:
    """``csv_text`` read back: a column whose cells hold several numbers becomes a field of that
    many elements (row-major, flat)."""
    header, *rows = text.strip().splitlines()
    names = [n.strip().strip('"') for n in header.split(",")]
    cells = [row.split(",") for row in rows]
    sizes = [len(c.split()) for c in cells[0]]
    dtype = [(n, np.float64, (k,)) if k > 1 else (n, np.float64) for n, k in zip(names, sizes)]
    return np.array([tuple(tuple(map(float, c.split())) if k > 1 else float(c)
                           for c, k in zip(row, sizes)) for row in cells], dtype=dtype)


# --- reading what an FMU carries ---------------------------------------------------------------

def sha3(data: bytes) -> str:
    return hashlib.sha3_256(data).hexdigest()


def carried(fmu: pathlib.Path) -> list[Experiment]:
    """The reference experiments ``fmu`` carries, with their files read and checked against the
    manifest's checksums."""
    with zipfile.ZipFile(fmu) as z:
        def read(name: str) -> bytes:
            path = f"{LS_DIR}/{name}"
            if path not in z.namelist():
                raise ValueError(f"{fmu.name}: {path} is missing")
            return z.read(path)

        manifest = ET.fromstring(z.read(MANIFEST))
        if manifest.get(f"{{{LS_NS}}}fmi-ls-name") != LS_NAME:
            raise ValueError(f"{fmu.name}: {MANIFEST} is not an {LS_NAME} manifest")
        sources = []
        for related in manifest.findall("Related"):
            data = read(related.get("source"))
            if related.get("checksum") and related.get("checksum") != sha3(data):
                raise ValueError(f"{fmu.name}: {related.get('source')} does not match its checksum")
            if related.get("role", "").startswith("experiment"):
                sources.append(related.get("source"))
        experiments = []
        for source in sources:
            for e in ET.fromstring(read(source)).findall("Experiment"):
                experiments.append(_experiment(e, read))
    return experiments


def _experiment(e: ET.Element, read) -> Experiment:
    parameters = {}
    p = e.find("Parameters")
    if p is not None:
        for parameter in ET.fromstring(read(p.get("source"))).iter():
            if parameter.tag.endswith("}Parameter"):
                typed = next(iter(parameter))
                kind, value = typed.tag.split("}")[1], typed.get("value")
                parameters[parameter.get("name")] = (
                    float(value) if kind == "Real" else int(value) if kind == "Integer"
                    else value == "true" if kind == "Boolean" else value)
    s = e.find("Stimuli")
    stimuli = None if s is None else read_csv(read(s.get("source")).decode())
    r = e.find("References")
    references = read_csv(read(r.get("source")).decode())
    comparison = r.find(f"Annotations/Annotation[@type='{ANNOTATION}']/Comparison")
    return Experiment(name=e.get("name"), description=e.get("description", ""),
                      start=float(e.get("startTime", 0.0)), stop=float(e.get("stopTime")),
                      step=float(e.get("stepSize")), tolerance=float(e.get("tolerance")),
                      outputs=list(references.dtype.names[1:]), parameters=parameters,
                      stimuli=stimuli, references=references,
                      relative=float(comparison.get("relative")),
                      absolute=float(comparison.get("absolute")))


def check(fmu: pathlib.Path) -> list[tuple[Experiment, dict[str, float]]]:
    """Runs ``fmu`` through every experiment it carries: (experiment, excess per output)."""
    return [(e, excess(simulate(fmu, e), e)) for e in carried(fmu)]


def cmd_check_references(args) -> int:
    """``emc check-references``: each FMU through every reference experiment it carries."""
    failed = False
    for fmu in args.fmus:
        for experiment, worst in check(pathlib.Path(fmu)):
            name, ratio = max(worst.items(), key=lambda kv: kv[1])
            ok = ratio <= 1.0
            failed |= not ok
            print(f"{pathlib.Path(fmu).name} {experiment.name}: {'passed' if ok else 'FAILED'} "
                  f"(closest to its band: {name} at {ratio:.2g} of the allowed deviation)")
    return 1 if failed else 0
