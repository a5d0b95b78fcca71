"""The quick-start notebook (examples/quickstart.ipynb, shipped in the release) runs from top to
bottom against the packaged FMU, in a fresh kernel, as a user would run it: from fmpy to the
waterfall, the order cuts and the transfer paths."""

import pathlib

import nbformat
from nbclient import NotebookClient

NOTEBOOK = pathlib.Path(__file__).resolve().parents[2] / "examples" / "quickstart.ipynb"


def test_the_quick_start_notebook_runs(fmu_path, tmp_path):
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    # Run where the release puts it: beside the FMU (the notebook also finds ../dist/ itself).
    (tmp_path / "EngineMountChassis.fmu").symlink_to(fmu_path)
    NotebookClient(notebook, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "steering wheel:" in text and "largest order of the steering wheel: 1.5" in text
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 4  # time signals, waterfall, order cuts, ranked paths
    assert (tmp_path / "out" / "quickstart" / "tpa" / "tpa.csv").is_file()
