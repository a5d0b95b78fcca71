"""The mount decoupling table: the powertrain's rigid modes on its mounts, each with its kinetic
energy over the six directions at the centre of mass (Jeong & Singh, J. Sound Vib. 2000), and the
torque-roll axis against the mounts' elastic axis.

The table is the FMU's own (the natural modes of its linearised model, ``powertrain.json`` of
the export). :func:`rigid_modes_6x6` and :func:`rigid_modes_in_body` compute the same modes
independently from the exported mass matrix, the mounts' stiffness and (in the body) the body's
modal data: numpy's symmetric eigen solver on ``K φ = ω² M φ`` assembled here, undamped.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..figures.plots import plt
from ..running.modal import Export

DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
# The paper's names of the directions for the transverse engine (crank axis along y).
NAMES = {"lateral": "x", "axial": "y", "vertical": "z", "pitch": "rx", "roll": "ry", "yaw": "rz"}


def table(export: Export, kinds=("rigid",)) -> pd.DataFrame:
    """The FMU's modes of ``kinds`` (rigid, ring_carrier, body) with their kinetic-energy
    fractions per direction at the powertrain's centre of mass (percent)."""
    if export.powertrain is None:
        raise ValueError("the export has no powertrain (the engine FMU writes it)")
    rows = []
    for k, m in enumerate(export.powertrain["modes"], 1):
        if m["kind"] not in kinds:
            continue
        row = {"mode": k, "frequency_hz": m["frequency_hz"], "damping": m["damping_ratio"],
               "kind": m["kind"], "direction": m["direction"] or "",
               "powertrain_share": m["powertrain_fraction"]}
        row.update({f"KE_{d} [%]": 100.0 * e
                    for d, e in zip(DIRECTIONS, m["directions_at_centre_of_mass"])})
        rows.append(row)
    return pd.DataFrame(rows)


def skew(a) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def bracket_map(bracket, centre) -> np.ndarray:
    """3×6: the bracket's displacement from the twist ``[u, θ]`` at the centre of mass."""
    return np.hstack([np.eye(3), -skew(np.asarray(bracket) - np.asarray(centre))])


def mount_stiffness_6x6(powertrain: dict, geometric: bool = True) -> np.ndarray:
    """The mounts' stiffness at the centre of mass, as if their far ends were held, assembled
    from each mount's 3×3 tangent stiffness and bracket; with ``geometric`` also the stiffness
    of the static mount forces turning with the powertrain: a force f on the powertrain at
    lever r gives the moment ``(r + θ × r) × f``, i.e. ``−[f]× [r]×`` per unit rotation (the
    weight acts at the centre of mass and adds none). It is what the FMU's full equations hold
    beside the tangent stiffness (0.01–0.14 % in the frequencies of the default and a raised
    mount layout)."""
    cg = np.asarray(powertrain["centre_of_mass"])
    k = np.zeros((6, 6))
    for m in powertrain["mounts"]:
        g = bracket_map(m["bracket"], cg)
        k += g.T @ np.asarray(m["stiffness"]) @ g
        if geometric:
            f = -np.asarray(m["force"])  # the mount's static force on the powertrain
            k[3:, 3:] -= skew(f) @ skew(np.asarray(m["bracket"]) - cg)
    return k


def _generalised_eigen(k: np.ndarray, m: np.ndarray):
    """``K φ = λ M φ`` with M positive definite: λ ascending, φ with ``φᵀ M φ = I``."""
    lower = np.linalg.cholesky(m)
    inv = np.linalg.inv(lower)
    lam, y = np.linalg.eigh(inv @ k @ inv.T)
    return lam, inv.T @ y


def energy_fractions(phi: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Kinetic energy per coordinate of each mode (columns of ``phi``): ``φ_i (M φ)_i / φᵀMφ``."""
    m_phi = mass @ phi
    return (phi * m_phi) / np.sum(phi * m_phi, axis=0)


def rigid_modes_6x6(powertrain: dict) -> pd.DataFrame:
    """The six modes of the rigid powertrain on its mounts held at their far ends (undamped)."""
    mass = np.asarray(powertrain["mass"])
    lam, phi = _generalised_eigen(mount_stiffness_6x6(powertrain), mass)
    return _rows(np.sqrt(lam) / (2 * np.pi), energy_fractions(phi, mass))


def rigid_modes_in_body(powertrain: dict, export: Export) -> pd.DataFrame:
    """The coupled modes of the rigid powertrain on its mounts in the elastic body (undamped),
    ``6 + modes`` coordinates: the powertrain's twist at its centre of mass and the body's modal
    coordinates; the powertrain's six directions are reported as in the 6×6 table, for the six
    modes with most kinetic energy in the powertrain."""
    body = export.body
    n = len(body.omega)
    mass = np.zeros((6 + n, 6 + n))
    mass[:6, :6] = np.asarray(powertrain["mass"])
    mass[6:, 6:] = np.eye(n)
    stiffness = np.zeros_like(mass)
    stiffness[6:, 6:] = np.diag(body.omega**2)
    cg = np.asarray(powertrain["centre_of_mass"])
    for m in powertrain["mounts"]:
        if m["body_point"] is None:
            raise ValueError(f"mount {m['name']} is on ground: no body to couple")
        # Relative displacement bracket − body point = [G, −Φ] [twist; η].
        g = np.hstack([bracket_map(m["bracket"], cg), -body.point(m["body_point"])[:, :3].T])
        stiffness += g.T @ np.asarray(m["stiffness"]) @ g
        f = -np.asarray(m["force"])
        stiffness[3:6, 3:6] -= skew(f) @ skew(np.asarray(m["bracket"]) - cg)
    lam, phi = _generalised_eigen(stiffness, mass)
    share = np.sum(phi[:6] * (mass[:6, :6] @ phi[:6]), axis=0)
    keep = np.sort(np.argsort(share)[-6:])
    fractions = energy_fractions(phi[:6, keep], mass[:6, :6])
    rows = _rows(np.sqrt(lam[keep]) / (2 * np.pi), fractions)
    rows.insert(2, "powertrain_share", share[keep])
    return rows


def _rows(hz: np.ndarray, fractions: np.ndarray) -> pd.DataFrame:
    out = pd.DataFrame({"frequency_hz": hz,
                        "direction": [DIRECTIONS[int(np.argmax(fractions[:, k]))]
                                      for k in range(len(hz))]})
    for i, d in enumerate(DIRECTIONS):
        out[f"KE_{d} [%]"] = 100.0 * fractions[i]
    return out


def axes(powertrain: dict) -> dict:
    """The torque-roll axis (through the centre of mass along ``J⁻¹ e_crank``) and the mounts'
    elastic axis (the screw axis of the static displacement ``K⁻¹ [0, e_crank]``, K of the
    mounts' tangent stiffness as Jeong & Singh define it), computed here from the exported mass
    and mount stiffness."""
    mass = np.asarray(powertrain["mass"])
    cg = np.asarray(powertrain["centre_of_mass"])
    e = np.asarray(powertrain["crank_axis"])
    roll = np.linalg.solve(mass[3:, 3:], e)
    x = np.linalg.solve(mount_stiffness_6x6(powertrain, geometric=False),
                        np.concatenate([np.zeros(3), e]))
    u, theta = x[:3], x[3:]
    point = cg + np.cross(theta, u) / theta.dot(theta)
    direction = theta / np.linalg.norm(theta)
    roll = roll / np.linalg.norm(roll)
    d = cg - point
    return {"torque_roll_axis": {"point": cg, "direction": roll},
            "elastic_axis": {"point": point, "direction": direction},
            "angle_deg": float(np.degrees(np.arccos(min(1.0, abs(roll.dot(direction)))))),
            "offset_m": float(np.linalg.norm(d - direction * d.dot(direction)))}


def plot(rows: pd.DataFrame, path: str, title: str = "", axis: dict | None = None):
    """The decoupling table as a colour map: modes (rows, with frequency) over directions."""
    values = rows[[f"KE_{d} [%]" for d in DIRECTIONS]].to_numpy()
    fig, ax = plt.subplots(figsize=(7.5, 0.5 * len(rows) + 1.9))
    image = ax.imshow(np.clip(values, 0, 100), cmap="Blues", vmin=0, vmax=100, aspect="auto")
    for (r, c), v in np.ndenumerate(values):
        ax.text(c, r, f"{v:.0f}" if abs(v) >= 0.5 else "0", ha="center", va="center",
                fontsize=9, color="white" if v > 55 else "black")
    ax.set_xticks(range(6), ["x (lateral)", "y (axial)", "z (vertical)", "rx (pitch)",
                             "ry (roll)", "rz (yaw)"], fontsize=8)
    ax.set_yticks(range(len(rows)), [f"{f:.2f} Hz" for f in rows.frequency_hz], fontsize=9)
    ax.set_xlabel("kinetic energy at the powertrain's centre of mass [%]")
    fig.colorbar(image, ax=ax, shrink=0.8, label="%")
    ax.set_title(title or "Decoupling table of the powertrain's rigid modes", fontsize=10)
    if axis is not None:
        fig.text(0.02, 0.02, f"torque-roll axis vs the mounts' elastic axis: "
                 f"{axis['angle_deg']:.1f}° apart, elastic axis {1e3 * axis['offset_m']:.0f} mm "
                 "from the centre of mass", fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)
