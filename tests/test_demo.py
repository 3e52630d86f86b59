"""README's first command: the showcase figures are rendered and not blank."""

import numpy as np
import pytest
from PIL import Image

from splinevis.studies.demo import render_showcase

pytestmark = pytest.mark.gl


def test_showcase_figures_are_written_and_show_something(tmp_path):
    written = render_showcase(tmp_path, progress=False, scale=0.5)  # the same code on a quarter of the pixels
    assert set(written) == {"composite", "composite_check", "effects", "terrain", "volume", "nurbs",
                            "geometry_image"}
    for name, path in written.items():
        img = np.asarray(Image.open(path).convert("RGB")).astype(int)
        non_white = ~np.all(img > 245, axis=-1)
        assert non_white.mean() > 0.05, name
    comp = np.asarray(Image.open(written["composite"]).convert("RGB")).astype(int)
    blue = (comp[..., 2] > comp[..., 0] + 40)
    tan = (comp[..., 0] > comp[..., 2] + 30)
    assert blue.sum() > 2000 and tan.sum() > 20000  # both the sphere mesh and the ray-cast patch are there
