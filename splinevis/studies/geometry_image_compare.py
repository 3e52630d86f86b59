"""What users have today beside a smooth geometry image: the raw mesh and its Loop and Catmull-Clark subdivisions,
measured the same way at equal triangle counts (the geometry-image study, section b).

* **Loop** [Loop1987] and **Catmull-Clark** [CatmullClark1978] subdivision come from MeshLab (pymeshlab's ``meshing_surface_subdivision_loop``
  and ``meshing_surface_subdivision_catmull_clark``; a triangle mesh becomes quads after the first Catmull-Clark
  step, returned triangulated), **Loop (VTK)** from ``vtkLoopSubdivisionFilter``. Their vertices are not moved to
  the limit surface, and their normals are what a user gets: averaged from the triangles
  (``pyvista.PolyData.compute_normals``).
* Each rendered mesh is measured where it is drawn: the distance of its vertices, edge midpoints and triangle
  centroids to the exact surface, and the angle between its vertex normals and the exact normals at the vertices.
  For a star-shaped test surface ``x = rho(d) d`` the distance is the radial error ``| |x| - rho(x / |x|) |``, an
  upper bound of the Euclidean distance that is tight where the surface is nearly spherical.

Why our own code: the subdivisions are MeshLab's and VTK's; this module only runs them and measures.
"""

from __future__ import annotations

import contextlib
import io
import os

import numpy as np

from ..geometry_image.measure import normal_angles

__all__ = ["loop_meshlab", "catmull_clark_meshlab", "loop_vtk", "vertex_normals", "radial_error", "mesh_rows"]


@contextlib.contextmanager
def _quiet():
    """MeshLab prints a line per mesh on the C stdout; keep the study's output readable."""
    fd = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                yield
        finally:
            os.dup2(fd, 1)
            os.close(fd)


def _meshlab(V, F, filter_name, steps):
    import pymeshlab

    with _quiet():
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int32)))
        if steps > 0:
            if filter_name == "loop":
                ms.meshing_surface_subdivision_loop(iterations=int(steps), threshold=pymeshlab.PercentageValue(0.0))
            else:
                ms.meshing_surface_subdivision_catmull_clark(iterations=int(steps))
        m = ms.current_mesh()
        return np.array(m.vertex_matrix(), dtype=np.float64), np.array(m.face_matrix(), dtype=np.int64)


def loop_meshlab(V, F, steps: int):
    """Loop subdivision by MeshLab, ``steps`` times (every edge split: threshold 0).

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=1)
    >>> V, F = loop_meshlab(s.points, s.faces.reshape(-1, 4)[:, 1:], 1)
    >>> len(F)
    320
    """
    return _meshlab(V, F, "loop", steps)


def catmull_clark_meshlab(V, F, steps: int):
    """Catmull-Clark subdivision by MeshLab, ``steps`` times, triangulated.

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=1)
    >>> V, F = catmull_clark_meshlab(s.points, s.faces.reshape(-1, 4)[:, 1:], 1)
    >>> len(F)  # 80 triangles -> 240 quads -> 480 triangles
    480
    """
    return _meshlab(V, F, "catmull_clark", steps)


def loop_vtk(V, F, steps: int):
    """Loop subdivision by VTK's ``vtkLoopSubdivisionFilter``.

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=1)
    >>> V, F = loop_vtk(s.points, s.faces.reshape(-1, 4)[:, 1:], 2)
    >>> len(F)
    1280
    """
    import pyvista as pv

    mesh = pv.PolyData(np.asarray(V, dtype=np.float64), faces=pv.CellArray.from_regular_cells(np.asarray(F)))
    if steps > 0:
        mesh = mesh.subdivide(int(steps), subfilter="loop")
    return np.asarray(mesh.points, dtype=np.float64), mesh.faces.reshape(-1, 4)[:, 1:].astype(np.int64)


def vertex_normals(V, F) -> np.ndarray:
    """Unit vertex normals averaged from the triangles, as VTK computes them for shading.

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=2)
    >>> n = vertex_normals(s.points, s.faces.reshape(-1, 4)[:, 1:])
    >>> bool(np.abs(np.einsum("ij,ij->i", n, s.points) - 1).max() < 0.01)  # outward, nearly radial
    True
    """
    import pyvista as pv

    mesh = pv.PolyData(np.asarray(V, dtype=np.float64), faces=pv.CellArray.from_regular_cells(np.asarray(F)))
    mesh = mesh.compute_normals(cell_normals=False, point_normals=True, split_vertices=False, consistent_normals=False,
                                auto_orient_normals=False)
    return np.asarray(mesh.point_data["Normals"], dtype=np.float64)


def _drawn_points(V, F):
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    e = np.unique(np.sort(e, axis=1), axis=0)
    return np.vstack([V, 0.5 * (V[e[:, 0]] + V[e[:, 1]]), V[F].mean(axis=1)])


def radial_error(points, rho) -> np.ndarray:
    """``| |x| - rho(x / |x|) |`` for a star-shaped surface ``rho(d) d`` (module docstring).

    >>> radial_error([[0.0, 0.0, 2.0]], lambda d: np.ones(len(d))).tolist()
    [1.0]
    """
    X = np.asarray(points, dtype=np.float64)
    r = np.linalg.norm(X, axis=1)
    return np.abs(r - rho(X / r[:, None]))


def mesh_rows(V, F, N, rho, exact_normals, diagonal) -> dict:
    """The row of one drawn mesh: triangles, distance of its drawn points to the exact star-shaped surface (max
    and RMS, in units of ``diagonal``) and its vertex normals' angle to the exact normals (degrees, max and RMS).

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> s = sphere_mesh(level=2)
    >>> F = s.faces.reshape(-1, 4)[:, 1:]
    >>> row = mesh_rows(s.points, F, vertex_normals(s.points, F), lambda d: np.ones(len(d)), lambda x: x, 1.0)
    >>> row["triangles"], bool(0 < row["distance_max"] < 0.02), bool(row["normal_max_deg"] < 3)
    (320, True, True)
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    d = radial_error(_drawn_points(V, F), rho) / float(diagonal)
    angle = normal_angles(N, exact_normals(V))
    return {"triangles": int(len(F)), "distance_max": float(d.max()), "distance_rms": float(np.sqrt((d ** 2).mean())),
            "normal_max_deg": angle["max"], "normal_rms_deg": angle["rms"]}
