"""A body reduced elsewhere, handed over as Nastran DMIG Craig-Bampton matrices.

`examples/write_dmig.rs` writes our own reduction of the default body as `body.pch` (KAAX, MAAX,
PHIOUT, GRID cards), a vehicle JSON naming it and the matrices as triplets. Here an independent
reader, pyNastran, reads the punch file: it must find the same matrices, and their eigen solve
the frequencies of our in-process reduction. Then the packaged FMU runs scene 2 once with the
procedural body and once with the DMIG body, and the outputs must agree.

pyNastran 1.4.1 pins numpy < 2, which fmpy cannot share, so it runs in its own venv
(`.venv/pynastran`, from python/requirements-pynastran.txt, installed by scripts/setup.sh).
"""

import json
import pathlib
import subprocess
import textwrap

import numpy as np
import pytest
from fmpy import simulate_fmu

ROOT = pathlib.Path(__file__).resolve().parents[2]
PYNASTRAN = ROOT / ".venv" / "pynastran" / "bin" / "python"

READER = textwrap.dedent("""
    import json, sys
    import numpy as np
    import scipy.linalg
    from pyNastran.bdf.bdf import BDF

    model = BDF(debug=None, log=None)
    model.read_bdf(sys.argv[1], punch=True, xref=False, validate=True)
    out = {"grids": {str(n): [float(x) for x in g.xyz] for n, g in model.nodes.items()},
           "matrices": {}}
    dense = {}
    for name, d in model.dmig.items():
        out["matrices"][name] = {
            "form": int(d.matrix_form),
            "entries": [[int(gj), int(cj), int(gi), int(ci), float(v)]
                        for (gj, cj), (gi, ci), v in zip(d.GCj, d.GCi, d.Real)]}
        matrix, rows, cols = d.get_matrix(is_sparse=False, apply_symmetry=True)
        dense[name] = (matrix, rows, cols)
    # The body's frequencies from pyNastran's own symmetric expansion of KAAX and MAAX.
    (k, rows, cols), (m, mrows, _) = dense["KAAX"], dense["MAAX"]
    assert rows == cols == mrows, "KAAX and MAAX over different DOFs"
    lam = scipy.linalg.eigh(k, m, eigvals_only=True)
    out["hz"] = [float(x) for x in np.sqrt(lam) / (2 * np.pi)]
    json.dump(out, sys.stdout)
""")


@pytest.fixture(scope="module")
def dmig_body(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dmig")
    subprocess.run(["cargo", "run", "--release", "--quiet", "--example", "write_dmig", "--",
                    str(folder)], cwd=ROOT, check=True)
    return folder


def test_pynastran_reads_the_same_matrices_and_frequencies(dmig_body):
    assert PYNASTRAN.exists(), "scripts/setup.sh installs pyNastran in .venv/pynastran"
    read = json.loads(subprocess.run([str(PYNASTRAN), "-c", READER, str(dmig_body / "body.pch")],
                                     check=True, capture_output=True, text=True).stdout)
    written = json.loads((dmig_body / "matrices.json").read_text())
    assert sorted(read["matrices"]) == sorted(written) == ["KAAX", "MAAX", "PHIOUT"]
    for name, matrix in written.items():
        assert read["matrices"][name]["form"] == matrix["form"], name
        # 17 significant digits: the second reader gets every entry bit for bit.
        assert sorted(map(tuple, read["matrices"][name]["entries"])) == \
            sorted(map(tuple, matrix["entries"])), name
    points = json.loads((dmig_body / "vehicle.json").read_text())["body"]["points"]
    assert sorted(read["grids"]) == sorted(str(g) for g in points.values())
    ours = json.loads((dmig_body / "modes.json").read_text())["hz"]
    assert len(read["hz"]) == len(ours) > 50
    # A dense generalized eigen solve (LAPACK) of pyNastran's matrices against our reduction's
    # scaled Cholesky solve: both backward stable, they agree to the conditioning of the pencil
    # (interface modes at 1.3 kHz next to suspension modes at 1.2 Hz); measured 3e-11.
    np.testing.assert_allclose(read["hz"], ours, rtol=1e-9)


WRITER = textwrap.dedent("""
    import sys
    from pyNastran.bdf.bdf import BDF

    model = BDF(debug=None, log=None)
    model.read_bdf(sys.argv[1], punch=True, xref=False)
    model.write_bdf(sys.argv[2], size=16, is_double=True, enddata=False)
""")


def test_our_reader_reads_the_large_field_punch_pynastran_writes(dmig_body):
    """The other direction, in the fixed large-field form Nastran punches (`DMIG*`, `D`
    exponents, 16-column fields, one column card per entry)."""
    large = dmig_body / "pynastran_large.pch"
    subprocess.run([str(PYNASTRAN), "-c", WRITER, str(dmig_body / "body.pch"), str(large)],
                   check=True)
    assert "DMIG*" in large.read_text()
    read = json.loads(subprocess.run(["cargo", "run", "--release", "--quiet", "--example",
                                      "read_dmig", "--", str(large)], cwd=ROOT, check=True,
                                     capture_output=True, text=True).stdout)
    written = json.loads((dmig_body / "matrices.json").read_text())
    assert sorted(read["matrices"]) == sorted(written)
    for name, matrix in written.items():
        assert read["matrices"][name]["form"] == matrix["form"], name
        want = {tuple(e[:4]): e[4] for e in matrix["entries"]}
        got = {tuple(e[:4]): e[4] for e in read["matrices"][name]["entries"]}
        assert got.keys() == want.keys(), name
        keys = sorted(want)
        # 16-column fields keep 10 significant digits: rounding within 5e-10 (measured 4.8e-10).
        np.testing.assert_allclose([got[k] for k in keys], [want[k] for k in keys], rtol=1e-9,
                                   err_msg=name)


OUTPUTS = ["mount[1].F[3]", "mount[2].F[3]", "mount[3].F[3]", "mount[4].F[3]",
           "mount[1].F[1]", "steeringWheel.a[3]", "seat.a[3]"]


def run(fmu_path, tmp_path, config=None):
    start = {"scene": 2, "rpm": 2000.0, "chassis.cacheDir": str(tmp_path / "cache")}
    if config is not None:
        start["configFile"] = str(config)
    return simulate_fmu(str(fmu_path), stop_time=0.3, output_interval=1e-3,
                        start_values=start, output=OUTPUTS)


def test_a_dmig_body_runs_through_the_fmu_and_equals_our_reduction(fmu_path, dmig_body, tmp_path):
    procedural = run(fmu_path, tmp_path)
    dmig = run(fmu_path, tmp_path, dmig_body / "vehicle.json")
    for name in OUTPUTS:
        a, b = procedural[name], dmig[name]
        assert np.all(np.isfinite(b)), name
        # The two bodies' modes agree to round-off (same matrices, same orthogonalisation; only
        # the sums that recover the points run in another order), so the integrator's error
        # control takes the same steps and the outputs agree to round-off too (measured: 0 for
        # the mount forces, 2e-15 of the swing for the accelerations). 1e-8 of the swing leaves
        # room for another platform's arithmetic, and is far below the integrator's tolerance,
        # which a real difference between the bodies would show at.
        swing = np.max(np.abs(a - np.mean(a)))
        assert np.max(np.abs(a - b)) <= 1e-8 * swing, name
    # The body moves: the engine's excitation reaches the steering wheel.
    assert np.std(dmig["steeringWheel.a[3]"][100:]) > 1e-3
