"""Is a triangle mesh a closed, connected, oriented 2-manifold of genus 0, the input a spherical
parametrization needs [Losasso2003, sec. 3]? Each check that fails says which it is and where.

The checks, in order (the first failure is raised, as :class:`splinevis.errors.MeshTopologyError`):

1. **triangles**: every cell is a triangle with three distinct vertices and non-zero area;
2. **manifold edges**: every edge is in exactly two triangles (one: a border, the mesh is not closed; three or
   more: a non-manifold edge), used once in each direction (else the orientation flips across it);
   **manifold vertices**: the triangles around each vertex form one fan (two fans meeting only at a vertex, a
   pinched vertex, would pass the edge test and give a wrong Euler characteristic);
3. **one component**: the triangles form one connected piece;
4. **genus 0**: the Euler characteristic ``V - E + F`` is 2 (genus ``g = (2 - chi) / 2``);
5. **outward**: the enclosed signed volume is positive (else every triangle is flipped).

Why our own code: the checks are a few array operations on the edge list (scipy's connected components); no kept
library reports them with locations for this purpose.
"""

from __future__ import annotations

import numpy as np

from ..errors import MeshTopologyError

__all__ = ["check_genus0"]


def _faces(mesh) -> tuple:
    points = np.asarray(mesh.points, dtype=np.float64)
    faces = np.asarray(mesh.faces)
    if faces.size == 0:
        raise MeshTopologyError("triangles", "the mesh has no faces.")
    sizes, k, tri = [], 0, []
    while k < faces.size:
        n = int(faces[k])
        sizes.append(n)
        tri.append(faces[k + 1:k + 1 + n])
        k += n + 1
    sizes = np.asarray(sizes)
    if (sizes != 3).any():
        c = int(np.flatnonzero(sizes != 3)[0])
        raise MeshTopologyError("triangles", f"cell {c} has {sizes[c]} vertices; triangulate the mesh first "
                                "(pyvista: mesh.triangulate()).")
    return points, np.asarray(tri, dtype=np.int64)


def _check_vertex_fans(tri, inv, directed, points, name):
    """Every vertex's triangles must form one fan: corners of one vertex are joined where their triangles share
    an edge at it; more than one group of corners is a pinched (non-manifold) vertex."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    F = len(tri)
    order = np.argsort(inv, kind="stable")  # each edge's two directed rows (every edge is in two triangles here)
    r1, r2 = order[0::2], order[1::2]
    t1, j1, t2, j2 = r1 % F, r1 // F, r2 % F, r2 // F
    # row r runs corner j to corner j+1 of triangle r % F (j = r // F); the other triangle runs the edge backwards
    a = np.concatenate([3 * t1 + j1, 3 * t1 + (j1 + 1) % 3])
    b = np.concatenate([3 * t2 + (j2 + 1) % 3, 3 * t2 + j2])
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(3 * F, 3 * F))
    _, label = connected_components(graph, directed=False)
    pairs = np.unique(np.column_stack([tri.ravel(), label]), axis=0)
    fans = np.bincount(pairs[:, 0], minlength=len(points))
    pinched = np.flatnonzero(fans > 1)
    if pinched.size:
        v = int(pinched[0])
        raise MeshTopologyError("manifold vertices", f"{name} is not a 2-manifold at {pinched.size} vertex(es) like "
                                f"vertex {v} {points[v].round(6).tolist()}, where {int(fans[v])} separate fans of "
                                "triangles meet (a pinched vertex); split the vertex, one copy per fan, or remove "
                                "the extra fans.")


def check_genus0(mesh, name: str = "mesh") -> dict:
    """Check ``mesh`` (a pyvista.PolyData) and return ``{"vertices", "edges", "triangles", "genus", "volume"}``;
    raise :class:`~splinevis.errors.MeshTopologyError` naming the failed check and where (module docstring).

    >>> from datasets_synthetic.closed_meshes import sphere_mesh, torus_mesh
    >>> check_genus0(sphere_mesh(level=1))["genus"]
    0
    >>> check_genus0(torus_mesh(n=8), "torus")
    Traceback (most recent call last):
    splinevis.errors.MeshTopologyError: genus 0: torus has genus 1 (V - E + F = 32 - 96 + 64 = 0); a spherical parametrization needs genus 0: cut the handles or use a genus-0 part.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    points, tri = _faces(mesh)
    same = (tri[:, 0] == tri[:, 1]) | (tri[:, 1] == tri[:, 2]) | (tri[:, 2] == tri[:, 0])
    area = 0.5 * np.linalg.norm(np.cross(points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]]),
                                axis=1)
    scale = float(np.ptp(points, axis=0).max()) if len(points) else 1.0
    bad = np.flatnonzero(same | (area <= 1e-14 * scale * scale))
    if bad.size:
        t = int(bad[0])
        raise MeshTopologyError("triangles", f"{name}: triangle {t} (vertices {tri[t].tolist()}) has no area "
                                f"({bad.size} such); remove degenerate triangles (pyvista: mesh.clean()).")
    directed = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    edges, inv, count = np.unique(undirected, axis=0, return_inverse=True, return_counts=True)
    for wrong, what, todo in ((count == 1, "a border edge (in one triangle)", "close the holes"),
                              (count > 2, "a non-manifold edge (in {n} triangles)", "split the mesh there")):
        if wrong.any():
            e = int(np.flatnonzero(wrong)[0])
            a, b = edges[e]
            raise MeshTopologyError("manifold edges", f"{name} is not a closed 2-manifold: {int(wrong.sum())} edges "
                                    f"like {what.format(n=int(count[e]))} between vertices {a} {points[a].round(6).tolist()} "
                                    f"and {b} {points[b].round(6).tolist()}; {todo}.")
    forward = directed[:, 0] < directed[:, 1]
    n_forward = np.bincount(inv.ravel(), weights=forward, minlength=len(edges))
    if (n_forward != 1).any():
        e = int(np.flatnonzero(n_forward != 1)[0])
        a, b = edges[e]
        raise MeshTopologyError("manifold edges", f"{name}: the orientation flips across the edge between vertices "
                                f"{a} and {b} (both triangles run it the same way); orient the triangles consistently "
                                "(pyvista: mesh.compute_normals(auto_orient_normals=True)).")
    F = len(tri)
    _check_vertex_fans(tri, inv.ravel(), directed, points, name)
    # triangles and edges as one graph: triangle t (row r % F of the directed edges) joined to its edges
    adj = coo_matrix((np.ones(F * 3), (np.tile(np.arange(F), 3), F + inv.ravel())), shape=(F + len(edges),) * 2)
    n_comp, labels = connected_components(adj, directed=False)
    comp = np.bincount(labels[:F])
    comp = comp[comp > 0]
    if comp.size > 1:
        raise MeshTopologyError("one component", f"{name} has {comp.size} separate pieces of "
                                f"{', '.join(str(int(c)) for c in sorted(comp, reverse=True))} triangles; give one closed "
                                "surface (pyvista: mesh.connectivity('largest')).")
    used = np.unique(tri)
    chi = used.size - len(edges) + F
    genus = (2 - chi) // 2
    if chi != 2:
        raise MeshTopologyError("genus 0", f"{name} has genus {genus} (V - E + F = {used.size} - {len(edges)} + {F} "
                                f"= {chi}); a spherical parametrization needs genus 0: cut the handles or use a genus-0 "
                                "part.")
    P = points[tri]
    volume = float(np.einsum("ij,ij->i", P[:, 0], np.cross(P[:, 1], P[:, 2])).sum() / 6.0)
    if volume <= 0:
        raise MeshTopologyError("outward", f"{name}: the triangles face inward (enclosed volume {volume:.6g}); flip "
                                "them (pyvista: mesh.flip_faces()).")
    return {"vertices": int(used.size), "edges": int(len(edges)), "triangles": int(F), "genus": 0, "volume": volume}
