"""Smooth geometry images [Losasso2003]: a closed genus-0 triangle mesh as one bicubic B-spline on an
octahedral geometry image, evaluated by subdivision passes on the GPU.

The data path, one module per stage:

* :mod:`.validate` -- is the mesh closed, manifold, connected, of genus 0 (which check fails, where);
* :mod:`.sphere` -- a bijective spherical parametrization with its stretch (:mod:`.stretch` the energy,
  :mod:`.mobius` the centering);
* :mod:`.image` -- the octahedral layout: the map, the X-cut's padding rules, the cut vertices;
* :mod:`.orient` -- which rotation of the sphere the image samples (the compressed part where sampling is dense);
* :mod:`.fit` -- least-squares fitting with fairness (the cut vertices eliminated as centroids);
* :mod:`.model` -- :class:`GeometryImage`, the bicubic surface in float64 (the reference);
* :mod:`.subdivision` -- the masks of subdivision as numpy float64 (the GPU passes' twin and CPU fallback);
* :mod:`.gpu` -- the same masks as fragment passes (moderngl, RGBA32F);
* :mod:`.program` -- the ``passes`` program: levels of detail, geomorphs, displacement, the mesh VTK draws;
* :mod:`.build` -- mesh to geometry image, stage by stage, with a report; :mod:`.measure` -- distances.

Examples
--------
>>> from datasets_synthetic.closed_meshes import star_blob
>>> from splinevis.geometry_image import geometry_image_from_mesh
>>> image, report = geometry_image_from_mesh(star_blob(level=2), n=17)
>>> image.n, report.stretch["flipped"]
(17, 0)
"""

from .build import BuildReport, geometry_image_from_mesh
from .model import GeometryImage

__all__ = ["GeometryImage", "geometry_image_from_mesh", "BuildReport"]
