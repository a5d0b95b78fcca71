"""Synthetic measurements: the model's own order cuts at known parameters, with measurement
noise and a noise floor, written as a test system would (UFF 58 over rpm, with a mapping file).

Used by the twin experiment (the tests), the calibration benchmark and the shipped example: a
car whose parameters the experiment knows, "measured" so that a calibration can be checked
against the truth.
"""

from __future__ import annotations

import dataclasses
import pathlib

import numpy as np
import pyuff

from ..running.engine import PointEngine
from . import units
from .simulate import Grid, evaluate, points

# The response nodes the synthetic files give each output (a test rig's numbering).
NODES = {"steeringWheel": 101, "seat": 201}


@dataclasses.dataclass(frozen=True)
class Cut:
    """One synthetic order cut: ``values`` complex, SI, 0-peak, at ``rpm``."""

    output: str
    order: float
    rpm: np.ndarray
    values: np.ndarray


def node_of(output: str) -> tuple[int, int]:
    """A UFF node and direction for an FMU output: the comfort points' nodes above, a mount's
    force ``mount[i].F[j]`` at node ``10 + i``."""
    if output.startswith("mount["):
        mount = int(output[len("mount["):].split("]")[0])
        return 10 + mount, int(output.rsplit("[", 1)[1].rstrip("]"))
    point, _, axis = output.partition(".a[")
    return NODES[point], int(axis.rstrip("]"))


def noisy(values: np.ndarray, relative: float, floor: float, rng: np.random.Generator):
    """``values`` with complex Gaussian noise of ``relative`` times each value (calibration and
    scatter of a level) and ``floor`` (the noise floor: the instrument's own noise), both as the
    RMS of the complex noise."""
    shape = np.shape(values)

    def complex_noise():
        return (rng.standard_normal(shape) + 1j * rng.standard_normal(shape)) / np.sqrt(2.0)

    return values * (1.0 + relative * complex_noise()) + floor * complex_noise()


def write_uff(path, cuts: list[Cut], unit: dict[str, str], amplitude: str = "peak",
              complex_data: bool = True):
    """The cuts as UFF 58 sets (function type 0, abscissa rpm: specific data type 19, uneven
    spacing, double precision) in ``unit[output]`` and the ``amplitude`` convention; ID line 1
    names the output and order, ID line 4 says the data are synthetic."""
    path = pathlib.Path(path)
    if path.exists():
        path.unlink()
    sets = []
    for k, cut in enumerate(cuts, 1):
        node, direction = node_of(cut.output)
        u = unit[cut.output]
        omega = 2.0 * np.pi * cut.order * cut.rpm / 60.0
        si_per_unit = units.to_si_acceleration(np.ones(len(cut.rpm), complex), u, omega)
        data = cut.values / si_per_unit / units.CONVENTIONS[amplitude]
        quantity = units.quantity(u)
        sets.append({
            "type": 58, "binary": 0, "func_type": 0, "func_id": k, "ver_num": 0,
            "load_case_id": 0,
            "id1": f"{cut.output} order {cut.order:g}", "id2": "run-up, constant load",
            "id3": "NONE", "id4": "SYNTHETIC: the model's own response with noise", "id5": "NONE",
            "rsp_ent_name": "NONE", "rsp_node": node, "rsp_dir": direction,
            "ref_ent_name": "NONE", "ref_node": 0, "ref_dir": 0,
            "ord_data_type": 6 if complex_data else 4, "num_pts": len(cut.rpm),
            "abscissa_spacing": 0, "abscissa_min": 0.0, "abscissa_inc": 0.0, "z_axis_value": 0.0,
            "abscissa_spec_data_type": 19, "abscissa_len_unit_exp": 0,
            "abscissa_force_unit_exp": 0, "abscissa_temp_unit_exp": 0,
            "abscissa_axis_lab": "engine speed", "abscissa_axis_units_lab": "rpm",
            "ordinate_spec_data_type": {"acceleration": 12, "velocity": 11, "displacement": 8,
                                        "force": 9}[quantity],
            "ordinate_len_unit_exp": 0, "ordinate_force_unit_exp": 0,
            "ordinate_temp_unit_exp": 0, "ordinate_axis_lab": cut.output,
            "ordinate_axis_units_lab": u,
            "orddenom_spec_data_type": 0, "orddenom_len_unit_exp": 0,
            "orddenom_force_unit_exp": 0, "orddenom_temp_unit_exp": 0,
            "orddenom_axis_lab": "NONE", "orddenom_axis_units_lab": "NONE",
            "z_axis_spec_data_type": 0, "z_axis_len_unit_exp": 0, "z_axis_force_unit_exp": 0,
            "z_axis_temp_unit_exp": 0, "z_axis_axis_lab": "NONE", "z_axis_axis_units_lab": "NONE",
            "x": np.asarray(cut.rpm, dtype=float),
            "data": data if complex_data else np.abs(data)})
    pyuff.UFF(str(path)).write_sets(sets, mode="add")


def mapping_text(file: str, cuts: list[Cut], unit: dict[str, str], amplitude: str,
                 floors: dict[str, float] | None = None, header: str = "") -> str:
    """A mapping file (TOML) for the sets :func:`write_uff` writes."""
    lines = [header.rstrip(), "[measurement]", f'file = "{file}"', ""] if header else [
        "[measurement]", f'file = "{file}"', ""]
    for cut in cuts:
        node, direction = node_of(cut.output)
        lines += ["[[channel]]", f'label = "{cut.output} order {cut.order:g}"',
                  f"node = {node}", f"direction = {direction}",
                  f'id = "{cut.output} order {cut.order:g}"', f'output = "{cut.output}"',
                  f"order = {cut.order:g}", f'unit = "{unit[cut.output]}"',
                  f'amplitude = "{amplitude}"', "sign = 1"]
        if floors and floors.get(cut.output):
            lines.append(f"noise_floor = {floors[cut.output]:.6g}")
        lines.append("")
    return "\n".join(lines)


def twin_measurement(fmu: str, folder, truth: dict, outputs: list[str], orders: list[float],
                     speeds, unit: dict[str, str], relative: float, floors: dict[str, float],
                     seed: int = 1, revolutions: int = 4, amplitude: str = "peak",
                     parameters: dict | None = None, pool=None,
                     name: str = "twin") -> pathlib.Path:
    """Simulates the car with the start values ``truth`` (on top of ``parameters``, default
    scene 2) at ``speeds``, writes its order cuts with noise (:func:`noisy`; ``floors`` in SI
    per output) as ``<name>.uff`` in ``folder`` and its mapping as ``<name>.toml``; returns the
    mapping's path."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    grid = Grid(tuple(float(s) for s in speeds), tuple(outputs), tuple(orders))
    start = {"scene": 2, **(parameters or {}), **truth}
    engine = PointEngine.on(fmu, pool)
    try:
        simulated = np.array(engine.map(evaluate, points(grid, start, None, revolutions)))
    finally:
        engine.close()
    rng = np.random.default_rng(seed)
    cuts = []
    for j, output in enumerate(outputs):
        for k, order in enumerate(orders):
            values = noisy(simulated[:, k, j], relative, floors.get(output, 0.0), rng)
            cuts.append(Cut(output, order, np.asarray(grid.speeds), values))
    write_uff(folder / f"{name}.uff", cuts, unit, amplitude)
    shown = {o: floors[o] / units.UNITS[units.normalise(unit[o])][1] /
             units.CONVENTIONS[amplitude] for o in floors if units.quantity(unit[o]) in (
                 "acceleration", "force")}
    header = ("# SYNTHETIC measurement: the model's own order cuts at hidden parameters, with "
              f"{relative:.0%} noise and a noise floor")
    (folder / f"{name}.toml").write_text(mapping_text(f"{name}.uff", cuts, unit, amplitude,
                                                      shown, header) + "\n")
    return folder / f"{name}.toml"
