"""The wheel installed with only the core dependencies (``pip install splinevis``, no extras) renders a terrain and
an isosurface from its packaged GLSL files, and a feature that needs an extra names the ``pip install`` to run
(a NIfTI file: ``[nifti]``, whose nibabel neither ``import splinevis`` nor another volume's reader imports).

The environment is made by ``tools/core_venv.py`` (wheel built from a copy of the sources, new venv without
system site-packages, the core dependencies' files linked in from this environment, no network). Its script runs
from a folder outside the repository, so only the installed package can be imported.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from splinevis._optional import EXTRAS
from tools.core_venv import build_wheel, clean_env, core_only_venv

SCRIPT = r'''
import importlib, importlib.util, json, sys
from pathlib import Path

out, extras, nii = Path(sys.argv[1]), json.loads(sys.argv[2]), Path(sys.argv[3])
facts = {"found_before_import": [m for m in extras if importlib.util.find_spec(m) is not None]}

import numpy as np
from PIL import Image

import splinevis
from splinevis.gl.assembler import glsl_root

facts["splinevis"] = splinevis.__file__
facts["glsl_root"] = str(glsl_root())
facts["glsl_files"] = len(list(glsl_root().rglob("*.glsl")))
vol = np.arange(24.0).reshape(2, 3, 4)
splinevis.io.VolumeGrid(vol, spacing=(1.0, 2.0, 3.0)).to_pyvista().save(out / "volume.vti")
facts["vti_shape"] = list(splinevis.read_volume(out / "volume.vti").values.shape)
facts["nibabel_imported"] = "nibabel" in sys.modules  # by splinevis or a non-NIfTI volume: must be False
facts["extra_errors"] = {}
for module in extras:
    try:
        importlib.import_module(module)
    except ModuleNotFoundError as exc:
        facts["extra_errors"][module] = str(exc)
try:
    facts["nii_shape"] = list(splinevis.read_volume(nii).values.shape)
except Exception as exc:  # the core: no nibabel
    facts["read_nii_error"] = f"{type(exc).__name__}: {exc}"
Image.fromarray(np.zeros((4, 4), np.float32)).save(out / "heights.tif")  # a TIFF: read through rasterio
try:
    splinevis.read_heights(out / "heights.tif")
except Exception as exc:  # with rasterio (development): no georeference in this TIFF
    facts["read_tif_error"] = f"{type(exc).__name__}: {exc}"

z = np.add.outer(np.sin(np.linspace(0, 3, 33)), np.cos(np.linspace(0, 3, 33)))
pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
pl.add_terrain(z, "C1", spacing=(3 / 32, 3 / 32), lights=1)
Image.fromarray(pl.screenshot(return_img=True)).save(out / "terrain.png")
pl.close()
x = np.linspace(-1, 1, 24)
r = np.sqrt(np.add.outer(np.add.outer(x ** 2, x ** 2), x ** 2))  # a sphere: the same in either axis order
pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
pl.add_isosurface(r, 0.7, spacing=(2 / 23,) * 3, lights=1)
Image.fromarray(pl.screenshot(return_img=True)).save(out / "isosurface.png")
pl.close()
print(json.dumps(facts))
'''


def _run(python, folder: Path, nii: Path) -> dict:
    folder.mkdir()
    (folder / "render.py").write_text(SCRIPT)
    done = subprocess.run([str(python), "render.py", str(folder), json.dumps(sorted(EXTRAS)), str(nii)],
                          cwd=folder, capture_output=True, text=True, env=clean_env(), timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_every_extra_module_is_an_import_name_of_the_development_environment():
    # the development environment has every extra (`make` installs [all]): a key of EXTRAS that is not found
    # here is not the name the code imports (the finder would never be asked for it)
    assert [m for m in EXTRAS if importlib.util.find_spec(m) is None] == []


@pytest.mark.gl
def test_wheel_with_core_dependencies_only_renders_and_names_the_extras(tmp_path):
    import nibabel as nib  # the development environment has the [nifti] extra: it writes the test's file

    nii = tmp_path / "small.nii"
    nib.save(nib.Nifti1Image(np.arange(24, dtype=np.int16).reshape(4, 3, 2), np.eye(4)), nii)
    venv_python = core_only_venv(tmp_path, build_wheel(tmp_path / "build"))
    facts = _run(venv_python, tmp_path / "core", nii)

    venv = (tmp_path / "venv").resolve()
    assert facts["found_before_import"] == []  # no extra's module is in the environment
    assert Path(facts["splinevis"]).resolve().is_relative_to(venv)  # the installed wheel, not the repository
    assert Path(facts["glsl_root"]).resolve().is_relative_to(venv)
    repo_glsl = Path(__file__).resolve().parents[1] / "glsl"
    assert facts["glsl_files"] == len(list(repo_glsl.rglob("*.glsl")))  # package data: every GLSL file shipped
    for module, (extra, _) in EXTRAS.items():
        assert f"pip install 'splinevis[{extra}]'" in facts["extra_errors"][module], module
    assert facts["read_tif_error"].startswith("ModuleNotFoundError: No module named 'rasterio'")
    assert "pip install 'splinevis[geo]'" in facts["read_tif_error"]
    # nibabel is the [nifti] extra: not in the core, never imported for other volumes, and a NIfTI file read
    # without it names the file and the install command
    assert "nibabel" in facts["extra_errors"] and not facts["nibabel_imported"]
    assert facts["vti_shape"] == [2, 3, 4]
    assert facts["read_nii_error"].startswith(f"ModuleNotFoundError: {nii}: No module named 'nibabel'")
    assert "pip install 'splinevis[nifti]'" in facts["read_nii_error"]

    dev = _run(sys.executable, tmp_path / "development", nii)  # the same script on the development install
    assert not dev["nibabel_imported"]  # importable here, and still not imported until a NIfTI file is read
    assert dev["nii_shape"] == [2, 3, 4] and "read_nii_error" not in dev  # values[k, j, i] of the (4, 3, 2) data
    for name in ("terrain.png", "isosurface.png"):
        img = np.asarray(Image.open(tmp_path / "core" / name).convert("RGB")).astype(int)
        assert img.shape == (120, 160, 3)
        covered = np.abs(img - img[0, 0]).max(axis=-1) > 0  # the corner is background in both views
        # not blank: the surface covers a good part of the view (terrain ~22 %, sphere of radius 0.7 in
        # [-1, 1]^3 ~8 % at the fitted camera) and is shaded (a lit curved surface takes many colours)
        assert covered.mean() > 0.04, (name, covered.mean())
        assert len(np.unique(img[covered], axis=0)) > 50, name
        # the same shaders on the same inputs and GL driver give the same bytes: the wheel draws what the
        # development tree draws
        np.testing.assert_array_equal(img, np.asarray(Image.open(tmp_path / "development" / name).convert("RGB")))
