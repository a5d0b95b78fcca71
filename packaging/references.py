"""The reference experiments the FMUs carry and the fmi-cross-check tree, written by package.py.

Each FMU gets its experiments as FMI-LS-REF files (python/emc/references.py describes the
layout): the stimulus, the parameter values, the expected outputs computed by the 2.0 FMU at
rtol 1e-9 (the experiments run at 1e-6), and the comparison tolerance. The FMI 3.0 FMU of the
same model carries the same experiments, their columns gathered into its array variables
(``emc.running.references.as_fmi3``): the references of both come from one run of the 2.0 FMU that
records every element of the arrays the 3.0 outputs are. The first experiment of each 2.0 FMU
also goes into the directory tree of the FMI cross-check
(github.com/modelica/fmi-cross-check, rules 4.1):

    cross-check/fmus/2.0/cs/<platform>/engine_mount_chassis/<version>/<model>/
        <model>.fmu  <model>_ref.csv  <model>_ref.opt  <model>_in.csv

for linux64 and win64 (the same FMU carries both binaries), which
``fmpy.cross_check.validate_vendor_repo`` checks (sizes, model description, options, CSVs). The
3.0 FMUs have no cross-check tree: ``validate_vendor_repo`` (fmpy 0.3.32) skips any folder below
``fmus/`` whose FMI version is not 1.0 or 2.0, so it would check nothing.
"""

from __future__ import annotations

import dataclasses
import html
import pathlib
import shutil
import sys
import zipfile
from xml.sax.saxutils import quoteattr

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "python"))
from emc.running.references import (ANNOTATION, EXPERIMENTS, EXPERIMENTS_TYPE, LS_DIR, LS_NAME,  # noqa: E402
                            LS_NS, LS_VERSION, MANIFEST, Experiment, as_fmi3, csv_text,
                            fmi3_arrays, fmi3_element, sha3, simulate)
from emc.running.ssp import parameter_set  # noqa: E402

TOOL = "engine_mount_chassis"
PLATFORMS = ["linux64", "win64"]
REFERENCE_TOLERANCE = 1e-9
RUN_TOLERANCE = 1e-6
# The comparison band: at rtol 1e-6 the engine's outputs stay within 0.4e-3 of their range of the
# rtol 1e-9 references (scene 2's powertrain.r[3] the closest), at the default 1e-5 within 3e-3;
# the body FMU propagates its modes exactly, whatever the tolerance.
RELATIVE = 2e-3


def table(columns: dict[str, np.ndarray]) -> np.ndarray:
    names = list(columns)
    out = np.zeros(len(columns[names[0]]), dtype=[(n, np.float64) for n in names])
    for n in names:
        out[n] = columns[n]
    return out


def engine_stimulus(given: dict[str, list[float]], times: list[float]) -> np.ndarray:
    """Every input of the engine FMU over ``times``: those ``given``, the others at their start
    values (load torque 0, mount scales 1, body points of scene 3 at rest), as the cross-check
    rules ask for every input."""
    columns = {"time": np.array(times), "rpm": np.full(len(times), 800.0),
               "loadTorque": np.zeros(len(times))}
    for i in range(1, 5):
        columns[f"mount[{i}].stiffnessScale"] = np.ones(len(times))
        columns[f"mount[{i}].dampingScale"] = np.ones(len(times))
    for quantity in ("r", "v"):
        for i in range(1, 5):
            for j in range(1, 4):
                columns[f"mount[{i}].body.{quantity}[{j}]"] = np.zeros(len(times))
    for name, values in given.items():
        columns[name] = np.array(values, dtype=float)
    return table(columns)


def engine_experiments() -> list[Experiment]:
    forces = [f"mount[{i}].F[3]" for i in range(1, 5)] + ["mount[1].F[1]", "mount[1].F[2]"]
    return [
        Experiment(
            name="runup", description="Scene 1 (engine on rigid ground): run-up 800 -> 1400 rpm "
            "in 0.5 s, idle load, excitation faded in over the first 0.1 s",
            stop=0.5, step=1e-3, tolerance=RUN_TOLERANCE, relative=RELATIVE,
            outputs=forces + ["powertrain.r[3]", "powertrain.phi[2]", "crankAngle"],
            stimuli=engine_stimulus({"rpm": [800.0, 1400.0]}, [0.0, 0.5])),
        Experiment(
            name="scene2", description="Scene 2 (engine in the elastic body, default vehicle, "
            "automatic cut-off): 1500 rpm, 0.3 s",
            stop=0.3, step=1e-3, tolerance=RUN_TOLERANCE, relative=RELATIVE, parameters={"scene": 2, "rpm": 1500.0},
            outputs=["mount[1].F[3]", "mount[3].F[3]", "powertrain.r[3]", "steeringWheel.a[2]",
                     "steeringWheel.a[3]", "seat.a[3]"]),
    ]


def body_experiments() -> list[Experiment]:
    t = np.arange(0.0, 0.3 + 5e-4, 1e-3)
    columns = {"time": t}
    for i in range(1, 5):
        for j in range(1, 4):
            columns[f"mount[{i}].F[{j}]"] = np.zeros_like(t)
        columns[f"mount[{i}].F[3]"] = np.full_like(t, -400.0)  # a weight share on each mount
    columns["mount[1].F[3]"] = -400.0 + 150.0 * np.sin(2 * np.pi * 30.0 * t) * np.minimum(t / 0.05, 1.0)
    columns["mount[2].F[1]"] = 80.0 * np.sin(2 * np.pi * 45.0 * t) * np.minimum(t / 0.05, 1.0)
    return [Experiment(
        name="forces", description="The body alone under a weight share of 400 N on each mount, "
        "a 30 Hz vertical force of 150 N on mount 1 and a 45 Hz longitudinal force of 80 N on "
        "mount 2, both faded in over 50 ms",
        stop=0.3, step=1e-3, tolerance=RUN_TOLERANCE, relative=RELATIVE, stimuli=table(columns),
        outputs=["mount[1].r[3]", "mount[1].v[3]", "mount[1].a[3]", "mount[2].r[1]",
                 "steeringWheel.a[1]", "steeringWheel.a[3]", "seat.a[3]"])]


def experiments_of(fmu: pathlib.Path) -> list[Experiment]:
    return engine_experiments() if fmu.stem == "EngineMountChassis" else body_experiments()


def experiments_xml(experiments: list[Experiment]) -> str:
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             '<Experiments name="References" description="Reference experiments of this FMU: run '
             'each, compare every output with its references within the annotated tolerance">']
    for e in experiments:
        lines.append(f"  <Experiment name={quoteattr(e.name)} description={quoteattr(e.description)} "
                     f'startTime="{e.start!r}" stopTime="{e.stop!r}" stepSize="{e.step!r}" '
                     f'tolerance="{e.tolerance!r}">')
        if e.parameters:
            lines.append(f'    <Parameters source="{e.name}.ssv"/>')
        if e.stimuli is not None:
            lines.append(f'    <Stimuli source="{e.name}_in.csv"/>')
        lines += [f'    <References source="{e.name}_ref.csv">',
                  f'      <Annotations><Annotation type="{ANNOTATION}"><Comparison '
                  f'relative="{e.relative!r}" absolute="{e.absolute!r}" rule="every sample: '
                  f'|output - reference| &lt;= relative * (max - min of the reference) + absolute"/>'
                  f"</Annotation></Annotations>",
                  "    </References>", "  </Experiment>"]
    lines.append("</Experiments>")
    return "\n".join(lines) + "\n"


def files_of(experiments: list[Experiment], computed_by: str) -> dict[str, tuple[bytes, str, str, str]]:
    """Every file of the layered standard's folder: name -> (content, MIME type, role, description)."""
    files = {EXPERIMENTS: (experiments_xml(experiments).encode(), EXPERIMENTS_TYPE,
                           "experiment/validation", "Reference experiments of this FMU")}
    for e in experiments:
        if e.parameters:
            files[f"{e.name}.ssv"] = (parameter_set(e.name, e.parameters).encode(),
                                      "application/x-ssp-parameter-set", "parameter",
                                      f"Parameter values of the experiment {e.name}")
        if e.stimuli is not None:
            files[f"{e.name}_in.csv"] = (csv_text(e.stimuli).encode(), "text/csv", "testcase",
                                         f"Stimulus of the experiment {e.name}")
        files[f"{e.name}_ref.csv"] = (csv_text(e.references).encode(), "text/csv", "result",
                                      f"Expected outputs of the experiment {e.name} ("
                                      f"{computed_by})")
    return files


def manifest_xml(files: dict[str, tuple[bytes, str, str, str]]) -> str:
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<fmiReferences xmlns:fmi-ls="{LS_NS}" fmi-ls:fmi-ls-name="{LS_NAME}" '
             f'fmi-ls:fmi-ls-version="{LS_VERSION}" fmi-ls:fmi-ls-description="Layered Standard '
             'providing information on related files included in an FMU.">']
    for name, (data, mime, role, description) in files.items():
        lines.append(f'  <Related type="{mime}" source="{name}" role="{role}" '
                     f'description={quoteattr(description)} checksum="{sha3(data)}"/>')
    lines.append("</fmiReferences>")
    return "\n".join(lines) + "\n"


def documentation(fmu: pathlib.Path, experiments: list[Experiment], computed_by: str) -> str:
    rows = "\n".join(
        f"<tr><td>{html.escape(e.name)}</td><td>{html.escape(e.description)}</td>"
        f"<td>{e.stop:g} s every {e.step * 1e3:g} ms, rtol {e.tolerance:g}</td>"
        f"<td>{', '.join(html.escape(o) for o in e.outputs)}</td>"
        f"<td>{e.relative:g} of each reference's range</td></tr>" for e in experiments)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{fmu.stem}: reference experiments</title></head><body>
<h1>{fmu.stem}: reference experiments</h1>
<p>The folder <code>{LS_DIR}</code> holds this FMU's reference experiments in the layout of the
FMI layered standard FMI-LS-REF (draft v{LS_VERSION}): <code>fmi-ls-manifest.xml</code> lists
the files with their SHA3-256 checksums, <code>{EXPERIMENTS}</code> the experiments. Run each from
its start to its stop time with the communication step and solver tolerance it gives, the
parameter values of its <code>.ssv</code> file, and the inputs of its <code>_in.csv</code>
(linear between rows); every output of its <code>_ref.csv</code> must then stay within the
tolerance below at every sample (each element of an array against the range of its own
reference). An array variable's elements share one CSV cell, separated by spaces, in row-major
order. The references were computed {computed_by}; a master that reproduces them drives the FMU
correctly.</p>
<table border="1"><tr><th>experiment</th><th>what</th><th>run</th><th>outputs compared</th><th>tolerance</th></tr>
{rows}
</table>
<p>With fmpy: <code>emc check-references {fmu.name}</code> (the emc tool of the project).</p>
</body></html>
"""


def add_references(fmu: pathlib.Path, fmu3: pathlib.Path) -> list[Experiment]:
    """Computes the references of the 2.0 FMU ``fmu`` and adds the layered standard's files to
    it and, with the columns as its array variables, to its 3.0 twin ``fmu3``."""
    from fmpy import read_model_description

    arrays = fmi3_arrays([v.name for v in read_model_description(str(fmu)).modelVariables])
    check_arrays(arrays, fmu3)
    experiments, experiments3 = experiments_of(fmu), []
    for e in experiments:
        outputs3 = list(dict.fromkeys(fmi3_element(name)[0] for name in e.outputs))
        recorded = [name for name3 in outputs3 for name in arrays[name3]]
        wide = simulate(fmu, dataclasses.replace(e, outputs=recorded), tolerance=REFERENCE_TOLERANCE)
        e.references = wide[["time", *e.outputs]]
        if any(fmi3_element(name)[1] for name in e.parameters):
            raise ValueError(f"{e.name}: an array element as a parameter has no 3.0 SSV name")
        experiments3.append(dataclasses.replace(
            e, outputs=outputs3, references=as_fmi3(wide, arrays),
            stimuli=None if e.stimuli is None else as_fmi3(e.stimuli, arrays)))
    by = f"by this FMU at rtol {REFERENCE_TOLERANCE:g}"
    by3 = (f"by the FMI 2.0 FMU of this model ({fmu.name}, the same binary) at rtol "
           f"{REFERENCE_TOLERANCE:g}")
    for target, carried, computed_by in [(fmu, experiments, by), (fmu3, experiments3, by3)]:
        files = files_of(carried, computed_by)
        with zipfile.ZipFile(target, "a", compression=zipfile.ZIP_DEFLATED) as z:
            for name, (data, *_rest) in files.items():
                z.writestr(f"{LS_DIR}/{name}", data)
            z.writestr(MANIFEST, manifest_xml(files))
            z.writestr("documentation/fmi-ls-ref.html", documentation(target, carried, computed_by))
    return experiments


def check_arrays(arrays: dict[str, list[str]], fmu3: pathlib.Path) -> None:
    """Every 3.0 variable named by the mapping of 2.0 names exists with as many elements."""
    from fmpy import read_model_description

    variables = {v.name: v for v in read_model_description(str(fmu3)).modelVariables}
    for name3, members in arrays.items():
        v = variables.get(name3)
        if v is None:
            raise ValueError(f"{fmu3.name} has no variable {name3} (from {members[0]})")
        if all(d.start is not None for d in v.dimensions):
            size = int(np.prod([int(d.start) for d in v.dimensions]))
            if size != len(members):
                raise ValueError(f"{fmu3.name}: {name3} has {size} elements, the 2.0 FMU {len(members)}")


def write_cross_check(fmu: pathlib.Path, experiment: Experiment, root: pathlib.Path, version: str) -> list[pathlib.Path]:
    """The cross-check folders of ``fmu`` (one per platform) with ``experiment`` as its reference."""
    model = fmu.stem
    opt = (f"StartTime, {experiment.start!r}\nStopTime, {experiment.stop!r}\n"
           f"StepSize, {experiment.step!r}\nRelTol, {experiment.tolerance!r}\n")
    folders = []
    for platform in PLATFORMS:
        folder = root / "fmus" / "2.0" / "cs" / platform / TOOL / version / model
        folder.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(fmu, folder / f"{model}.fmu")
        (folder / f"{model}_ref.csv").write_text(csv_text(experiment.references))
        (folder / f"{model}_ref.opt").write_text(opt)
        if experiment.stimuli is not None:
            (folder / f"{model}_in.csv").write_text(csv_text(experiment.stimuli))
        folders.append(folder)
    return folders
