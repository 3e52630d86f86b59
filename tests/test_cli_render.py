"""``splinevis render FILE`` and ``splinevis --version``: a user's file to a picture in one line."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import splinevis
from splinevis import cli

pytestmark = pytest.mark.gl


def _ramp(path):
    z = np.add.outer(np.linspace(0, 40, 12), np.linspace(0, 30, 16) ** 1.5 / 10)
    path.write_text("ncols 16\nnrows 12\nxllcorner 0\nyllcorner 0\ncellsize 5\n"
                    + "\n".join(" ".join(f"{v:.2f}" for v in row) for row in z))
    return path


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"splinevis {splinevis.__version__}"


@pytest.mark.parametrize("effect", ["shaded", "zebra", "curvature"])
def test_render_a_terrain_file(tmp_path, capsys, effect):
    src = _ramp(tmp_path / "ramp.asc")
    out = tmp_path / f"{effect}.png"
    assert cli.main(["render", str(src), "-o", str(out), "--effect", effect, "--window", "160x120"]) == 0
    assert f"terrain {effect}, 160 x 120" in capsys.readouterr().out
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    assert img.shape == (120, 160, 3)
    background = img[0, 0]
    surface = np.any(img != background, axis=-1)
    assert surface.mean() > 0.2  # the model fills a good part of the picture, not a speck
    if effect == "zebra":
        assert img[surface].sum(-1).min() < 150 and img[surface].sum(-1).max() > 350  # dark and bright (lit tan) stripes


def test_render_errors_are_named(tmp_path, capsys):
    src = _ramp(tmp_path / "ramp.asc")
    assert cli.main(["render", str(src), "--window", "big"]) == 2
    assert "--window 'big' must be WIDTHxHEIGHT" in capsys.readouterr().err
    assert cli.main(["render", str(tmp_path / "none.asc")]) == 4 or "no such file" in capsys.readouterr().err
    notes = tmp_path / "notes.txt"
    notes.write_text("hello")
    assert cli.main(["render", str(notes)]) == 2
    assert "not a file splinevis reads" in capsys.readouterr().err
