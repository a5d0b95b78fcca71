"""The mapping file: which measured channel is which FMU output, in which unit and convention.

A TOML file (comments allowed), paths relative to its own folder::

    [measurement]
    file = "runup.uff"          # UFF (.uff, .unv) or CSV (.csv)
    unmapped = "error"          # a function no channel maps: "error" (default) or "ignore"

    [[channel]]
    label = "steering wheel vertical, order 1.5"   # optional
    node = 101                  # UFF: the set's response node and direction (record 6) ...
    direction = 3
    id = "SW +Z order 1.5"      # ... and/or the whole text of one of its ID lines
    # channel = "SW_Z"          # CSV: the channel column (the order column must equal `order`)
    output = "steeringWheel.a[3]"
    order = 1.5                 # order cuts: the engine order (0.5 ... 6, in halves)
    # input = "mount[1].F[3]"   # FRFs: the force (at that mount's body point) instead of order
    unit = "g"                  # the data's unit: g, m/s^2, mm/s^2, m/s, mm/s, m, mm, um, N, kN
                                # (FRFs: response unit / force unit, e.g. g/N)
    amplitude = "rms"           # peak (0-peak), rms, peak-peak
    sign = 1                    # -1: the sensor points against the output's axis
    noise_floor = 0.0005        # optional, in `unit`: levels below it carry no information
    # file = "other.uff"        # optional: this channel's own file

    [modes]                     # optional: measured mode shapes for the MAC
    file = "modes.uff"
    length_unit = "mm"          # of the node coordinates: m or mm (default m)
    tolerance = 0.03            # m: a measured node must lie this close to a body node

Everything is checked when the file is read (:func:`load`); a failure is one line naming the
mapping file, the channel and the field, or the measurement file, its set and the field.
"""

from __future__ import annotations

import dataclasses
import pathlib
import tomllib

import numpy as np

from . import units
from .measurement import Function, MeasurementError, ModeShapes, read_functions, read_modes

KEYS = {"label", "node", "direction", "id", "channel", "output", "order", "input", "unit",
        "amplitude", "sign", "noise_floor", "file"}
ORDERS_ANALYSED = tuple(k / 2 for k in range(1, 13))
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}


@dataclasses.dataclass(frozen=True)
class ChannelMap:
    """One ``[[channel]]`` entry (checked)."""

    number: int
    label: str
    output: str
    unit: str
    amplitude: str
    sign: int
    file: str
    order: float | None = None
    input: str | None = None
    node: int | None = None
    direction: int | None = None
    id: str | None = None
    channel: str | None = None
    noise_floor: float = 0.0

    @property
    def kind(self) -> str:
        return "frf" if self.input else "order"


@dataclasses.dataclass
class Channel:
    """A mapped measured function in the FMU's terms: ``x`` (rpm for an order cut, Hz for an
    FRF), ``values`` in SI and 0-peak with the sign applied (complex where the file has phase,
    else amplitudes), ``floor`` the noise floor at each point in the same terms."""

    map: ChannelMap
    source: Function
    x: np.ndarray
    values: np.ndarray
    floor: np.ndarray

    @property
    def label(self) -> str:
        return self.map.label

    @property
    def has_phase(self) -> bool:
        return np.iscomplexobj(self.values)


@dataclasses.dataclass
class Mapping:
    path: pathlib.Path
    channels: list[Channel]
    modes: ModeShapes | None = None
    modes_length_unit: float = 1.0
    modes_tolerance: float = 0.03
    files: list[str] = dataclasses.field(default_factory=list)

    def order_channels(self) -> list[Channel]:
        return [c for c in self.channels if c.map.kind == "order"]

    def frf_channels(self) -> list[Channel]:
        return [c for c in self.channels if c.map.kind == "frf"]

    def describe(self) -> list[dict]:
        """The mapping as plain records (metadata)."""
        return [{**{k: v for k, v in dataclasses.asdict(c.map).items() if v is not None},
                 "set": c.source.describe(), "points": int(len(c.x)),
                 "phase": bool(c.has_phase)} for c in self.channels]


def _fail(path, where: str, field: str, what: str):
    raise MeasurementError(f"{path}, {where}, {field}: {what}")


def _channel_map(path: pathlib.Path, number: int, entry: dict, default_file: str | None,
                 outputs: dict) -> ChannelMap:
    where = f"channel {number}" + (f" ({entry['label']})" if isinstance(entry.get("label"), str)
                                   else "")
    for key in entry:
        if key not in KEYS:
            _fail(path, where, key, f"unknown field (fields: {', '.join(sorted(KEYS))})")
    for key in ("output", "unit", "amplitude"):
        if key not in entry:
            _fail(path, where, key, "missing")
    output = entry["output"]
    if not isinstance(output, str) or output not in outputs:
        close = [o for o in outputs if isinstance(output, str) and output.split("[")[0] in o][:3]
        _fail(path, where, "output", f"{output!r} is not an output of the FMU"
                                     + (f" (did you mean {', '.join(close)}?)" if close else ""))
    output_quantity = units.OUTPUT_QUANTITY.get(outputs[output] or "")
    if output_quantity is None:
        _fail(path, where, "output", f"{output} has the unit {outputs[output]!r}: only "
                                     "accelerations (m/s2) and forces (N) are compared")
    frf = "input" in entry
    unit = str(entry["unit"])
    if frf:
        parts = units.frf_units(unit)
        if parts is None:
            _fail(path, where, "unit", f"{unit!r}: an FRF's unit is a motion over a force, "
                                       "e.g. g/N or m/s^2/N")
        unit_quantity = units.quantity(parts[0])
        if "order" in entry:
            _fail(path, where, "order", "an FRF channel (with input) has no order")
        inp = entry["input"]
        if not isinstance(inp, str) or inp not in outputs or units.OUTPUT_QUANTITY.get(
                outputs[inp] or "") != "force" or not inp.startswith("mount["):
            _fail(path, where, "input", f"{inp!r}: the input of an FRF is a mount force "
                                        "mount[i].F[j] (a force at that mount's body point)")
        if output_quantity != "acceleration":
            _fail(path, where, "output", f"{output}: an FRF's response is an acceleration")
    else:
        if not units.known(unit):
            _fail(path, where, "unit", f"{unit!r} is not a unit this tool knows "
                                       f"({', '.join(units.UNITS)})")
        unit_quantity = units.quantity(unit)
        if "order" not in entry:
            _fail(path, where, "order", "missing (the engine order of the cut, e.g. 1.5)")
        order = entry["order"]
        if not isinstance(order, (int, float)) or float(order) not in ORDERS_ANALYSED:
            _fail(path, where, "order", f"{order!r}: the analysis gives orders 0.5 to 6 in "
                                        "halves")
    fits = (unit_quantity == output_quantity or (output_quantity == "acceleration"
                                                 and unit_quantity in ("velocity",
                                                                       "displacement")))
    if not fits:
        article = "an" if output_quantity[0] == "a" else "a"
        _fail(path, where, "unit", f"{unit!r} measures {unit_quantity}, {output} is {article} "
                                   f"{output_quantity}")
    amplitude = str(entry["amplitude"]).lower()
    if amplitude not in units.CONVENTIONS:
        _fail(path, where, "amplitude", f"{entry['amplitude']!r}: one of peak, rms, peak-peak")
    sign = entry.get("sign", 1)
    if sign not in (1, -1) or isinstance(sign, bool):
        _fail(path, where, "sign", f"{sign!r}: 1 or -1")
    floor = entry.get("noise_floor", 0.0)
    if not isinstance(floor, (int, float)) or isinstance(floor, bool) or not (
            np.isfinite(floor) and floor >= 0.0):
        _fail(path, where, "noise_floor", f"{floor!r}: a number >= 0 in the channel's unit")
    file = entry.get("file", default_file)
    if not file:
        _fail(path, where, "file", "no measurement file (give [measurement] file or the "
                                   "channel's own)")
    selectors = {k: entry[k] for k in ("node", "direction", "id", "channel") if k in entry}
    is_csv = str(file).lower().endswith(".csv")
    if is_csv:
        if "channel" not in selectors or len(selectors) > 1:
            _fail(path, where, "channel", "a CSV channel is selected by `channel` (the CSV's "
                                          "channel column) alone")
        if frf:
            _fail(path, where, "input", "the CSV holds order cuts only")
    else:
        if "channel" in selectors:
            _fail(path, where, "channel", "selects CSV rows; a universal file's set is selected "
                                          "by node and direction and/or id")
        if ("node" in selectors) != ("direction" in selectors):
            _fail(path, where, "node" if "node" not in selectors else "direction",
                  "node and direction go together")
        if not selectors:
            _fail(path, where, "node", "the set is selected by node and direction and/or id")
        for key in ("node", "direction"):
            if key in selectors and (not isinstance(selectors[key], int)
                                     or isinstance(selectors[key], bool)):
                _fail(path, where, key, f"{selectors[key]!r} is not a whole number")
    label = entry.get("label") or (f"{output} order {float(entry['order']):g}" if not frf
                                   else f"{output} / {entry['input']}")
    return ChannelMap(number=number, label=str(label), output=output, unit=unit,
                      amplitude=amplitude, sign=int(sign), file=str(file),
                      order=None if frf else float(entry["order"]),
                      input=entry.get("input"), node=selectors.get("node"),
                      direction=selectors.get("direction"), id=selectors.get("id"),
                      channel=selectors.get("channel"), noise_floor=float(floor))


def _selects(m: ChannelMap, f: Function) -> bool:
    if m.channel is not None:
        return f.channel == m.channel and f.order == m.order
    if m.node is not None and (f.node, f.direction) != (m.node, m.direction):
        return False
    if m.id is not None and not any(m.id.strip().lower() == i.strip().lower() for i in f.ids):
        return False
    return True


def _convert(path, m: ChannelMap, f: Function) -> Channel:
    where = f"channel {m.number} ({m.label})"
    wanted = "order" if m.kind == "order" else "frf"
    if f.kind != wanted:
        what = "an order cut over rpm" if f.kind == "order" else f"a {f.kind} over Hz"
        _fail(path, where, "input" if wanted == "frf" else "order",
              f"selects {f.describe()}, which is {what}")
    unit = m.unit if m.kind == "order" else units.frf_units(m.unit)[0]
    if f.unit_label is not None:
        if m.kind == "order":
            differs = (units.known(f.unit_label)
                       and units.normalise(f.unit_label) != units.normalise(m.unit))
        else:
            theirs = units.frf_units(f.unit_label)
            differs = theirs is not None and theirs != units.frf_units(m.unit)
        if differs:
            _fail(path, where, "unit", f"{m.unit!r}, but {f.describe()} says {f.unit_label!r}")
    if f.quantity is not None and m.kind == "order" and f.quantity != units.quantity(unit):
        _fail(path, where, "unit", f"{m.unit!r} measures {units.quantity(unit)}, but "
                                   f"{f.describe()} holds {f.quantity} (ordinate data type)")
    if m.kind == "order":
        omega = 2.0 * np.pi * m.order * f.x / 60.0
    else:
        omega = 2.0 * np.pi * f.x
        force = units.UNITS[units.frf_units(m.unit)[1]][1]
    convention = units.CONVENTIONS[m.amplitude]
    values = units.to_si_acceleration(f.values, unit, omega) * convention * m.sign
    floor = np.abs(units.to_si_acceleration(np.full(len(f.x), m.noise_floor), unit, omega)) \
        * convention
    if m.kind == "frf":
        values, floor = values / force, floor / force
    if not np.iscomplexobj(values) and np.any(values < 0.0):
        _fail(path, where, "amplitude", f"{f.describe()} holds negative amplitudes (real data "
                                        "are read as amplitudes)")
    return Channel(map=m, source=f, x=f.x, values=values, floor=floor)


def load(path, outputs: dict) -> Mapping:
    """Reads the mapping file at ``path`` and the measurements it names; ``outputs``: the FMU's
    outputs and their units (name → unit). Raises :class:`MeasurementError` (one line) on the
    first problem."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MeasurementError(f"{path}: no such mapping file")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise MeasurementError(f"{path}: not a TOML mapping file ({error})") from None
    for key in data:
        if key not in ("measurement", "channel", "modes"):
            _fail(path, "top level", key, "unknown table (measurement, channel, modes)")
    measurement = data.get("measurement", {})
    for key in measurement:
        if key not in ("file", "unmapped"):
            _fail(path, "[measurement]", key, "unknown field (file, unmapped)")
    unmapped = measurement.get("unmapped", "error")
    if unmapped not in ("error", "ignore"):
        _fail(path, "[measurement]", "unmapped", f"{unmapped!r}: error or ignore")
    entries = data.get("channel", [])
    if not isinstance(entries, list) or not entries and "modes" not in data:
        _fail(path, "top level", "channel", "no [[channel]] entries")
    maps = [_channel_map(path, n, e, measurement.get("file"), outputs)
            for n, e in enumerate(entries, 1)]
    seen: dict[tuple, int] = {}
    for m in maps:
        key = (m.output, m.order, m.input)
        if key in seen:
            _fail(path, f"channel {m.number} ({m.label})", "output",
                  f"{m.output} {'order ' + format(m.order, 'g') if m.order else m.input} is "
                  f"mapped twice (channel {seen[key]} too)")
        seen[key] = m.number
    folder = path.parent
    functions: dict[str, list[Function]] = {}
    for m in maps:
        if m.file not in functions:
            functions[m.file] = read_functions(folder / m.file)
    channels, used = [], {}
    for m in maps:
        where = f"channel {m.number} ({m.label})"
        chosen = [(k, f) for k, f in enumerate(functions[m.file]) if _selects(m, f)]
        selector = (f"channel {m.channel!r} order {m.order:g}" if m.channel is not None else
                    " and ".join(s for s in (m.node is not None and f"node {m.node} direction "
                                             f"{m.direction}", m.id and f"id {m.id!r}") if s))
        if not chosen:
            _fail(path, where, "channel" if m.channel is not None else
                  ("node" if m.node is not None else "id"),
                  f"{m.file} has no function with {selector}")
        if len(chosen) > 1:
            _fail(path, where, "id", f"{selector} selects {len(chosen)} functions of {m.file} "
                                     f"({', '.join(f.where for _, f in chosen[:4])}): add an id "
                                     "to tell them apart")
        k, f = chosen[0]
        if (m.file, k) in used:
            _fail(path, where, "node" if m.node is not None else "id",
                  f"{f.describe()} is mapped twice (channel {used[(m.file, k)]} too)")
        used[(m.file, k)] = m.number
        channels.append(_convert(path, m, f))
    if unmapped == "error":
        for file, found in functions.items():
            for k, f in enumerate(found):
                if (file, k) not in used:
                    raise MeasurementError(
                        f"{f.file}, {f.where}, node/direction/id: no channel of {path.name} "
                        f"maps it{' (' + f.ids[0] + ')' if f.ids and f.ids[0] else ''}; map it "
                        "or set unmapped = \"ignore\" under [measurement]")
    mapping = Mapping(path=path, channels=channels, files=sorted(functions))
    if "modes" in data:
        modes = data["modes"]
        for key in modes:
            if key not in ("file", "length_unit", "tolerance"):
                _fail(path, "[modes]", key, "unknown field (file, length_unit, tolerance)")
        if "file" not in modes:
            _fail(path, "[modes]", "file", "missing")
        length = modes.get("length_unit", "m")
        if length not in LENGTH_UNITS:
            _fail(path, "[modes]", "length_unit", f"{length!r}: m or mm")
        tolerance = modes.get("tolerance", 0.03)
        if not isinstance(tolerance, (int, float)) or not tolerance > 0.0:
            _fail(path, "[modes]", "tolerance", f"{tolerance!r}: a distance > 0 in m")
        mapping.modes = read_modes(folder / modes["file"])
        mapping.modes_length_unit = LENGTH_UNITS[length]
        mapping.modes_tolerance = float(tolerance)
        mapping.files.append(modes["file"])
    return mapping
