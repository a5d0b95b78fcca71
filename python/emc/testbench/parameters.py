"""The parameters a calibration fits, and the vehicle configuration they make.

Every parameter is a positive factor on a nominal property (1 = the configuration as it is):

- ``mount[i].stiffnessScale``: mount ``i``'s force-deflection curves, every axis (an FMU input);
- ``mount[i].rate[j]``: mount ``i``'s curve along its axis ``j`` alone (a change of the vehicle
  configuration, as in ``emc optimise``);
- ``mount[i].dampingScale``: mount ``i``'s viscous damping (an FMU input);
- ``mount[*].dampingScale``: every mount's damping by one factor;
- ``chassis.modalDampingScale``: the body's physical modal damping, its table and overrides (an
  FMU parameter; the interface modes' numerical damping stays);
- ``body.damping.table[k]``: the ``k``-th ordinate (1-based) of the body's damping table alone
  (a change of the vehicle configuration; without a table of its own the procedural body's
  default is one point, 5 % at every frequency): a damping that changes with frequency.

The calibrated configuration folds the factors into the vehicle configuration, exactly as the FMU
applies them: a stiffness scale multiplies every knot's stiffness (the mount force is
``preload − scale · g(δ)``, and ``g`` is the integral of the knots' stiffness), a damping scale
the mount's damping coefficients, the body's scale the ordinates of its damping table (crit and g:
the value; q: its reciprocal) and the per-mode overrides.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import re

from ..base.checks import name_and_bounds

PATTERN = re.compile(r"^(?:mount\[(\d+|\*)\]\.(stiffnessScale|dampingScale|rate\[([123])\])"
                     r"|(chassis\.modalDampingScale)|body\.damping\.table\[(\d+)\])$")
DEFAULT_BOUNDS = {"stiffnessScale": (0.5, 2.0), "rate": (0.5, 2.0), "dampingScale": (0.25, 4.0),
                  "modalDampingScale": (0.25, 4.0), "dampingTable": (0.25, 4.0)}
# The default body damping when the configuration gives none (src/cms/damping.rs).
DEFAULT_BODY_DAMPING = 0.05


class ParameterError(ValueError):
    """A parameter that cannot be calibrated: one line."""


@dataclasses.dataclass(frozen=True)
class Parameter:
    name: str
    kind: str                 # stiffnessScale, rate, dampingScale, modalDampingScale, dampingTable
    mounts: tuple[int, ...]   # 1-based; empty for the body
    axis: int | None          # a rate's axis, a damping table's point (1-based)
    low: float
    high: float

    @property
    def is_damping(self) -> bool:
        return self.kind in ("dampingScale", "modalDampingScale", "dampingTable")

    @property
    def in_configuration(self) -> bool:
        return self.kind in ("rate", "dampingTable")

    def fmu_values(self, value: float) -> dict:
        if self.kind == "modalDampingScale":
            return {"chassis.modalDampingScale": value}
        if self.kind in ("stiffnessScale", "dampingScale"):
            return {f"mount[{i}].{self.kind}": value for i in self.mounts}
        return {}


def parse(text: str, mounts: int) -> Parameter:
    """``NAME`` or ``NAME=LOW:HIGH`` (factors; the bounds must enclose 1, the nominal)."""
    name, bounds = name_and_bounds(text, "--param", ParameterError)
    match = PATTERN.match(name)
    if not match:
        raise ParameterError(f"--param {text}: not a calibration parameter (mount[i]."
                             "stiffnessScale, mount[i].rate[j], mount[i].dampingScale, "
                             "mount[*].dampingScale, chassis.modalDampingScale, "
                             "body.damping.table[k])")
    if match.group(4):
        kind, chosen, axis = "modalDampingScale", (), None
    elif match.group(5):
        kind, chosen, axis = "dampingTable", (), int(match.group(5))
        if axis < 1:
            raise ParameterError(f"--param {text}: the table's points are numbered from 1")
    else:
        kind = match.group(2).split("[")[0]
        axis = int(match.group(3)) if match.group(3) else None
        if match.group(1) == "*":
            if kind != "dampingScale":
                raise ParameterError(f"--param {text}: mount[*] goes with dampingScale only "
                                     "(stiffnesses are fitted per mount)")
            chosen = tuple(range(1, mounts + 1))
        else:
            mount = int(match.group(1))
            if not 1 <= mount <= mounts:
                raise ParameterError(f"--param {text}: the FMU has mounts 1 to {mounts}")
            chosen = (mount,)
    low, high = bounds or DEFAULT_BOUNDS[kind]
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 < low < 1.0 < high):
        raise ParameterError(f"--param {text}: the bounds must be finite factors with 0 < LOW "
                             "< 1 < HIGH (the nominal is 1)")
    return Parameter(name, kind, chosen, axis, low, high)


def parse_all(texts: list[str], mounts: int) -> tuple[Parameter, ...]:
    chosen = tuple(parse(t, mounts) for t in texts)
    names = [p.name for p in chosen]
    for name in names:
        if names.count(name) > 1:
            raise ParameterError(f"--param {name} is given twice")
    damped = [i for p in chosen if p.kind == "dampingScale" for i in p.mounts]
    if len(set(damped)) != len(damped):
        raise ParameterError("--param: a mount's dampingScale is given alone and in "
                             "mount[*].dampingScale")
    stiff = {(i, p.axis) for p in chosen if p.kind in ("stiffnessScale", "rate")
             for i in p.mounts}
    for i, axis in stiff:
        if axis is not None and (i, None) in stiff:
            raise ParameterError(f"--param mount[{i}].rate[{axis}] and mount[{i}]."
                                 "stiffnessScale cannot be told apart along that axis: fit one")
    return chosen


def fmu_values(parameters, values) -> dict:
    out = {}
    for p, v in zip(parameters, values):
        out.update(p.fmu_values(float(v)))
    return out


def _scale_curve(mount: dict, axis: int, factor: float):
    for knot in mount["curves"][axis]["knots"]:
        knot["stiffness"] *= factor


def apply(config: dict, parameters, values, fold_inputs: bool) -> dict:
    """A copy of the complete vehicle configuration ``config`` with the configuration
    parameters (rates) applied and, if ``fold_inputs``, the FMU inputs and parameters too (the
    calibrated configuration, used with every scale at 1)."""
    out = copy.deepcopy(config)
    for p, value in zip(parameters, values):
        value = float(value)
        if p.kind == "rate":
            _scale_curve(out["mounts"][p.mounts[0] - 1], p.axis - 1, value)
        elif p.kind == "dampingTable":
            _scale_body_damping(out, value, point=p.axis)
        elif not fold_inputs:
            continue
        elif p.kind == "stiffnessScale":
            for axis in range(3):
                _scale_curve(out["mounts"][p.mounts[0] - 1], axis, value)
        elif p.kind == "dampingScale":
            for i in p.mounts:
                mount = out["mounts"][i - 1]
                mount["damping"] = [d * value for d in mount["damping"]]
        else:
            _scale_body_damping(out, value)
    return out


def _scale_body_damping(config: dict, value: float, point: int | None = None):
    """The body's damping table (and overrides) times ``value``; only its ``point``-th ordinate
    if given."""
    body = config["body"]
    damping = body.get("damping")
    if damping is None:
        if body.get("kind") != "procedural":
            raise ParameterError(
                f"the body's damping: the {body.get('kind')} body brings its own (a deck's "
                "TABDMP1 or a reduced body's ratios), which the vehicle configuration does not "
                "hold; give the configuration a body.damping table to calibrate it")
        damping = {"table": {"type": "crit", "points": [[0.0, DEFAULT_BODY_DAMPING]]}}
    damping = copy.deepcopy(damping)
    table = damping["table"]
    unit = str(table.get("type", "crit")).lower()
    if point is not None:
        if point > len(table["points"]):
            raise ParameterError(f"body.damping.table[{point}]: the body's damping table has "
                                 f"{len(table['points'])} point(s)")
        f, v = table["points"][point - 1]
        table["points"][point - 1] = [f, v / value if unit == "q" else v * value]
        body["damping"] = damping
        return
    table["points"] = [[f, v / value if unit == "q" else v * value] for f, v in table["points"]]
    if "modes" in damping:
        damping["modes"] = [[mode, zeta * value] for mode, zeta in damping["modes"]]
    body["damping"] = damping


def configuration_text(config: dict) -> str:
    return json.dumps(config, sort_keys=True)
