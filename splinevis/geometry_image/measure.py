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

__all__ = ["surface_distance", "normal_angles"]


def _samples(V, F):
    return np.vstack([V, V[F].mean(axis=1)])


def surface_distance(V, F, V_ref, F_ref) -> dict:
    """Two-sided distance between the triangle meshes ``(V, F)`` and ``(V_ref, F_ref)`` in units of the reference's
    bounding-box diagonal (module docstring).

    Returns
    -------
    dict
        ``hausdorff`` (symmetric), ``to_reference`` (largest distance of ``(V, F)``'s samples to the reference),
        ``from_reference`` (the other way), ``rms`` (both sample sets), ``diagonal`` (the unit).

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
    a = np.sqrt(igl.point_mesh_squared_distance(_samples(V, F), V_ref, F_ref)[0]) / diagonal
    b = np.sqrt(igl.point_mesh_squared_distance(_samples(V_ref, F_ref), V, F)[0]) / diagonal
    both = np.concatenate([a, b])
    return {"hausdorff": float(max(a.max(), b.max())), "to_reference": float(a.max()),
            "from_reference": float(b.max()), "rms": float(np.sqrt((both ** 2).mean())), "diagonal": diagonal}


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
