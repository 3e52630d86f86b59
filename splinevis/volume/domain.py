"""Bernstein-Bezier domain points of degree n on one type-6 cube, and the C1 conditions across the 36
inner faces of its split in blossom form: the tables both volume schemes (degree 2 and 3) derive from.

A cube is in local coordinates ``[0, 1]^3``; its 24 tetrahedra are those of
:mod:`splinevis.volume.partition`, whose vertices are multiples of 1/2, so the domain points of degree n
are multiples of ``1/(2n)`` and are keyed by the integer vector ``2n * point``.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from ..bb import simplex as bb
from .partition import NUM_TETS, _bary_mats, _inner_faces, _tets

__all__ = ["domain_table", "domain_index", "inner_face_rows"]


@functools.lru_cache(maxsize=None)
def domain_table(n):
    """The distinct domain points of degree n of one cube.

    Parameters
    ----------
    n : int
        Polynomial degree (2 or 3 in this package).

    Returns
    -------
    points : (N, 3) float64 ndarray, read-only
        The distinct domain points (local coordinates) in order of first appearance over the tetrahedra
        and their BB coefficients; N = 65 for n = 2, 175 for n = 3.
    tet_map : (24, (n + 1)(n + 2)(n + 3) / 6) int64 ndarray, read-only
        For every tetrahedron and BB coefficient (:func:`splinevis.bb.simplex.multi_indices` ``(n, 3)``
        order), the index of its domain point.
    keys : dict
        ``2n * point`` (a tuple of ints) -> index.

    Examples
    --------
    >>> points, tet_map, keys = domain_table(2)
    >>> points.shape, tet_map.shape, points.flags.writeable, keys[(2, 2, 2)]  # the cube centre: index 0
    ((65, 3), (24, 10), False, 0)
    """
    v = _tets()
    mi = bb._multi_indices(n, 3)
    keys: dict = {}
    tmap = np.zeros((NUM_TETS, len(mi)), dtype=np.int64)
    for t in range(NUM_TETS):
        for q, a in enumerate(mi):
            k = tuple(int(x) for x in np.round(2 * (a @ v[t])))  # 2n * domain point (a @ v / n)
            keys.setdefault(k, len(keys))
            tmap[t, q] = keys[k]
    pts = np.array(sorted(keys, key=keys.get), dtype=np.float64) / (2 * n)
    pts.setflags(write=False)
    tmap.setflags(write=False)
    return pts, tmap, keys


def domain_index(n, x):
    """Index in :func:`domain_table` ``(n)`` of the domain point ``x`` (local coordinates, array_like (3,)).

    Examples
    --------
    >>> domain_index(2, [0.5, 0.5, 0.5]), domain_index(2, [0.0, 0.0, 0.0])  # the cube centre comes first
    (0, 7)
    >>> domain_table(2)[0][7]
    array([0., 0., 0.])
    """
    return domain_table(n)[2][tuple(int(v) for v in np.round(2 * n * np.asarray(x)))]


@functools.lru_cache(maxsize=None)
def inner_face_rows(n):
    """C1 conditions of degree-n splines across the 36 inner faces of the split of a cube.

    For tetrahedra ``t``, ``s`` sharing the face ``sh`` and the vertex ``e`` of ``s`` opposite to it, with
    barycentric coordinates ``lam`` of ``e`` w.r.t. ``t``, the blossom form of the C1 condition is
    ``c_s(e, b) = sum_i lam_i c_t(v_i, b)`` for every ``b``, a sum of ``n - 1`` vertices of ``sh``.

    Parameters
    ----------
    n : int
        Polynomial degree (2 or 3).

    Returns
    -------
    A : (36 * C(n + 1, 2), N) float64 ndarray, read-only
        ``A @ c = 0`` for the coefficients ``c`` (indexed like :func:`domain_table`) of a spline that is C1
        inside the cube; the rows of face ``m`` are consecutive, in ``itertools.combinations_with_replacement``
        order of ``b``.
    pairs : list of tuple of int
        ``pairs[m] = (t, s)``, the tetrahedra sharing face ``m``.

    Examples
    --------
    >>> A, pairs = inner_face_rows(3)  # 6 conditions per face of a cubic
    >>> A.shape, len(pairs), bool(np.allclose(A.sum(axis=1), 0.0))  # constants satisfy every condition
    ((216, 175), 36, True)
    """
    v = _tets()
    npts = len(domain_table(n)[0])
    rows, pairs = [], []
    for t, s, sh in _inner_faces():
        e = [w for w in v[s] if not any(np.array_equal(w, z) for z in sh)][0]
        lam = _bary_mats()[t][:, :3] @ e + _bary_mats()[t][:, 3]
        for combo in itertools.combinations_with_replacement(range(3), n - 1):
            b = sum(sh[i] for i in combo)
            r = np.zeros(npts)
            r[domain_index(n, (e + b) / n)] += 1.0
            for i in range(4):
                r[domain_index(n, (v[t][i] + b) / n)] -= lam[i]
            rows.append(r)
        pairs.append((t, s))
    A = np.array(rows)
    A.setflags(write=False)
    return A, pairs
