"""Docstring examples run, and packaging lists every subpackage and ships the GLSL files."""

import doctest
import importlib
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("module", [
    "splinevis.gl.assembler", "splinevis.effects", "splinevis.analytic.patch", "splinevis.gl.headless",
    "splinevis.plotting", "splinevis.volume.model",
])
def test_docstring_examples_run(module):
    mod = importlib.import_module(module)
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0, f"{module} has no examples"
    assert result.failed == 0


def test_every_subpackage_is_listed_in_pyproject():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    listed = set(cfg["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "splinevis").rglob("__init__.py")}
    found.add("datasets_synthetic")  # the study commands generate their data with it
    assert found - listed == set(), f"add to pyproject packages: {sorted(found - listed)}"
    assert "splinevis.glsl" in listed
    assert cfg["tool"]["setuptools"]["package-dir"]["splinevis.glsl"] == "glsl"


def test_pinned_versions_cover_every_dependency():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    pinned = {line.split("==")[0].lower() for line in (ROOT / "requirements/pinned.txt").read_text().splitlines()
              if "==" in line and not line.startswith("#")}
    deps = cfg["project"]["dependencies"] + cfg["project"]["optional-dependencies"]["test"]
    names = {d.split(">")[0].split("=")[0].split("<")[0].strip().lower() for d in deps}
    assert names <= pinned, names - pinned
