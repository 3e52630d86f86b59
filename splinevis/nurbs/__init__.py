"""NURBS surfaces: the float64 model (knots, basis functions, rational surfaces, curvature), exact reference
surfaces and multi-patch models with trim loops. The fragment program that draws them lives in
:mod:`.program` (kind ``surface``) with its GLSL under ``glsl/lib/nurbs/`` and ``glsl/programs/``."""

from .basis import basis_funs as basis_funs, ders_basis_funs as ders_basis_funs, find_span as find_span
from .model import NurbsModel as NurbsModel, TrimCurve as TrimCurve
from .surface import NurbsSurface as NurbsSurface
