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
tree that packaging/references.py writes.

    python -m emc.references dist/EngineMountChassis.fmu dist/EngineMountBody.fmu
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import io
import pathlib
import sys
import xml.etree.ElementTree as ET
import zipfile

import numpy as np

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
    outputs every ``step``, the inputs set from the stimulus at each communication point."""
    from fmpy import simulate_fmu

    result = simulate_fmu(str(fmu), start_time=experiment.start, stop_time=experiment.stop,
                          output_interval=experiment.step,
                          relative_tolerance=tolerance or experiment.tolerance,
                          start_values=experiment.parameters, input=experiment.stimuli,
                          output=experiment.outputs)
    return result[["time", *experiment.outputs]]


def excess(result: np.ndarray, experiment: Experiment) -> dict[str, float]:
    """Per output the largest deviation from the reference as a fraction of what is allowed
    (above 1: the output leaves its band)."""
    ref = experiment.references
    if len(result) != len(ref) or not np.allclose(result["time"], ref["time"], rtol=0, atol=1e-9):
        raise ValueError(f"{experiment.name}: the run's {len(result)} samples are not the "
                         f"references' {len(ref)}")
    out = {}
    for name in experiment.outputs:
        allowed = experiment.relative * float(np.ptp(ref[name])) + experiment.absolute
        worst = float(np.max(np.abs(result[name] - ref[name])))
        out[name] = worst / allowed if allowed > 0 else (0.0 if worst == 0 else np.inf)
    return out


# --- CSV as the FMI cross-check rules have it ---------------------------------------------------

def csv_text(table: np.ndarray) -> str:
    names = table.dtype.names
    lines = [",".join(f'"{n}"' for n in names)]
    for row in table:
        lines.append(",".join(repr(float(row[n])) for n in names))
    return "\n".join(lines) + "\n"


def read_csv(text: str) -> np.ndarray:
    return np.genfromtxt(io.StringIO(text), delimiter=",", names=True, deletechars="")


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


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("fmu", nargs="+", type=pathlib.Path)
    args = parser.parse_args(argv)
    failed = False
    for fmu in args.fmu:
        for experiment, worst in check(fmu):
            name, ratio = max(worst.items(), key=lambda kv: kv[1])
            ok = ratio <= 1.0
            failed |= not ok
            print(f"{fmu.name} {experiment.name}: {'passed' if ok else 'FAILED'} "
                  f"(closest to its band: {name} at {ratio:.2g} of the allowed deviation)")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
