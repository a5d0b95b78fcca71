"""The SSP archive carries what each common SSP host reads to run it at the coupling step it
declares: OSP's annotation (libcosim) and OpenModelica's (OMSimulator). Neither host can run in CI
here (OMSimulator's package downloads its binaries from elsewhere), so these tests pin the
annotations down as the hosts' importers read them: OMSimulator's command line matches element
names with their prefixes as written (pugixml, no namespaces) and looks at the first
``ssc:Annotation`` of an ``ssd:Annotations`` only; its Python API and libcosim resolve namespaces.
scripts/omsimulator-check.py runs the archive in OMSimulator where it is installed."""

import pathlib
import xml.etree.ElementTree as ET
import zipfile

import pytest
from fmpy.ssp.ssd import read_ssd

from emc.running.ssp import OMS, OSP, SSC, SSD, write_ssp

ROOT = pathlib.Path(__file__).resolve().parents[2]
NS = {"ssd": SSD, "ssc": SSC, "osp": OSP, "oms": OMS}


def ssd_text(ssp: pathlib.Path) -> str:
    with zipfile.ZipFile(ssp) as z:
        return z.read("SystemStructure.ssd").decode()


def osp_step(root: ET.Element) -> float:
    """The step libcosim takes: ssd:DefaultExperiment's OSP fixed-step algorithm."""
    found = root.findall("ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation"
                         "[@type='com.opensimulationplatform']/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    assert len(found) == 1, "libcosim's osp:FixedStepAlgorithm is missing"
    return float(found[0].get("baseStepSize"))


def oms_command_line_step(root: ET.Element) -> float:
    """The step OMSimulator's command line takes, read as its importer reads it: the first
    ssc:Annotation of the system's ssd:Annotations, of type org.openmodelica, its
    oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster with solver oms-ma."""
    annotations = root.find("ssd:System/ssd:Annotations", NS)
    assert annotations is not None, "the system has no ssd:Annotations for OMSimulator"
    first = annotations.find("ssc:Annotation", NS)
    assert first is not None and first.get("type") == "org.openmodelica", \
        "OMSimulator reads only the first ssc:Annotation of the system; it must be org.openmodelica"
    master = first.find("oms:Annotations/oms:SimulationInformation/oms:FixedStepMaster", NS)
    assert master is not None, "oms:FixedStepMaster is missing: OMSimulator refuses the system"
    assert master.get("description") == "oms-ma"
    assert float(master.get("relativeTolerance")) > 0
    return float(master.get("stepSize"))


def oms_python_step(root: ET.Element) -> float:
    """The step OMSimulator's Python API takes: the attributes of oms:SimulationInformation as a
    solver, named as the solver it gives co-simulation FMUs that name none."""
    found = root.findall("ssd:System/ssd:Annotations/ssc:Annotation[@type='org.openmodelica']"
                         "/oms:Annotations/oms:SimulationInformation", NS)
    assert len(found) == 1, "one oms:SimulationInformation (a second without a master is refused)"
    info = found[0]
    assert info.get("name") == "oms_ma_default" and info.get("method") == "oms_ma"
    return float(info.get("fixedStepSize"))


def literal_names_present(text: str) -> None:
    # OMSimulator's C++ importer compares qualified names: another prefix for the same namespace
    # would be valid XML that it does not see.
    for name in ("<ssd:System ", "<ssd:Annotations>", '<ssc:Annotation type="org.openmodelica">',
                 "<oms:Annotations>", "<oms:SimulationInformation ", "<oms:FixedStepMaster "):
        assert name in text, f"{name} not written with the prefix OMSimulator's importer expects"


def test_the_shipped_ssp_declares_its_one_step_to_libcosim_and_omsimulator(body_fmu_path):
    text = ssd_text(ROOT / "dist" / "EngineInBody.ssp")
    root = ET.fromstring(text)
    literal_names_present(text)
    steps = {osp_step(root), oms_command_line_step(root), oms_python_step(root)}
    assert steps == {5e-5}


@pytest.mark.parametrize("step", [1e-4, 2.5e-5])
def test_a_chosen_step_reaches_every_host_annotation_and_stays_schema_valid(fmu_path, body_fmu_path,
                                                                            tmp_path, step):
    ssp = write_ssp(fmu_path, body_fmu_path, tmp_path / "hosts.ssp", step_size=step)
    text = ssd_text(ssp)
    root = ET.fromstring(text)
    literal_names_present(text)
    assert osp_step(root) == oms_command_line_step(root) == oms_python_step(root) == step
    read_ssd(str(ssp), validate=True)
