"""The smooth-geometry-image program (kind ``passes``): subdivision as fragment passes on the GPU, the limit
surface with its exact normals handed to VTK as a mesh [Losasso2003, sec. 5].

``build`` runs the passes (:func:`.gpu.subdivide_gpu`) to the requested *continuous* level of detail and returns
a PyVista PolyData: the limit points ``p^k`` on the grid triangulation whose diagonals join ``(r, c)`` and
``(r + 1, c + 1)``, the exact unit normals ``n^k`` from the tangent masks as the active normals, and (only when
the scene shows curvature) the point array ``curvature`` = (mean, Gaussian). The scene's effects (lights,
reflection lines, isophotes, curvature, transparency) are drawn by :mod:`splinevis.gl.mesh_effects` with only the
declared ones compiled in.

Level of detail ``level = k + alpha``:

* ``k >= 0``: ``k`` subdivision steps; ``alpha > 0`` blends the linearly subdivided ``p^k`` (taken from
  ``p^{k+1}`` by subsampling, which is exact: both are limit points) with ``p^{k+1}`` (:func:`.gpu.geomorph_gpu`),
  normals blended and renormalized, so the mesh changes continuously with ``level``;
* ``k < 0``: "negative" subdivision, every ``2^-k``-th limit point of level 0, down to the octahedron at
  ``level = -(log2 N - 1)`` for an image of ``N + 1 = 2^m + 1`` samples.

``displacement``: a scalar map ``d`` on the output grid, the mesh becomes ``p + d n``
(:func:`.gpu.displace_gpu`; :func:`displacement_map` makes one that moves the surface onto a mesh).
``backend="numpy"`` uses the float64 twin instead of the GPU (the CPU fallback).
"""

from __future__ import annotations

import math

import numpy as np

from ..gl.contract import HardCase, SplineProgram
from .model import GeometryImage
from .renderers import RENDERERS

__all__ = ["surface_arrays", "surface_mesh", "displacement_map", "model_from", "min_level", "PROGRAM"]


def min_level(n: int) -> int:
    """The coarsest level of an ``n x n`` image: the octahedron (3 x 3 samples).

    >>> min_level(65), min_level(33), min_level(31)
    (-5, -4, 0)
    """
    N = int(n) - 1
    j = 0
    while N % (1 << (j + 2)) == 0:  # subsampling by 2^(j+1) leaves an odd image
        j += 1
    return -j


def _level(image, level):
    try:
        level = float(level)
    except (TypeError, ValueError):
        raise TypeError(f"level must be a number (a continuous level of detail), got {level!r}.") from None
    lo = min_level(image.n)
    if not (math.isfinite(level) and lo <= level <= 8):
        raise ValueError(f"level must be in [{lo}, 8] for a {image.n} x {image.n} image ({lo}: the octahedron), "
                         f"got {level!r}.")
    k = math.floor(level)
    return k, level - k


def _at(image, k, backend, curvature):
    """Limit points, normals (and curvature) of the integer level ``k`` (negative: subsampled level 0)."""
    from .subdivision import subdivide, subsample

    levels = max(k, 0)
    if backend == "gpu":
        from .gpu import subdivide_gpu

        # float32 passes on coordinates relative to the image's centre (exact affine invariance of the masks):
        # far from the origin the rounding then scales with the model's size, not with its distance
        centre = 0.5 * (image.control.reshape(-1, 3).min(axis=0) + image.control.reshape(-1, 3).max(axis=0))
        sub = subdivide_gpu(image.control - centre, levels, **({"curvature": True} if curvature else {}))
        p = np.asarray(sub.p, dtype=np.float64) + centre
    else:
        sub = subdivide(image.control, levels)
        p = np.asarray(sub.p, dtype=np.float64)
    n = np.asarray(sub.n, dtype=np.float64)
    c = None
    if curvature:
        c = getattr(sub, "curvature", None)
        if c is None:
            from .subdivision import curvature as twin_curvature

            c = np.stack(twin_curvature(np.asarray(sub.g, dtype=np.float64)), axis=-1)
        c = np.asarray(c, dtype=np.float64)[..., :2]
    if k < 0:
        p, n = subsample(p, -k), subsample(n, -k)
        c = None if c is None else subsample(c, -k)
    return p, n, c


def surface_arrays(image: GeometryImage, level=3.0, *, displacement=None, curvature: bool = False,
                   backend: str = "gpu"):
    """Limit points ``(M, M, 3)``, unit normals ``(M, M, 3)`` and, if asked, curvature ``(M, M, 2)`` (else None)
    of ``image`` at the continuous ``level`` (module docstring), float64.

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> [surface_arrays(gi, lv, backend="numpy")[0].shape[0] for lv in (-2, -1.5, 0, 0.5, 2)]
    [3, 5, 9, 17, 33]
    """
    if backend not in ("gpu", "numpy"):
        raise ValueError(f"backend must be 'gpu' or 'numpy', got {backend!r}.")
    k, alpha = _level(image, level)
    if alpha == 0.0:
        p, n, c = _at(image, k, backend, curvature)
    else:
        from .subdivision import geomorph, subsample

        p1, n1, c1 = _at(image, k + 1, backend, curvature)
        p0, n0 = subsample(p1, 1), subsample(n1, 1)
        if backend == "gpu":
            from .gpu import geomorph_gpu

            p = np.asarray(geomorph_gpu(p0, p1, alpha), dtype=np.float64)
            n = np.asarray(geomorph_gpu(n0, n1, alpha, unit=True), dtype=np.float64)
        else:
            p, n = geomorph(p0, p1, alpha), geomorph(n0, n1, alpha, unit=True)
        c = None if c1 is None else geomorph(subsample(c1, 1), c1, alpha)
    if displacement is not None:
        d = np.asarray(displacement, dtype=np.float64)
        if d.shape != p.shape[:2]:
            raise ValueError(f"the displacement map must have the output grid's shape {p.shape[:2]} at level {level}, "
                             f"got {d.shape}.")
        if backend == "gpu":
            from .gpu import displace_gpu

            p = np.asarray(displace_gpu(p, n, d), dtype=np.float64)
        else:
            from .subdivision import displace

            p = displace(p, n, d)
    return p, n, c


def surface_mesh(image: GeometryImage, level=3.0, *, displacement=None, curvature: bool = False,
                 backend: str = "gpu"):
    """A PyVista PolyData of ``image`` at ``level``: limit points, exact normals (active), ``curvature`` if asked;
    field data ``level`` and ``backend``.

    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> mesh = surface_mesh(gi, 1, backend="numpy")
    >>> mesh.n_points, mesh.n_cells, mesh.point_data.active_normals.shape
    (289, 512, (289, 3))
    """
    import pyvista as pv

    from .subdivision import grid_faces

    p, n, c = surface_arrays(image, level, displacement=displacement, curvature=curvature, backend=backend)
    M = p.shape[0]
    mesh = pv.PolyData(p.reshape(-1, 3), faces=pv.CellArray.from_regular_cells(grid_faces(M)))
    mesh.point_data["Normals"] = n.reshape(-1, 3)
    mesh.point_data.active_normals_name = "Normals"
    if c is not None:
        mesh.point_data["curvature"] = c.reshape(-1, 2)
    mesh.field_data["level"] = np.array([float(level)])
    mesh.field_data["backend"] = np.array([backend])
    return mesh


def displacement_map(image: GeometryImage, mesh, level: int, *, backend: str = "numpy") -> np.ndarray:
    """A scalar displacement map ``d`` at integer ``level`` that moves each limit point along its normal onto the
    closest point of ``mesh`` (``d = (c - p) . n``, ``c`` the closest mesh point; first-order exact for small
    residuals): detail the smooth surface left out [Losasso2003, sec. 5, "Displacement mapping"].

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> d = displacement_map(gi, sphere_mesh(level=4), 1)
    >>> d.shape, bool(d.mean() > 0)  # the control-point sphere's limit surface lies inside the unit sphere
    ((17, 17), True)
    """
    import igl

    p, n, _ = surface_arrays(image, int(level), backend=backend)
    V = np.ascontiguousarray(mesh.points, dtype=np.float64)
    F = np.ascontiguousarray(mesh.faces.reshape(-1, 4)[:, 1:], dtype=np.int64)
    _, _, C = igl.point_mesh_squared_distance(np.ascontiguousarray(p.reshape(-1, 3)), V, F)
    return np.einsum("ij,ij->i", C - p.reshape(-1, 3), n.reshape(-1, 3)).reshape(p.shape[:2])


def model_from(data, n="auto", *, fairness="auto", **options) -> GeometryImage:
    """A :class:`GeometryImage` from ``data``: itself, an ``(n, n, 3)`` control array, or a closed genus-0 mesh
    (pyvista PolyData or a file pyvista reads), built by :func:`.build.geometry_image_from_mesh` (call that for
    the build report: times per stage, stretch, distance to the mesh); ``n="auto"`` picks the image size from the
    mesh's detail.

    >>> from datasets_synthetic.closed_meshes import star_blob
    >>> model_from(star_blob(level=2), n=9).n
    9
    """
    if isinstance(data, GeometryImage):
        return data
    if isinstance(data, np.ndarray):
        return GeometryImage(data, constrain=True)
    from .build import geometry_image_from_mesh

    # n="auto" measures the distance anyway (and warns of folds and of detail it cannot resolve)
    image, _ = geometry_image_from_mesh(data, n, fairness=fairness, measure=False, **options)
    return image


def _hard_cases():
    """Scenes where the geometry image is numerically or visually hard (tests/test_geometry_image_program.py
    draws each with the GPU passes and compares the mesh with the float64 twin's)."""
    from datasets_synthetic.closed_meshes import star_blob, stretched_blob

    def blob(offset=(0.0, 0.0, 0.0), shape=star_blob, level=3, n=33):
        def make():
            image = model_from(shape(level=level), n)
            return GeometryImage(image.control + np.asarray(offset, dtype=np.float64))
        return make

    far = (4.0e5, 5.2e6, 300.0)  # UTM-sized coordinates
    return [HardCase("cut-vertex-close-up", blob(), [(0.0, 0.0, -2.2), (0.0, 0.0, -1.0), (0, 1, 0)],
                     program_options={"level": 4}),
            HardCase("octahedron", blob(), [(3.0, -4.0, 2.5), (0, 0, 0), (0, 0, 1)],
                     program_options={"level": -4}),
            HardCase("utm-coordinates", blob(far), [tuple(np.add(far, (3.0, -4.0, 2.5))), far, (0, 0, 1)],
                     program_options={"level": 3}),
            HardCase("stretched-deep", blob(shape=stretched_blob), [(9.0, -12.0, 6.0), (0, 0, 0), (0, 0, 1)],
                     program_options={"level": 5.5})]


def _build(model, style, *, newton_iterations, level=3.0, displacement=None, backend="gpu"):
    del newton_iterations  # no root finding: subdivision is exact
    return surface_mesh(model, level, displacement=displacement, curvature="curvature" in style.effect_set(),
                        backend=backend)


PROGRAM = SplineProgram(
    "geometry_image", "passes", GeometryImage, build=_build, model_from=model_from, hard_cases=_hard_cases,
    options=("level", "displacement", "backend"), renderers=RENDERERS,
    description="smooth geometry images: one bicubic B-spline, GPU subdivision passes [Losasso2003]")
