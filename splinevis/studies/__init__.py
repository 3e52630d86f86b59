"""The studies: what accuracy costs in time, measured and written as JSON, markdown tables and figures.

:data:`STUDIES` is the one list of them; ``splinevis study NAME`` takes its choices from it. A study's
runner is imported only when it runs (the studies pull in matplotlib, tqdm and the synthetic data sets).

A runner is ``run(out_dir, *, quick=False, progress=True) -> dict``; it writes ``out_dir/<name>.json``
and returns what it wrote there. A part of the result that reports something missing, a dict
``{"available": False, "note": ...}`` (such as ``result["cubic"]`` of the volume study when the cubic
scheme is not available), is listed by :func:`notes`.

Examples
--------
>>> sorted(STUDIES)
['antialiasing', 'geometry-image', 'nurbs', 'terrain', 'volume', 'walkthrough']
>>> STUDIES["volume"].runner
'splinevis.studies.volume:run_volume_study'
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Study", "STUDIES", "get", "notes"]


@dataclass(frozen=True)
class Study:
    """One study: its name, the ``"module:function"`` of its runner and a line saying what it measures.

    Examples
    --------
    >>> Study("terrain", "splinevis.studies.terrain:run_terrain_study", "").json_file("out").name
    'terrain.json'
    """

    name: str
    runner: str
    summary: str

    def run(self, out_dir, *, quick: bool = False, progress: bool = True) -> dict:
        """Import the runner and run it (see the module docstring for what it writes and returns).

        Examples
        --------
        A stand-in runner in a module of its own (the real ones take minutes):

        >>> import json, sys, tempfile, types
        >>> def tiny(out_dir, *, quick=False, progress=True):
        ...     result = {"quick": quick, "cubic": {"available": False, "note": "no cubic here"}}
        ...     Path(out_dir, "tiny.json").write_text(json.dumps(result))
        ...     return result
        >>> sys.modules["tiny_study"] = types.ModuleType("tiny_study")
        >>> sys.modules["tiny_study"].run = tiny
        >>> study = Study("tiny", "tiny_study:run", "a stand-in")
        >>> with tempfile.TemporaryDirectory() as out:
        ...     result = study.run(out, quick=True, progress=False)
        ...     written = json.loads(study.json_file(out).read_text())
        >>> result["quick"], written == result, notes(result)
        (True, True, ['no cubic here'])
        >>> del sys.modules["tiny_study"]
        """
        module, _, function = self.runner.partition(":")
        return getattr(importlib.import_module(module), function)(out_dir, quick=quick, progress=progress)

    def json_file(self, out_dir) -> Path:
        """The JSON file the study writes into ``out_dir``.

        Examples
        --------
        >>> STUDIES["volume"].json_file("results").as_posix()
        'results/volume.json'
        """
        return Path(out_dir) / f"{self.name}.json"


STUDIES = {s.name: s for s in (
    Study("terrain", "splinevis.studies.terrain:run_terrain_study",
          "terrain splines of Franke's function against triangle meshes"),
    Study("volume", "splinevis.studies.volume:run_volume_study",
          "isosurface splines against marching cubes and VTK's volume ray caster"),
    Study("nurbs", "splinevis.studies.nurbs:run_nurbs_study",
          "NURBS zebra stripes per fragment against tessellated meshes (ours and OpenCASCADE's)"),
    Study("walkthrough", "splinevis.studies.walkthrough:run_walkthrough_study",
          "large NURBS models at interactive rates: levels of detail, culling, threads [Kumar1997]"),
    Study("geometry-image", "splinevis.studies.geometry_image:run_geometry_image_study",
          "smooth geometry images: GPU subdivision passes against the twin and against Loop/Catmull-Clark [Losasso2003]"),
    Study("antialiasing", "splinevis.studies.antialiasing:run_antialiasing_study",
          "reflection lines: plain step, filtered, supersampled and the users' mesh against a 4x4 reference"),
)}


def get(name: str) -> Study:
    """The study called ``name``.

    Raises
    ------
    ValueError
        If there is no such study (the message lists the known ones).

    Examples
    --------
    >>> get("volume").name
    'volume'
    >>> get("sphere")
    Traceback (most recent call last):
    ...
    ValueError: study 'sphere' is not known; choose one of 'terrain', 'volume', 'nurbs', 'walkthrough', 'geometry-image', 'antialiasing'.
    """
    try:
        return STUDIES[name]
    except KeyError:
        raise ValueError(f"study {name!r} is not known; choose one of {', '.join(map(repr, STUDIES))}.") from None


def notes(result: dict) -> list:
    """The notes of the parts of a study's result that report something not available, in result order.

    Examples
    --------
    >>> notes({"quick": True, "cubic": {"available": False, "note": "cubic scheme NOT available"}})
    ['cubic scheme NOT available']
    >>> notes({"cubic": {"available": True, "note": "cubic scheme available"}})
    []
    """
    return [part["note"] for part in result.values()
            if isinstance(part, dict) and part.get("available") is False and "note" in part]
