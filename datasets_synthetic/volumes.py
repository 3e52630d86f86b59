"""Analytic scalar fields with exact gradients (and, where cheap, exact ray hits) for volume tests and
studies, and :func:`write_volume` to put sampled grids into the files :func:`splinevis.io.read_volume` reads.

Every field is an :class:`AnalyticField`: ``value(points)``, ``gradient(points)``, ``normal(points)``,
``bounds``, ``isovalue``, ``name`` and ``sample(n)`` -> :class:`splinevis.io.VolumeGrid`. The sphere,
torus and thin sheet also give ``ray_hit(origins, directions)`` (first crossing of the isosurface) and
``closest_point(points)`` (sphere, torus), which measure silhouette and normal errors of renderings.

Fields
------
* :func:`marschner_lobb` - the Marschner-Lobb test signal on [-1, 1]^3, level 0.5.
* :func:`sphere_distance`, :func:`torus_distance` - signed distances, level 0.
* :func:`blob` - a sum of four Gaussians, level 0.5: one smooth, non-convex blob.
* :func:`thin_sheet` - a tilted slab about one voxel thick (at 64 samples per axis): thin features.
* :func:`plateau` - exactly equal to the level on a thick spherical shell (flat data at the level).
* :func:`constant` - one value everywhere (the degenerate case).

Examples
--------
>>> f = sphere_distance(radius=0.5)
>>> g = f.sample(9)
>>> g.shape, g.spacing, float(g.values[4, 4, 4])
((9, 9, 9), (0.25, 0.25, 0.25), -0.5)
>>> t = f.ray_hit([[-3.0, 0.0, 0.0]], [[1.0, 0.0, 0.0]])
>>> t.tolist(), f.value([[-3.0 + t[0], 0.0, 0.0]]).tolist()
([2.5], [0.0])
"""

from __future__ import annotations

import math

import numpy as np

from splinevis.io.volumes import VolumeGrid

__all__ = [
    "AnalyticField", "SphereDistance", "TorusDistance", "ThinSheet",
    "marschner_lobb", "sphere_distance", "torus_distance", "blob", "thin_sheet", "plateau", "constant",
    "write_volume", "WRITE_FORMATS",
]

_CUBE = (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)


def _points(points) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.shape[-1:] != (3,):
        raise ValueError(f"points must have shape (..., 3), got {p.shape}.")
    return p


def _vectors(points, name) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1:
        p = p[None, :]
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {p.shape}.")
    return p


def _check_bounds(bounds) -> tuple:
    b = tuple(float(v) for v in bounds)
    if len(b) != 6 or not all(math.isfinite(v) for v in b) or not (b[0] < b[1] and b[2] < b[3] and b[4] < b[5]):
        raise ValueError(f"bounds must be (xmin, xmax, ymin, ymax, zmin, zmax) with min < max, got {bounds!r}.")
    return b


class AnalyticField:
    """A scalar field f: R^3 -> R with its exact gradient, a domain box and a default level.

    Parameters
    ----------
    name : str
    bounds : (xmin, xmax, ymin, ymax, zmin, zmax)
        The box :meth:`sample` covers.
    isovalue : float
        A sensible level: the isosurface ``f = isovalue`` lies inside ``bounds``.
    value, gradient : callables
        ``value(p (..., 3)) -> (...)`` and ``gradient(p) -> (..., 3)``.
    """

    def __init__(self, name, bounds, isovalue, value, gradient):
        self.name = str(name)
        self.bounds = _check_bounds(bounds)
        self.isovalue = float(isovalue)
        self._value = value
        self._gradient = gradient

    def __repr__(self):
        return f"{type(self).__name__}(name={self.name!r}, bounds={self.bounds}, isovalue={self.isovalue})"

    def value(self, points) -> np.ndarray:
        """f at ``points`` (..., 3) -> (...), float64."""
        return self._value(_points(points))

    def gradient(self, points) -> np.ndarray:
        """Exact gradient at ``points`` (..., 3) -> (..., 3)."""
        return self._gradient(_points(points))

    def normal(self, points) -> np.ndarray:
        """Unit gradient (outward where f grows outward); NaN where the gradient vanishes."""
        g = self.gradient(points)
        n = np.linalg.norm(g, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, g / np.where(n > 0, n, 1.0), np.nan)

    def ray_hit(self, origins, directions, *, clip_to_bounds=True) -> np.ndarray:
        """First ``t >= 0`` with ``f(o + t d) = isovalue`` (NaN for a miss); only for some fields."""
        raise NotImplementedError(f"{self.name}: exact ray hits are available for sphere_distance, "
                                  "torus_distance and thin_sheet only.")

    def grid_shape(self, n) -> tuple:
        """``(nx, ny, nz)`` from an int (same on every axis) or a triple."""
        if isinstance(n, (int, np.integer)) and not isinstance(n, bool):
            n = (int(n),) * 3
        try:
            shape = tuple(int(v) for v in n)
        except TypeError:
            raise TypeError(f"n must be an int or (nx, ny, nz), got {n!r}.") from None
        if len(shape) != 3 or min(shape) < 2:
            raise ValueError(f"n must give at least 2 samples per axis as an int or (nx, ny, nz), got {n!r}.")
        return shape

    def sample(self, n=64, *, dtype=None, noise=None, seed=0, value_range=None) -> VolumeGrid:
        """Samples on a uniform grid spanning :attr:`bounds` (both ends included).

        Parameters
        ----------
        n : int or (nx, ny, nz)
            Samples per axis (>= 2). ``values[k, j, i]`` is f at ``(xmin + i*dx, ymin + j*dy, zmin + k*dz)``
            with ``dx = (xmax - xmin) / (nx - 1)``.
        dtype : {None, "uint8", "uint16"}
            Quantise: the value range (``value_range`` or the samples' min/max) is mapped to the integer
            codes 0 .. 2**bits - 1 (round to nearest); the grid holds the dequantised values
            ``slope * code + intercept`` and records ``rescale=(slope, intercept)`` and ``dtype``, so the
            field's :attr:`isovalue` still applies.
        noise : float, optional
            Standard deviation of Gaussian noise added to every sample (before quantisation).
        seed : int
            Seed of the noise (``numpy.random.default_rng``).
        value_range : (lo, hi), optional
            Range mapped onto the codes; samples outside are clipped.
        """
        nx, ny, nz = self.grid_shape(n)
        x0, x1, y0, y1, z0, z1 = self.bounds
        spacing = ((x1 - x0) / (nx - 1), (y1 - y0) / (ny - 1), (z1 - z0) / (nz - 1))
        x = x0 + np.arange(nx) * spacing[0]
        y = y0 + np.arange(ny) * spacing[1]
        z = z0 + np.arange(nz) * spacing[2]
        zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")
        v = self.value(np.stack([xx, yy, zz], axis=-1))
        if noise is not None:
            if not (float(noise) >= 0 and math.isfinite(float(noise))):
                raise ValueError(f"noise must be a finite standard deviation >= 0, got {noise!r}.")
            v = v + np.random.default_rng(seed).normal(0.0, float(noise), v.shape)
        rescale, stored = (1.0, 0.0), "float64"
        if dtype is not None:
            dt = np.dtype(dtype)
            if dt not in (np.dtype(np.uint8), np.dtype(np.uint16)):
                raise ValueError(f"dtype {dtype!r} is not a quantisation type; choose 'uint8' or 'uint16'.")
            lo, hi = (float(v.min()), float(v.max())) if value_range is None else map(float, value_range)
            levels = float(np.iinfo(dt).max)
            slope = (hi - lo) / levels if hi > lo else 1.0
            codes = np.clip(np.rint((v - lo) / slope), 0, levels)
            v = slope * codes + lo
            rescale, stored = (slope, lo), dt.name
        return VolumeGrid(values=v, spacing=spacing, origin=(x0, y0, z0), source=f"synthetic:{self.name}",
                          scalars=self.name, dtype=stored, rescale=rescale)


# --------------------------------------------------------------------------------------------------
# Marschner-Lobb
# --------------------------------------------------------------------------------------------------
def marschner_lobb(alpha: float = 0.25, f_m: float = 6.0) -> AnalyticField:
    """The Marschner-Lobb signal [MarschnerLobb1994] on [-1, 1]^3, level 0.5::

        f = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi f_M cos(pi r / 2)))) / (2 (1 + alpha)),  r = sqrt(x^2 + y^2)

    Examples
    --------
    >>> f = marschner_lobb()
    >>> float(f.value([0.0, 0.0, 0.0]))  # (1 + alpha (1 + cos(2 pi f_M))) / (2 (1 + alpha))
    0.6
    """
    a, fm = float(alpha), float(f_m)
    norm = 2.0 * (1.0 + a)

    def value(p):
        x, y, z = p[..., 0], p[..., 1], p[..., 2]
        r = np.hypot(x, y)
        return (1.0 - np.sin(np.pi * z / 2) + a * (1.0 + np.cos(2 * np.pi * fm * np.cos(np.pi * r / 2)))) / norm

    def gradient(p):
        x, y, z = p[..., 0], p[..., 1], p[..., 2]
        r = np.hypot(x, y)
        # d/dr cos(2 pi fm cos(pi r / 2)) = pi^2 fm sin(2 pi fm cos(pi r / 2)) sin(pi r / 2); divide by r with
        # sin(pi r / 2) / r = (pi / 2) sinc(r / 2), finite at the axis
        dr_over_r = np.pi ** 2 * fm * np.sin(2 * np.pi * fm * np.cos(np.pi * r / 2)) * (np.pi / 2) * np.sinc(r / 2)
        gx = a * dr_over_r * x / norm
        gy = a * dr_over_r * y / norm
        gz = -(np.pi / 2) * np.cos(np.pi * z / 2) / norm
        return np.stack([gx, gy, gz], axis=-1)

    return AnalyticField("marschner_lobb", _CUBE, 0.5, value, gradient)


# --------------------------------------------------------------------------------------------------
# Fields with exact ray hits
# --------------------------------------------------------------------------------------------------
def _first_hit(candidates: np.ndarray, o, d, bounds, clip) -> np.ndarray:
    """Smallest candidate t >= 0 per row (NaN columns ignored) whose point lies in ``bounds`` if ``clip``."""
    t = np.where(candidates >= 0, candidates, np.nan)
    if clip:
        b = np.asarray(bounds).reshape(3, 2)
        p = o[:, None, :] + t[..., None] * d[:, None, :]
        slack = 1e-12 * (np.abs(b).max() + 1.0)
        inside = np.all((p >= b[:, 0] - slack) & (p <= b[:, 1] + slack), axis=-1)
        t = np.where(inside, t, np.nan)
    out = np.full(t.shape[0], np.nan)
    ok = ~np.all(np.isnan(t), axis=1)
    out[ok] = np.nanmin(t[ok], axis=1)
    return out


class SphereDistance(AnalyticField):
    """Signed distance to a sphere, ``|p - center| - radius`` (level 0)."""

    def __init__(self, radius=0.7, center=(0.0, 0.0, 0.0), bounds=None):
        self.radius = float(radius)
        self.center = np.asarray(center, dtype=np.float64).reshape(3)
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0, got {radius!r}.")
        c = self.center
        bounds = bounds if bounds is not None else (c[0] - 1, c[0] + 1, c[1] - 1, c[1] + 1, c[2] - 1, c[2] + 1)
        super().__init__("sphere_distance", bounds, 0.0, self._f, self._g)

    def _f(self, p):
        return np.linalg.norm(p - self.center, axis=-1) - self.radius

    def _g(self, p):
        q = p - self.center
        n = np.linalg.norm(q, axis=-1, keepdims=True)
        return np.where(n > 0, q / np.where(n > 0, n, 1.0), 0.0)

    def closest_point(self, points) -> np.ndarray:
        """The nearest point of the sphere (the centre maps to the +x pole)."""
        q = _points(points) - self.center
        n = np.linalg.norm(q, axis=-1, keepdims=True)
        u = np.where(n > 0, q / np.where(n > 0, n, 1.0), np.array([1.0, 0.0, 0.0]))
        return self.center + self.radius * u

    def ray_hit(self, origins, directions, *, clip_to_bounds=True) -> np.ndarray:
        """First ``t >= 0`` with ``|o + t d - c| = radius`` (t in units of ``|d|``); NaN for a miss.

        Solved with the cancellation-free quadratic formula; the hit point's distance to the centre equals
        the radius to a few ulps.
        """
        o, d = _vectors(origins, "origins"), _vectors(directions, "directions")
        q = o - self.center
        a = np.einsum("ij,ij->i", d, d)
        b = np.einsum("ij,ij->i", q, d)
        c = np.einsum("ij,ij->i", q, q) - self.radius ** 2
        disc = b * b - a * c
        with np.errstate(invalid="ignore", divide="ignore"):
            s = np.sqrt(np.where(disc >= 0, disc, np.nan))
            qq = -(b + np.copysign(s, b))
            t1, t2 = qq / a, c / qq
        return _first_hit(np.stack([t1, t2], axis=1), o, d, self.bounds, clip_to_bounds)


class TorusDistance(AnalyticField):
    """Signed distance to a torus about the z axis through ``center``: ring radius ``R``, tube ``r``."""

    def __init__(self, R=0.6, r=0.25, center=(0.0, 0.0, 0.0), bounds=None):
        self.R, self.r = float(R), float(r)
        if not (0 < self.r < self.R):
            raise ValueError(f"need 0 < r < R for a ring torus, got R={R!r}, r={r!r}.")
        self.center = np.asarray(center, dtype=np.float64).reshape(3)
        c = self.center
        bounds = bounds if bounds is not None else (c[0] - 1, c[0] + 1, c[1] - 1, c[1] + 1, c[2] - 1, c[2] + 1)
        super().__init__("torus_distance", bounds, 0.0, self._f, self._g)

    def _f(self, p):
        q = p - self.center
        return np.hypot(np.hypot(q[..., 0], q[..., 1]) - self.R, q[..., 2]) - self.r

    def _g(self, p):
        q = p - self.center
        rho = np.hypot(q[..., 0], q[..., 1])
        w = rho - self.R
        dist = np.hypot(w, q[..., 2])
        with np.errstate(invalid="ignore", divide="ignore"):
            cx = np.where(rho > 0, q[..., 0] / rho, 0.0)
            cy = np.where(rho > 0, q[..., 1] / rho, 0.0)
            s = np.where(dist > 0, w / dist, 0.0)
            sz = np.where(dist > 0, q[..., 2] / dist, 0.0)
        return np.stack([s * cx, s * cy, sz], axis=-1)

    def closest_point(self, points) -> np.ndarray:
        """The nearest point of the torus surface (points on the axis map to the ring's +x side)."""
        q = _points(points) - self.center
        rho = np.hypot(q[..., 0], q[..., 1])[..., None]
        u = np.where(rho > 0, q[..., :2] / np.where(rho > 0, rho, 1.0), np.array([1.0, 0.0]))
        ring = np.concatenate([self.R * u, np.zeros(u.shape[:-1] + (1,))], axis=-1)
        v = q - ring
        n = np.linalg.norm(v, axis=-1, keepdims=True)
        v = np.where(n > 0, v / np.where(n > 0, n, 1.0), np.concatenate([u, np.zeros_like(rho)], axis=-1))
        return self.center + ring + self.r * v

    def _quartic(self, p, d):
        """F(t) = (|p|^2 + R^2 - r^2)^2 - 4 R^2 (px^2 + py^2) and F'(t) along ``d`` at the points ``p``."""
        R2, r2 = self.R ** 2, self.r ** 2
        s = np.einsum("...i,...i->...", p, p) + R2 - r2
        F = s * s - 4 * R2 * (p[..., 0] ** 2 + p[..., 1] ** 2)
        dF = 2 * s * 2 * np.einsum("...i,...i->...", p, d) - 8 * R2 * (p[..., 0] * d[..., 0] + p[..., 1] * d[..., 1])
        return F, dF

    def ray_hit(self, origins, directions, *, clip_to_bounds=True) -> np.ndarray:
        """First ``t >= 0`` where the ray meets the torus (t in units of ``|d|``); NaN for a miss.

        The quartic is solved in a frame centred at the ray point nearest the torus centre, with unit
        direction (eigenvalues of the companion matrix), and each real root is polished by Newton steps
        on the quartic. Roots that do not polish to a point within ``1e-9 * (R + r)`` of the surface
        (grazing misses whose complex roots have a tiny imaginary part) are dropped.
        """
        o, d = _vectors(origins, "origins"), _vectors(directions, "directions")
        dn = np.linalg.norm(d, axis=1)
        if np.any(dn == 0):
            raise ValueError("directions must be nonzero.")
        u = d / dn[:, None]
        q = o - self.center
        t0 = -np.einsum("ij,ij->i", q, u)
        o2 = q + t0[:, None] * u  # ray point nearest the centre
        R2, r2 = self.R ** 2, self.r ** 2
        b = 2 * np.einsum("ij,ij->i", o2, u)  # 0 up to rounding
        c = np.einsum("ij,ij->i", o2, o2) + R2 - r2
        e = 4 * R2
        c3 = 2 * b
        c2 = b * b + 2 * c - e * (u[:, 0] ** 2 + u[:, 1] ** 2)
        c1 = 2 * b * c - 2 * e * (o2[:, 0] * u[:, 0] + o2[:, 1] * u[:, 1])
        c0 = c * c - e * (o2[:, 0] ** 2 + o2[:, 1] ** 2)
        comp = np.zeros((o.shape[0], 4, 4))
        comp[:, 0, :] = -np.stack([c3, c2, c1, c0], axis=1)
        comp[:, 1, 0] = comp[:, 2, 1] = comp[:, 3, 2] = 1.0
        roots = np.linalg.eigvals(comp)
        scale = self.R + self.r
        real = np.where(np.abs(roots.imag) <= 1e-4 * scale, roots.real, np.nan)
        for _ in range(6):
            p = o2[:, None, :] + real[..., None] * u[:, None, :]
            F, dF = self._quartic(p, u[:, None, :])
            with np.errstate(invalid="ignore", divide="ignore"):
                real = real - np.where(dF != 0, F / dF, 0.0)
        p = o2[:, None, :] + real[..., None] * u[:, None, :]
        off = np.abs(np.hypot(np.hypot(p[..., 0], p[..., 1]) - self.R, p[..., 2]) - self.r)
        real = np.where(off <= 1e-9 * scale, real, np.nan)
        t = (real + t0[:, None]) / dn[:, None]
        return _first_hit(t, o, d, self.bounds, clip_to_bounds)


class ThinSheet(AnalyticField):
    """A Gaussian ridge across the plane ``n . p = offset``; level 0.5 bounds a slab ``thickness`` thick."""

    def __init__(self, thickness=2.0 / 63.0, normal=(1.0, 2.0, 3.0), offset=0.1, bounds=_CUBE):
        self.thickness = float(thickness)
        if not self.thickness > 0:
            raise ValueError(f"thickness must be > 0, got {thickness!r}.")
        n = np.asarray(normal, dtype=np.float64).reshape(3)
        self.plane_normal = n / np.linalg.norm(n)
        self.offset = float(offset)
        # exp(-s^2 / (2 sigma^2)) = 0.5 at |s| = sigma sqrt(2 ln 2) = thickness / 2
        self.sigma = self.thickness / (2.0 * math.sqrt(2.0 * math.log(2.0)))
        super().__init__("thin_sheet", bounds, 0.5, self._f, self._g)

    def _s(self, p):
        return p @ self.plane_normal - self.offset

    def _f(self, p):
        s = self._s(p)
        return np.exp(-s * s / (2 * self.sigma ** 2))

    def _g(self, p):
        s = self._s(p)
        return (np.exp(-s * s / (2 * self.sigma ** 2)) * (-s / self.sigma ** 2))[..., None] * self.plane_normal

    def ray_hit(self, origins, directions, *, clip_to_bounds=True) -> np.ndarray:
        """First ``t >= 0`` on either face ``n . p = offset +- thickness / 2``; NaN for a miss."""
        o, d = _vectors(origins, "origins"), _vectors(directions, "directions")
        nd = d @ self.plane_normal
        no = o @ self.plane_normal
        h = self.thickness / 2
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.stack([(self.offset - h - no) / nd, (self.offset + h - no) / nd], axis=1)
        t = np.where(np.isfinite(t), t, np.nan)
        return _first_hit(t, o, d, self.bounds, clip_to_bounds)


def sphere_distance(radius: float = 0.7, center=(0.0, 0.0, 0.0), bounds=None) -> SphereDistance:
    """Signed distance to a sphere (level 0); bounds default to ``center +- 1``."""
    return SphereDistance(radius, center, bounds)


def torus_distance(R: float = 0.6, r: float = 0.25, center=(0.0, 0.0, 0.0), bounds=None) -> TorusDistance:
    """Signed distance to a ring torus about the z axis (level 0); bounds default to ``center +- 1``."""
    return TorusDistance(R, r, center, bounds)


def thin_sheet(thickness: float = 2.0 / 63.0, normal=(1.0, 2.0, 3.0), offset: float = 0.1) -> ThinSheet:
    """A tilted slab ``thickness`` thick (default: one voxel of a 64^3 sampling of [-1, 1]^3), level 0.5.

    The field is a Gaussian ridge ``exp(-s^2 / (2 sigma^2))`` of the signed distance ``s`` to the mid-plane,
    with ``sigma`` such that the level 0.5 lies at ``|s| = thickness / 2``.
    """
    return ThinSheet(thickness, normal, offset)


_BLOB_CENTERS = np.array([[-0.35, -0.1, 0.0], [0.3, 0.15, 0.05], [0.0, 0.3, -0.25], [0.05, -0.3, 0.3]])
_BLOB_SIGMA = 0.3


def blob() -> AnalyticField:
    """Sum of four unit Gaussians (sigma 0.3) at level 0.5 on [-1, 1]^3: one smooth, non-convex blob."""
    c, s2 = _BLOB_CENTERS, _BLOB_SIGMA ** 2

    def terms(p):
        q = p[..., None, :] - c  # (..., 4, 3)
        return q, np.exp(-np.einsum("...ij,...ij->...i", q, q) / (2 * s2))

    def value(p):
        return terms(p)[1].sum(axis=-1)

    def gradient(p):
        q, w = terms(p)
        return -(w[..., None] * q).sum(axis=-2) / s2

    return AnalyticField("blob", _CUBE, 0.5, value, gradient)


def plateau(radius: float = 0.5, half_width: float = 0.15, level: float = 0.5) -> AnalyticField:
    """Exactly ``level`` on the shell ``radius - half_width <= |p| <= radius + half_width`` (a flat region of
    data at the level), below it inside and above it outside; C1 (the second derivative jumps at the shell).

    ``f = level + sign(u) max(|u| - half_width, 0)^2`` with ``u = |p| - radius``, on [-1, 1]^3.
    """
    R, w, L = float(radius), float(half_width), float(level)

    def value(p):
        u = np.linalg.norm(p, axis=-1) - R
        return L + np.sign(u) * np.maximum(np.abs(u) - w, 0.0) ** 2

    def gradient(p):
        n = np.linalg.norm(p, axis=-1, keepdims=True)
        u = n[..., 0] - R
        unit = np.where(n > 0, p / np.where(n > 0, n, 1.0), 0.0)
        return (2.0 * np.maximum(np.abs(u) - w, 0.0))[..., None] * unit

    return AnalyticField("plateau", _CUBE, L, value, gradient)


def constant(value: float = 0.0, isovalue: float | None = None) -> AnalyticField:
    """``value`` everywhere on [-1, 1]^3; the level defaults to ``value`` itself (every point is on it)."""
    v = float(value)
    return AnalyticField("constant", _CUBE, v if isovalue is None else isovalue,
                         lambda p: np.full(p.shape[:-1], v), lambda p: np.zeros(p.shape))


# --------------------------------------------------------------------------------------------------
# Writers
# --------------------------------------------------------------------------------------------------
#: Extensions :func:`write_volume` writes.


from .volume_files import WRITE_FORMATS as WRITE_FORMATS, write_volume as write_volume  # noqa: E402 (re-exported)
