"""Operating deflection shapes: how the whole body deflects in one engine order at one speed.

From the order's complex amplitudes of the operational mount forces ``F_p`` the body's modal
coordinates follow exactly (the body is linear, only the mount forces act on it):

    η_k = Σ_p φ_pk · F_p / (ω_k² − ω² + 2i ζ_k ω_k ω),

and every node's motion is ``Σ_k Φ_node,k η_k`` with the modes recovered on every node by the FMU
(``analysis.fullRecovery``). The engine's rigid motion comes from the simulated ``powertrain.r``
and ``powertrain.phi``. Written as a VTU file (ParaView: *Warp By Vector* on ``displacement``,
animate the phase with the real and imaginary parts) through meshio, and as a picture.
"""

from __future__ import annotations

import meshio
import numpy as np
import pandas as pd
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from ..figures.plots import plt
from ..running.modal import Export
from ..signals.spectra import order_components
from .tpa import force_signals

POWERTRAIN_SIGNALS = ([f"powertrain.r[{j}]" for j in (1, 2, 3)]
                      + [f"powertrain.phi[{j}]" for j in (1, 2, 3)])


def signals(export: Export) -> list[str]:
    return force_signals(export) + POWERTRAIN_SIGNALS


def operating_shape(export: Export, samples: dict, revolutions: int, rpm: float,
                    order: float) -> dict:
    """The complex displacement (m) of every node and of the powertrain's points in one order.

    Returns ``nodes`` (n, 3) positions, ``body`` (n, 3) complex displacements, ``modal`` the
    modal coordinates, and the powertrain's ``points`` (its housing's centre of mass, then the
    brackets) with their ``powertrain`` (m, 3) complex displacements."""
    mesh, shapes = export.full_recovery()
    body = export.body
    frequency = order * rpm / 60.0
    paths = export.paths()
    forces = np.column_stack([samples[s] for s in force_signals(export)])
    f = order_components(forces, revolutions, [order])[0]               # (paths,)
    generalised = np.zeros(len(body.omega), complex)
    for (_, j, p), fp in zip(paths, f):
        generalised += body.point(p)[:, j - 1] * fp
    eta = body.modal_receptance([frequency])[0] * generalised
    displacement = shapes[:, :3, :] @ eta                                 # (nodes, 3)
    # The powertrain: its housing's reference point and the brackets, moved rigidly.
    motion = order_components(np.column_stack([samples[s] for s in POWERTRAIN_SIGNALS]),
                              revolutions, [order])[0]
    u, theta = motion[:3], motion[3:]
    pt = export.powertrain or {}
    centre = np.asarray(pt.get("housing_centre_of_mass", pt.get("centre_of_mass", [0, 0, 0])))
    brackets = [np.asarray(m["bracket"]) for m in pt.get("mounts", [])]
    points = np.array([centre] + brackets)
    rigid = np.array([u + np.cross(theta, x - centre) for x in points])
    return {"nodes": np.asarray(mesh["nodes"], float), "cells": mesh["cells"],
            "body": displacement, "modal": eta, "points": points, "powertrain": rigid,
            "frequency": frequency, "order": order, "rpm": rpm}


def write_vtu(shape: dict, path: str):
    """The shape as an unstructured grid (binary VTU through meshio): the body's cells, then the
    powertrain as lines from its centre to each bracket and between the brackets. Point data:
    ``displacement`` (real part: the shape at phase 0), ``displacement_imag`` (phase 90°),
    ``amplitude`` (m); cell data ``part`` (0 body, 1 powertrain)."""

    nodes = shape["nodes"]
    n = len(nodes)
    cells = [(kind, np.asarray(c, dtype=np.int64)) for kind, c in shape["cells"].items()]
    m = len(shape["points"])
    lines = [[n, n + k] for k in range(1, m)] + [[n + k, n + k % (m - 1) + 1]
                                                  for k in range(1, m)]
    if m > 1:
        cells.append(("line", np.asarray(lines, dtype=np.int64)))
    points = np.vstack([nodes, shape["points"]])
    u = np.vstack([shape["body"], shape["powertrain"]])
    part = [np.zeros(len(c), dtype=np.int64) for _, c in cells]
    if m > 1:
        part[-1][:] = 1
    mesh = meshio.Mesh(points, cells,
                       point_data={"displacement": u.real, "displacement_imag": u.imag,
                                   "amplitude": np.sqrt(np.sum(np.abs(u) ** 2, axis=1))},
                       cell_data={"part": part})
    meshio.write(path, mesh, file_format="vtu", binary=True, compression=None)


def plot(shape: dict, path: str, title: str = "", scale: float | None = None,
         point_labels: dict | None = None):
    """The body at the phase of its largest deflection, magnified, coloured by amplitude, over
    the undeformed body in grey; the powertrain in red."""

    nodes, u = shape["nodes"], shape["body"]
    # The phase at which the body's deflection is largest: maximise |Re(u e^{iψ})|².
    s = np.sum(u * u)
    psi = -0.5 * np.angle(s)
    real = (u * np.exp(1j * psi)).real
    pt = (shape["powertrain"] * np.exp(1j * psi)).real
    amplitude = np.sqrt(np.sum(np.abs(u) ** 2, axis=1))
    size = np.ptp(nodes, axis=0).max()
    if scale is None:
        scale = 0.06 * size / max(np.abs(real).max(), 1e-30)
    deformed = nodes + scale * real
    fig = plt.figure(figsize=(10, 6.5))
    ax = fig.add_subplot(projection="3d")
    cmap = plt.get_cmap("viridis")
    # The colour scale ends at the 97th percentile: a steering wheel swinging ten times more
    # than the floor would otherwise leave the whole body one colour.
    top = float(np.percentile(amplitude, 97.0)) or float(amplitude.max()) or 1.0
    for kind in ("quad", "triangle"):
        cells = np.asarray(shape["cells"].get(kind, []), dtype=int)
        if len(cells) == 0:
            continue
        ax.add_collection3d(Poly3DCollection(nodes[cells], facecolor="none", edgecolor="0.85",
                                             linewidths=0.2))
        colours = cmap(np.minimum(amplitude[cells].mean(axis=1) / top, 1.0))
        ax.add_collection3d(Poly3DCollection(deformed[cells], facecolors=colours,
                                             edgecolor=colours, linewidths=0.1, alpha=0.45))
    beams = np.asarray(shape["cells"].get("line", []), dtype=int)
    if len(beams):
        ax.add_collection3d(Line3DCollection(deformed[beams],
                                             colors=cmap(np.minimum(
                                                 amplitude[beams].mean(axis=1) / top, 1.0)),
                                             linewidths=1.8))
    points = shape["points"] + scale * pt
    if len(points) > 1:
        segments = [[points[0], p] for p in points[1:]]
        ax.add_collection3d(Line3DCollection(segments, colors="tab:red", linewidths=2.0))
        ax.scatter(*points.T, color="tab:red", s=12)
    for name, node in (point_labels or {}).items():
        ax.scatter(*deformed[node], color="k", s=25)
        ax.text(*deformed[node], f"  {name}", fontsize=8)
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo).max()
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half * 0.6, centre[2] + half * 0.6)
    ax.set_box_aspect((1, 1, 0.6))
    ax.view_init(elev=24, azim=-50)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    mappable = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, top * 1e6))
    fig.colorbar(mappable, ax=ax, shrink=0.6, extend="max",
                 label=f"amplitude [µm] (largest {amplitude.max() * 1e6:.0f} µm)")
    ax.set_title(title or f"Operating deflection shape, order {shape['order']:g} at "
                          f"{shape['rpm']:g} rpm ({shape['frequency']:.1f} Hz), "
                          f"magnified {scale:.0f}×", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def modal_contributions(shape: dict, export: Export, point: str, dof: int,
                        top: int = 6) -> "pd.DataFrame":
    """Which of the body's modes carry a point's motion in the shape: ``φ_point,k · η_k`` per
    mode, largest first, with its share of the motion in phase with the whole."""

    body = export.body
    parts = body.point(point)[:, dof] * shape["modal"]
    total = parts.sum()
    in_phase = (parts * np.conj(total)).real / max(abs(total), 1e-300)
    table = pd.DataFrame({"mode": np.arange(1, len(parts) + 1),
                          "frequency_hz": body.omega / (2 * np.pi), "damping": body.zeta,
                          "amplitude": np.abs(parts), "share": in_phase / max(abs(total), 1e-300)})
    descriptions = (export.mesh or {}).get("mode_descriptions") or []
    if len(descriptions) == len(parts):
        table["description"] = descriptions
    return table.sort_values("amplitude", ascending=False).head(top).reset_index(drop=True)
