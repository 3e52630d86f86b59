"""How far two triangulated surfaces are apart, and how far normals are from exact ones: the numbers the
geometry-image study and tests report [Losasso2003, sec. 4 reports none; these are the usual metrics].

Distances are measured both ways between point samples of one surface (its vertices and triangle centroids) and
the triangles of the other (libigl's exact point-triangle distance on an AABB tree), in units of the reference
mesh's bounding-box diagonal: the symmetric Hausdorff distance is the larger of the two one-sided maxima, the RMS is
over both sample sets. A smooth surface enters as a dense triangulation of its limit points; its chord error (the
distance from the triangles to the surface) then adds to what is measured, so the surface should be sampled a few
levels finer than the mesh it is compared with.

Why our own code: the point-to-triangle distances are libigl's; this module only fixes the sampling and units.
"""

from __future__ import annotations

import numpy as np

__all__ = ["surface_distance", "normal_angles", "reversed_normals", "defect_points", "folded_triangles"]


def _samples(V, F):
    return np.vstack([V, V[F].mean(axis=1)])


def surface_distance(V, F, V_ref, F_ref, *, closest: bool = False) -> dict:
    """Two-sided distance between the triangle meshes ``(V, F)`` and ``(V_ref, F_ref)`` in units of the reference's
    bounding-box diagonal (module docstring).

    Returns
    -------
    dict
        ``hausdorff`` (symmetric), ``to_reference`` (largest distance of ``(V, F)``'s samples to the reference),
        ``from_reference`` (the other way), ``rms`` (both sample sets), ``diagonal`` (the unit); with
        ``closest``, also ``closest_face``: the reference triangle nearest to each vertex of ``(V, F)``.

    Examples
    --------
    >>> V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]); F = np.array([[0, 1, 2]])
    >>> d = surface_distance(V + [0, 0, 0.1], F, V, F)
    >>> round(d["hausdorff"] * d["diagonal"], 12), round(d["rms"] * d["diagonal"], 12)
    (0.1, 0.1)
    """
    import igl

    V = np.ascontiguousarray(V, dtype=np.float64)
    V_ref = np.ascontiguousarray(V_ref, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    F_ref = np.ascontiguousarray(F_ref, dtype=np.int64)
    diagonal = float(np.linalg.norm(V_ref.max(axis=0) - V_ref.min(axis=0)))
    if not diagonal > 0:
        raise ValueError("the reference mesh has a zero bounding box: nothing to measure distances in.")
    d2, face, _ = igl.point_mesh_squared_distance(_samples(V, F), V_ref, F_ref)
    a = np.sqrt(d2) / diagonal
    b = np.sqrt(igl.point_mesh_squared_distance(_samples(V_ref, F_ref), V, F)[0]) / diagonal
    both = np.concatenate([a, b])
    out = {"hausdorff": float(max(a.max(), b.max())), "to_reference": float(a.max()),
           "from_reference": float(b.max()), "rms": float(np.sqrt((both ** 2).mean())), "diagonal": diagonal}
    if closest:
        out["closest_face"] = np.asarray(face[:len(V)], dtype=np.int64)
    return out


def _reference_folds(V_ref, F_ref):
    """The reference triangles' unit normals and which of them fold themselves (a neighbour facing more than 120
    degrees away): where the closest triangle's normal judges nothing."""
    import igl

    V_ref = np.asarray(V_ref, dtype=np.float64)
    F_ref = np.asarray(F_ref, dtype=np.int64)
    face_normal = np.cross(V_ref[F_ref[:, 1]] - V_ref[F_ref[:, 0]], V_ref[F_ref[:, 2]] - V_ref[F_ref[:, 0]])
    face_normal /= np.maximum(np.linalg.norm(face_normal, axis=1, keepdims=True), 1e-300)
    adjacent, _ = igl.triangle_triangle_adjacency(F_ref)
    folds_itself = (np.einsum("ij,ikj->ik", face_normal, face_normal[np.maximum(adjacent, 0)]) < -0.5).any(axis=1)
    return face_normal, folds_itself


def reversed_normals(normals, closest_face, V_ref, F_ref) -> dict:
    """Points of a smooth surface whose unit ``normals`` are more than 120 degrees from the outward normal of the
    reference triangle closest to them (``closest_face``), where the reference itself does not fold (no
    neighbour of that triangle faces more than 120 degrees away from it): the surface is inside out there
    (:mod:`.judge` module docstring). Returns ``reversed_points``, ``reversed_fraction`` (of the points judged),
    ``reversed_grid_points`` (judged) and ``input_folded_faces``.

    >>> V = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])  # a regular tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])  # outward: face 0 faces (1, 1, -1)
    >>> r = reversed_normals([[1.0, 1, -1], [-1.0, -1, 1]], np.array([0, 0]), V, F)
    >>> r["reversed_points"], r["reversed_fraction"], r["input_folded_faces"]
    (1, 0.5, 0)
    """
    face_normal, folds_itself = _reference_folds(V_ref, F_ref)
    N = np.asarray(normals, dtype=np.float64)
    judged = ~folds_itself[closest_face]
    against = judged & (np.einsum("ij,ij->i", N, face_normal[closest_face]) < -0.5)
    return {"reversed_points": int(against.sum()), "reversed_fraction": float(against.sum() / max(judged.sum(), 1)),
            "reversed_grid_points": int(judged.sum()), "input_folded_faces": int(folds_itself.sum())}


def normal_angles(normals, exact) -> dict:
    """Angles in degrees between ``normals`` and ``exact`` normals (both ``(n, 3)``, any length): ``max``,
    ``rms`` and ``p99``.

    >>> normal_angles([[0, 0, 1.0], [0, 1.0, 1.0]], [[0, 0, 2.0], [0, 0, 1.0]])["max"]
    45.0
    """
    a = np.asarray(normals, dtype=np.float64)
    b = np.asarray(exact, dtype=np.float64)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0)))
    return {"max": float(round(angle.max(), 12)), "rms": float(np.sqrt((angle ** 2).mean())),
            "p99": float(np.percentile(angle, 99))}


def folded_triangles(points, normals, faces) -> np.ndarray:
    """Which triangles ``faces`` of a surface given as ``points`` with unit ``normals`` face against the sum of
    their corners' normals (their orientation ``(b - a) x (c - a)`` against it): where it folds over. The test of
    :func:`splinevis.geometry_image.build.folded_fraction` and :func:`defect_points`.

    >>> P = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]); up = np.tile([0.0, 0, 1], (3, 1))
    >>> F = np.array([[0, 1, 2]])
    >>> folded_triangles(P, up, F).tolist(), folded_triangles(P, -up, F).tolist()
    ([False], [True])
    """
    P, N, F = (np.asarray(a) for a in (points, normals, faces))
    orient = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    return np.einsum("ij,ij->i", orient, N[F].sum(axis=1)) < 0.0


def defect_points(points, normals, faces, V_ref, F_ref) -> dict:
    """Where a smooth surface, given as limit ``points`` with unit ``normals`` and the triangles ``faces`` between
    them, folds and is inside out against the reference mesh ``(V_ref, F_ref)``: ``folded``, the centroids of the
    triangles facing against the sum of their corners' normals (the test of
    :func:`splinevis.geometry_image.build.folded_fraction`), and ``inside_out``, the points whose normal is more
    than 120 degrees from the closest reference triangle's where the reference does not fold itself
    (:func:`reversed_normals`). For pictures: the study's real meshes show them on the input.

    >>> V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])  # a unit square facing +z
    >>> F = np.array([[0, 1, 2], [0, 2, 3]])
    >>> up = np.tile([0.0, 0.0, 1.0], (4, 1))
    >>> d = defect_points(V, up, F, V, F)
    >>> len(d["folded"]), len(d["inside_out"])
    (0, 0)
    >>> d = defect_points(V, -up, F, V, F)  # every normal turned over
    >>> len(d["folded"]), len(d["inside_out"]), d["folded"][0].round(3).tolist()
    (2, 4, [0.667, 0.333, 0.0])
    """
    import igl

    P = np.ascontiguousarray(points, dtype=np.float64)
    N = np.asarray(normals, dtype=np.float64)
    F = np.asarray(faces, dtype=np.int64)
    V_ref = np.ascontiguousarray(V_ref, dtype=np.float64)
    F_ref = np.ascontiguousarray(F_ref, dtype=np.int64)
    folded = folded_triangles(P, N, F)
    _, closest, _ = igl.point_mesh_squared_distance(P, V_ref, F_ref)
    face_normal, folds_itself = _reference_folds(V_ref, F_ref)
    closest = np.asarray(closest, dtype=np.int64)
    against = ~folds_itself[closest] & (np.einsum("ij,ij->i", N, face_normal[closest]) < -0.5)
    return {"folded": P[F[folded]].mean(axis=1), "inside_out": P[against]}
