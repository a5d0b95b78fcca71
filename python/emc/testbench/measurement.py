"""Measured data as test systems export it, read and checked.

- **Universal files** (``.uff``, ``.unv``), read with pyuff: functions at nodal DOFs (dataset
  58): run-up order cuts (abscissa rpm, specific data type 19), FRFs (function type 4, abscissa
  Hz) and spectra (abscissa Hz); real or complex, single or double precision, even or uneven
  abscissa. Mode shapes (dataset 55, normal or complex modes) with their nodes (dataset 15 or
  2411).
- **CSV** order cuts with the header this module documents (:func:`read_csv`).

Every check happens here, on read, and a failed one raises :class:`MeasurementError` with one
line naming the file, the set and the field: a non-finite value, an abscissa that does not
increase, a point given twice, too few points, a set this tool cannot use. Nothing is guessed:
what a channel is (its FMU output, unit, amplitude convention, order) comes from the mapping
file (:mod:`.mapping`).
"""

from __future__ import annotations

import csv
import dataclasses
import pathlib

import numpy as np
import pyuff

from . import units

# The fewest points an order cut or FRF must have (a peak needs a point on either side).
MIN_POINTS = 3
FUNCTION_TYPES = {0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
                  4: "FRF", 5: "transmissibility", 9: "PSD", 12: "spectrum", 27: "order function"}
ABSCISSA_RPM, ABSCISSA_HZ = 19, 18
# What a set with each abscissa can be: order cuts over rpm, FRFs and spectra over Hz.
USABLE_ON_RPM = {0, 1, 2, 3, 12, 27}
USABLE_ON_HZ = {0, 2, 3, 4, 12}
CSV_COLUMNS = ("channel", "order", "rpm")


class MeasurementError(ValueError):
    """Measured data this tool cannot use: one line naming the file, the set and the field."""


@dataclasses.dataclass
class Function:
    """One measured function: a UFF 58 set, or a CSV channel's rows of one order.

    ``kind``: ``order`` (abscissa rpm), ``frf`` or ``spectrum`` (abscissa Hz). ``values`` are
    complex where the file holds phase, else real (amplitudes). ``unit_label``: the ordinate's
    unit as the file writes it (None if it names none); ``quantity``: what the file says the
    ordinate measures (None if it does not say)."""

    file: str
    where: str                       # "set 3" or "channel 'SW_Z' order 1.5"
    kind: str
    x: np.ndarray
    values: np.ndarray
    ids: tuple[str, ...] = ()
    node: int | None = None
    direction: int | None = None
    reference_node: int | None = None
    reference_direction: int | None = None
    unit_label: str | None = None
    quantity: str | None = None
    channel: str | None = None      # CSV: the channel column
    order: float | None = None      # CSV: the order column

    @property
    def complex(self) -> bool:
        return np.iscomplexobj(self.values)

    def describe(self) -> str:
        first = next((i for i in self.ids if i), "")
        return f"{self.file}, {self.where}" + (f" ({first})" if first else "")


@dataclasses.dataclass
class ModeShapes:
    """Measured modes (UFF 55) on their nodes (UFF 15/2411): ``shapes`` (modes, nodes, 3),
    translations; ``positions`` (nodes, 3) in the file's length unit."""

    file: str
    frequencies: np.ndarray
    damping: np.ndarray
    nodes: np.ndarray
    positions: np.ndarray
    shapes: np.ndarray


def fail(file, where: str, field: str, what: str):
    raise MeasurementError(f"{file}, {where}, {field}: {what}")


def check_abscissa(file, where: str, x: np.ndarray, name: str, minimum: int = MIN_POINTS):
    """Finite, strictly increasing, no point twice, enough points."""
    if len(x) < minimum:
        fail(file, where, name, f"{len(x)} points, at least {minimum} needed")
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        fail(file, where, name, f"not a finite number at point {bad[0] + 1}")
    step = np.diff(x)
    twice = np.flatnonzero(step == 0.0)
    if twice.size:
        fail(file, where, name, f"point {twice[0] + 2} repeats {x[twice[0]]:g} (a duplicate "
                                "point)")
    down = np.flatnonzero(step < 0.0)
    if down.size:
        k = down[0] + 1
        fail(file, where, name, f"does not increase at point {k + 1} ({x[k - 1]:g} then "
                                f"{x[k]:g})")
    if x[0] <= 0.0 and name in ("rpm", "abscissa (rpm)"):
        fail(file, where, name, f"speeds must be positive, got {x[0]:g}")


def check_values(file, where: str, values: np.ndarray, name: str):
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        fail(file, where, name, f"not a finite number at point {bad[0] + 1}")


def _text(value) -> str | None:
    text = str(value or "").strip()
    return None if not text or text.upper() == "NONE" else text


def _open_uff(path: pathlib.Path) -> pyuff.UFF:
    if not path.is_file():
        raise MeasurementError(f"{path}: no such file")
    try:
        uff = pyuff.UFF(str(path))
        types = uff.get_set_types()
    except Exception as error:  # noqa: BLE001 - pyuff raises plain Exception
        raise MeasurementError(f"{path}: not a readable universal file ({error})") from None
    if len(types) == 0:
        raise MeasurementError(f"{path}: no universal file datasets in it (is it a UFF file?)")
    return uff


def _read_set(uff: pyuff.UFF, path, index: int) -> dict:
    try:
        return uff.read_sets(index)
    except Exception as error:  # noqa: BLE001 - pyuff raises plain Exception
        raise MeasurementError(f"{path}, set {index + 1}: unreadable ({error})") from None


def read_uff_functions(path) -> list[Function]:
    """Every dataset 58 of a universal file, checked (see the module's documentation)."""
    path = pathlib.Path(path)
    uff = _open_uff(path)
    functions = []
    for index, kind in enumerate(uff.get_set_types()):
        if int(kind) != 58:
            continue
        functions.append(function_from_uff58(_read_set(uff, path, index), path, index + 1))
    return functions


def function_from_uff58(d: dict, path, number: int) -> Function:
    """One dataset 58 as a :class:`Function`, checked."""
    where = f"set {number}"
    ftype = int(d.get("func_type", 0))
    abscissa = int(d.get("abscissa_spec_data_type", 0))
    if abscissa == ABSCISSA_RPM:
        kind, usable = "order", USABLE_ON_RPM
    elif abscissa == ABSCISSA_HZ:
        kind, usable = ("frf" if ftype == 4 else "spectrum"), USABLE_ON_HZ
    else:
        fail(path, where, "abscissa_spec_data_type",
             f"{abscissa}: this tool reads functions over rpm (19) or frequency (18)")
    if ftype not in usable:
        name = FUNCTION_TYPES.get(ftype, "")
        fail(path, where, "func_type", f"{ftype}{' (' + name + ')' if name else ''} over "
                                       f"{'rpm' if kind == 'order' else 'Hz'}: not an order "
                                       "cut, FRF or spectrum")
    x = np.asarray(d["x"], dtype=float)
    values = np.asarray(d["data"])
    if values.shape != x.shape:
        fail(path, where, "data", f"{values.size} values for {x.size} abscissa points")
    check_abscissa(path, where, x, "abscissa (rpm)" if kind == "order" else "abscissa (Hz)")
    check_values(path, where, values, "data")
    if kind != "order" and x[0] < 0.0:
        fail(path, where, "abscissa (Hz)", f"frequencies must be >= 0, got {x[0]:g}")
    ordinate = int(d.get("ordinate_spec_data_type", 0))
    return Function(
        file=str(path), where=where, kind=kind, x=x,
        values=values if np.iscomplexobj(values) else values.astype(float),
        ids=tuple(_text(d.get(f"id{k}")) or "" for k in range(1, 6)),
        node=int(d.get("rsp_node", 0)), direction=int(d.get("rsp_dir", 0)),
        reference_node=int(d.get("ref_node", 0)), reference_direction=int(d.get("ref_dir", 0)),
        unit_label=_text(d.get("ordinate_axis_units_lab")),
        quantity=units.UFF_QUANTITY.get(ordinate))


def read_csv(path) -> list[Function]:
    """Order cuts from a CSV: lines starting with ``#`` are comments; the first other line is
    the header, with the columns ``channel``, ``order``, ``rpm`` and either ``amplitude``
    (optionally ``phase_deg``) or ``real`` and ``imag``; one row per channel, order and speed,
    the speeds of each channel and order increasing. Units and conventions come from the mapping
    file."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MeasurementError(f"{path}: no such file")
    lines = [(n, line) for n, line in enumerate(path.read_text().splitlines(), 1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise MeasurementError(f"{path}: no header line")
    reader = csv.reader([line for _, line in lines])
    header = [h.strip() for h in next(reader)]
    where = f"header (line {lines[0][0]})"
    for column in CSV_COLUMNS:
        if column not in header:
            fail(path, where, column, f"missing column (the header needs {', '.join(CSV_COLUMNS)}"
                                      " and amplitude[, phase_deg] or real, imag)")
    if "amplitude" in header:
        complex_data = "phase_deg" in header
        value_columns = ["amplitude"] + (["phase_deg"] if complex_data else [])
        if "real" in header or "imag" in header:
            fail(path, where, "amplitude", "give amplitude[, phase_deg] or real, imag, not both")
    elif "real" in header and "imag" in header:
        complex_data, value_columns = True, ["real", "imag"]
    else:
        fail(path, where, "amplitude", "missing column (amplitude[, phase_deg] or real, imag)")
    known = set(CSV_COLUMNS) | set(value_columns)
    for column in header:
        if column not in known:
            fail(path, where, column, f"unknown column (known: {', '.join(sorted(known))})")
    if len(set(header)) != len(header):
        fail(path, where, "header", "a column is named twice")
    groups: dict[tuple[str, float], list] = {}
    for (number, _), row in zip(lines[1:], reader):
        if len(row) != len(header):
            fail(path, f"line {number}", "row", f"{len(row)} fields, the header has "
                                                f"{len(header)}")
        cells = dict(zip(header, (c.strip() for c in row)))
        numbers = {}
        for column in ("order", "rpm", *value_columns):
            try:
                numbers[column] = float(cells[column])
            except ValueError:
                fail(path, f"line {number}", column, f"{cells[column]!r} is not a number")
            if not np.isfinite(numbers[column]):
                fail(path, f"line {number}", column, "not a finite number")
        if not cells["channel"]:
            fail(path, f"line {number}", "channel", "empty")
        if numbers["order"] <= 0.0:
            fail(path, f"line {number}", "order", f"must be > 0, got {numbers['order']:g}")
        if "amplitude" in numbers and numbers["amplitude"] < 0.0:
            fail(path, f"line {number}", "amplitude", f"must be >= 0, got "
                                                      f"{numbers['amplitude']:g}")
        if complex_data:
            value = (numbers["amplitude"] * np.exp(1j * np.radians(numbers["phase_deg"]))
                     if "amplitude" in numbers else numbers["real"] + 1j * numbers["imag"])
        else:
            value = numbers["amplitude"]
        groups.setdefault((cells["channel"], numbers["order"]), []).append(
            (numbers["rpm"], value))
    if not groups:
        raise MeasurementError(f"{path}: no data rows under the header")
    functions = []
    for (channel, order), rows in groups.items():
        where = f"channel {channel!r} order {order:g}"
        x = np.array([r for r, _ in rows])
        check_abscissa(path, where, x, "rpm")
        values = np.array([v for _, v in rows])
        functions.append(Function(file=str(path), where=where, kind="order", x=x,
                                  values=values, channel=channel, order=order))
    return functions


def read_functions(path) -> list[Function]:
    """The functions of a measurement file: a CSV by its ``.csv`` ending, else a universal
    file."""
    path = pathlib.Path(path)
    return read_csv(path) if path.suffix.lower() == ".csv" else read_uff_functions(path)


def read_modes(path) -> ModeShapes:
    """The mode shapes (dataset 55) of a universal file and its nodes (dataset 15 or 2411),
    checked: every shape's nodes defined, frequencies finite, positive and increasing."""
    path = pathlib.Path(path)
    uff = _open_uff(path)
    types = [int(t) for t in uff.get_set_types()]
    positions: dict[int, np.ndarray] = {}
    modes = []
    for index, kind in enumerate(types):
        if kind in (15, 2411):
            d = _read_set(uff, path, index)
            xyz = np.column_stack([d["x"], d["y"], d["z"]]).astype(float)
            check_values(path, f"set {index + 1}", xyz.ravel(), "node coordinates")
            for node, p in zip(np.asarray(d["node_nums"]).astype(int), xyz):
                if node in positions:
                    fail(path, f"set {index + 1}", "node_nums", f"node {node} defined twice")
                positions[int(node)] = p
        elif kind == 55:
            modes.append((index + 1, _read_set(uff, path, index)))
    if not modes:
        raise MeasurementError(f"{path}: no mode shapes (dataset 55) in it")
    if not positions:
        raise MeasurementError(f"{path}: no nodes (dataset 15 or 2411) for its mode shapes")
    nodes = np.asarray(modes[0][1]["node_nums"]).astype(int)
    frequencies, damping, shapes = [], [], []
    for number, d in modes:
        where = f"set {number}"
        if int(d.get("analysis_type", 2)) not in (2, 3):
            fail(path, where, "analysis_type", f"{d.get('analysis_type')}: not normal (2) or "
                                               "complex (3) modes")
        mine = np.asarray(d["node_nums"]).astype(int)
        if not np.array_equal(mine, nodes):
            fail(path, where, "node_nums", f"other nodes than set {modes[0][0]}: every shape "
                                           "needs the same nodes")
        missing = [n for n in mine if n not in positions]
        if missing:
            fail(path, where, "node_nums", f"node {missing[0]} has no coordinates (dataset "
                                           "15/2411)")
        shape = np.column_stack([np.asarray(d[f"r{k}"]) for k in (1, 2, 3)])
        check_values(path, where, shape.ravel(), "r1..r3")
        if np.allclose(shape, 0.0):
            fail(path, where, "r1..r3", "the shape is zero everywhere")
        if "freq" in d:
            f = float(d["freq"])
            zeta = float(d.get("modal_damp_vis", 0.0) or 0.0)
        else:  # complex modes: the eigenvalue s = -zeta w + i w sqrt(1 - zeta²)
            s = complex(d["eig"])
            f, zeta = abs(s) / (2.0 * np.pi), -s.real / abs(s)
        if not (np.isfinite(f) and f > 0.0):
            fail(path, where, "freq", f"must be a positive frequency, got {f:g}")
        frequencies.append(f)
        damping.append(zeta)
        shapes.append(shape)
    frequencies = np.array(frequencies)
    down = np.flatnonzero(np.diff(frequencies) <= 0.0)
    if down.size:
        fail(path, f"set {modes[down[0] + 1][0]}", "freq",
             f"{frequencies[down[0] + 1]:g} Hz does not increase on the mode before "
             f"({frequencies[down[0]]:g} Hz)")
    return ModeShapes(file=str(path), frequencies=frequencies, damping=np.array(damping),
                      nodes=nodes, positions=np.array([positions[n] for n in nodes]),
                      shapes=np.array(shapes))
