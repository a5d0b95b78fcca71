"""The engine on the body as a system a co-simulation tool loads: an SSP 1.0 archive (``.ssp``)
holding both FMUs, their mount-by-mount connections and the parameter values.

The archive is valid against the SSP 1.0 schemas (fmpy's ``read_ssd(..., validate=True)`` checks
it in python/tests/test_coupling.py): the parameter values of each FMU are an SSV parameter set of
their own, ``resources/<element>.ssv``, bound by ``source`` (fmpy validates it against the SSV
schema; libcosim reads it from there too). The one fixed coupling step is written where each
common SSP host looks for it (``host_annotations``): OSP's annotation on ``ssd:DefaultExperiment``
(libcosim) and OpenModelica's on ``ssd:System`` (OMSimulator).

The engine FMU (EngineMountChassis, scene 3) passes each mount's force on the body to the body
FMU (EngineMountBody); the body passes the displacement and velocity of each mount point back.
Together they are scene 2 split at the mounts.

    emc ssp --fmu dist/EngineMountChassis.fmu --body-fmu dist/EngineMountBody.fmu dist/EngineInBody.ssp
"""

from __future__ import annotations

import pathlib
import zipfile
from xml.sax.saxutils import quoteattr

from ..base.checks import typed_value
from ..base.errors import UsageError
from ..base.fmu import model_variables, mount_count

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
# libcosim's fixed-step annotation. Its namespace is declared on the root: libcosim 0.11 reads
# every child of osp:Algorithm, attributes included, as an algorithm, so an xmlns attribute there
# makes it refuse the file ("Unknown algorithm: <xmlattr>").
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
# OMSimulator's annotation namespace (the URI its own exporter declares).
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
# The relative tolerance OMSimulator's algebraic-loop solver gets (its own default, --tolerance).
OMS_TOLERANCE = 1e-4

AXES = 3


def connections(mounts: int) -> list[tuple[str, str, str, str]]:
    """(from element, from connector, to element, to connector), mount by mount (``mounts``: the
    engine FMU's mount ports) and axis by axis."""
    out = []
    for i in range(1, mounts + 1):
        for j in range(1, AXES + 1):
            out.append(("engine", f"mount[{i}].F[{j}]", "body", f"mount[{i}].F[{j}]"))
            out.append(("body", f"mount[{i}].r[{j}]", "engine", f"mount[{i}].body.r[{j}]"))
            out.append(("body", f"mount[{i}].v[{j}]", "engine", f"mount[{i}].body.v[{j}]"))
    return out


def _value(v) -> str:
    if isinstance(v, bool):
        return f'<ssv:Boolean value="{str(v).lower()}"/>'
    if isinstance(v, int):
        return f'<ssv:Integer value="{v}"/>'
    if isinstance(v, float):
        return f'<ssv:Real value="{v!r}"/>'
    return f"<ssv:String value={quoteattr(str(v))}/>"


def _component(name: str, fmu: str, connectors: list[tuple[str, str]], has_parameters: bool) -> str:
    lines = [f'      <ssd:Component name="{name}" source="resources/{fmu}" '
             'type="application/x-fmu-sharedlibrary">', "        <ssd:Connectors>"]
    for connector, kind in connectors:
        lines.append(f"          <ssd:Connector name={quoteattr(connector)} kind=\"{kind}\"><ssc:Real/></ssd:Connector>")
    lines.append("        </ssd:Connectors>")
    if has_parameters:
        lines += ["        <ssd:ParameterBindings>",
                  f'          <ssd:ParameterBinding source="{parameter_set_path(name)}"/>',
                  "        </ssd:ParameterBindings>"]
    lines.append("      </ssd:Component>")
    return "\n".join(lines)


def parameter_set_path(element: str) -> str:
    """Where the parameter set of ``element`` lies in the archive (relative to the SSD)."""
    return f"resources/{element}.ssv"


def parameter_set(name: str, parameters: dict) -> str:
    """An SSV 1.0 parameter set (``.ssv`` file) with ``parameters`` by FMI variable name."""
    rows = "\n".join(f"    <ssv:Parameter name={quoteattr(key)}>{_value(value)}</ssv:Parameter>"
                     for key, value in parameters.items())
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet xmlns:ssv="{SSV}" version="1.0" name={quoteattr(name)}>
  <ssv:Parameters>
{rows}
  </ssv:Parameters>
</ssv:ParameterSet>
"""


def parameters_of(engine_parameters: dict | None, body_parameters: dict | None) -> dict[str, dict]:
    """The parameter values by element; the engine's ``scene`` is 3 whatever is given."""
    return {"engine": {**(engine_parameters or {}), "scene": 3}, "body": dict(body_parameters or {})}


def system_structure(engine_fmu: str, body_fmu: str, mounts: int,
                     engine_parameters: dict | None = None, body_parameters: dict | None = None,
                     step_size: float = 5e-5, stop_time: float = 1.0) -> str:
    """The SystemStructure.ssd text. ``engine_parameters`` and ``body_parameters`` are start values
    by FMI variable name; the engine's ``scene`` is 3 whatever is given; ``mounts``: the engine
    FMU's mount ports, each connected on its three axes. The parameter sets
    themselves are separate files (``parameter_set``), which the SSD binds by ``source``."""
    parameters = parameters_of(engine_parameters, body_parameters)
    links = connections(mounts)

    def connectors(element: str) -> list[tuple[str, str]]:
        return ([(c, "output") for e, c, _, _ in links if e == element]
                + [(c, "input") for _, _, e, c in links if e == element])

    elements = "\n".join([
        _component("engine", engine_fmu, connectors("engine"), bool(parameters["engine"])),
        _component("body", body_fmu, connectors("body"), bool(parameters["body"])),
    ])
    wires = "\n".join(
        f'      <ssd:Connection startElement="{a}" startConnector={quoteattr(b)} '
        f'endElement="{c}" endConnector={quoteattr(d)}/>' for a, b, c, d in links)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:osp="{OSP}"
    xmlns:oms="{OMS}" version="1.0" name="EngineInBody">
  <ssd:System name="EngineInBody" description="The engine (EngineMountChassis, scene 3) on the elastic body (EngineMountBody), coupled at the four engine mounts: scene 2 split at the mounts.">
    <ssd:Elements>
{elements}
    </ssd:Elements>
    <ssd:Connections>
{wires}
    </ssd:Connections>
{system_annotation(step_size)}
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="{stop_time!r}">
{experiment_annotation(step_size)}
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def system_annotation(step_size: float) -> str:
    """OpenModelica's annotation on ``ssd:System``: the fixed-step master at ``step_size``.

    OMSimulator needs it to load the file at all: its command line (``oms_importFile``) takes the
    system type from ``oms:SimulationInformation`` and, with none, refuses the system ("Unable to
    add System") and aborts. The command line reads the ``oms:FixedStepMaster`` child; its Python
    API (``OMSimulator.SSP``) reads the attributes of ``oms:SimulationInformation`` as a solver,
    which it gives to every co-simulation FMU that names none under the name ``oms_ma_default`` (a
    component cannot name one here: the command line refuses annotations on components)."""
    return f"""    <ssd:Annotations>
      <ssc:Annotation type="org.openmodelica">
        <oms:Annotations>
          <oms:SimulationInformation name="oms_ma_default" method="oms_ma" fixedStepSize="{step_size!r}" relativeTolerance="{OMS_TOLERANCE!r}">
            <oms:FixedStepMaster description="oms-ma" stepSize="{step_size!r}" relativeTolerance="{OMS_TOLERANCE!r}"/>
          </oms:SimulationInformation>
        </oms:Annotations>
      </ssc:Annotation>
    </ssd:Annotations>"""


def experiment_annotation(step_size: float) -> str:
    """OSP's annotation on ``ssd:DefaultExperiment``: libcosim's fixed-step algorithm at
    ``step_size``."""
    return f"""    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm>
          <osp:FixedStepAlgorithm baseStepSize="{step_size!r}"/>
        </osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>"""


def checked_parameters(fmu: pathlib.Path, parameters: dict) -> dict:
    """``parameters`` checked against the model description of ``fmu`` (a settable variable of
    that name, its type, its declared range) and typed as it declares them. A value the FMU would
    refuse never reaches the archive: libcosim 0.11 aborts the whole process when an FMU refuses
    a parameter value of an SSP."""

    variables = model_variables(str(fmu), model=None)
    out = {}
    for name, value in parameters.items():
        if name not in variables:
            raise ValueError(f"{fmu.name}: no variable named {name}")
        text = str(value).lower() if isinstance(value, bool) else str(value)
        try:
            out[name] = typed_value(variables[name], text, controlled={})
        except UsageError as e:
            raise ValueError(f"{fmu.name}: {str(e).removeprefix('--set ')}") from None
    return out


def write_ssp(engine_fmu: pathlib.Path, body_fmu: pathlib.Path, out: pathlib.Path,
              engine_parameters: dict | None = None, body_parameters: dict | None = None,
              step_size: float = 5e-5, stop_time: float = 1.0) -> pathlib.Path:
    """Writes the ``.ssp`` archive: SystemStructure.ssd, both FMUs and their parameter sets under
    resources/. The parameter values are checked against the FMUs' model descriptions first
    (``checked_parameters``: ValueError naming the variable)."""
    engine_fmu, body_fmu, out = pathlib.Path(engine_fmu), pathlib.Path(body_fmu), pathlib.Path(out)
    engine_parameters = checked_parameters(engine_fmu, engine_parameters or {})
    body_parameters = checked_parameters(body_fmu, body_parameters or {})

    mounts = mount_count(model_variables(str(engine_fmu)))
    ssd = system_structure(engine_fmu.name, body_fmu.name, mounts, engine_parameters,
                           body_parameters, step_size, stop_time)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".ssp.tmp")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", ssd)
        for element, values in parameters_of(engine_parameters, body_parameters).items():
            if values:
                z.writestr(parameter_set_path(element), parameter_set(element, values))
        z.write(engine_fmu, f"resources/{engine_fmu.name}")
        z.write(body_fmu, f"resources/{body_fmu.name}")
    tmp.replace(out)
    return out


def cmd_ssp(args) -> int:
    """``emc ssp``: writes the archive of the engine and the body FMU."""
    print(write_ssp(args.fmu, args.body_fmu, pathlib.Path(args.archive), step_size=args.step))
    return 0
