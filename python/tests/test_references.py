"""The FMU world's conventions for shipping an FMU: each FMU (2.0 and 3.0) carries its reference
experiments (FMI-LS-REF layout) and passes them, and packaging writes the fmi-cross-check tree of
the 2.0 FMUs, which fmpy's validator of vendor repositories accepts."""

import dataclasses
import pathlib
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest

from emc.running import references

ROOT = pathlib.Path(__file__).resolve().parents[2]
DIST = ROOT / "dist"
MODELS = ["EngineMountChassis", "EngineMountBody"]
MODELS3 = [f"{m}-fmi3" for m in MODELS]
# The roles the draft's manifest schema allows (fmi3LayeredStandardReferenceManifest.xsd).
ROLES = re.compile(r"(document|requirement|specification|model|parameter|system|testcase|"
                   r"experiment(/(smoke-test|validation|uncertainty-analysis))?|result|method|"
                   r"rationale|report|request|delivery|configuration|signature|"
                   r"serialized-state(/.*)?|meta-data|other)$")


@pytest.fixture(scope="module")
def packaged(fmu_path) -> pathlib.Path:
    if not (DIST / "cross-check").is_dir() or not (DIST / "EngineMountBody-fmi3.fmu").is_file():
        subprocess.run([sys.executable, str(ROOT / "packaging" / "package.py")], check=True)
    return DIST


def test_the_cross_check_tree_validates_with_fmpy(packaged):
    from fmpy.cross_check.validate_vendor_repo import validate_repo

    fmus, results, problems = validate_repo(str(packaged / "cross-check"))
    assert (fmus, results, problems) == (4, 0, [])
    version = re.search(r'^version = "([^"]+)"', (ROOT / "Cargo.toml").read_text(), re.M).group(1)
    for platform in ["linux64", "win64"]:
        for model in MODELS:
            folder = packaged / "cross-check/fmus/2.0/cs" / platform / "engine_mount_chassis" / version / model
            names = sorted(p.name for p in folder.iterdir())
            assert names == sorted(f"{model}{s}" for s in [".fmu", "_in.csv", "_ref.csv", "_ref.opt"])
            # The cross-check reference is the first experiment the FMU carries.
            with zipfile.ZipFile(folder / f"{model}.fmu") as z:
                first = next(n for n in z.namelist() if n.endswith("_ref.csv"))
                assert z.read(first) == (folder / f"{model}_ref.csv").read_bytes()


@pytest.mark.parametrize("model", MODELS + MODELS3)
def test_the_manifest_lists_every_file_with_its_role_and_checksum(packaged, model):
    with zipfile.ZipFile(packaged / f"{model}.fmu") as z:
        manifest = ET.fromstring(z.read(references.MANIFEST))
        ns = references.LS_NS
        assert manifest.get(f"{{{ns}}}fmi-ls-name") == "org.fmi-standard.fmi-ls-ref"
        assert manifest.get(f"{{{ns}}}fmi-ls-version") == references.LS_VERSION
        listed = {r.get("source"): r for r in manifest.findall("Related")}
        files = {n.removeprefix(references.LS_DIR + "/") for n in z.namelist()
                 if n.startswith(references.LS_DIR + "/") and n != references.MANIFEST}
        assert set(listed) == files
        for source, related in listed.items():
            assert ROLES.match(related.get("role")), related.get("role")
            assert related.get("checksum") == references.sha3(z.read(f"{references.LS_DIR}/{source}"))
        assert "documentation/fmi-ls-ref.html" in z.namelist()


@pytest.mark.parametrize("model", MODELS + MODELS3)
def test_each_fmu_passes_the_reference_experiments_it_carries(packaged, model):
    checked = references.check(packaged / f"{model}.fmu")
    assert checked
    for experiment, worst in checked:
        assert set(worst) == set(experiment.outputs)
        assert max(worst.values()) <= 1.0, (experiment.name, worst)


def test_the_references_catch_a_master_that_gets_the_inputs_wrong(packaged):
    # Run-up with the speed held at 800 rpm, and the body with its forces 1 % too large: both must
    # leave the band, or the references check nothing.
    runup = references.carried(packaged / "EngineMountChassis.fmu")[0]
    held = runup.stimuli.copy()
    held["rpm"] = 800.0
    worst = references.excess(references.simulate(packaged / "EngineMountChassis.fmu",
                                                  dataclasses.replace(runup, stimuli=held)), runup)
    assert max(worst.values()) > 1.0
    forces = references.carried(packaged / "EngineMountBody.fmu")[0]
    scaled = forces.stimuli.copy()
    for name in scaled.dtype.names[1:]:
        scaled[name] *= 1.01
    worst = references.excess(references.simulate(packaged / "EngineMountBody.fmu",
                                                  dataclasses.replace(forces, stimuli=scaled)), forces)
    assert max(worst.values()) > 1.0


def test_the_references_were_computed_at_a_tighter_tolerance(packaged):
    # The experiment runs at rtol 1e-6 against references at 1e-9: the engine's outputs differ
    # (they are not the same run), within the band.
    runup = references.carried(packaged / "EngineMountChassis.fmu")[0]
    assert runup.tolerance == 1e-6
    worst = references.excess(references.simulate(packaged / "EngineMountChassis.fmu", runup), runup)
    assert 0.0 < max(worst.values()) <= 1.0
    assert np.all(np.diff(runup.references["time"]) > 0)


@pytest.mark.parametrize("model", MODELS)
def test_the_fmi3_fmus_carry_the_2_0_experiments_in_their_array_variables(packaged, model):
    from fmpy import read_model_description

    two = references.carried(packaged / f"{model}.fmu")
    three = references.carried(packaged / f"{model}-fmi3.fmu")
    variables3 = {v.name: v for v in read_model_description(str(packaged / f"{model}-fmi3.fmu")).modelVariables}
    assert [e.name for e in three] == [e.name for e in two]
    for e2, e3 in zip(two, three):
        assert (e3.start, e3.stop, e3.step, e3.tolerance, e3.relative, e3.absolute, e3.parameters) == \
            (e2.start, e2.stop, e2.step, e2.tolerance, e2.relative, e2.absolute, e2.parameters)
        for table2, table3 in [(e2.stimuli, e3.stimuli), (e2.references, e3.references)]:
            if table2 is None:
                assert table3 is None
                continue
            assert np.array_equal(table2["time"], table3["time"])
            for name3 in table3.dtype.names[1:]:
                dims = [int(d.start) for d in variables3[name3].dimensions]
                assert table3[name3].shape[1:] == ((int(np.prod(dims)),) if dims else ())
            # Each 2.0 column is the element of its 3.0 array that build.rs maps it to (row-major).
            for name in table2.dtype.names[1:]:
                name3, index = references.fmi3_element(name)
                dims = [int(d.start) for d in variables3[name3].dimensions]
                flat = int(np.ravel_multi_index([i - 1 for i in index], dims)) if dims else None
                column = table3[name3] if flat is None else table3[name3][:, flat]
                assert np.array_equal(column, table2[name]), name
        # The 3.0 outputs are the whole arrays holding the 2.0 outputs.
        assert e3.outputs == list(dict.fromkeys(references.fmi3_element(n)[0] for n in e2.outputs))


def test_the_fmi3_references_catch_a_master_that_lays_out_an_array_wrongly(packaged):
    # The body's force stimulus set column-major (mount.F as 3 x 4 instead of 4 x 3).
    forces = references.carried(packaged / "EngineMountBody-fmi3.fmu")[0]
    swapped = forces.stimuli.copy()
    swapped["mount.F"] = forces.stimuli["mount.F"].reshape(-1, 4, 3).transpose(0, 2, 1).reshape(-1, 12)
    worst = references.excess(references.simulate(packaged / "EngineMountBody-fmi3.fmu",
                                                  dataclasses.replace(forces, stimuli=swapped)), forces)
    assert max(worst.values()) > 1.0


def test_fmpys_vendor_repository_validator_skips_fmi3_trees(tmp_path):
    # Why packaging writes no fmus/3.0 tree: fmpy's validator counts such a folder and checks
    # nothing in it (an empty file for an FMU and no references pass).
    from fmpy.cross_check.validate_vendor_repo import validate_repo

    folder = tmp_path / "fmus/3.0/cs/x86_64-linux/engine_mount_chassis/0.2.0/Broken"
    folder.mkdir(parents=True)
    (folder / "Broken.fmu").write_bytes(b"")
    assert validate_repo(str(tmp_path)) == (1, 0, [])
    twin = tmp_path / "fmus/2.0/cs/linux64/engine_mount_chassis/0.2.0/Broken"
    twin.mkdir(parents=True)
    (twin / "Broken.fmu").write_bytes(b"")
    assert validate_repo(str(tmp_path))[2]
