"""Every notebook runs top to bottom (with the small settings its first cell reads from
VCC_NOTEBOOK_SMALL), so a notebook broken by a change fails the suite."""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"


@pytest.mark.parametrize("path", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda p: p.stem)
def test_notebook_runs_top_to_bottom(path, monkeypatch):
    monkeypatch.setenv("VCC_NOTEBOOK_SMALL", "1")
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=900, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert any(o.get("output_type") == "display_data" and "image/png" in o.get("data", {}) for o in outputs), \
        "a notebook that draws nothing"


def test_there_are_six_notebooks():
    assert [p.stem for p in sorted(NOTEBOOKS.glob("*.ipynb"))] == [
        "01_emulator_traces", "02_induction", "03_argpred", "04_robot", "05_teach", "06_zero_shot"]
