"""Examples run and produce a picture that is not blank."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.gl
def test_analytic_example_writes_a_nonblank_png(tmp_path):
    out = tmp_path / "patch.png"
    subprocess.run([sys.executable, str(ROOT / "examples/analytic_patch_with_mesh.py"), str(out)], check=True,
                   capture_output=True)
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    non_white = ~np.all(img > 250, axis=-1)
    assert 0.1 < non_white.mean() < 0.9
    # reflection lines: dark stripes on the surface
    dark = np.all(img < 60, axis=-1)
    assert dark.sum() > 1000


@pytest.mark.gl
def test_dem_example_reads_a_dem_and_draws_reflection_lines(tmp_path):
    out = tmp_path / "dem.png"
    res = subprocess.run([sys.executable, str(ROOT / "examples/dem_reflection_lines.py"), "", str(out)], check=True,
                         capture_output=True, text=True, cwd=ROOT)
    assert "129x129 heights, spacing (30.0, 30.0), origin (500010.0, 5100020.0)" in res.stdout
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    non_white = ~np.all(img > 250, axis=-1)
    assert non_white.mean() > 0.5
    dark = np.all(img < 50, axis=-1)
    assert 0.1 < dark.mean() < 0.6  # stripes, not a black or empty picture
