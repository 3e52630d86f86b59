"""The example notebooks run as a user runs them: executed by nbclient in a Jupyter kernel, each picture the
static backend returns decoded and checked (not blank, the spline's colours present)."""

from __future__ import annotations

import base64
import io
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.gl

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "examples" / "notebooks").glob("*.ipynb"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_and_shows_the_spline(path, tmp_path):
    import nbformat
    from nbclient import NotebookClient
    from PIL import Image

    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    pictures = [out["data"]["image/png"] for cell in nb.cells if cell.cell_type == "code"
                for out in cell.get("outputs", []) if "image/png" in out.get("data", {})]
    assert pictures, f"{path.name} shows no picture"
    img = np.asarray(Image.open(io.BytesIO(base64.b64decode(pictures[-1]))).convert("RGB")).astype(int)
    surface = np.any(np.abs(img - img[0, 0]) > 30, axis=-1)
    assert surface.mean() > 0.1  # drawn, not the background alone
    green = (img[..., 1] > img[..., 0] + 20) & (img[..., 1] > img[..., 2] + 10)  # the terrain colormap's lowlands
    assert green.sum() > 200
