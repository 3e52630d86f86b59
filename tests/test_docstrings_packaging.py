"""Docstring examples run, and packaging lists every subpackage and ships the GLSL files.

The examples themselves run as doctests: ``pyproject.toml`` collects the package with ``--doctest-modules``
(``pytest splinevis``, or the whole suite with plain ``pytest``). The tests here check that this stays so:
the configuration, that every public function, class, method and property (a name in a module's
``__all__``, defined in that module) carries a ``>>>`` example, and that pytest collects each of them.
"""

import importlib
import inspect
import pkgutil
import subprocess
import sys
import tomllib
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]

# Public names without an example, because no sub-second one exists: each renders many scenes or runs a
# whole study (minutes). Remove a name once its docstring has one (the test below fails on stale entries,
# so the list can only shrink).
WITHOUT_EXAMPLES = {
    # every showcase figure: ~24 offscreen scenes of 360x270 to 640x480 (three 65x65 terrains, the
    # 41^3 volume close-ups of side_by_side_figure), each figure's size fixed
    "splinevis.studies.demo": {"render_showcase"},
    # the full terrain study (minutes even with quick=True)
    "splinevis.studies.terrain": {"run_terrain_study"},
    # the full volume study (minutes even with quick=True)
    "splinevis.studies.volume": {"run_volume_study"},
    # the NURBS study and its parts: dozens of 320x240 to 640x480 scenes, the float64 twin per pixel
    "splinevis.studies.nurbs": {"run_nurbs_study"},
    # the walkthrough study: builds levels of detail of up to 40,000 patches and flies through them
    "splinevis.studies.walkthrough": {"run_walkthrough_study"},
    # the showcase's NURBS figure: four 520x390 scenes
    "splinevis.studies.nurbs_demo": {"nurbs_figure"},
    # the sweep: ~24 windows of 200x150 (its window is fixed) even with quick=True, cubic=False, n=8,
    # repeats=1: several seconds
    "splinevis.studies.volume_accuracy": {"accuracy_vs_time"},
    # 6-8 offscreen scenes with VolumeSpline builds: 1.2 s even at n=8 in a 40x30 window, and a close-up
    # that tiny is all surface (nothing meaningful to show)
    "splinevis.studies.volume_figures": {"side_by_side_figure"},
    # the geometry-image study (8 s with quick=True) and its pipeline figure (a spherical parametrization, a
    # fit and six panels, three of them offscreen scenes of 360x300)
    "splinevis.studies.geometry_image": {"run_geometry_image_study"},
    "splinevis.studies.geometry_image_figures": {"pipeline_figure"},
    # the antialiasing study: six offscreen renders per scene and renderer, four scenes (25 s with quick=True)
    "splinevis.studies.antialiasing": {"run_antialiasing_study"},
}


def _package_modules():
    import splinevis

    yield "splinevis"
    for info in pkgutil.walk_packages(splinevis.__path__, "splinevis."):
        if info.name.rsplit(".", 1)[-1] != "__main__":
            yield info.name


def _public_objects(module):
    """(name, object) of every function, class, method and property a module defines and lists in
    ``__all__`` (re-exported names belong to the module that defines them; cached functions count)."""
    for name in getattr(module, "__all__", ()):
        obj = getattr(module, name, None)
        target = inspect.unwrap(obj) if callable(obj) else obj
        if not (inspect.isfunction(target) or inspect.isclass(target)) or target.__module__ != module.__name__:
            continue
        yield name, obj
        if inspect.isclass(obj):
            for attr, value in vars(obj).items():
                if attr.startswith("_"):
                    continue
                if isinstance(value, (staticmethod, classmethod)):
                    value = value.__func__
                if isinstance(value, property) or inspect.isfunction(value):
                    yield f"{name}.{attr}", value


def _doctest_name(module, name, obj) -> str:
    """The name pytest gives the object's doctest: module + qualified name (an alias such as
    ``NAME = _function`` is collected under the function's own name)."""
    if "." in name:  # a method or property: Class.attr as listed
        return f"{module.__name__}.{name}"
    return f"{module.__name__}.{getattr(inspect.unwrap(obj), '__qualname__', name)}"


def _has_example(obj) -> bool:
    return ">>>" in (inspect.getdoc(obj) or "")


def _public_names():
    """{module: {name: (has an example, doctest name)}} over the whole package."""
    out = {}
    for modname in _package_modules():
        module = importlib.import_module(modname)
        out[modname] = {name: (_has_example(obj), _doctest_name(module, name, obj))
                        for name, obj in _public_objects(module)}
    return out


def test_doctest_collection_is_configured_for_the_package():
    opts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert "--doctest-modules" in opts["addopts"].split()
    assert {"tests", "splinevis"} <= set(opts["testpaths"])
    assert set(opts["doctest_optionflags"].split()) >= {"ELLIPSIS", "NORMALIZE_WHITESPACE"}


def test_every_public_name_has_an_example():
    names = _public_names()
    missing = sorted(f"{m}.{q}" for m, qs in names.items() for q, (ok, _) in qs.items()
                     if not ok and q not in WITHOUT_EXAMPLES.get(m, ()))
    stale = sorted(f"{m}.{q}" for m, qs in WITHOUT_EXAMPLES.items() for q in qs
                   if names.get(m, {}).get(q, (True,))[0])
    assert not missing, ("public names without a '>>>' example in their docstring (add an Examples "
                         "section):\n  " + "\n  ".join(missing))
    assert not stale, ("names in WITHOUT_EXAMPLES that have an example now or no longer exist (remove them "
                       "from the list):\n  " + "\n  ".join(stale))


def test_pytest_collects_every_example():
    """What pytest collects from the package (a module that fails to import shows as an error here)."""
    run = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                          "splinevis"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    collected = {line.split("::", 1)[1] for line in run.stdout.splitlines() if "::" in line}
    expected = {doctest_name for qs in _public_names().values() for ok, doctest_name in qs.values() if ok}
    assert expected, "no public name has an example"
    assert not expected - collected, f"examples pytest does not collect: {sorted(expected - collected)}"


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
    names = {d.split(">")[0].split("=")[0].split("<")[0].split("[")[0].strip().lower() for d in deps}  # no extras
    assert names <= pinned, names - pinned
