"""VolumeSpline: a trivariate spline of volume data on the type-6 partition, in world coordinates.

The model keeps only what does not depend on an isovalue: the padded data (float64), the per-cube
coefficient bounds and their min-max octree (:class:`~splinevis.hierarchy.MinMaxPyramid` in 3-D). For an isovalue,
:meth:`VolumeSpline.relevant` finds the cubes and tetrahedra whose BB coefficients straddle it ([Kalbe2008,
sec. 4]: octree branches with the isovalue in ``[fmin, fmax]``, then the convex-hull test per tetrahedron).

Coordinates: data point ``values[k, j, i]`` sits at ``origin + (i, j, k) * spacing`` and is the centre of
its cube, so the spline is defined on ``origin - spacing/2 .. origin + (n - 1/2) * spacing`` per axis.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..bb import simplex as bb
from ..io.volumes import VolumeGrid
from . import schemes as _schemes
from ..hierarchy.pyramid import MinMaxPyramid
from .partition import NUM_TETS, _bary_mats, _locate
from .prefilter import _padded

__all__ = ["VolumeSpline", "Relevant", "tet_weights", "SCHEME_DEGREE", "MIN_SAMPLES"]

#: Polynomial degree of each scheme on the type-6 partition.
SCHEME_DEGREE = {"quadratic": 2, "cubic": 3}

#: Samples per axis the 27-point stencil needs (a 3 x 3 x 3 block around every cube).
MIN_SAMPLES = 3


def tet_weights(scheme: str) -> np.ndarray:
    """(24, m, 27) data weights of the scheme: coefficient q of tetrahedron t of the cube at data point
    ``(i, j, k)`` is ``sum_s W[t, q, s] * padded_data[(i, j, k) + STENCIL[s]]`` (m = 10 quadratic, 20 cubic).

    Examples
    --------
    >>> W = tet_weights("cubic")
    >>> W.shape, bool(np.allclose(W.sum(axis=-1), 1.0)), bool(W.min() >= 0)  # convex combinations of the data
    ((24, 20, 27), True, True)
    """
    if scheme not in SCHEME_DEGREE:
        raise ValueError(f"scheme must be one of {sorted(SCHEME_DEGREE)}, got {scheme!r}.")
    return _schemes.tet_weights(scheme)


def _negative_mass(W: np.ndarray) -> float:
    """Largest total negative weight of any coefficient: every coefficient (weights summing to 1) then
    lies in ``[min - N (max - min), max + N (max - min)]`` of its 27 data values."""
    return float(np.clip(-W, 0, None).sum(axis=-1).max())


@dataclass(frozen=True)
class Relevant:
    """The cubes and tetrahedra that can hold the isosurface of one isovalue.

    Attributes
    ----------
    isovalue : float
    cubes : (n, 3) int64 ``(i, j, k)`` of the relevant cubes.
    masks : (n,) int64, bit t set when tetrahedron t of the cube has coefficients on both sides of the
        isovalue (or touching it).
    candidates : int, cubes the octree proposed (before the per-tetrahedron test).
    seconds : float, time taken.

    Examples
    --------
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> rel = VolumeSpline(x, "quadratic", order="zyx").relevant(2.5)  # the plane x = 2.5 between two slabs of cubes
    >>> sorted(set(rel.cubes[:, 0].tolist())), len(rel.cubes), rel.candidates
    ([2, 3], 72, 72)
    """

    isovalue: float
    cubes: np.ndarray
    masks: np.ndarray
    candidates: int
    seconds: float

    @property
    def num_tets(self) -> int:
        """Number of relevant tetrahedra (set bits of all masks).

        >>> Relevant(0.5, np.zeros((2, 3), np.int64), np.array([0b1011, 1 << 23]), 5, 0.0).num_tets
        4
        """
        return int(np.bitwise_count(self.masks).sum())


class VolumeSpline:
    """Quadratic or cubic spline on the type-6 partition of a volume [Kalbe2008].

    Parameters
    ----------
    volume : VolumeGrid, or anything :func:`splinevis.io.volumes.read_volume` accepts (a 3-D array, in the axis
        order ``order=``: ``"xyz"``, ``arr[i, j, k]`` as ``pyvista.wrap``, by default, or ``"zyx"``; a file path, a
        pyvista ImageData, ...).
    scheme : {"quadratic", "cubic"}
        ``"quadratic"``: quadratic super spline; ``"cubic"``: cubic C1 quasi-interpolant
        (docs/volume-schemes.md).
    prefilter : {"none", "local", "interpolate"}
        The data the scheme reads (:mod:`splinevis.volume.prefilter`): the samples (``"none"``, [Kalbe2008]),
        the local correction that makes the spline reproduce quadratics (``"local"``: values of order 3), or
        the data whose spline interpolates the samples (``"interpolate"``, cubic only, a global solve).
    padding : {"linear", "quadratic", "cubic"}
        Extrapolation of the data by one layer beyond the boundary
        (:data:`splinevis.volume.stencil.PADDINGS`); ``"linear"`` is the paper's, the others keep order 2
        for gradients up to the boundary.
    **read_options
        Passed to ``read_volume`` (order, spacing, origin, scalars, ...).

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(float)
    >>> s = VolumeSpline(x + 2 * y + 3 * z, "quadratic", order="zyx")
    >>> float(s.evaluate([[3.25, 2.5, 1.0]])[0])  # linear data are reproduced
    11.25
    >>> q = VolumeSpline(x ** 2, "quadratic", order="zyx", prefilter="local", padding="quadratic")  # x^2 exact
    >>> float(q.evaluate([[-0.5, 0.0, 0.0]])[0]), float(VolumeSpline(x ** 2, order="zyx").evaluate([[-0.5, 0, 0]])[0])
    (0.25, -0.5)
    """

    def __init__(self, volume, scheme: str = "quadratic", *, prefilter: str = "none", padding: str = "linear",
                 **read_options):
        if scheme not in SCHEME_DEGREE:
            raise ValueError(f"scheme must be one of {sorted(SCHEME_DEGREE)}, got {scheme!r}.")
        if isinstance(volume, VolumeGrid):
            if read_options:
                raise TypeError(f"read options {sorted(read_options)} apply to files and arrays, not to a VolumeGrid.")
            grid = volume
        else:
            grid = _read(volume, read_options)
        if min(grid.shape) < MIN_SAMPLES:
            raise ValueError(
                f"the {scheme} scheme needs at least {MIN_SAMPLES} samples along every axis (its 27-point stencil spans "
                f"3 x 3 x 3 samples); {grid.source} has shape (nz, ny, nx) = {grid.shape}. Resample the data to a finer grid "
                f"or use a baseline (marching cubes) for such small volumes.")
        self.grid = grid
        self.scheme = scheme
        self.degree = SCHEME_DEGREE[scheme]
        self.weights = tet_weights(scheme)
        self.ncoef = self.weights.shape[1]
        self.prefilter, self.padding = prefilter, padding
        t0 = time.perf_counter()
        try:
            self.padded = _padded(grid.values, scheme, prefilter, padding)  # the grid is validated already
        except ValueError as e:
            raise ValueError(f"{grid.source}: {e}") from None
        self._octree = None
        self.setup_seconds = time.perf_counter() - t0

    @classmethod
    def from_padded(cls, padded, scheme: str = "quadratic", *, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0),
                    source: str = "padded data") -> "VolumeSpline":
        """The spline of given padded data ``(nz + 2, ny + 2, nx + 2)`` (the samples and one layer around them,
        kept as given: a window of a larger volume pads with the neighbouring samples, not extrapolation).

        >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
        >>> full = VolumeSpline(x * y + z, order="zyx")
        >>> w = VolumeSpline.from_padded(full.padded[2:7, 1:6, 0:5], origin=(0.0, 1.0, 2.0))  # cubes z 2..4, y 1..3
        >>> w.shape, bool((w.cube_coefficients([[1, 1, 1]]) == full.cube_coefficients([[1, 2, 3]])).all())
        ((3, 3, 3), True)
        """
        if scheme not in SCHEME_DEGREE:
            raise ValueError(f"scheme must be one of {sorted(SCHEME_DEGREE)}, got {scheme!r}.")
        P = np.ascontiguousarray(padded, dtype=np.float64)
        if P.ndim != 3 or min(P.shape) < MIN_SAMPLES + 2:
            raise ValueError(f"padded data must be 3-D with at least {MIN_SAMPLES + 2} samples along every axis "
                             f"(the samples and one layer around them), got shape {P.shape}.")
        if not np.isfinite(P).all():
            raise ValueError("padded data must be finite.")
        self = cls.__new__(cls)
        self.grid = VolumeGrid(P[1:-1, 1:-1, 1:-1], spacing=tuple(spacing), origin=tuple(origin), source=source)
        self.prefilter, self.padding = "none", "given"
        self.scheme = scheme
        self.degree = SCHEME_DEGREE[scheme]
        self.weights = tet_weights(scheme)
        self.ncoef = self.weights.shape[1]
        self.padded = P
        self._octree = None
        self.setup_seconds = 0.0
        return self

    # ------------------------------------------------------------------ geometry
    @property
    def shape(self) -> tuple:
        """``(nz, ny, nx)`` cubes (= data points).

        >>> s = VolumeSpline(np.zeros((3, 4, 5)), order="zyx")
        >>> s.shape, s.padded.shape  # the padded data add a layer on every side
        ((3, 4, 5), (5, 6, 7))
        """
        return self.grid.shape

    @property
    def spacing(self) -> np.ndarray:
        """``(dx, dy, dz)`` of the data, float64 (world units per cube).

        >>> VolumeSpline(np.zeros((3, 4, 5)), spacing=(0.5, 0.5, 2.0), order="zyx").spacing
        array([0.5, 0.5, 2. ])
        """
        return np.asarray(self.grid.spacing, dtype=np.float64)

    @property
    def origin(self) -> np.ndarray:
        """World position of data point (0, 0, 0), the centre of the first cube, float64.

        >>> VolumeSpline(np.zeros((3, 4, 5)), origin=(5e5, 0.0, -10.0), order="zyx").origin
        array([ 5.e+05,  0.e+00, -1.e+01])
        """
        return np.asarray(self.grid.origin, dtype=np.float64)

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the spline's domain (cube faces, world).

        >>> VolumeSpline(np.zeros((3, 4, 5)), spacing=(0.5, 1.0, 2.0), order="zyx").bounds  # half a cube beyond the data
        (-0.25, 2.25, -0.5, 3.5, -1.0, 5.0)
        """
        n = np.array(self.shape[::-1], dtype=np.float64)
        lo = self.origin - 0.5 * self.spacing
        hi = self.origin + (n - 0.5) * self.spacing
        return (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]), float(lo[2]), float(hi[2]))

    @property
    def value_range(self) -> tuple:
        """``(min, max)`` of the data.

        >>> VolumeSpline(np.arange(27.0).reshape(3, 3, 3), order="zyx").value_range
        (0.0, 26.0)
        """
        return self.grid.value_range

    @property
    def data_range(self) -> tuple:
        """``(min, max)`` of the padded data the scheme reads: the samples, the extrapolated layer and, when
        prefiltered, the prefiltered values (what float32 rounding of the data texture scales with; it can
        exceed :attr:`value_range`).

        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> s = VolumeSpline(x, order="zyx")
        >>> s.value_range, s.data_range  # the padding extrapolates to -1 and 4
        ((0.0, 3.0), (-1.0, 4.0))
        """
        r = getattr(self, "_data_range", None)
        if r is None:
            r = self._data_range = (float(self.padded.min()), float(self.padded.max()))
        return r

    # ------------------------------------------------------------------ coefficients
    def stencil_data(self, cubes) -> np.ndarray:
        """(n, 27) padded data of the cubes' 27-point stencils (cubes as (n, 3) ``(i, j, k)``).

        Examples
        --------
        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> s = VolumeSpline(x, order="zyx")
        >>> s.stencil_data([[1, 1, 1], [0, 0, 0]])[:, :3]  # x - 1, x, x + 1; the padding extrapolates linearly
        array([[ 0.,  1.,  2.],
               [-1.,  0.,  1.]])
        """
        c = np.asarray(cubes, dtype=np.int64).reshape(-1, 3)
        off = _schemes.STENCIL  # (27, 3) as (x, y, z)
        i = c[:, None, 0] + 1 + off[None, :, 0]
        j = c[:, None, 1] + 1 + off[None, :, 1]
        k = c[:, None, 2] + 1 + off[None, :, 2]
        return self.padded[k, j, i]

    def cube_coefficients(self, cubes, *, chunk: int = 32768) -> np.ndarray:
        """(n, 24, m) BB coefficients of the given cubes (float64), computed in chunks.

        Examples
        --------
        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> c = VolumeSpline(x + 2 * y + 3 * z, "cubic", order="zyx").cube_coefficients([[1, 2, 3]])
        >>> c.shape, round(float(c[0, 0, 0]), 9)  # coefficient 0 of every tetrahedron: the cube centre (1, 2, 3)
        ((1, 24, 20), 14.0)
        """
        c = np.asarray(cubes, dtype=np.int64).reshape(-1, 3)
        W = self.weights.reshape(-1, 27).T  # (27, 24 m)
        out = np.empty((len(c), NUM_TETS, self.ncoef))
        for s in range(0, len(c), chunk):
            out[s:s + chunk] = (self.stencil_data(c[s:s + chunk]) @ W).reshape(-1, NUM_TETS, self.ncoef)
        return out

    # ------------------------------------------------------------------ evaluation (float64 reference)
    def _locate(self, points):
        q = self.grid.to_index(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        n = np.array(self.shape[::-1])
        lo, hi = -0.5, n - 0.5
        bad = ((q < lo - 1e-9) | (q > hi + 1e-9)).any(axis=1)
        if bad.any():
            b = int(np.argmax(bad))
            raise ValueError(f"point {b} {np.asarray(points).reshape(-1, 3)[b].tolist()} lies outside the spline's domain "
                             f"{tuple(round(v, 6) for v in self.bounds)} (xmin, xmax, ymin, ymax, zmin, zmax).")
        cell = np.clip(np.floor(q + 0.5), 0, n - 1).astype(np.int64)
        local = np.clip(q - (cell - 0.5), 0.0, 1.0)
        t, lam = _locate(local)
        return cell, t, lam

    def evaluate(self, points, *, gradient: bool = False):
        """Spline values (and world gradients ``(n, 3)`` if ``gradient``) at world points ``(n, 3)``.

        Examples
        --------
        >>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(float)
        >>> s = VolumeSpline(x + 2 * y + 3 * z, "quadratic", order="zyx", spacing=(0.5, 0.5, 1.0),
        ...                  origin=(10.0, 0.0, 0.0))
        >>> s.evaluate([[11.25, 1.0, 2.5]], gradient=True)  # index (2.5, 2, 2.5); gradient per world unit
        (array([14.]), array([[2., 4., 3.]]))
        """
        cell, t, lam = self._locate(points)
        uc, inv = np.unique(cell, axis=0, return_inverse=True)
        coef = self.cube_coefficients(uc)[inv.ravel(), t]  # (n, m)
        val = bb._decasteljau(coef, self.degree, 3, lam)
        if not gradient:
            return val
        g = bb.gradient(coef, d=3)
        dlam = bb._decasteljau(g, self.degree - 1, 3, lam[:, None, :])
        grad_local = np.einsum("ni,nij->nj", dlam, _bary_mats()[t][..., :3])
        return val, grad_local / self.spacing

    def curvature(self, points) -> np.ndarray:
        """(n, 2) mean and Gaussian curvature of the level sets through world points (float64 twin of the
        shader's ``sv_tet_curvature``): mean = (|g|^2 tr H - g^T H g) / (2 |g|^3), gauss = g^T adj(H) g / |g|^4
        with g, H the spline's gradient and Hessian (1/r and 1/r^2 on a sphere of a field increasing
        outwards).

        Examples
        --------
        The level sets of |x|^2 are spheres; both schemes reproduce its Hessian:

        >>> z, y, x = np.mgrid[-1:1:11j, -1:1:11j, -1:1:11j]
        >>> s = VolumeSpline(x ** 2 + y ** 2 + z ** 2, "cubic", spacing=(0.2,) * 3, origin=(-1.0,) * 3, order="zyx")
        >>> s.curvature([[0.5, 0.0, 0.0], [0.0, 0.3, 0.4]]).round(9)  # r = 0.5: mean 2, Gaussian 4
        array([[2., 4.],
               [2., 4.]])
        """
        cell, t, lam = self._locate(points)
        uc, inv = np.unique(cell, axis=0, return_inverse=True)
        coef = self.cube_coefficients(uc)[inv.ravel(), t]
        n = self.degree
        g = bb.gradient(coef, d=3)
        dlam = bb._decasteljau(g, n - 1, 3, lam[:, None, :])
        G = _bary_mats()[t][..., :3] / self.spacing  # (n, 4, 3): grad lam_i, model = world coordinates
        grad = np.einsum("ni,nij->nj", dlam, G)
        a2 = coef if n == 2 else bb._decasteljau(_second_blossom(coef), 1, 3, lam[:, None, :])
        idx = bb.index_of(2, 3)
        A = np.empty((len(coef), 4, 4))
        for i in range(4):
            for j in range(4):
                e = [0, 0, 0, 0]
                e[i] += 1
                e[j] += 1
                A[:, i, j] = a2[:, idx[tuple(e)]]
        H = n * (n - 1) * np.einsum("nia,nij,njb->nab", G, A, G)
        gg = np.einsum("ni,ni->n", grad, grad)
        mean = (gg * np.trace(H, axis1=1, axis2=2) - np.einsum("ni,nij,nj->n", grad, H, grad)) / (2 * gg ** 1.5)
        adj = np.stack([np.cross(H[:, :, 1], H[:, :, 2]), np.cross(H[:, :, 2], H[:, :, 0]),
                        np.cross(H[:, :, 0], H[:, :, 1])], axis=1)  # rows of the adjugate (H symmetric)
        gauss = np.einsum("ni,nij,nj->n", grad, adj, grad) / gg ** 2
        return np.column_stack([mean, gauss])

    # ------------------------------------------------------------------ isovalue-independent structure
    def cube_ranges(self) -> tuple:
        """Per-cube ``(lo, hi)`` float32 bounds of the cube's BB coefficients (rounded outward), from the min
        and max of its 27 data values and the scheme's negative weight mass.

        Examples
        --------
        >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
        >>> lo, hi = VolumeSpline(x, order="zyx").cube_ranges()
        >>> lo.shape, lo.dtype, float(lo[1, 1, 1]), float(hi[1, 1, 1])  # data 0..2, one float32 step outward
        ((4, 4, 4), dtype('float32'), -1.401298464324817e-45, 2.000000238418579)
        """
        P = self.padded.astype(np.float32)  # rounding is undone by the outward nextafter below
        mn, mx = _box3(P, np.minimum), _box3(P, np.maximum)
        N = _negative_mass(self.weights)
        if N > 0:
            spread = mx - mn
            mn = mn - np.float32(N) * spread * np.float32(1 + 1e-6)
            mx = mx + np.float32(N) * spread * np.float32(1 + 1e-6)
        # float32 of a float64 value is within half an ulp: one step outward encloses the float64 range
        # (with N > 0 the extra products are covered by the relative widening of 1e-6 above)
        lo = np.nextafter(mn, np.float32(-np.inf), out=mn)
        hi = np.nextafter(mx, np.float32(np.inf), out=mx)
        return lo, hi

    def _distinct_weights(self):
        """(27, D) weights of the cube's distinct coefficients and the (24, m) map into them."""
        if getattr(self, "_distinct", None) is None:
            flat = self.weights.reshape(-1, 27)
            uniq, inv = np.unique(np.round(flat, 15), axis=0, return_inverse=True)
            self._distinct = (np.ascontiguousarray(uniq.T), inv.reshape(NUM_TETS, self.ncoef))
        return self._distinct

    @property
    def octree(self) -> MinMaxPyramid:
        """The min-max octree (built on first use; independent of the isovalue).

        >>> z, y, x = np.mgrid[0:8, 0:8, 0:8].astype(float)
        >>> octree = VolumeSpline(x, order="zyx").octree
        >>> octree.depth, octree.nodes(2.5, 1).shape  # blocks of 2^3 cubes that can hold x = 2.5
        (3, (16, 3))
        """
        if self._octree is None:
            self._octree = MinMaxPyramid(*self.cube_ranges())
        return self._octree

    def relevant(self, isovalue: float, *, chunk: int = 32768) -> Relevant:
        """Cubes and tetrahedra that can contain the isosurface ``s = isovalue`` [Kalbe2008, sec. 4].

        An isovalue outside the data's range gives an empty result (an empty scene), not an error.

        Examples
        --------
        >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
        >>> s = VolumeSpline(x, "quadratic", order="zyx")
        >>> rel = s.relevant(2.5)
        >>> len(rel.cubes), rel.num_tets, len(s.relevant(100.0).cubes)
        (72, 1152, 0)
        """
        iso = float(isovalue)
        if not np.isfinite(iso):
            raise ValueError(f"isovalue must be a finite number, got {isovalue!r}.")
        t0 = time.perf_counter()
        cand = self.octree.nodes(iso, 0)[:, ::-1]  # (i, j, k), in (k, j, i) order
        cubes, masks = [], []
        bits = (np.int64(1) << np.arange(NUM_TETS, dtype=np.int64))
        # The 24 m coefficients of a cube are few distinct combinations of its data (65 for the quadratic,
        # shared between neighbouring tetrahedra): those are computed once per cube, in float32, and the
        # test is widened by their rounding error, so the result is a superset of the exact float64 answer
        # (a spare tetrahedron is tested by the shader and simply has no root). Bound: a coefficient is
        # sum_s w_s f_s with sum |w_s| <= 1 + 2 N (N the negative weight mass) -- at most 27 roundings of terms
        # bounded by (1 + 2 N) F, F = max |data - ref| -- so |error| <= 28 u32 (1 + 2 N) F; doubled for safety
        # of the float32 comparison itself.
        Wd, tmap = self._distinct_weights()
        Wd32 = Wd.astype(np.float32)
        ref = 0.5 * (self.value_range[0] + self.value_range[1])
        lo, hi = self.data_range  # the stencil reads padded (and prefiltered) data, not only the samples
        F = max(abs(lo - ref), abs(hi - ref), abs(iso - ref))
        delta = np.float32(2 * 28 * 2.0**-24 * (1 + 2 * _negative_mass(self.weights)) * max(F, 1e-300))
        iso32 = np.float32(iso - ref)
        a32, b32 = iso32 - delta, iso32 + delta
        for s in range(0, len(cand), chunk):
            c = cand[s:s + chunk]
            coef = (self.stencil_data(c) - ref).astype(np.float32) @ Wd32  # (n, distinct)
            # cube level first: a cube whose distinct coefficients all miss the isovalue has no relevant tet
            straddle = (coef.min(axis=1) <= b32) & (coef.max(axis=1) >= a32)
            c, coef = c[straddle], coef[straddle]
            lo = coef[:, tmap[:, 0]]
            hi = lo.copy()
            for q in range(1, self.ncoef):
                col = coef[:, tmap[:, q]]
                np.minimum(lo, col, out=lo)
                np.maximum(hi, col, out=hi)
            rel = (lo <= b32) & (a32 <= hi)
            m = rel @ bits
            keep = m != 0
            cubes.append(c[keep])
            masks.append(m[keep])
        cubes = np.concatenate(cubes) if cubes else np.zeros((0, 3), np.int64)
        masks = np.concatenate(masks) if masks else np.zeros(0, np.int64)
        return Relevant(iso, cubes, masks, len(cand), time.perf_counter() - t0)

    def __repr__(self):
        nz, ny, nx = self.shape
        extra = "" if (self.prefilter, self.padding) in (("none", "linear"), ("none", "given")) else \
            f", prefilter={self.prefilter!r}, padding={self.padding!r}"
        return (f"VolumeSpline({self.scheme}, {nx}x{ny}x{nz} cubes, spacing={self.grid.spacing}, origin={self.grid.origin}, "
                f"source={self.grid.source!r}{extra})")


def _second_blossom(coef: np.ndarray) -> np.ndarray:
    """(n, 10, 4) cubic -> for each quadratic multi-index a, the 4 coefficients c[a + e_k] (one de Casteljau
    step at lam is then ``sum_k lam_k c[a + e_k]``), so that ``_decasteljau(., 1, 3, lam)`` gives the
    degree-2 blossom a2 of the cubic at lam."""
    i3, i2 = bb.index_of(3, 3), bb.index_of(2, 3)
    out = np.empty(coef.shape[:-1] + (10, 4))
    for a, q in i2.items():
        for k in range(4):
            e = list(a)
            e[k] += 1
            out[..., q, k] = coef[..., i3[tuple(e)]]
    return out


def _box3(P: np.ndarray, op) -> np.ndarray:
    """op over the 3 x 3 x 3 neighbourhood of every interior sample of a padded array (separable)."""
    a = op(op(P[:-2], P[1:-1]), P[2:])
    a = op(op(a[:, :-2], a[:, 1:-1]), a[:, 2:])
    return op(op(a[:, :, :-2], a[:, :, 1:-1]), a[:, :, 2:])


def _read(volume, options) -> VolumeGrid:
    try:
        from ..io.volumes import read_volume
    except ImportError:  # pragma: no cover - a build without the volume readers
        read_volume = None
    if read_volume is not None:
        return read_volume(volume, **options)
    return VolumeGrid(np.asarray(volume, dtype=np.float64), **options)
