"""Reading data into splinevis models: height grids (terrain) and volumes from arrays, pyvista grids and files."""

from .heights import SUPPORTED_EXTENSIONS as SUPPORTED_EXTENSIONS
from .heights import HeightGrid as HeightGrid
from .heights import read_heights as read_heights
from .volumes import VOLUME_EXTENSIONS as VOLUME_EXTENSIONS
from .volumes import VolumeGrid as VolumeGrid
from .volumes import read_volume as read_volume

__all__ = ["HeightGrid", "read_heights", "SUPPORTED_EXTENSIONS", "VolumeGrid", "read_volume", "VOLUME_EXTENSIONS"]
