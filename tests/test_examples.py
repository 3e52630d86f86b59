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
