"""A missing optional module names the extra that brings it (splinevis._optional), through the import system."""

from __future__ import annotations

import importlib

import pytest

import splinevis  # noqa: F401 - installs the finder
from splinevis import _optional


def test_missing_extra_module_names_the_install_command(monkeypatch):
    monkeypatch.setitem(_optional.EXTRAS, "splinevis_absent_optional_module", ("cad", "a test of the message"))
    with pytest.raises(ModuleNotFoundError, match=r"pip install 'splinevis\[cad\]'") as info:
        importlib.import_module("splinevis_absent_optional_module.sub")
    assert info.value.name == "splinevis_absent_optional_module"
    # an installed optional module imports as usual; a module that is not ours keeps Python's own message
    assert importlib.import_module("rasterio") is not None
    with pytest.raises(ModuleNotFoundError, match=r"^No module named 'splinevis_absent_other'$"):
        importlib.import_module("splinevis_absent_other")


def test_every_extra_module_is_in_pyproject():
    import tomllib
    from pathlib import Path

    extras = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    for extra in {e for e, _ in _optional.EXTRAS.values()}:
        assert extra in extras and extras[extra], extra
    assert extras["all"] == ["splinevis[nifti,geo,cad,mesh,dask]"]  # every extra, by name
    assert set(extras) == {"test", "all", "nifti", "geo", "cad", "mesh", "dask"}
