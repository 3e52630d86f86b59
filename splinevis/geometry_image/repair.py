"""Meshes as exported, put in the form a spherical parametrization needs [PraunHoppe2003]: one closed
triangle mesh with one vertex per position. Each repair is reported, none is silent:

* **read**: OBJ, PLY, STL, VTP, ... with pyvista; OFF with libigl (VTK has no OFF reader); point and line cells
  are ignored (counted);
* **unused points** (no face uses them) are dropped;
* **welding**: points closer than a tolerance become one vertex (VTK's OBJ reader gives every face corner its
  own point when the file has texture coordinates or normals, so the mesh arrives as a soup of separate faces;
  exporters that split normals write a position once per face). The tolerance is relative to the bounding
  box's diagonal ``D``, :data:`WELD_TOLERANCE` by default: a position written twice from one value differs by
  its storage rounding at most, ``2^-24`` of the coordinate for float32 (STL, PLY) and ``5e-7`` relative for
  the 7 significant digits common in ASCII files, so a few ``1e-7 D`` for coordinates of the box's size; while
  the shortest edge of a scan is rarely below ``1e-4 D`` (``1e-6 D`` would be a 10^6 x 10^6 vertex grid).
  Points chained within the tolerance form one vertex at the position of the cluster's first point in the file;
  the largest distance merged is reported. A face whose corners weld together (an edge shorter than the
  tolerance) is removed and counted. The vertices keep the file's order, so a mesh needing no repair keeps its
  numbering;
* **polygons** are triangulated, each into a fan whose diagonals are not edges of the mesh already (a fixed fan
  can make a closed quad mesh non-manifold: two quads sharing two sides, each cut along the same diagonal, make
  one triangle twice); among the fans that qualify, the one with the shortest diagonals;
* **orientation**: a closed mesh whose faces are consistently turned inward (negative enclosed volume; VTK's
  parametric surfaces come so) has every triangle turned over.

Why our own code: pyvista's ``clean`` merges by a tolerance and ``triangulate`` cuts fixed fans; neither says
what it changed, and a fixed fan breaks closed quad meshes (``beast.obj``).
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np

__all__ = ["prepare_mesh", "WELD_TOLERANCE"]

#: Default welding tolerance, relative to the bounding box's diagonal (module docstring).
WELD_TOLERANCE = 1e-6

_POLYGON_NAMES = {3: "triangles", 4: "quads", 5: "pentagons", 6: "hexagons"}


def _polygons_from_vtk(mesh):
    """``(points, offsets, connectivity, ignored)`` of a pyvista PolyData's polygons (triangle strips split into
    triangles); ``ignored`` counts its vertex and line cells."""
    import pyvista as pv
    from vtkmodules.util.numpy_support import vtk_to_numpy

    points = np.asarray(mesh.points, dtype=np.float64)
    polys = mesh.GetPolys()
    offsets = vtk_to_numpy(polys.GetOffsetsArray()).astype(np.int64)
    conn = vtk_to_numpy(polys.GetConnectivityArray()).astype(np.int64)
    if mesh.n_strips:
        tri = pv.PolyData(mesh.points, strips=mesh.strips).triangulate()
        t = np.asarray(tri.faces).reshape(-1, 4)[:, 1:].astype(np.int64)
        offsets = np.concatenate([offsets, offsets[-1] + 3 * np.arange(1, len(t) + 1)])
        conn = np.concatenate([conn, t.ravel()])
    return points, offsets, conn, int(mesh.n_verts + mesh.n_lines)


def _diagonal(points) -> float:
    return float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0


def _weld(points, tolerance: float):
    """``(vertices, rank, largest)``: one vertex per cluster of ``points`` chained closer than ``tolerance`` x
    the diagonal (module docstring), in the order of each cluster's first point; ``rank[i]`` is point ``i``'s
    vertex; ``largest`` the largest distance from a point to its vertex (0 when only exact copies merged)."""
    _, first, inverse = np.unique(points + 0.0, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    r = float(tolerance) * _diagonal(points)
    if r > 0 and len(first) > 1:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        from scipy.spatial import cKDTree

        distinct = points[first]
        pairs = cKDTree(distinct).query_pairs(r, output_type="ndarray")
        if len(pairs):
            graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(first),) * 2)
            _, label = connected_components(graph, directed=False)
            # every distinct position's cluster, represented by the cluster's first point in the file
            head = np.full(label.max() + 1, len(points), dtype=np.int64)
            np.minimum.at(head, label, first)
            first, cluster = np.unique(head[label], return_inverse=True)
            inverse = cluster.ravel()[inverse]
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(first), dtype=np.int64)
    rank[order] = np.arange(len(first))
    vertices = points[first[order]]
    largest = float(np.linalg.norm(points - vertices[rank[inverse]], axis=1).max()) if len(points) else 0.0
    return vertices, rank[inverse], largest


def _drop_collapsed(offsets, conn):
    """Polygons without the ones that have fewer than 3 distinct corners after welding: ``(offsets, conn,
    removed)``."""
    sizes = np.diff(offsets)
    keep = np.ones(len(sizes), dtype=bool)
    for k in np.unique(sizes).tolist():
        idx = np.flatnonzero(sizes == k)
        ring = np.sort(conn[offsets[idx][:, None] + np.arange(k)], axis=1)
        distinct = 1 + (np.diff(ring, axis=1) != 0).sum(axis=1)
        keep[idx[distinct < 3]] = False
    if keep.all():
        return offsets, conn, 0
    cell = np.repeat(np.arange(len(sizes)), sizes)
    conn = conn[keep[cell]]
    offsets = np.concatenate([[0], np.cumsum(sizes[keep])]).astype(np.int64)
    return offsets, conn, int((~keep).sum())


def _triangulate(points, offsets, conn):
    """Triangles ``(T, 3)`` of polygons given as VTK offsets and connectivity (module docstring: fans whose
    diagonals are not edges already, shortest first); also the polygon sizes."""
    sizes = np.diff(offsets)
    if sizes.size == 0:
        return np.zeros((0, 3), np.int64), sizes
    if (sizes == 3).all():
        return conn.reshape(-1, 3), sizes
    if (sizes < 3).any():
        c = int(np.flatnonzero(sizes < 3)[0])
        raise ValueError(f"polygon {c} has {int(sizes[c])} vertices; a face needs at least 3.")
    edges = set()
    for k in np.unique(sizes):
        ring = conn[offsets[:-1][sizes == k][:, None] + np.arange(k)]
        e = np.sort(np.stack([ring, np.roll(ring, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
        edges.update(map(tuple, e.tolist()))
    triangles = [conn[offsets[:-1][sizes == 3][:, None] + np.arange(3)]]
    for k in np.unique(sizes[sizes > 3]).tolist():
        ring = conn[offsets[:-1][sizes == k][:, None] + np.arange(k)]  # (polygons, k)
        j = np.arange(2, k - 1)
        # fan from corner s: diagonals (ring[s], ring[s + j]); its total diagonal length, (polygons, k)
        length = np.stack([np.linalg.norm(points[ring[:, (s + j) % k]] - points[ring[:, [s]]], axis=-1).sum(axis=1)
                           for s in range(k)], axis=1)
        order = np.argsort(length, axis=1, kind="stable")
        chosen = np.empty(len(ring), dtype=np.int64)
        for i, (r, starts) in enumerate(zip(ring.tolist(), order.tolist())):
            for s in starts:
                diagonals = [(min(r[s], r[(s + jj) % k]), max(r[s], r[(s + jj) % k])) for jj in range(2, k - 1)]
                if not any(d in edges for d in diagonals):
                    break
            else:
                s = starts[0]  # every fan repeats an edge: the shortest (the topology check will say where)
                diagonals = [(min(r[s], r[(s + jj) % k]), max(r[s], r[(s + jj) % k])) for jj in range(2, k - 1)]
            edges.update(diagonals)
            chosen[i] = s
        fan = ring[np.arange(len(ring))[:, None], (chosen[:, None] + np.arange(k)) % k]  # rotated to start at s
        triangles.append(np.stack([np.repeat(fan[:, :1], k - 2, axis=1), fan[:, 1:-1], fan[:, 2:]],
                                  axis=-1).reshape(-1, 3))
    return np.concatenate(triangles).astype(np.int64), sizes


def prepare_mesh(mesh, name: str = "mesh", weld_tolerance: float = WELD_TOLERANCE) -> tuple:
    """``(PolyData, repairs)``: ``mesh`` (a pyvista DataSet or a file name) as one triangle mesh with one vertex
    per position, and a list of sentences saying what was changed (module docstring); empty when nothing was.
    ``weld_tolerance``: points closer than this share of the bounding box's diagonal become one vertex (0: only
    points at exactly the same position).

    >>> import pyvista as pv
    >>> soup = pv.PolyData(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]),
    ...                    faces=[3, 0, 1, 2, 3, 3, 5, 4])
    >>> m, repairs = prepare_mesh(soup, "two triangles")
    >>> m.n_points, repairs[0][:42]
    (4, 'welded 6 points into 4 vertices (points at')

    A closed mesh turned inside out is turned back:

    >>> inside_out = pv.Sphere(theta_resolution=6, phi_resolution=6).flip_faces()
    >>> prepare_mesh(inside_out, "sphere")[1][0][:34]
    'turned all 48 triangles over: they'
    """
    import pyvista as pv

    if not isinstance(mesh, pv.DataSet):
        path = Path(mesh)
        name = path.name if name == "mesh" else name
        if path.suffix.lower() == ".off":
            import igl

            V, F = igl.read_triangle_mesh(str(path))  # triangulates polygons itself (fans)
            F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
            mesh = pv.PolyData(np.asarray(V, dtype=np.float64), np.column_stack([np.full(len(F), 3), F]).ravel())
        else:
            mesh = pv.read(path)
    if not isinstance(mesh, pv.PolyData):
        mesh = mesh.extract_surface(algorithm=None)
    points, offsets, conn, ignored = _polygons_from_vtk(mesh)
    repairs = []
    if conn.size == 0:
        raise ValueError(f"{name} has no faces ({len(points)} points): a point cloud or lines are not a surface.")
    if ignored:
        repairs.append(f"ignored {ignored:,} point and line cells: only faces are drawn")
    if not np.isfinite(points).all():
        raise ValueError(f"{name}: {int((~np.isfinite(points)).any(axis=1).sum())} points have a NaN or infinite "
                         "coordinate.")
    used = np.unique(conn)
    if used.size < len(points):
        repairs.append(f"dropped {len(points) - used.size:,} of {len(points):,} points that no face uses")
    unique, rank, merged = _weld(points[used], weld_tolerance)
    remap = np.empty(len(points), dtype=np.int64)
    remap[used] = rank
    conn = remap[conn]
    if len(unique) < used.size:
        how = ("points at exactly the same position" if merged == 0 else
               f"points within {weld_tolerance:g} of the bounding box's diagonal; the largest distance merged is "
               f"{merged:.3g}, {merged / _diagonal(points[used]):.2g} of the diagonal")
        repairs.append(f"welded {used.size:,} points into {len(unique):,} vertices ({how}; VTK's reader gives each "
                       "face corner its own point when an OBJ file has texture coordinates or normals)")
    offsets, conn, collapsed = _drop_collapsed(offsets, conn)
    if collapsed:
        repairs.append(f"removed {collapsed:,} faces whose corners welded into fewer than 3 vertices (edges "
                       f"shorter than {weld_tolerance:g} of the diagonal)")
    tri, sizes = _triangulate(unique, offsets, conn)
    if (sizes != 3).any():
        count = Counter(sizes.tolist())
        what = ", ".join(f"{count[k]:,} {_POLYGON_NAMES.get(k, f'{k}-gons')}" for k in sorted(count) if k != 3)
        repairs.append(f"triangulated {int((sizes != 3).sum()):,} polygons ({what}) into {len(tri):,} triangles in "
                       "all (fans whose diagonals are not edges already)")
    if len(tri) and _closed(tri):
        P = unique[tri]
        volume = float(np.einsum("ij,ij->i", P[:, 0], np.cross(P[:, 1], P[:, 2])).sum() / 6.0)
        if volume < 0:  # closed and consistently turned inward (VTK's parametric ellipsoid): turn every face
            tri = tri[:, ::-1]
            repairs.append(f"turned all {len(tri):,} triangles over: they faced inward (enclosed volume {volume:.6g})")
    faces = np.column_stack([np.full(len(tri), 3, dtype=np.int64), tri]).ravel()
    return pv.PolyData(unique, faces), repairs


def _closed(tri) -> bool:
    """Whether every edge of the triangles ``tri`` is used once in each direction (closed, consistently oriented),
    the case where the sign of the enclosed volume says which way the faces point."""
    e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    fwd = np.unique(e, axis=0, return_counts=True)
    if (fwd[1] != 1).any():
        return False
    rev = np.unique(e[:, ::-1], axis=0)
    return fwd[0].shape == rev.shape and bool((fwd[0] == rev).all())
