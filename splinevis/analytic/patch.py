"""A single quartic Bernstein-Bezier triangle patch z = f(x, y): the analytic test surface.

It proves the core (program assembly, injection, ray casting, depth compositing, effects) before the
terrain program lands, and is exactly one terrain patch: the same restriction by blossoming
[Reis2008, eqs. (6)-(7)] and the same Newton iteration from secure starting points [Reis2008, sec. V].

The model is immutable float64 numpy and never imports VTK. :meth:`QuarticTrianglePatch.raycast` is the
float64 twin of ``glsl/programs/analytic_patch.glsl``, step for step; with ``method="reference"`` it
finds the first root with the robust all-roots finder instead of Newton, which is what tests compare
the GPU against.
"""

from __future__ import annotations

import numpy as np

from .._validation import as_float64_array, check_choice
from ..bb import simplex as _simplex
from ..bb.ray import graph_patch_first_hit
from ..gl.contract import RayHits

__all__ = ["QuarticTrianglePatch"]

DEGREE = 4


class QuarticTrianglePatch:
    """A quartic BB patch over a triangle in the xy-plane, as a graph surface.

    Parameters
    ----------
    coefficients : (15,) array_like
        BB coefficients (heights) in :func:`splinevis.bb.simplex.multi_indices` ``(4, 2)`` order.
    vertices : (3, 2) array_like
        The domain triangle's vertices (counter-clockwise or clockwise; must not be degenerate).

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> p = QuarticTrianglePatch(np.full(15, 2.0), [[0, 0], [1, 0], [0, 1]])
    >>> float(p.evaluate([0.25, 0.25]))
    2.0
    """

    def __init__(self, coefficients, vertices):
        c = as_float64_array(coefficients, "coefficients", ndim=1)
        n_expected = (DEGREE + 1) * (DEGREE + 2) // 2
        if c.shape != (n_expected,):
            raise ValueError(f"coefficients of a quartic triangle patch must have shape ({n_expected},), got {c.shape}.")
        v = as_float64_array(vertices, "vertices", ndim=2, shape_tail=(3, 2))
        if v.shape != (3, 2):
            raise ValueError(f"vertices must have shape (3, 2), got {v.shape}.")
        area2 = (v[1, 0] - v[0, 0]) * (v[2, 1] - v[0, 1]) - (v[2, 0] - v[0, 0]) * (v[1, 1] - v[0, 1])
        scale = np.ptp(v, axis=0).max()
        if not abs(area2) > 1e-12 * scale * scale:
            raise ValueError(f"vertices {v.tolist()} span a degenerate triangle (twice its area is {area2:g}).")
        self._c = c.copy()
        self._c.setflags(write=False)
        self._v = v.copy()
        self._v.setflags(write=False)
        # lam = M @ (x, y, 1)
        self._m = np.linalg.inv(np.vstack([v.T, np.ones(3)]))
        self._m.setflags(write=False)

    # -- data -----------------------------------------------------------------------------------------
    @property
    def coefficients(self) -> np.ndarray:
        """(15,) read-only BB coefficients (heights) in ``multi_indices(4, 2)`` order.

        Examples
        --------
        >>> p = QuarticTrianglePatch(np.arange(15.0), [[0, 0], [2, 0], [0, 2]])
        >>> p.coefficients[:4], p.coefficients.flags.writeable
        (array([0., 1., 2., 3.]), False)
        """
        return self._c

    @property
    def vertices(self) -> np.ndarray:
        """(3, 2) read-only vertices of the domain triangle.

        Examples
        --------
        >>> QuarticTrianglePatch(np.zeros(15), [[0, 0], [2, 0], [0, 2]]).vertices
        array([[0., 0.],
               [2., 0.],
               [0., 2.]])
        """
        return self._v

    @property
    def barycentric_matrix(self) -> np.ndarray:
        """(3, 3) M with barycentric coordinates ``M @ (x, y, 1)``.

        Examples
        --------
        >>> M = QuarticTrianglePatch(np.zeros(15), [[0, 0], [2, 0], [0, 2]]).barycentric_matrix
        >>> M
        array([[-0.5, -0.5,  1. ],
               [ 0.5,  0. ,  0. ],
               [ 0. ,  0.5,  0. ]])
        >>> M @ [1.0, 1.0, 1.0]  # the point (1, 1): midway between the second and third vertex
        array([0. , 0.5, 0.5])
        """
        return self._m

    @property
    def zrange(self) -> tuple:
        """(min, max) coefficient: the surface lies in this slab (convex-hull property).

        Examples
        --------
        >>> QuarticTrianglePatch(np.arange(15.0), [[0, 0], [2, 0], [0, 2]]).zrange
        (0.0, 14.0)
        """
        return float(self._c.min()), float(self._c.max())

    @classmethod
    def from_function(cls, func, vertices) -> "QuarticTrianglePatch":
        """The patch interpolating ``func(x, y)`` at the 15 domain points (quartic interpolation).

        Examples
        --------
        Polynomials of degree <= 4 are reproduced:

        >>> p = QuarticTrianglePatch.from_function(lambda x, y: x * y, [[0, 0], [1, 0], [0, 1]])
        >>> round(float(p.evaluate([0.25, 0.5])), 12)
        0.125
        """
        v = as_float64_array(vertices, "vertices", ndim=2, shape_tail=(3, 2))
        idx = _simplex.multi_indices(DEGREE, 2)
        pts = (idx / DEGREE) @ v  # domain points
        b = _simplex.bernstein_basis(DEGREE, 2, idx / DEGREE)  # (15 points, 15 basis)
        values = np.asarray(func(pts[:, 0], pts[:, 1]), dtype=np.float64)
        return cls(np.linalg.solve(b, values), v)

    @classmethod
    def demo(cls) -> "QuarticTrianglePatch":
        """A saddle-and-bump patch over the triangle (-1, -1), (1.2, -0.9), (-0.2, 1.1).

        Examples
        --------
        >>> tuple(round(z, 12) for z in QuarticTrianglePatch.demo().zrange)  # its last bits follow the BLAS kernels
        (-0.216431851212, 1.077124019039)
        """
        return cls.from_function(
            lambda x, y: 0.35 * np.exp(-2.0 * (x * x + y * y)) + 0.15 * x * y - 0.05 * x * x * y * y,
            [[-1.0, -1.0], [1.2, -0.9], [-0.2, 1.1]],
        )

    # -- evaluation -----------------------------------------------------------------------------------
    def barycentric(self, xy) -> np.ndarray:
        """(…, 3) barycentric coordinates of points (…, 2) with respect to the domain triangle.

        Examples
        --------
        >>> p = QuarticTrianglePatch(np.zeros(15), [[0, 0], [2, 0], [0, 2]])
        >>> p.barycentric([[0, 0], [1, 1], [0.5, 0.5]])
        array([[1.  , 0.  , 0.  ],
               [0.  , 0.5 , 0.5 ],
               [0.5 , 0.25, 0.25]])
        """
        xy = as_float64_array(xy, "xy", shape_tail=(2,))
        return xy @ self._m[:, :2].T + self._m[:, 2]

    def evaluate(self, xy) -> np.ndarray:
        """f(x, y) for points (…, 2) (extrapolated outside the triangle).

        Examples
        --------
        >>> p = QuarticTrianglePatch.from_function(lambda x, y: x * x - y, [[0, 0], [1, 0], [0, 1]])
        >>> p.evaluate([[0.5, 0.25], [2.0, 0.0]]).round(12)  # the second point lies outside
        array([0., 4.])
        """
        return _simplex.de_casteljau(self._c, self.barycentric(xy), d=2)

    def gradient(self, xy) -> np.ndarray:
        """(…, 2) gradient (f_x, f_y) by the derivative patch along the Cartesian directions.

        Examples
        --------
        >>> p = QuarticTrianglePatch.from_function(lambda x, y: x * y, [[0, 0], [1, 0], [0, 1]])
        >>> p.gradient([0.25, 0.5]).round(12)  # (y, x)
        array([0.5 , 0.25])
        """
        lam = self.barycentric(xy)
        out = []
        for k in range(2):
            dc = _simplex.derivative(self._c, self._m[:, k], d=2)
            out.append(_simplex.de_casteljau(dc, lam, d=2))
        return np.stack(out, axis=-1)

    def triangulate(self, k: int):
        """The linear mesh users draw today: the triangle split into k*k sub-triangles, vertices on the
        surface. Returns (points (M, 3), triangles (k*k, 3)).

        Examples
        --------
        >>> p = QuarticTrianglePatch.from_function(lambda x, y: x * y, [[0, 0], [1, 0], [0, 1]])
        >>> points, triangles = p.triangulate(2)
        >>> points.shape, triangles.shape
        ((6, 3), (4, 3))
        >>> points[4].round(12)  # the midpoint of the long edge, on the surface z = x y
        array([0.5 , 0.5 , 0.25])
        """
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"k must be a positive integer (k*k triangles), got {k!r}.")
        k = int(k)
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        i, j = i[keep], j[keep]
        lam = np.stack([k - i - j, i, j], axis=-1) / k
        xy = lam @ self._v
        pts = np.c_[xy, _simplex.de_casteljau(self._c, lam, d=2)]
        index = -np.ones((k + 1, k + 1), dtype=np.int64)
        index[i, j] = np.arange(len(i))
        a, b = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
        up = a + b <= k - 1
        a1, b1 = a[up], b[up]
        tris = [np.stack([index[a1, b1], index[a1 + 1, b1], index[a1, b1 + 1]], axis=-1)]
        dn = a + b <= k - 2
        a2, b2 = a[dn], b[dn]
        tris.append(np.stack([index[a2 + 1, b2], index[a2 + 1, b2 + 1], index[a2, b2 + 1]], axis=-1))
        return pts, np.concatenate(tris)

    def proxy(self):
        """The prism over the triangle between the coefficient extremes: (6, 3) points, (8, 3) triangles
        oriented outward.

        Examples
        --------
        >>> points, triangles = QuarticTrianglePatch(np.arange(15.0), [[0, 0], [1, 0], [0, 1]]).proxy()
        >>> points[:, 2], triangles.shape
        (array([ 0.,  0.,  0., 14., 14., 14.]), (8, 3))
        """
        zlo, zhi = self.zrange
        if zhi - zlo < 1e-9 * max(1.0, abs(zhi)):
            pad = 1e-6 * max(1.0, abs(zhi))  # a flat patch still needs a prism with volume
            zlo, zhi = zlo - pad, zhi + pad
        v = self._v
        e1, e2 = v[1] - v[0], v[2] - v[0]
        if e1[0] * e2[1] - e1[1] * e2[0] < 0:
            v = v[[0, 2, 1]]
        pts = np.vstack([np.c_[v, np.full(3, zlo)], np.c_[v, np.full(3, zhi)]])
        tris = np.array([[0, 2, 1], [3, 4, 5],
                         [0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [2, 0, 3], [2, 3, 5]])
        return pts, tris

    # -- float64 twin of glsl/programs/analytic_patch.glsl ------------------------------------------------
    def raycast(self, origins, directions, tmin=0.0, *, method: str = "reference", iterations: int = 6) -> RayHits:
        """Intersect rays with the patch in float64.

        Parameters
        ----------
        origins, directions : (…, 3) array_like
            Rays ``o + t d``; directions need not be unit.
        tmin : float or (…) array_like
            Smallest admissible t (0 for perspective rays starting at the eye, -inf for parallel rays).
        method : {"reference", "bracketed", "paper"}
            ``"bracketed"`` mirrors the shader's default root finder (bracketed Newton on the convex pieces
            between the secure starting points, ``iterations`` steps); ``"paper"`` is the
            four-start Newton of [Reis2008, sec. V] (``SV_ROOTS_PAPER``); ``"reference"`` takes the first root from
            the robust all-roots finder.

        Returns
        -------
        RayHits

        Examples
        --------
        >>> p = QuarticTrianglePatch.from_function(lambda x, y: x * y, [[0, 0], [1, 0], [0, 1]])
        >>> hits = p.raycast([[0.25, 0.5, 1.0], [2.0, 2.0, 1.0]], [0.0, 0.0, -1.0])  # the second misses
        >>> hits.t.round(12), hits.hit
        (array([0.875,   nan]), array([ True, False]))
        >>> hits.normals[0].round(12)  # (-f_x, -f_y, 1)
        array([-0.5 , -0.25,  1.  ])
        """
        check_choice(method, "method", {"reference", "bracketed", "paper"})
        o = as_float64_array(origins, "origins", shape_tail=(3,))
        d = as_float64_array(directions, "directions", shape_tail=(3,))
        o, d = np.broadcast_arrays(o, d)
        tmin = np.broadcast_to(np.asarray(tmin, dtype=np.float64), o.shape[:-1])
        m = self._m
        lam_o = o[..., :2] @ m[:, :2].T + m[:, 2]
        lam_d = d[..., :2] @ m[:, :2].T
        shape = o.shape[:-1]
        t = graph_patch_first_hit(
            np.broadcast_to(self._c, shape + (15,)).reshape(-1, 15), lam_o.reshape(-1, 3), lam_d.reshape(-1, 3),
            o[..., 2].ravel(), d[..., 2].ravel(), tmin.ravel(), np.full(tmin.size, np.inf),
            method=method, iterations=iterations).reshape(shape)
        pts = o + t[..., None] * d
        hit = np.isfinite(t)
        normals = np.full(pts.shape, np.nan)
        if hit.any():
            g = self.gradient(pts[hit][:, :2])
            pts[hit, 2] = self.evaluate(pts[hit][:, :2])
            normals[hit] = np.c_[-g, np.ones(len(g))]
        return RayHits(t, pts, normals)
