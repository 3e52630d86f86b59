"""TerrainSpline: a quartic spline on the type-1 triangulation of a height grid [Reis2008, sec. IV].

The model is immutable float64 numpy and never imports VTK. Geometry is kept exactly as the data gave
it: anisotropic spacing and real-world origins (UTM eastings of 5e5, northings of 5e6) are stored in
float64, and everything the GPU sees is expressed in a *local frame* -- model coordinates relative to
``offset`` = (centre x, centre y, reference height) -- so float32 keeps sub-millimetre precision on
UTM-sized data (see ``splinevis.gl.inject``: the actor is placed at ``offset`` in double precision).

Index space: spline cell (i, j) is [i, i+1] x [j, j+1] with triangles
T0 = [(0,0), (1,0), (1,1)] and T1 = [(0,0), (1,1), (0,1)] (cell-local coordinates); physical
x = x0 + u * cell_dx, y = y0 + v * cell_dy, z = z_ref + (spline value).
"""

from __future__ import annotations

import numpy as np

from .._validation import as_float64_array, check_choice
from ..bb import simplex as _simplex
from ..hierarchy.pyramid import MinMaxPyramid

__all__ = ["TerrainSpline", "cell_barycentric"]


def cell_barycentric(u, v, tri):
    """Barycentric coordinates (…, 3) of cell-local (u, v) in triangle ``tri`` (0 or 1, arrays allowed).

    T0 = [(0,0), (1,0), (1,1)]: (1 - u, u - v, v);  T1 = [(0,0), (1,1), (0,1)]: (1 - v, u, v - u).

    Examples
    --------
    >>> cell_barycentric(0.75, 0.25, 0), cell_barycentric(0.25, 0.75, 1)
    (array([0.25, 0.5 , 0.25]), array([0.25, 0.25, 0.5 ]))
    """
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    tri = np.asarray(tri)
    l0 = np.where(tri == 0, 1.0 - u, 1.0 - v)
    l1 = np.where(tri == 0, u - v, u)
    l2 = np.where(tri == 0, v, v - u)
    return np.stack([l0, l1, l2], axis=-1)


#: d(lambda)/du and d(lambda)/dv of T0 and T1 (rows: triangle; columns: lambda components)
_DLAM_DU = np.array([[-1.0, 1.0, 0.0], [0.0, 1.0, -1.0]])
_DLAM_DV = np.array([[0.0, -1.0, 1.0], [-1.0, 0.0, 1.0]])


class TerrainSpline:
    """A quartic spline surface z = s(x, y) over a height grid.

    Build one with :meth:`from_heights` (a scheme of :mod:`splinevis.terrain.schemes` applied to a
    :class:`~splinevis.io.HeightGrid` or a 2-D array) or :meth:`from_coefficients`.

    Attributes
    ----------
    coefficients : (ncy, ncx, 2, 15) ndarray
        BB coefficients of T0 and T1 of every cell, heights relative to ``z_ref``.
    cell_spacing : (float, float)
        Physical size of a spline cell (data spacing times the scheme's cell size: 4 for C0).
    origin : (float, float)
        Physical position of index point (0, 0).
    z_ref : float
        Reference height (the data mean): coefficients are stored relative to it.
    scheme : str

    Examples
    --------
    The C1 scheme reproduces cubics, so a plane comes back exactly:

    >>> y, x = np.mgrid[0:5, 0:6].astype(float)
    >>> t = TerrainSpline.from_heights(x + 2 * y, "C1", spacing=(10.0, 10.0), origin=(100.0, 200.0))
    >>> t
    TerrainSpline(scheme='C1', cells=5x4, patches=40, cell_spacing=(10.0, 10.0), origin=(100.0, 200.0), z_ref=6.5)
    >>> round(float(t.evaluate(125.0, 215.0)), 12)  # x = 2.5, y = 1.5 in data indices
    5.5
    """

    def __init__(self, coefficients, cell_spacing, origin=(0.0, 0.0), z_ref=0.0, scheme="custom", source=""):
        c = as_float64_array(coefficients, "coefficients", ndim=4)
        if c.shape[2:] != (2, 15) or c.shape[0] < 1 or c.shape[1] < 1:
            raise ValueError(f"coefficients must have shape (ncy, ncx, 2, 15), got {c.shape}.")
        sp = as_float64_array(cell_spacing, "cell_spacing", ndim=1, shape_tail=(2,))
        if not (sp > 0).all():
            raise ValueError(f"cell_spacing must be positive, got {tuple(sp)}.")
        org = as_float64_array(origin, "origin", ndim=1, shape_tail=(2,))
        z_ref = float(as_float64_array(z_ref, "z_ref", ndim=0))
        self._c = np.ascontiguousarray(c)
        self._c.setflags(write=False)
        self.cell_spacing = (float(sp[0]), float(sp[1]))
        self.origin = (float(org[0]), float(org[1]))
        self.z_ref = z_ref
        self.scheme = scheme
        self.source = source
        #: (min, max) of the height data the spline was built from (None: built from coefficients); what a
        #: colormap spans by default: the coefficients' range includes the schemes' overshoot at cliffs and
        #: edges (C0: several %), which squeezed the data into a few colours.
        self.data_range = None
        self._pyramid = None

    @classmethod
    def from_coefficients(cls, coefficients, cell_spacing=(1.0, 1.0), origin=(0.0, 0.0), z_ref=0.0):
        """A spline from BB coefficients ``(ncy, ncx, 2, 15)`` relative to ``z_ref`` (scheme ``"custom"``).

        Examples
        --------
        >>> t = TerrainSpline.from_coefficients(np.full((1, 2, 2, 15), 0.5), (2.0, 2.0), z_ref=10.0)
        >>> t.shape, float(t.evaluate(1.0, 1.0)), t.scheme
        ((1, 2), 10.5, 'custom')
        """
        return cls(coefficients, cell_spacing, origin, z_ref, scheme="custom", source="coefficients")

    @classmethod
    def from_heights(cls, heights, scheme: str = "C1", *, presmooth: int = 0, **read_options) -> "TerrainSpline":
        """Apply ``scheme`` to height data (anything :func:`splinevis.io.read_heights` reads).

        Scheme ``"C0"`` works on macro cells of 4 x 4 samples: grids of other sizes are resampled onto the
        next ``4k + 1`` grid over the same rectangle (:func:`splinevis.terrain.schemes.resample_for_c0`; the
        model's ``source`` says so). ``presmooth`` > 0 first smooths the heights with that many passes of the binomial filter on the GPU
        (:func:`splinevis.terrain.prefilter.smooth_heights`: for noisy measured data).

        Examples
        --------
        >>> import numpy as np
        >>> z = np.zeros((9, 9)); z[4, 4] = 1.0
        >>> t = TerrainSpline.from_heights(z, "C2", presmooth=1)
        >>> round(float(t.evaluate(4.0, 4.0)) - t.z_ref, 4) < round(float(TerrainSpline.from_heights(z, "C2").evaluate(4.0, 4.0)) - t.z_ref, 4)
        True
        """
        from ..io import HeightGrid, read_heights
        from .schemes import SCHEMES, terrain_coefficients

        check_choice(scheme, "scheme", set(SCHEMES))
        grid = heights if isinstance(heights, HeightGrid) else read_heights(heights, **read_options)
        if presmooth:
            from .prefilter import smooth_heights

            grid = smooth_heights(grid, presmooth)
        z = np.asarray(grid.heights, dtype=np.float64)
        from .limits import check_grid_size, check_height_range

        check_height_range(z)  # before anything is built: float32 on the GPU would overflow
        spacing = grid.spacing
        source = grid.source
        if scheme == "C0" and ((z.shape[0] - 1) % 4 or (z.shape[1] - 1) % 4) and min(z.shape) >= 4:
            # C0's macro cells are 4 x 4 samples: other sizes are resampled onto the 4k + 1 grid spanning the
            # same rectangle (cubic interpolation, resample_for_c0), documented in the model's source
            from .schemes import resample_for_c0

            shape = z.shape
            z, (sx, sy) = resample_for_c0(z)
            spacing = (spacing[0] * sx, spacing[1] * sy)
            source = f"{source} (resampled from {shape[1]}x{shape[0]} to {z.shape[1]}x{z.shape[0]} samples for C0)"
        cell = 4 if scheme == "C0" else 1  # samples per spline cell
        check_grid_size(max(1, (z.shape[1] - 1) // cell), max(1, (z.shape[0] - 1) // cell))  # before building
        z_ref = float(np.mean(z))
        coef, info = terrain_coefficients(z - z_ref, scheme)
        cell = info["cell_size"] if isinstance(info, dict) else info.cell_size
        sp = (spacing[0] * cell, spacing[1] * cell)
        out = cls(coef, sp, grid.origin, z_ref, scheme=scheme, source=source)
        out.data_range = (float(np.min(z)), float(np.max(z)))
        return out

    # -- data -----------------------------------------------------------------------------------------
    @property
    def coefficients(self) -> np.ndarray:
        """(ncy, ncx, 2, 15) read-only BB coefficients of T0 and T1 of every cell, relative to ``z_ref``.

        >>> t = TerrainSpline.from_heights(np.zeros((4, 6)), "linear")
        >>> t.coefficients.shape, t.coefficients.flags.writeable
        ((3, 5, 2, 15), False)
        """
        return self._c

    @property
    def shape(self) -> tuple:
        """(ncy, ncx): number of spline cells.

        >>> TerrainSpline.from_heights(np.zeros((9, 13)), "C0").shape  # C0 cells span 4 x 4 data cells
        (2, 3)
        """
        return self._c.shape[:2]

    @property
    def num_patches(self) -> int:
        """Number of triangle patches: two per cell.

        >>> TerrainSpline.from_heights(np.zeros((4, 6)), "linear").num_patches
        30
        """
        return 2 * self._c.shape[0] * self._c.shape[1]

    @property
    def extent(self) -> tuple:
        """(xmin, xmax, ymin, ymax) of the domain.

        >>> TerrainSpline.from_heights(np.zeros((4, 6)), "linear", spacing=(10.0, 5.0), origin=(100.0, 0.0)).extent
        (100.0, 150.0, 0.0, 15.0)
        """
        ncy, ncx = self.shape
        return (self.origin[0], self.origin[0] + ncx * self.cell_spacing[0],
                self.origin[1], self.origin[1] + ncy * self.cell_spacing[1])

    @property
    def zrange(self) -> tuple:
        """(min, max) physical height bound from the coefficients (convex hull property).

        >>> y, x = np.mgrid[0:5, 0:6].astype(float)
        >>> TerrainSpline.from_heights(x + 2 * y, "linear").zrange
        (0.0, 13.0)
        """
        return (self.z_ref + float(self._c.min()), self.z_ref + float(self._c.max()))

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)``: the domain and :attr:`zrange` (world; what a camera is
        fitted to, as a PyVista dataset's bounds).

        >>> TerrainSpline.from_heights(np.full((4, 6), 7.0), "linear", spacing=(10.0, 5.0)).bounds
        (0.0, 50.0, 0.0, 15.0, 7.0, 7.0)
        """
        return (*self.extent, *self.zrange)

    @property
    def offset(self) -> np.ndarray:
        """Origin of the local (model) frame: domain centre and z_ref, float64.

        >>> TerrainSpline.from_heights(np.full((4, 6), 7.0), "linear", spacing=(10.0, 5.0), origin=(5e5, 5e6)).offset.tolist()
        [500025.0, 5000007.5, 7.0]
        """
        x0, x1, y0, y1 = self.extent
        return np.array([0.5 * (x0 + x1), 0.5 * (y0 + y1), self.z_ref])

    @property
    def hierarchy(self) -> MinMaxPyramid:
        """The min/max quadtree of the coefficients: level 0 bounds each cell's 30 coefficients, level L the
        blocks of 2^L x 2^L cells; the top level is a single block (built on first use).

        >>> y, x = np.mgrid[0:5, 0:6].astype(float)
        >>> pyramid = TerrainSpline.from_heights(x + 2 * y, "linear").hierarchy
        >>> pyramid.depth, pyramid.value_range  # heights relative to z_ref = 6.5
        (3, (-6.5, 6.5))
        """
        if self._pyramid is None:
            c = self._c.reshape(self._c.shape[0], self._c.shape[1], 30)
            self._pyramid = MinMaxPyramid(c.min(axis=-1), c.max(axis=-1))
        return self._pyramid

    # -- evaluation -----------------------------------------------------------------------------------
    def to_index(self, x, y):
        """Physical (x, y) -> index coordinates (u, v) in spline cells.

        >>> t = TerrainSpline.from_heights(np.zeros((4, 6)), "linear", spacing=(10.0, 5.0), origin=(100.0, 0.0))
        >>> [float(c) for c in t.to_index(125.0, 7.5)]
        [2.5, 1.5]
        """
        u = (np.asarray(x, dtype=np.float64) - self.origin[0]) / self.cell_spacing[0]
        v = (np.asarray(y, dtype=np.float64) - self.origin[1]) / self.cell_spacing[1]
        return u, v

    def _locate(self, u, v):
        ncy, ncx = self.shape
        i = np.clip(np.floor(u).astype(np.int64), 0, ncx - 1)
        j = np.clip(np.floor(v).astype(np.int64), 0, ncy - 1)
        lu, lv = u - i, v - j
        tri = (lv > lu).astype(np.int64)
        return i, j, tri, lu, lv

    def evaluate(self, x, y) -> np.ndarray:
        """Physical height s(x, y) (points outside the domain are extrapolated from the border cell).

        >>> y, x = np.mgrid[0:5, 0:6].astype(float)
        >>> t = TerrainSpline.from_heights(x * x - y, "C1")  # cubics are reproduced
        >>> t.evaluate(np.array([2.5, 7.0]), np.array([1.5, 1.0])).round(12)  # the second point lies outside
        array([ 4.75, 48.  ])
        """
        return self.z_ref + self.height_at_index(*self.to_index(x, y))

    def height_at_index(self, u, v) -> np.ndarray:
        """Height relative to ``z_ref`` at index coordinates (u, v) (spline cells; the cell and triangle by
        floor and u = v, clamped to the grid as :meth:`evaluate`).

        >>> y, x = np.mgrid[0:5, 0:6].astype(float)
        >>> t = TerrainSpline.from_heights(x * x - y, "C1")
        >>> round(float(t.height_at_index(2.5, 1.5) + t.z_ref), 12)
        4.75
        """
        i, j, tri, lu, lv = self._locate(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
        lam = cell_barycentric(lu, lv, tri)
        return _simplex.de_casteljau(self._c[j, i, tri], lam, d=2)

    def gradient(self, x, y) -> np.ndarray:
        """(…, 2) physical gradient (ds/dx, ds/dy).

        >>> y, x = np.mgrid[0:5, 0:6].astype(float)
        >>> t = TerrainSpline.from_heights(x + 2 * y, "C1", spacing=(10.0, 10.0))
        >>> t.gradient(25.0, 15.0).round(12)  # per metre
        array([0.1, 0.2])
        """
        u, v = self.to_index(x, y)
        i, j, tri, lu, lv = self._locate(u, v)
        lam = cell_barycentric(lu, lv, tri)
        c = self._c[j, i, tri]
        out = []
        for table, h in ((_DLAM_DU, self.cell_spacing[0]), (_DLAM_DV, self.cell_spacing[1])):
            dc = _simplex.derivative(c, table[tri], d=2)
            out.append(_simplex.de_casteljau(dc, lam, d=2) / h)
        return np.stack(out, axis=-1)

    def __repr__(self):
        ncy, ncx = self.shape
        return (f"TerrainSpline(scheme={self.scheme!r}, cells={ncx}x{ncy}, patches={self.num_patches}, "
                f"cell_spacing={self.cell_spacing}, origin={self.origin}, z_ref={self.z_ref:g})")
