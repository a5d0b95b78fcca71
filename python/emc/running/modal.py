"""The modal data and linearised model an FMU instance exports for the analyses.

The FMU writes them at initialisation into the folder named by its parameter
``analysis.exportFolder`` (see the FMU's documentation): the reduced body exactly as it simulates
it (frequencies, damping, mode-shape rows of the named points), the powertrain as a rigid body on
its mounts with the natural modes' kinetic-energy table, the state-space model linearised at the
static equilibrium and, with ``analysis.fullRecovery``, the body's modes on every node. Every
analysis of ``emc`` reads them here: one source of modal data, never a second reduction beside
the simulation.
"""

from __future__ import annotations

import dataclasses
import json
import pathlib
import shutil
import tempfile

import numpy as np

from .runner import PointFailed, Runner

EXPORT_VERSION = 1
# The FMU's comfort-point outputs and the body points they report.
OUTPUT_POINTS = {"steeringWheel": "steering_wheel", "seat": "seat_rail"}


@dataclasses.dataclass
class Body:
    """The reduced body: ``eta_k'' + 2 zeta_k omega_k eta_k' + omega_k^2 eta_k = sum_p phi_pk . F_p``."""

    omega: np.ndarray            # rad/s, per mode
    zeta: np.ndarray             # damping ratio, per mode
    shapes: dict[str, np.ndarray]  # point name -> (modes, 6): ux uy uz rx ry rz per unit eta
    nodes: dict[str, int]
    positions: dict[str, np.ndarray]

    @classmethod
    def from_json(cls, data: dict) -> "Body":
        return cls(omega=np.asarray(data["omega"], float), zeta=np.asarray(data["zeta"], float),
                   shapes={p["name"]: np.asarray(p["shape"], float).reshape(-1, 6)
                           for p in data["points"]},
                   nodes={p["name"]: int(p["node"]) for p in data["points"]},
                   positions={p["name"]: np.asarray(p["position"], float) for p in data["points"]})

    def point(self, name: str) -> np.ndarray:
        if name not in self.shapes:
            raise KeyError(f"body point {name!r} is not recovered (points: "
                           f"{', '.join(self.shapes)})")
        return self.shapes[name]

    def modal_receptance(self, frequencies_hz) -> np.ndarray:
        """``1 / (omega_k^2 - omega^2 + 2i zeta_k omega_k omega)``, (frequencies, modes)."""
        w = 2.0 * np.pi * np.atleast_1d(np.asarray(frequencies_hz, float))[:, None]
        return 1.0 / (self.omega**2 - w**2 + 2j * self.zeta * self.omega * w)

    def accelerance(self, output: str, output_dof: int, inputs: list[tuple[str, int]],
                    frequencies_hz) -> np.ndarray:
        """Acceleration of ``output`` (dof 0..2) per unit force at each ``(point, dof)`` of
        ``inputs``: (frequencies, inputs), m/s²/N."""
        f = np.atleast_1d(np.asarray(frequencies_hz, float))
        w = 2.0 * np.pi * f[:, None]
        receptance = self.modal_receptance(f)  # (F, modes)
        out = self.point(output)[:, output_dof]
        gains = np.column_stack([self.point(p)[:, d] * out for p, d in inputs])  # (modes, I)
        return -(w**2) * (receptance @ gains)


@dataclasses.dataclass
class Export:
    folder: pathlib.Path
    manifest: dict
    body: Body | None
    powertrain: dict | None
    linear: dict | None
    mesh: dict | None = None
    shapes: np.ndarray | None = None

    @property
    def mount_points(self) -> list[str | None]:
        """Per FMU mount ``mount[i]`` (i = 1..): the body point it acts on, or None."""
        return self.manifest["mount_points"]

    def paths(self) -> list[tuple[int, int, str]]:
        """The transfer paths: (mount i, direction j, body point), both 1-based as the FMU's
        ``mount[i].F[j]``."""
        return [(i, j, p) for i, p in enumerate(self.mount_points, 1) if p for j in (1, 2, 3)]

    def full_recovery(self) -> tuple[dict, np.ndarray]:
        """The body's mesh (nodes, cells by VTK type) and its modes on every node
        (nodes, 6, modes)."""
        if self.mesh is None or self.shapes is None:
            raise ValueError("the export holds no modes on the nodes: export with "
                             "analysis.fullRecovery=true")
        return self.mesh, self.shapes


def read_export(folder) -> Export:
    folder = pathlib.Path(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    if manifest.get("version") != EXPORT_VERSION:
        raise ValueError(f"{folder}: analysis export version {manifest.get('version')}, "
                         f"this emc reads {EXPORT_VERSION}")

    def optional(name):
        path = folder / name
        return json.loads(path.read_text()) if name in manifest["files"] else None

    body = optional("body.json")
    return Export(folder=folder, manifest=manifest,
                  body=Body.from_json(body) if body is not None else None,
                  powertrain=optional("powertrain.json"), linear=optional("linear.json"),
                  mesh=optional("mesh.json"),
                  shapes=np.load(folder / "shapes.npy") if "shapes.npy" in manifest["files"]
                  else None)


def export_from_fmu(fmu: str, parameters: dict, folder=None,
                    full_recovery: bool = False) -> Export:
    """Instantiates ``fmu`` with ``parameters`` (start values), lets it write its export into
    ``folder`` (a temporary folder if None, removed after reading) and reads it."""
    own = folder is None
    folder = pathlib.Path(tempfile.mkdtemp(prefix="emc-export-") if own else folder)
    try:
        with Runner(fmu, instance_name="export") as runner:
            if "analysis.exportFolder" not in runner.vr:
                raise PointFailed(f"{fmu} has no analysis.exportFolder parameter: package a "
                                  "newer FMU")
            values = {**parameters, "analysis.exportFolder": str(folder.resolve())}
            if full_recovery:
                values["analysis.fullRecovery"] = True
            try:
                runner._start(values)
            except PointFailed:
                raise
            except Exception as error:  # noqa: BLE001 - fmpy raises plain exceptions
                raise runner.failure("analysis export", error) from None
        return read_export(folder)
    finally:
        if own:
            shutil.rmtree(folder, ignore_errors=True)


def body_point_of(output: str) -> tuple[str, int]:
    """``steeringWheel.a[3]`` → (``steering_wheel``, 2); ``<point>.a[j]`` for any body point."""
    name, _, rest = output.partition(".a[")
    if not rest.endswith("]") or not rest[:-1].isdigit() or not 1 <= int(rest[:-1]) <= 3:
        raise ValueError(f"{output!r} is not an acceleration output (NAME.a[1..3])")
    return OUTPUT_POINTS.get(name, name), int(rest[:-1]) - 1
