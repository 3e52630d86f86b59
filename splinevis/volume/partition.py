"""The type-6 tetrahedral partition of the unit cube ``[0, 1]^3`` (local cube coordinates).

Each cube Q with centre ``vQ = (1/2, 1/2, 1/2)`` is split into 6 pyramids (apex vQ, base a face F of Q)
and each pyramid into 4 tetrahedra ``[vQ, wF, u, u']`` with ``wF`` the centre of F and ``u, u'`` the two
ends of one edge of F: 24 tetrahedra in all [Nuernberger2005; Kalbe2008, sec. 3, Fig. 3].

Fixed order and orientation
---------------------------
Tetrahedron ``t = 4 f + k`` belongs to face ``f`` and edge ``k`` of that face:

* faces ``f = 0..5`` in the order -x, +x, -y, +y, -z, +z (axis ``a = f // 2``, side ``s = f % 2``);
* on face f let ``(b, c) = ((a + 1) % 3, (a + 2) % 3)`` be the two in-face axes. The corners of F in
  cyclic order are ``(x_b, x_c) = (0, 0), (1, 0), (1, 1), (0, 1)`` on the + faces and the reverse cycle
  ``(0, 0), (0, 1), (1, 1), (1, 0)`` on the - faces; edge ``k`` joins corner ``k`` (= ``u``) to corner
  ``k + 1 mod 4`` (= ``u'``).
* With this choice every tetrahedron ``[vQ, wF, u, u']`` is positively oriented:
  ``det[wF - vQ, u - vQ, u' - vQ] = +1/4`` (volume 1/24).

Barycentric coordinates ``(lam_0, lam_1, lam_2, lam_3)`` refer to ``(vQ, wF, u, u')`` in this order, the
order of the BB multi-indices of :mod:`splinevis.bb.simplex` with d = 3.
"""

from __future__ import annotations

import functools

import numpy as np

from .._validation import as_float64_array

__all__ = ["NUM_TETS", "type6_tetrahedra", "face_of_tet", "barycentric_matrices", "barycentric", "locate"]

#: Number of tetrahedra of the type-6 split of one cube.
NUM_TETS = 24


@functools.lru_cache(maxsize=None)
def _tets() -> np.ndarray:
    out = np.empty((NUM_TETS, 4, 3))
    for f in range(6):
        a, s = divmod(f, 2)
        b, c = (a + 1) % 3, (a + 2) % 3
        cyc = [(0, 0), (1, 0), (1, 1), (0, 1)] if s == 1 else [(0, 0), (0, 1), (1, 1), (1, 0)]
        centre = np.full(3, 0.5)
        wf = centre.copy()
        wf[a] = float(s)
        for k in range(4):
            u = np.zeros(3)
            v = np.zeros(3)
            u[a] = v[a] = float(s)
            u[b], u[c] = cyc[k]
            v[b], v[c] = cyc[(k + 1) % 4]
            out[4 * f + k] = [centre, wf, u, v]
    out.setflags(write=False)
    return out


@functools.lru_cache(maxsize=None)
def _inner_faces():
    """The 36 faces shared by two tetrahedra of one cube: ``[(t, s, (3, 3) shared vertices), ...]``, t < s."""
    v = _tets()
    out = []
    for t in range(NUM_TETS):
        for s in range(t + 1, NUM_TETS):
            shared = [w for w in v[t] if any(np.array_equal(w, z) for z in v[s])]
            if len(shared) == 3:
                out.append((t, s, np.array(shared)))
    return out


def type6_tetrahedra() -> np.ndarray:
    """Vertices of the 24 tetrahedra, shape ``(24, 4, 3)``: ``[vQ, wF, u, u']`` in the documented order.

    Examples
    --------
    >>> type6_tetrahedra()[0]  # the cube centre, the centre of face 0 (x = 0), an edge of that face
    array([[0.5, 0.5, 0.5],
           [0. , 0.5, 0.5],
           [0. , 0. , 0. ],
           [0. , 0. , 1. ]])
    """
    return _tets().copy()


def face_of_tet(t: int) -> tuple[int, int]:
    """``(face f, edge k)`` of tetrahedron ``t = 4 f + k``.

    Examples
    --------
    >>> face_of_tet(5), face_of_tet(23)
    ((1, 1), (5, 3))
    """
    return divmod(int(t), 4)


@functools.lru_cache(maxsize=None)
def _bary_mats() -> np.ndarray:
    v = _tets()
    m = np.concatenate([v, np.ones((NUM_TETS, 4, 1))], axis=2)  # rows (x, y, z, 1) per vertex
    inv = np.linalg.inv(np.swapaxes(m, 1, 2))  # lam = inv @ (x, y, z, 1)
    # the entries are integers (vertices at 0, 1/2, 1): snap away the LAPACK kernel's rounding, so every machine
    # gets the same bits (and no negative zeros)
    inv = np.round(inv) + 0.0
    inv.setflags(write=False)
    return inv


def barycentric_matrices() -> np.ndarray:
    """``(24, 4, 4)`` matrices ``B_t`` with ``lam = B_t @ (x, y, z, 1)``; column j < 3 of ``B_t`` is the
    gradient of the barycentric coordinates w.r.t. local coordinate j.

    Examples
    --------
    >>> B = barycentric_matrices()
    >>> B.shape, B[0] @ [0.5, 0.5, 0.5, 1.0]  # the cube centre is vertex vQ of every tetrahedron
    ((24, 4, 4), array([1., 0., 0., 0.]))
    """
    return _bary_mats().copy()


def _bary(t, p):
    b = _bary_mats()[t]  # (..., 4, 4)
    return np.einsum("...ij,...j->...i", b[..., :3], p) + b[..., 3]


def barycentric(t, p) -> np.ndarray:
    """Barycentric coordinates of local points ``p`` (..., 3) w.r.t. tetrahedra ``t`` (int array, broadcast).

    Examples
    --------
    >>> barycentric(0, [[0.0, 0.5, 0.5], [0.25, 0.375, 0.5]])  # the face centre wF; an interior point
    array([[0.   , 1.   , 0.   , 0.   ],
           [0.5  , 0.25 , 0.125, 0.125]])
    """
    p = as_float64_array(p, "p (local cube coordinates)", shape_tail=(3,))
    t = np.asarray(t)
    if not np.issubdtype(t.dtype, np.integer) or (t.size and (t.min() < 0 or t.max() >= NUM_TETS)):
        raise ValueError(f"t must hold integer tetrahedron indices in 0..{NUM_TETS - 1}.")
    return _bary(t, p)


def _locate(p):
    lam_all = np.einsum("tij,...j->...ti", _bary_mats()[:, :, :3], p) + _bary_mats()[:, :, 3]
    t = np.argmax(lam_all.min(axis=-1), axis=-1)
    lam = np.take_along_axis(lam_all, t[..., None, None], axis=-2)[..., 0, :]
    return t, lam


def locate(p, *, tol: float = 1e-12):
    """Tetrahedron containing each local point and its barycentric coordinates (vectorized).

    Parameters
    ----------
    p : (..., 3) array_like
        Points in local cube coordinates, inside ``[0, 1]^3`` up to ``tol``.
    tol : float
        Allowed distance outside the unit cube.

    Returns
    -------
    t : (...) int64 ndarray
        Tetrahedron index (the one maximizing the smallest barycentric coordinate, so points on shared
        faces go to one of the tetrahedra sharing them, deterministically).
    lam : (..., 4) ndarray
        Barycentric coordinates w.r.t. ``[vQ, wF, u, u']`` of tetrahedron t; they sum to 1 and
        reproduce ``p``.

    Examples
    --------
    >>> t, lam = locate([[0.5, 0.5, 0.5], [0.9, 0.5, 0.5], [0.1, 0.2, 0.3]])
    >>> t
    array([0, 4, 0])
    >>> lam
    array([[1. , 0. , 0. , 0. ],
           [0.2, 0.8, 0. , 0. ],
           [0.2, 0.2, 0.5, 0.1]])
    >>> locate([1.5, 0.0, 0.0])
    Traceback (most recent call last):
    ValueError: p must lie in the unit cube [0, 1]^3 (local cube coordinates); the point at index () is [1.5, 0.0, 0.0].
    """
    p = as_float64_array(p, "p (local cube coordinates)", shape_tail=(3,))
    out = (p < -tol) | (p > 1 + tol)
    if out.any():
        idx = tuple(int(i) for i in np.argwhere(out.any(axis=-1))[0]) if p.ndim > 1 else ()
        raise ValueError(f"p must lie in the unit cube [0, 1]^3 (local cube coordinates); the point at index {idx} "
                         f"is {p[idx].tolist()}.")
    return _locate(p)
