"""What an FMU's model description says, for checks before anything runs: its variables, its
outputs, how many mounts it has, the signals a sweep records, and which configuration files a
``configFile`` can name."""

from __future__ import annotations

import difflib
import hashlib
import pathlib
import platform
import re
import xml.etree.ElementTree as ET
import zipfile
from typing import Iterable

from .errors import UsageError

# What a sweep records without --signal: the mount forces and the comfort points.
DEFAULT_SIGNAL_PREFIXES = ("mount[", "steeringWheel.a", "seat.a")
# The chassis mode cut-off (Hz) the body in use keeps, as the FMU reports it.
CUTOFF_IN_USE = "chassis.modeCutoffInUse"
# The FMUs of this project, by the model identifier of their co-simulation interface.
ENGINE = "EngineMountChassis"
BODY = "EngineMountBody"
KIND = {ENGINE: "the engine FMU", BODY: "the body FMU"}


def file_sha256(path) -> str:
    """The SHA-256 of a file's content (an FMU, a configuration), read in blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def binaries_folder() -> str:
    """The FMI 2.0 binaries folder of this platform (linux64, win64, darwin64, …)."""
    system = {"Linux": "linux", "Windows": "win", "Darwin": "darwin"}.get(platform.system(),
                                                                          platform.system())
    bits = "64" if platform.architecture()[0] == "64bit" else "32"
    return system + bits


def check_fmu(fmu: str, option: str = "--fmu", model: str | None = ENGINE):
    """That ``fmu`` is an FMU this tool can run, before anything is extracted or loaded: a file,
    a zip with an FMI 2.0 co-simulation model description, a binary for this platform, and (if
    ``model`` is given) the model identifier ``model``."""
    path = pathlib.Path(fmu)
    if not path.is_file():
        hint = " (package it with bash packaging/package.sh)" if option == "--fmu" else ""
        raise UsageError(f"{option} {fmu}: no such file{hint}")
    try:
        with zipfile.ZipFile(path) as z:
            names = set(z.namelist())
            if "modelDescription.xml" not in names:
                raise UsageError(f"{option} {fmu}: an archive without modelDescription.xml, not "
                                 "an FMU")
            root = ET.fromstring(z.read("modelDescription.xml"))
    except zipfile.BadZipFile:
        raise UsageError(f"{option} {fmu}: not an FMU (not a zip archive)") from None
    except ET.ParseError as error:
        raise UsageError(f"{option} {fmu}: its modelDescription.xml is not XML ({error})") \
            from None
    version = root.get("fmiVersion", "?")
    if version != "2.0":
        twin = f" (the FMI 2.0 twin of {path.name} is {path.name.replace('-fmi3', '')})" \
            if "-fmi3" in path.name else ""
        raise UsageError(f"{option} {fmu}: an FMI {version} FMU; emc drives FMI 2.0 FMUs{twin}")
    cosim = root.find("CoSimulation")
    if cosim is None:
        raise UsageError(f"{option} {fmu}: no co-simulation interface (model exchange only)")
    identifier = cosim.get("modelIdentifier", "")
    if model is not None and identifier != model:
        what = KIND.get(identifier, f"the FMU {identifier}")
        raise UsageError(f"{option} {fmu} is {what}; {option} takes {KIND.get(model, model)} "
                         f"({model}.fmu)")
    folder = binaries_folder()
    suffix = {"linux": ".so", "win": ".dll", "darwin": ".dylib"}.get(folder[:-2], "")
    if f"binaries/{folder}/{identifier}{suffix}" not in names:
        have = sorted({n.split("/")[1] for n in names if n.startswith("binaries/")
                       and n.count("/") >= 2})
        raise UsageError(f"{option} {fmu}: no binary for this platform ({folder}; it has "
                         f"{', '.join(have) or 'none'})")


def model_variables(fmu: str, option: str = "--fmu", model: str | None = ENGINE) -> dict:
    """The FMU's variables by name (from its model description), the FMU checked first
    (:func:`check_fmu`)."""
    # Deferred: fmpy imports numpy, which the command line does not need to start.
    from fmpy import read_model_description

    check_fmu(fmu, option, model)
    return {v.name: v for v in read_model_description(fmu).modelVariables}


def output_names(variables: dict) -> list[str]:
    return [n for n, v in variables.items() if v.causality == "output"]


def default_signals(variables: dict) -> list[str]:
    """What a sweep records without --signal: the mount forces and the comfort points."""
    return [n for n in output_names(variables) if variables[n].type == "Real"
            and n.startswith(DEFAULT_SIGNAL_PREFIXES)]


def units_of(variables: dict) -> dict:
    return {name: v.unit for name, v in variables.items()}


def highest_speed(variables: dict) -> float:
    rpm = variables.get("rpm")
    return float(rpm.max) if rpm is not None and rpm.max is not None else 6000.0


def start_value(variables: dict, parameters: dict, name: str):
    """The value ``name`` starts with: set in ``parameters``, else the model description's."""
    if name in parameters:
        return parameters[name]
    v = variables.get(name)
    return None if v is None or v.start is None else float(v.start)


def mount_count(names: Iterable[str]) -> int:
    """How many mounts an FMU has: the highest ``i`` of its variables ``mount[i].…`` (``names``:
    the variable names of its model description)."""
    found = [int(m.group(1)) for name in names if (m := re.match(r"mount\[(\d+)\]\.", name))]
    return max(found, default=0)


def variable_names(model_description) -> list[str]:
    return [v.name for v in model_description.modelVariables]


def check_outputs(option: str, names: list[str], variables: dict, among: list[str] | None = None):
    """Each name an output of the FMU (and, if ``among`` is given, one of those)."""
    outputs = output_names(variables)
    for name in names:
        if name not in variables or variables[name].causality != "output":
            close = difflib.get_close_matches(name, outputs, n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise UsageError(f"{option} {name}: not an output of the FMU{hint}")
        if among is not None and name not in among:
            raise UsageError(f"{option} {name}: not among the analysed signals "
                             f"({', '.join(among)}); add --signal {name}")


def check_config_file(fmu: str, parameters: dict, remote: bool = False):
    """A configFile names a file in the FMU's resources (relative) or an existing file (absolute;
    on a Dask cluster the workers' file system counts, where the pool checks it)."""
    name = str(parameters.get("configFile", "") or "")
    if not name:
        return
    if pathlib.PurePosixPath(name).is_absolute():
        if not remote and not pathlib.Path(name).is_file():
            raise UsageError(f"--set configFile={name}: no such file")
        return
    with zipfile.ZipFile(fmu) as z:
        resources = [n[len("resources/"):] for n in z.namelist()
                     if n.startswith("resources/") and not n.endswith("/")]
    if name not in resources:
        close = difflib.get_close_matches(name, resources, n=3)
        hint = f"did you mean {', '.join(close)}? " if close else ""
        raise UsageError(f"--set configFile={name}: not in the FMU's resources ({hint}"
                         f"available: {', '.join(sorted(resources))}); or give an absolute path")
