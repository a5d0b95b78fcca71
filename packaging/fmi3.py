"""Writes the FMI 3.0 FMUs beside the 2.0 ones (the engine FMU and the body FMU), from the same
binaries (which export both the fmi2 and the fmi3 functions) and the same resources.

Layout of <modelIdentifier>-fmi3.fmu:
    modelDescription.xml                           the FMI 3.0 description build.rs generated
                                                   (OUT_DIR/fmi3/, the body's prefixed body.) from
                                                   modelDescription/variables.json
    binaries/x86_64-linux/<modelIdentifier>.so     the same shared library as the 2.0 FMU's
    binaries/x86_64-windows/<modelIdentifier>.dll  the same DLL as the 2.0 FMU's
    terminalsAndIcons/terminalsAndIcons.xml        terminals: engine inputs, mounts, powertrain, comfort
    resources/                                     as in the 2.0 FMU
    documentation/index.html                       as in the 2.0 FMU (the variables by their 2.0 names)
    documentation/fmi-ls-ref.html, extra/org.fmi-standard.fmi-ls-ref/
                                                   the 2.0 FMU's reference experiments with the 3.0
                                                   array variables, added by references.py
"""

import pathlib
import zipfile


def write_fmu(out: pathlib.Path, out_dir: pathlib.Path, shipped_so: pathlib.Path, dll: pathlib.Path,
              model_identifier: str, root: pathlib.Path, prefix: str = "") -> pathlib.Path:
    """Writes ``out/<model_identifier>-fmi3.fmu`` from the generated files starting with
    ``prefix`` (``body.`` for the body FMU) and returns its path."""
    xml = (out_dir / "fmi3" / f"{prefix}modelDescription.xml").read_text()
    if 'fmiVersion="3.0"' not in xml or f'modelIdentifier="{model_identifier}"' not in xml:
        raise SystemExit("package: the FMI 3.0 model description does not match the 2.0 one")
    fmu = out / f"{model_identifier}-fmi3.fmu"
    tmp = fmu.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("modelDescription.xml", xml)
        z.write(shipped_so, f"binaries/x86_64-linux/{model_identifier}.so")
        z.write(dll, f"binaries/x86_64-windows/{model_identifier}.dll")
        z.write(out_dir / "fmi3" / f"{prefix}terminalsAndIcons.xml",
                "terminalsAndIcons/terminalsAndIcons.xml")
        z.write(out_dir / f"{prefix}index.html", "documentation/index.html")
        for resource in sorted((root / "resources").glob("*")):
            if resource.is_file():
                z.write(resource, f"resources/{resource.name}")
    tmp.replace(fmu)
    return fmu
