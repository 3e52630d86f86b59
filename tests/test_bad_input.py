"""Bad input gives a clear error naming the argument, the value and what to do (not a blank picture, a
silent default or a traceback)."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

import splinevis
from splinevis.cli import main
from splinevis.terrain.limits import HEIGHT_LIMIT


@pytest.mark.parametrize("size", [(0, 0), (-5, 10), (10,), (1.5, 20), "big", (True, 10)])
def test_window_size_must_be_two_positive_ints(size, recwarn):
    with pytest.raises(ValueError, match=r"window_size=.* must be two positive pixel counts \(width, height\), "
                                         r"e\.g\. window_size=\(800, 600\)"):
        splinevis.Plotter(off_screen=True, window_size=size)


def test_a_valid_window_size_still_renders_at_that_size():
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    assert pl.screenshot().shape == (30, 40, 3)
    pl.close()


def test_heights_beyond_float32_raise_naming_the_limit_and_rescale():
    z = np.zeros((9, 9))
    z[4, 4] = 1e300
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    with pytest.raises(ValueError, match=r"largest \|height\| is 1e\+300 .*beyond the limit 3\.4e\+32 .*float32, "
                                         r"max 3\.4e38.*Rescale the heights"):
        pl.add_terrain(z)
    with pytest.raises(ValueError, match=r"span 2e\+33"):  # a span beyond the limit too
        pl.add_terrain(np.add.outer(np.zeros(5), np.linspace(-1e33, 1e33, 5)))
    z_ok = np.add.outer(np.sin(np.linspace(0, 3, 9)), np.cos(np.linspace(0, 3, 9))) * 1e6
    assert pl.add_terrain(z_ok, read_options={"spacing": (0.1, 0.1)}).model.num_patches > 0
    assert HEIGHT_LIMIT < float(np.finfo(np.float32).max)
    pl.close()


def _write_out_cases(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    cases = [str(afile), str(afile / "below")]
    if os.geteuid() != 0:  # root writes anywhere: an unwritable folder only bites ordinary users
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        cases.append(str(locked / "out"))
    cases.append("/proc/splinevis_cannot_write_here")
    return cases


def test_cli_out_not_a_writable_directory_is_one_line_and_nonzero(tmp_path, capsys):
    for out in _write_out_cases(tmp_path):
        code = main(["demo", "--out", out, "--quiet"])
        err = capsys.readouterr().err
        assert code == 4, (out, err)
        assert err.count("\n") == 1 and "Traceback" not in err, err
        assert err.startswith("splinevis: cannot write to ") and f"--out {out}" in err, err


def test_cli_out_error_through_a_subprocess_has_no_traceback(tmp_path):
    import subprocess

    afile = tmp_path / "afile"
    afile.write_text("x")
    run = subprocess.run([sys.executable, "-m", "splinevis.cli", "selftest", "--out", str(afile / "sub"),
                          "--quiet"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 4, run.stderr
    assert "Traceback" not in run.stderr and str(afile / "sub") in run.stderr
