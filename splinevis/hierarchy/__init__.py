"""Spatial hierarchies shared by the families: an n-dimensional min-max pyramid (terrain quadtree, volume
octree, later the walkthrough's patch hierarchy) and hierarchical view-frustum culling of proxy boxes.
Plain numpy; the culler's VTK hook imports VTK only when attached."""

from .culling import FrustumCuller as FrustumCuller
from .pyramid import MinMaxPyramid as MinMaxPyramid

__all__ = ["MinMaxPyramid", "FrustumCuller"]
