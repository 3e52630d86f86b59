"""Approximation study of the volume schemes: sample a known field on n^3 grids, reconstruct, and measure
value and gradient errors and the observed orders ([Kalbe2008, sec. 4]: "the models as well as their
derivatives approximate with order two"; [Kalbe2008, sec. 6]: the constants are "slightly better for
cubics"; both schemes use a 27-point data stencil and should give order 2 for values and gradients, which
tests/test_volume_approximation.py checks).

Set-up
------
* The field is sampled on ``n`` points per axis spanning its bounds: ``x_i = xmin + i h_x``,
  ``h_x = (xmax - xmin) / (n - 1)``; index space is ``(x - xmin) / h_x``. Gradients of the
  reconstructions are converted to world units (divided by ``h`` per axis).
* The same random world points are used for every size and scheme. They lie at least 2 cells of the
  *coarsest* grid away from the boundary, so no scheme reads padded (extrapolated) data there: the
  splines' 27-point stencil of the cube containing a point at index distance >= 2 from the boundary only
  reads real samples, and trilinear interpolation reads its own cell only.
* Errors: ``|s - f|`` for values and the Euclidean norm ``|grad s - grad f|`` for gradients, max and
  rms over the points. With ``relative=True`` value errors are divided by the field's value range
  ``max f - min f`` and gradient errors by ``max |grad f|``, both taken over the evaluation points.
* Observed order between sizes ``n1 < n2``: ``log(e1 / e2) / log(h1 / h2)``.
* Only the cubes (or cells) containing the points are built (:func:`splinevis.volume.schemes.evaluate_volume`),
  so n = 128 costs the sampling of 128^3 values plus O(points) work.
"""

from __future__ import annotations

import math

import numpy as np

from .._validation import as_float64_array
from .schemes import evaluate_volume
from .trilinear import trilinear_interpolate

__all__ = ["ALL_SCHEMES", "FIDELITY_METHODS", "parse_method", "sample_field", "evaluation_points", "scheme_errors",
           "approximation_table"]

#: Schemes of the study: the trilinear baseline and the two splines.
ALL_SCHEMES = ("trilinear", "quadratic", "cubic")

#: The methods side by side in the data-fidelity table (``splinevis study volume``): what VTK shades with
#: (trilinear values, trilinear interpolation of central-difference gradients), the paper's splines, the plain
#: quadratic spline with quadratic padding, and the prefiltered splines (:mod:`splinevis.volume.prefilter`).
FIDELITY_METHODS = ("trilinear", "central-differences", "quadratic", "cubic", "quadratic/quadratic",
                    "quadratic+local/quadratic", "cubic+local/quadratic", "cubic+interpolate/cubic")


def parse_method(name: str) -> dict:
    """A method of the study by name: ``"trilinear"``, ``"central-differences"`` (trilinear values; gradients
    trilinearly interpolated from central differences of the samples, one-sided at the boundary, as VTK's
    volume mappers shade) or ``"<scheme>[+<prefilter>][/<padding>]"`` for a spline (prefilter ``none`` and
    padding ``linear`` when left out).

    >>> parse_method("cubic+interpolate/cubic")
    {'kind': 'spline', 'scheme': 'cubic', 'prefilter': 'interpolate', 'padding': 'cubic'}
    >>> parse_method("quadratic")["padding"], parse_method("central-differences")["kind"]
    ('linear', 'central-differences')
    """
    from .prefilter import PREFILTERS
    from .stencil import PADDINGS

    if name in ("trilinear", "central-differences"):
        return {"kind": name}
    base, _, padding = str(name).partition("/")
    scheme, _, prefilter = base.partition("+")
    spec = {"kind": "spline", "scheme": scheme, "prefilter": prefilter or "none", "padding": padding or "linear"}
    if scheme not in ("quadratic", "cubic") or spec["prefilter"] not in PREFILTERS or spec["padding"] not in PADDINGS:
        raise ValueError(f"method {name!r} is not known: use 'trilinear', 'central-differences' or "
                         f"'<scheme>[+<prefilter>][/<padding>]' with scheme quadratic|cubic, prefilter one of "
                         f"{PREFILTERS}, padding one of {tuple(PADDINGS)}.")
    return spec


def _bounds(field):
    b = getattr(field, "bounds", None)
    if b is None:
        raise TypeError("field must have .bounds = (xmin, xmax, ymin, ymax, zmin, zmax), .value(points) -> (n,) and "
                        ".gradient(points) -> (n, 3).")
    b = as_float64_array(b, "field.bounds")
    if b.shape != (6,) or np.any(b[1::2] <= b[0::2]):
        raise ValueError(f"field.bounds must be (xmin, xmax, ymin, ymax, zmin, zmax) with min < max per axis; got "
                         f"{b.tolist()}.")
    return b


def _check_size(n):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 6:
        raise ValueError(f"grid size n must be an integer >= 6 (the evaluation points keep 2 cells from the "
                         f"boundary); got {n!r}.")
    return int(n)


def _check_method(name):
    try:
        return parse_method(name)
    except ValueError:
        raise ValueError(f"scheme {name!r} is not known; choose one of {ALL_SCHEMES} or a method of parse_method "
                         f"(e.g. {FIDELITY_METHODS[-1]!r}).") from None


def sample_field(field, n: int) -> np.ndarray:
    """Samples ``volume[k, j, i] = field.value((x_i, y_j, z_k))`` on the ``n^3`` grid spanning the bounds.

    Examples
    --------
    Sampling needs only ``bounds`` and ``value``:

    >>> class Square:  # f = x^2 on the unit cube
    ...     bounds = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    ...     def value(self, p):
    ...         return p[:, 0] ** 2
    >>> sample_field(Square(), 6)[0, 0]  # x = 0, 0.2, ..., 1
    array([0.  , 0.04, 0.16, 0.36, 0.64, 1.  ])
    """
    b = _bounds(field)
    n = _check_size(n)
    axes = [np.linspace(b[2 * a], b[2 * a + 1], n) for a in range(3)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    vals = as_float64_array(field.value(np.stack([x, y, z], axis=-1).reshape(-1, 3)), "field.value(points)")
    if vals.shape != (n ** 3,):
        raise ValueError(f"field.value must return shape (n,) for (n, 3) points; got {vals.shape}.")
    return vals.reshape(n, n, n)


def evaluation_points(field, n_points: int, coarsest: int, seed: int = 0, *, region: str = "inner") -> np.ndarray:
    """``n_points`` uniform random world points at least 2 cells of the ``coarsest`` grid from the boundary
    (``region="inner"``), or anywhere in the sampled box (``region="full"``: the boundary cells too, where
    the splines read the padding; every fourth point is moved onto a face of the box, so that every grid size
    is measured at index distance 0 from the boundary, where the padding's error is largest).

    Examples
    --------
    >>> class Box:
    ...     bounds = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    >>> p = evaluation_points(Box(), 1000, 11)  # cells of 0.1: the points keep 0.2 from the faces
    >>> p.shape, bool(p.min() >= 0.2 and p.max() <= 0.8)
    ((1000, 3), True)
    >>> bool(evaluation_points(Box(), 1000, 11, region="full").min() < 0.01)
    True
    """
    b = _bounds(field)
    coarsest = _check_size(coarsest)
    if region not in ("inner", "full"):
        raise ValueError(f"region must be 'inner' or 'full', got {region!r}.")
    lo, hi = b[0::2], b[1::2]
    margin = 2 * (hi - lo) / (coarsest - 1) if region == "inner" else 0.0 * lo
    rng = np.random.default_rng(seed)
    p = lo + margin + rng.random((int(n_points), 3)) * (hi - lo - 2 * margin)
    if region == "full":
        on_face = np.arange(len(p))[::4]
        axis = rng.integers(0, 3, len(on_face))
        side = rng.integers(0, 2, len(on_face))
        p[on_face, axis] = np.where(side == 1, hi[axis], lo[axis])
    return p


def central_difference_gradients(volume) -> np.ndarray:
    """(nz, ny, nx, 3) index-space gradients ``(d/dx, d/dy, d/dz)`` of the samples by central differences,
    one-sided (first order) on the boundary samples: what VTK's volume mappers shade with.

    >>> z, y, x = np.mgrid[0:3, 0:3, 0:4].astype(float)
    >>> central_difference_gradients(x ** 2)[0, 0, :, 0]  # 2x inside; one-sided at the ends
    array([1., 2., 4., 5.])
    """
    v = np.asarray(volume, dtype=np.float64)
    return np.stack([np.gradient(v, axis=a) for a in (2, 1, 0)], axis=-1)


def _reconstruct(volume, field, points, scheme):
    b = _bounds(field)
    n = volume.shape[0]
    lo = b[0::2]
    h = (b[1::2] - lo) / (n - 1)
    idx = (points - lo) / h
    spec = parse_method(scheme)
    if spec["kind"] == "trilinear":
        v, g = trilinear_interpolate(volume, idx, gradient=True)
    elif spec["kind"] == "central-differences":
        v = trilinear_interpolate(volume, idx)
        G = central_difference_gradients(volume)
        g = np.stack([trilinear_interpolate(G[..., a], idx) for a in range(3)], axis=-1)
    else:
        v, g = evaluate_volume(volume, idx, spec["scheme"], gradient=True, prefilter=spec["prefilter"],
                               padding=spec["padding"])
    return v, g / h


def _angles_deg(g, fg):
    """Angle in degrees between reconstructed and true gradients (0 where both vanish)."""
    ng, nf = np.linalg.norm(g, axis=1), np.linalg.norm(fg, axis=1)
    cos = np.einsum("ij,ij->i", g, fg) / np.where(ng * nf > 0, ng * nf, 1.0)
    return np.degrees(np.arccos(np.clip(np.where(ng * nf > 0, cos, 1.0), -1.0, 1.0)))


def scheme_errors(field, n: int, scheme: str, points, *, relative: bool = False, volume=None) -> dict:
    """Errors of one scheme on the ``n^3`` grid at world ``points`` (see the module docstring).

    Parameters
    ----------
    field : object with ``.value``, ``.gradient``, ``.bounds``
    n : int >= 6
    scheme : {"trilinear", "quadratic", "cubic"}
    points : (m, 3) array_like, world coordinates inside the bounds
    relative : bool
        Divide value errors by the value range and gradient errors by the largest gradient norm of the
        field at ``points``.
    volume : optional (n, n, n) samples (from :func:`sample_field`), to share them between schemes.

    Returns
    -------
    dict with ``scheme, n, h`` (the largest grid spacing), ``value_max, value_rms, gradient_max,
    gradient_rms`` and the angle between reconstructed and true gradient in degrees, ``angle_mean,
    angle_median, angle_rms, angle_max`` (a normal's error on an isosurface through the point).
    ``scheme`` is any method of :func:`parse_method`.

    Examples
    --------
    Both splines reproduce the gradients of quadratics and shift x^2 by h^2 / 4; trilinear interpolation
    has a first-order gradient error:

    >>> class Square:  # f = x^2 on the unit cube
    ...     bounds = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    ...     def value(self, p):
    ...         return p[:, 0] ** 2
    ...     def gradient(self, p):
    ...         return np.stack([2 * p[:, 0], 0 * p[:, 0], 0 * p[:, 0]], axis=1)
    >>> points = evaluation_points(Square(), 100, 11)
    >>> e = scheme_errors(Square(), 11, "cubic", points)
    >>> e["h"], round(e["value_max"], 12), round(e["gradient_max"], 12)
    (0.1, 0.0025, 0.0)
    >>> bool(scheme_errors(Square(), 11, "trilinear", points)["gradient_max"] > 0.05)
    True
    """
    _check_method(scheme)
    n = _check_size(n)
    p = as_float64_array(points, "points", shape_tail=(3,)).reshape(-1, 3)
    vol = sample_field(field, n) if volume is None else volume
    v, g = _reconstruct(vol, field, p, scheme)
    fv = np.asarray(field.value(p), dtype=np.float64)
    fg = np.asarray(field.gradient(p), dtype=np.float64)
    ev = np.abs(v - fv)
    eg = np.linalg.norm(g - fg, axis=1)
    ang = _angles_deg(g, fg)
    if relative:
        ev = ev / (fv.max() - fv.min())
        eg = eg / np.linalg.norm(fg, axis=1).max()
    b = _bounds(field)
    return {"scheme": scheme, "n": n, "h": float(((b[1::2] - b[0::2]) / (n - 1)).max()),
            "value_max": float(ev.max()), "value_rms": float(np.sqrt(np.mean(ev ** 2))),
            "gradient_max": float(eg.max()), "gradient_rms": float(np.sqrt(np.mean(eg ** 2))),
            "angle_mean": float(ang.mean()), "angle_median": float(np.median(ang)),
            "angle_rms": float(np.sqrt(np.mean(ang ** 2))), "angle_max": float(ang.max())}


def approximation_table(field, sizes=(16, 32, 64, 128), schemes=ALL_SCHEMES, n_points: int = 20000, seed: int = 0,
                        *, relative: bool = False, region: str = "inner") -> list:
    """Error table of ``schemes`` (any methods of :func:`parse_method`) on ``n^3`` samples of ``field`` for
    each n in ``sizes``, at points of ``region`` (:func:`evaluation_points`).

    Returns
    -------
    list of dicts (one per scheme and size, sizes ascending within a scheme): the keys of
    :func:`scheme_errors` plus ``order_value_max, order_value_rms, order_gradient_max,
    order_gradient_rms`` (observed order w.r.t. the previous size of the same scheme; None for the first).

    Examples
    --------
    >>> class Exp:  # exp(x + y / 2) on the unit cube
    ...     bounds = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    ...     def value(self, p):
    ...         return np.exp(p[:, 0] + 0.5 * p[:, 1])
    ...     def gradient(self, p):
    ...         e = np.exp(p[:, 0] + 0.5 * p[:, 1])
    ...         return np.stack([e, 0.5 * e, 0 * e], axis=1)
    >>> rows = approximation_table(Exp(), sizes=(8, 16), schemes=("trilinear", "cubic"), n_points=500)
    >>> [(r["scheme"], r["n"], round(r["order_gradient_max"], 1)) for r in rows if r["n"] == 16]
    [('trilinear', 16, 1.0), ('cubic', 16, 2.1)]
    """
    sizes = sorted(_check_size(n) for n in sizes)
    for s in schemes:
        _check_method(s)
    pts = evaluation_points(field, n_points, sizes[0], seed, region=region)
    rows = {s: [] for s in schemes}
    for n in sizes:
        vol = sample_field(field, n)
        for s in schemes:
            rows[s].append({**scheme_errors(field, n, s, pts, relative=relative, volume=vol), "region": region})
    out = []
    keys = ("value_max", "value_rms", "gradient_max", "gradient_rms", "angle_mean")
    for s in schemes:
        prev = None
        for r in rows[s]:
            for k in keys:
                r["order_" + k] = None if prev is None else math.log(prev[k] / r[k]) / math.log(prev["h"] / r["h"])
            out.append(r)
            prev = r
    return out


def format_table(rows) -> str:
    """The table as fixed-width text (errors in %.3e, orders in %.2f)."""
    head = f"{'scheme':10s} {'n':>4s} {'val max':>10s} {'ord':>5s} {'val rms':>10s} {'ord':>5s} " \
           f"{'grad max':>10s} {'ord':>5s} {'grad rms':>10s} {'ord':>5s}"
    lines = [head]
    for r in rows:
        cells = []
        for k in ("value_max", "value_rms", "gradient_max", "gradient_rms"):
            o = r["order_" + k]
            cells.append(f"{r[k]:10.3e} {'' if o is None else f'{o:5.2f}':>5s}")
        lines.append(f"{r['scheme']:10s} {r['n']:4d} " + " ".join(cells))
    return "\n".join(lines)


class _MarschnerLobb:
    """Marschner-Lobb test function on [-1, 1]^3 (f_M = 6, alpha = 0.25):
    f = (1 - sin(pi z / 2) + alpha (1 + cos(2 pi f_M cos(pi r / 2)))) / (2 (1 + alpha)), r = sqrt(x^2 + y^2)."""

    bounds = (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)
    fm, alpha = 6.0, 0.25

    def value(self, p):
        p = np.asarray(p, dtype=np.float64)
        r = np.hypot(p[..., 0], p[..., 1])
        rho = np.cos(2 * np.pi * self.fm * np.cos(np.pi * r / 2))
        return (1 - np.sin(np.pi * p[..., 2] / 2) + self.alpha * (1 + rho)) / (2 * (1 + self.alpha))

    def gradient(self, p):
        p = np.asarray(p, dtype=np.float64)
        x, y, z = p[..., 0], p[..., 1], p[..., 2]
        r = np.hypot(x, y)
        # rho = cos(a), a = 2 pi fM cos(pi r / 2): d rho / dr = sin(a) 2 pi fM sin(pi r / 2) pi / 2, and
        # d r / dx = x / r; sin(pi r / 2) / r is smooth at r = 0 (limit pi / 2)
        a = 2 * np.pi * self.fm * np.cos(np.pi * r / 2)
        safe = np.where(r > 1e-12, r, 1.0)
        s_over_r = np.where(r > 1e-12, np.sin(np.pi * r / 2) / safe, np.pi / 2)
        drho_over_r = np.sin(a) * 2 * np.pi * self.fm * s_over_r * np.pi / 2
        c = self.alpha / (2 * (1 + self.alpha))
        gx = c * drho_over_r * x
        gy = c * drho_over_r * y
        gz = -np.cos(np.pi * z / 2) * (np.pi / 2) / (2 * (1 + self.alpha))
        return np.stack([gx, gy, gz], axis=-1)


class _SmoothProduct:
    """A smooth (entire) test field on [-1, 1]^3: f = exp(x / 2) sin(1.3 y + 0.4) cos(0.9 z - 0.2)."""

    bounds = (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)

    def value(self, p):
        p = np.asarray(p, dtype=np.float64)
        return np.exp(p[..., 0] / 2) * np.sin(1.3 * p[..., 1] + 0.4) * np.cos(0.9 * p[..., 2] - 0.2)

    def gradient(self, p):
        p = np.asarray(p, dtype=np.float64)
        ex, sy, cz = np.exp(p[..., 0] / 2), np.sin(1.3 * p[..., 1] + 0.4), np.cos(0.9 * p[..., 2] - 0.2)
        return np.stack([0.5 * ex * sy * cz, 1.3 * ex * np.cos(1.3 * p[..., 1] + 0.4) * cz,
                         -0.9 * ex * sy * np.sin(0.9 * p[..., 2] - 0.2)], axis=-1)
