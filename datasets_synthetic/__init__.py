"""Generators of the synthetic test data (no downloads): analytic functions sampled on grids.

Volumes: analytic scalar fields with exact gradients and a file writer, in
:mod:`datasets_synthetic.volumes`; the names below are re-exported from there.
"""

from .volumes import AnalyticField as AnalyticField
from .volumes import blob as blob
from .volumes import constant as constant
from .volumes import marschner_lobb as marschner_lobb
from .volumes import plateau as plateau
from .volumes import sphere_distance as sphere_distance
from .volumes import thin_sheet as thin_sheet
from .volumes import torus_distance as torus_distance
from .volumes import write_volume as write_volume

__all__ = ["AnalyticField", "blob", "constant", "marschner_lobb", "plateau", "sphere_distance", "thin_sheet",
           "torus_distance", "write_volume"]
