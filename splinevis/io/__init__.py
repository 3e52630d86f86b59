"""Reading data into splinevis models: height grids (terrain) and volumes from arrays, pyvista grids and files,
NURBS models from CAD and spline files."""

from .heights import SUPPORTED_EXTENSIONS as SUPPORTED_EXTENSIONS
from .heights import HeightGrid as HeightGrid
from .heights import read_heights as read_heights
from .nurbs_files import NURBS_EXTENSIONS as NURBS_EXTENSIONS
from .nurbs_files import read_nurbs as read_nurbs
from .volumes import VOLUME_EXTENSIONS as VOLUME_EXTENSIONS
from .volumes import VolumeGrid as VolumeGrid
from .volumes import read_volume as read_volume

__all__ = ["HeightGrid", "read_heights", "SUPPORTED_EXTENSIONS", "VolumeGrid", "read_volume", "VOLUME_EXTENSIONS", "read_nurbs",
           "NURBS_EXTENSIONS"]
