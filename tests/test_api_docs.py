"""docs/api.md: its five-line scripts run, use only top-level names of splinevis, and draw something."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import splinevis

pytestmark = pytest.mark.gl

API = Path(__file__).resolve().parents[1] / "docs" / "api.md"
BLOCKS = re.findall(r"```python\n(.*?)```", API.read_text(), re.S)


def test_the_table_lists_every_public_name():
    text = API.read_text()
    missing = [n for n in splinevis.__all__ if n != "__version__" and f"`{n}`" not in text]
    assert not missing, f"docs/api.md does not list {missing}"


@pytest.mark.parametrize("code", BLOCKS, ids=["terrain", "volume", "nurbs", "geometry-image", "walkthrough"])
def test_five_line_scripts_run_with_top_level_names(code):
    assert len(code.strip().splitlines()) <= 5
    used = set(re.findall(r"splinevis\.(\w+)", code))
    assert used <= set(splinevis.__all__), used - set(splinevis.__all__)
    env: dict = {}
    exec(compile(code, str(API), "exec"), env)  # noqa: S102 - the documented scripts themselves
    if "image" in env:
        img = np.asarray(env["image"]).astype(int)
        assert np.any(img != img[0, 0], axis=-1).mean() > 0.05  # something drawn, not a blank picture
    else:
        assert env["frames"][-1]["triangles"] > 0
    env["pl"].close()
