"""splinevis: exact per-pixel rendering of spline models in GLSL injected into VTK/PyVista.

The data flows one way: readers (``splinevis.io``) -> spline models in float64 numpy (``splinevis.bb``,
``splinevis.analytic``, ...) -> GPU programs (``glsl/`` + ``splinevis.gl``) -> analysis and studies.
Nothing heavy is imported here: ``Plotter`` loads VTK on first use.
"""

from __future__ import annotations

__version__ = "0.1.0"

from ._optional import install as _install_extras_finder

_install_extras_finder()  # a missing optional module names the extra that brings it

from .effects import Style as Style
from .errors import (
    OpenGLUnavailableError as OpenGLUnavailableError,
    ShaderCompileError as ShaderCompileError,
    SplinevisError as SplinevisError,
)

from .io import HeightGrid as HeightGrid, read_heights as read_heights
from .terrain.model import TerrainSpline as TerrainSpline

#: Public names loaded on first use (VTK, OpenCASCADE and the mesh libraries are not imported by ``import
#: splinevis``): name -> (module, attribute).
_LAZY = {
    "Plotter": (".plotting", "Plotter"),
    "read": (".read_any", "read"),
    "read_volume": (".io", "read_volume"),
    "read_nurbs": (".io", "read_nurbs"),
    "VolumeGrid": (".io", "VolumeGrid"),
    "VolumeSpline": (".volume.model", "VolumeSpline"),
    "Isosurface": (".volume.isosurface", "Isosurface"),
    "NurbsModel": (".nurbs.model", "NurbsModel"),
    "NurbsSurface": (".nurbs.surface", "NurbsSurface"),
    "GeometryImage": (".geometry_image.model", "GeometryImage"),
    "Walkthrough": (".nurbs.lod.pipeline", "Walkthrough"),
    "render_file": (".render_file", "render_file"),
}

__all__ = ["Style", "TerrainSpline", "HeightGrid", "read_heights", "SplinevisError", "OpenGLUnavailableError",
           "ShaderCompileError", "__version__", *_LAZY]


def __getattr__(name):
    if name in _LAZY:
        import importlib

        module, attr = _LAZY[name]
        value = getattr(importlib.import_module(module, __name__), attr)
        globals()[name] = value  # once: later lookups do not come here
        return value
    raise AttributeError(f"module 'splinevis' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
