"""nibabel is the ``[nifti]`` extra: ``import splinevis`` and other volumes do not import it, and a NIfTI file
read without it raises the install advice of splinevis._optional with the file's name. The core-only install
(tests/test_wheel_core_install.py) checks the same on a real environment without nibabel; here its absence is
simulated in the development environment, where nibabel is installed."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import splinevis
from splinevis._optional import EXTRAS, MissingExtraFinder


def test_import_and_non_nifti_volumes_do_not_import_nibabel(tmp_path):
    code = ("import sys, numpy as np, splinevis\n"
            "splinevis.read_volume(np.zeros((4, 4, 4)), order='zyx')\n"
            "print('nibabel' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=tmp_path)
    assert done.stdout.strip() == "False"


class _Absent(MissingExtraFinder):
    """First on sys.meta_path: for nibabel, what the last finder says when nothing else found it."""

    def find_spec(self, fullname, path=None, target=None):
        return super().find_spec(fullname, path, target) if fullname.partition(".")[0] == "nibabel" else None


def test_nifti_file_without_nibabel_names_the_file_and_the_extra(tmp_path, monkeypatch):
    import nibabel as nib

    assert EXTRAS["nibabel"][0] == "nifti"
    path = tmp_path / "small.nii.gz"
    nib.save(nib.Nifti1Image(np.zeros((3, 3, 3), np.int16), np.eye(4)), path)
    for name in [m for m in sys.modules if m == "nibabel" or m.startswith("nibabel.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setattr(sys, "meta_path", [_Absent(), *sys.meta_path])
    with pytest.raises(ModuleNotFoundError) as info:
        splinevis.read_volume(path)
    assert str(info.value).startswith(f"{path}: No module named 'nibabel'")
    assert "pip install 'splinevis[nifti]'" in str(info.value) and info.value.name == "nibabel"
