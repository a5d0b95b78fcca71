"""The result files are what the guide's reference page says (python/emc/base/result_files.py,
from which docs/reference.py writes docs/src/reference/results.md): each command runs on a small
case and the columns of every table it writes are checked against the list."""

import pandas as pd
import pytest

from emc.base.result_files import FILES
from emc.cli import main as emc

WHEEL_SEAT = [f"{p}.a[{j}]" for p in ("steeringWheel", "seat") for j in (1, 2, 3)]
SIGNALS = ["mount[1].F[3]"] + WHEEL_SEAT
GROUPS = ["mount", "steeringWheel.a"]  # the default signals of emc accuracy, by group


def listed(name: str, band: bool) -> list[str]:
    """The columns the list gives for ``name``, placeholders written out for this run."""
    entry = next(f for f in FILES if f.name == name)
    comfort = [c for c, _ in next(f for f in FILES if f.name == "comfort.csv").columns
               if c not in ("case", "rpm", "bound")]
    out = []
    for column, _ in entry.columns:
        if column == "bound" and not band:
            continue
        if column == "<signal>":
            out += SIGNALS
        elif column.endswith("<group>"):
            out += [c.replace("<group>", g) for g in GROUPS for c in column.split(", ")]
        elif column.startswith("<value>_low"):
            out += [f"{v}_{b}" for v in comfort for b in ("low", "nominal", "high")]
        else:
            out.append(column)
    return out


def written(folder, name: str) -> list[str]:
    return list(pd.read_csv(folder / name, nrows=0).columns)


@pytest.fixture(scope="module")
def runs(fmu_path, tmp_path_factory):
    """Every command whose files the list covers, on a small case, with and without the band."""
    out = {}
    signals = [a for s in SIGNALS for a in ("--signal", s)]
    commands = {
        "sweep": ["sweep", "--rpm", "1000", "1100", "--count", "2", "--serial", *signals],
        "sweep-band": ["sweep", "--rpm", "1000", "1100", "--count", "2", "--serial", "--band",
                       *signals],
        "runup": ["runup", "--rpm", "1000", "1200", "--duration", "1", *signals],
        "runup-band": ["runup", "--rpm", "1000", "1200", "--duration", "1", "--band", *signals],
        "campbell": ["campbell", "--rpm", "800", "2500"],
        "accuracy": ["accuracy", "--rtol", "1e-4", "--reference-rtol", "1e-6", "--duration",
                     "0.05", "--runup", "1000", "1100"],
    }
    for key, args in commands.items():
        folder = tmp_path_factory.mktemp(key)
        code = emc([*args, "--fmu", str(fmu_path), "--quiet", "--out", str(folder)])
        assert code == 0, key
        out[key] = folder
    return out


@pytest.mark.parametrize("run, name, band", [
    ("sweep", "orders.csv", False), ("sweep", "spectra.csv", False),
    ("sweep", "comfort.csv", False), ("sweep-band", "orders.csv", True),
    ("sweep-band", "spectra.csv", True), ("sweep-band", "comfort.csv", True),
    ("sweep-band", "order_band.csv", True), ("sweep-band", "comfort_band.csv", True),
    ("runup", "runup.csv", False), ("runup", "runup_orders.csv", False),
    ("runup-band", "runup.csv", True), ("runup-band", "runup_orders.csv", True),
    ("runup-band", "runup_order_band.csv", True),
    ("campbell", "natural_modes.csv", False), ("campbell", "crossings.csv", False),
    ("accuracy", "accuracy.csv", False),
])
def test_a_result_file_has_the_columns_the_guide_lists(runs, run, name, band):
    assert written(runs[run], name) == listed(name, band)


def test_every_listed_file_is_checked():
    checked = {p.args[1] if hasattr(p, "args") else p[1] for p in
               test_a_result_file_has_the_columns_the_guide_lists.pytestmark[0].args[1]}
    assert checked == {f.name for f in FILES}


def test_a_column_the_list_lacks_is_found():
    assert listed("orders.csv", band=False) != listed("orders.csv", band=True)
    assert "amplitude" in listed("orders.csv", band=False)
