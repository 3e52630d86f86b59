"""Reading data into splinevis models: height grids (terrain) from arrays, pyvista grids and files."""

from .heights import SUPPORTED_EXTENSIONS as SUPPORTED_EXTENSIONS
from .heights import HeightGrid as HeightGrid
from .heights import read_heights as read_heights

__all__ = ["HeightGrid", "read_heights", "SUPPORTED_EXTENSIONS"]
