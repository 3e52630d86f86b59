"""A smooth geometry image: one uniform bicubic B-spline whose control points are an octahedral geometry image,
a closed surface [Losasso2003, sec. 3].

``P(s, t) = sum_{r, c} G~[r, c] N(s - c) N(t - r)`` over the padded image ``G~`` (:func:`.image.pad`), ``N`` the
centred uniform cubic B-spline, ``(s, t)`` in ``[0, N]^2`` (image units: one sample per unit). The surface is
``C^2`` everywhere except at the four cut vertices, where it is ``C^1`` because the cut vertices are the centroids
of their neighbours [Losasso2003, eq. 2, appendix]. :class:`GeometryImage` keeps that constraint and the X-cut's
symmetry as invariants (it refuses images that break them) and evaluates ``P`` with its derivatives up to order
two, in float64: the reference the subdivision passes and the fitted surfaces are tested against.

Why our own code: scipy's ``NdBSpline`` evaluates the same tensor product (the tests use it as the reference),
but the padding, the invariants and one-sided evaluation at knot lines (to test smoothness across them) are ours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .image import apply_cut_constraint, cut_vertices, pad, symmetry_defect

__all__ = ["GeometryImage", "bspline_weights"]

# uniform cubic B-spline pieces on [0, 1]: weights of the controls c-1, c, c+1, c+2 for s = c + f
_B = np.array([[1, -3, 3, -1], [4, 0, -6, 3], [1, 3, 3, -3], [0, 0, 0, 1]], dtype=np.float64) / 6.0


def bspline_weights(f, order: int = 0) -> np.ndarray:
    """Weights of the four controls ``c - 1 .. c + 2`` of the uniform cubic B-spline at ``s = c + f``
    (``f`` in ``[0, 1]``), or of its ``order``-th derivative; shape ``f.shape + (4,)``.

    >>> bspline_weights(0.0).tolist()  # the limit mask [1, 4, 1] / 6
    [0.16666666666666666, 0.6666666666666666, 0.16666666666666666, 0.0]
    >>> bspline_weights(0.0, 1).tolist()  # the tangent mask [-1, 0, 1] / 2
    [-0.5, 0.0, 0.5, 0.0]
    """
    f = np.asarray(f, dtype=np.float64)
    powers = np.stack([np.ones_like(f), f, f * f, f * f * f], axis=-1)
    if order == 0:
        return powers @ _B.T
    if order == 1:
        d = np.stack([np.zeros_like(f), np.ones_like(f), 2 * f, 3 * f * f], axis=-1)
        return d @ _B.T
    if order == 2:
        d = np.stack([np.zeros_like(f), np.zeros_like(f), 2 * np.ones_like(f), 6 * f], axis=-1)
        return d @ _B.T
    raise ValueError(f"order must be 0, 1 or 2, got {order}.")


@dataclass(frozen=True, eq=False)
class GeometryImage:
    """Control points of a smooth geometry image, ``(n, n, 3)`` float64 (layout: :mod:`.image`).

    Parameters
    ----------
    control : (n, n, 3) array_like
        The geometry image. Its X-cut symmetry must hold (identified samples equal within ``1e-12`` of its size)
        and its cut vertices must be the centroids of their neighbours; pass ``constrain=True`` to set them.
    constrain : bool
        Apply the centroid constraint [Losasso2003, eq. 2] to the cut vertices instead of checking it.

    Examples
    --------
    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> gi.n, gi.evaluate([[4.0, 4.0]]).round(3).tolist()  # the image centre is -X
    (9, [[-0.957, 0.0, 0.0]])
    """

    control: np.ndarray
    constrain: bool = False

    def __post_init__(self):
        G = np.array(self.control, dtype=np.float64)
        if G.ndim != 3 or G.shape[0] != G.shape[1] or G.shape[2] != 3:
            raise ValueError(f"a geometry image has shape (n, n, 3), got {G.shape}.")
        if not np.isfinite(G).all():
            bad = np.argwhere(~np.isfinite(G).all(axis=2))[0].tolist()
            raise ValueError(f"geometry image sample (row, column) = {tuple(bad)} is not finite.")
        size = max(float(np.abs(G).max()), 1e-300)
        defect = symmetry_defect(G)
        if defect > 1e-12 * size:
            raise ValueError(f"geometry image samples identified by the X-cut differ by {defect:.3g} (size {size:.3g}): "
                             "each border must be symmetric about its midpoint and the four corners equal "
                             "(splinevis.geometry_image.image.symmetrize).")
        if self.constrain:
            G = apply_cut_constraint(G)
        else:
            off = np.abs(apply_cut_constraint(G) - G).max()
            if off > 1e-12 * size:
                raise ValueError(f"the cut vertices are off their neighbours' centroids by {off:.3g}: the surface would "
                                 "have cusps there; pass constrain=True [Losasso2003, eq. 2].")
        G.setflags(write=False)
        object.__setattr__(self, "control", G)
        object.__setattr__(self, "constrain", False)

    @property
    def n(self) -> int:
        """Samples per side.

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> GeometryImage(octahedral_to_sphere(image_uv(5)), constrain=True).n
        5
        """
        return int(self.control.shape[0])

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the control points: the limit surface lies in their convex
        hull (a B-spline surface in that of its control net; the padding only repeats control points).

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> [round(v, 6) for v in GeometryImage(octahedral_to_sphere(image_uv(5)), constrain=True).bounds]
        [-1.0, 1.0, -0.707107, 0.707107, -0.707107, 0.707107]
        """
        c = self.control.reshape(-1, 3)
        lo, hi = c.min(axis=0), c.max(axis=0)
        return tuple(float(v) for pair in zip(lo, hi) for v in pair)

    @property
    def cut_vertices(self) -> np.ndarray:
        """``(4, 2)`` image coordinates ``(s, t)`` of the cut vertices.

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> GeometryImage(octahedral_to_sphere(image_uv(5)), constrain=True).cut_vertices.tolist()
        [[2.0, 0.0], [2.0, 4.0], [0.0, 2.0], [4.0, 2.0]]
        """
        rc = cut_vertices(self.n)
        return rc[:, ::-1].astype(np.float64)

    def evaluate(self, st, derivatives: int = 0, *, cells=None):
        """``P`` at image coordinates ``st`` (``(..., 2)``, ``(s, t)``; ``s, t`` may leave ``[0, N]`` by up to one
        sample, into the padding: the closed surface's other side).

        Parameters
        ----------
        derivatives : int
            0: the points ``(..., 3)``. 1: ``(P, P_s, P_t)``. 2: ``(P, P_s, P_t, P_ss, P_st, P_tt)``.
        cells : (..., 2) int array_like, optional
            Evaluate the polynomial piece of cell ``(floor s, floor t)`` given here (one-sided values at knot
            lines); by default the cell containing the point (the last one at ``s = N``).

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
        >>> P, Ps, Pt = gi.evaluate(gi.cut_vertices, derivatives=1)
        >>> bool(abs(Ps).max() < 1e-15 and abs(Pt).max() < 1e-15)  # zero tangents at cut vertices [Losasso2003, eq. 1]
        True
        """
        st = np.asarray(st, dtype=np.float64)
        N = self.n - 1
        if st.shape[-1] != 2:
            raise ValueError(f"image coordinates have shape (..., 2), got {st.shape}.")
        if (st < -1.0).any() or (st > N + 1.0).any():
            raise ValueError(f"image coordinates must lie in [-1, {N + 1}] (one sample of padding), got "
                             f"{st.min():.6g} .. {st.max():.6g}.")
        if cells is None:
            cell = np.clip(np.floor(st), -1, N).astype(np.int64)
            cell = np.where(st >= N + 1.0, N, cell)
        else:
            cell = np.broadcast_to(np.asarray(cells, dtype=np.int64), st.shape)
        f = st - cell
        Gp = pad(self.control, 2)  # index shift 2: columns -2 .. N + 2
        shape = st.shape[:-1]
        out = []
        orders = [(0, 0)] if derivatives == 0 else [(0, 0), (1, 0), (0, 1)]
        if derivatives == 2:
            orders += [(2, 0), (1, 1), (0, 2)]
        elif derivatives not in (0, 1):
            raise ValueError(f"derivatives must be 0, 1 or 2, got {derivatives}.")
        cs = cell[..., 0][..., None] + np.arange(-1, 3) + 2  # padded column indices
        rs = cell[..., 1][..., None] + np.arange(-1, 3) + 2
        patch = Gp[rs[..., :, None], cs[..., None, :]]  # (..., 4 rows, 4 cols, 3)
        for ds, dt in orders:
            ws = bspline_weights(f[..., 0], ds)
            wt = bspline_weights(f[..., 1], dt)
            out.append(np.einsum("...r,...c,...rcx->...x", wt, ws, patch).reshape(shape + (3,)))
        return out[0] if derivatives == 0 else tuple(out)

    def normals(self, st) -> np.ndarray:
        """Unit normals ``unit(P_s x P_t)`` at ``st``; at the cut vertices, where ``P_s = P_t = 0``, the limit
        ``unit(P_ss x P_st + P_st x P_tt)`` (the quadratic terms of ``P_s x P_t`` near a valence-2 vertex).

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
        >>> (gi.normals(gi.cut_vertices).round(6) + 0.0).tolist()  # -Z, +Z, +Y, -Y: outward
        [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]
        """
        P, Ps, Pt, Pss, Pst, Ptt = self.evaluate(st, derivatives=2)
        n = np.cross(Ps, Pt)
        size = np.linalg.norm(Ps, axis=-1) * np.linalg.norm(Pt, axis=-1)
        scale = max(float(np.abs(self.control).max()), 1e-300)
        flat = np.linalg.norm(n, axis=-1) <= 1e-12 * scale * scale + 1e-12 * size
        if flat.any():
            m = np.cross(Pss, Pst) + np.cross(Pst, Ptt)
            n = np.where(flat[..., None], m, n)
        return n / np.linalg.norm(n, axis=-1, keepdims=True)

    def sample_grid(self, level: int = 0) -> np.ndarray:
        """Image coordinates of the limit points of subdivision level ``level``: ``(M, M, 2)``,
        ``M = 2^level N + 1``, row-major like the image.

        >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
        >>> GeometryImage(octahedral_to_sphere(image_uv(5)), constrain=True).sample_grid(1).shape
        (9, 9, 2)
        """
        N = self.n - 1
        w = np.linspace(0.0, N, (N << int(level)) + 1)
        s, t = np.meshgrid(w, w, indexing="xy")
        return np.stack([s, t], axis=-1)
