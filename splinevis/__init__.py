"""splinevis: exact per-pixel rendering of spline models in GLSL injected into VTK/PyVista.

The data flows one way: readers (``splinevis.io``) -> spline models in float64 numpy (``splinevis.bb``,
``splinevis.analytic``, ...) -> GPU programs (``glsl/`` + ``splinevis.gl``) -> analysis and studies.
Nothing heavy is imported here: ``Plotter`` loads VTK on first use.
"""

from __future__ import annotations

__version__ = "0.1.0"

from .effects import Style as Style
from .errors import (
    OpenGLUnavailableError as OpenGLUnavailableError,
    ShaderCompileError as ShaderCompileError,
    SplinevisError as SplinevisError,
)

from .io import HeightGrid as HeightGrid, read_heights as read_heights
from .terrain.model import TerrainSpline as TerrainSpline

__all__ = ["Style", "Plotter", "TerrainSpline", "HeightGrid", "read_heights", "SplinevisError",
           "OpenGLUnavailableError", "ShaderCompileError", "__version__"]


def __getattr__(name):
    if name == "Plotter":
        from .plotting import Plotter

        return Plotter
    raise AttributeError(f"module 'splinevis' has no attribute {name!r}")
