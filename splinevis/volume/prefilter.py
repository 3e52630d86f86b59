"""Prefiltered volume splines: the data the type-6 schemes read, chosen so that the spline reproduces
quadratics (``"local"``) or interpolates the samples (``"interpolate"``), beyond [Kalbe2008]; the plain
quasi-interpolant of the paper is ``"none"``. Cardinal prefiltering in the sense of [Unser1993]; see
docs/volume-schemes.md, "Prefiltered and interpolating splines".

Why our own: scipy.ndimage.spline_filter prefilters tensor-product B-splines (a separable recursive
filter); the type-6 schemes' value at a data point is a non-separable average of the padded data, whose
inverse no library provides.

The centre stencil
------------------
Every data point is the centre ``vQ`` of its cube, a vertex of all 24 tetrahedra, so the spline's value
there is the BB coefficient at ``vQ``, a fixed average ``K`` of the cube's 27-point data stencil
(:func:`centre_kernel`, read from the schemes' weight tables):

* quadratic: 1/4 at the centre, 1/8 at the 6 face neighbours; symbol
  ``K(w) = (1 + cos w1 + cos w2 + cos w3) / 4``;
* cubic: 3/8 at the centre, 1/12 at the 6 face and 1/96 at the 12 edge neighbours; symbol
  ``K(w) = 3/8 + (c1 + c2 + c3) / 6 + (c1 c2 + c2 c3 + c3 c1) / 24`` with ``ci = cos wi``.

Both have the second moment 1/4 per axis: for smooth ``f``, ``K f = f + (h^2 / 8) laplace f + O(h^4)``
(the shift ``x^2 -> x^2 + h^2/4`` of the schemes' doctests), which is why the plain schemes' values
converge at order 2 with a larger constant than trilinear interpolation.

The three prefilters
--------------------
* ``"none"``: the samples themselves ([Kalbe2008]).
* ``"local"``: ``d = 2 f - K f``, one step of the Neumann series of ``K^-1``. Then
  ``K d = f - (I - K)^2 f = f + O(h^4)``; ``I - K`` maps quadratics to constants and constants to 0, so the
  spline of ``d`` reproduces every quadratic exactly (the schemes map quadratic data to the quadratic plus
  the constant ``(h^2/8) laplace f``, which the correction removes). Values then converge at order 3, the
  full order of the quadratic space, gradients at order 2. ``d`` is a 7-point (quadratic) or 19-point
  (cubic) stencil of the padded samples: local, so tiles need one more halo layer.
* ``"interpolate"`` (cubic only): solve ``K pad(d) = f`` for ``d`` (GMRES, started from ``"local"``); the
  spline interpolates every sample. The cubic symbol is >= 0 with one zero, at ``w = (pi, pi, pi)``, where
  ``K ~ |w - (pi, pi, pi)|^2 / 24``: on an n-grid the system is invertible, with a condition number
  growing like ``n^2`` (the smallest symbol ~ ``pi^2 / (8 n^2)``), and the checkerboard component of noisy
  data is amplified by up to that factor. The cubic scheme does not reproduce cubics, so interpolating
  gains only constants over ``"local"`` (same orders, measured in tests/test_volume_prefilter.py).
  The quadratic symbol changes sign (``K = -1/2`` at ``(pi, pi, pi)``) and vanishes on the surface
  ``c1 + c2 + c3 = -1``: on a periodic grid of period 4 the data ``(-1)^i cos(pi j / 2) cos(pi k / 2)``
  give the value 0 at every data point, so interpolation with the quadratic super spline is not
  well-posed, and it is refused.

The padding (:data:`splinevis.volume.stencil.PADDINGS`) is applied to ``d``; ``"quadratic"`` or
``"cubic"`` padding keeps the orders up to the boundary.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .stencil import STENCIL, _check_volume, _pad, _stored_weights, check_padding

__all__ = ["PREFILTERS", "check_prefilter", "centre_kernel", "centre_symbol", "centre_values", "prefilter_data", "padded_data"]

#: Prefilters of the samples: the paper's plain scheme, the local quadratic-reproducing correction, and
#: interpolation (cubic scheme only).
PREFILTERS = ("none", "local", "interpolate")


@functools.lru_cache(maxsize=None)
def centre_kernel(scheme: str) -> np.ndarray:
    """(3, 3, 3) weights ``K[dz + 1, dy + 1, dx + 1]``: the spline's value at a data point as an average of
    the padded data around it (the BB coefficient at the cube centre, row 0 of the scheme's weights).

    >>> K = centre_kernel("quadratic")
    >>> float(K[1, 1, 1]), float(K[1, 1, 2]), float(K[0, 0, 1]), float(K.sum())
    (0.25, 0.125, 0.0, 1.0)
    >>> K = centre_kernel("cubic")
    >>> float(K[1, 1, 1]), float(K[1, 1, 2] * 12), float(K[0, 0, 1] * 96), float(K[0, 0, 0])
    (0.375, 1.0, 1.0, 0.0)
    """
    if scheme not in ("quadratic", "cubic"):
        raise ValueError(f"scheme must be 'quadratic' or 'cubic', got {scheme!r}.")
    row = _stored_weights(scheme)[0]  # domain point 0 is the cube centre vQ
    K = np.zeros((3, 3, 3))
    for (ox, oy, oz), w in zip(STENCIL, row):
        K[oz + 1, oy + 1, ox + 1] = w
    K.setflags(write=False)
    return K


def centre_symbol(scheme: str, w) -> np.ndarray:
    """The symbol ``K(w) = sum_o K_o cos(o . w)`` of :func:`centre_kernel` at frequencies ``w`` (..., 3).

    >>> K = centre_symbol("quadratic", [[np.pi, np.pi, np.pi], [np.pi, np.pi / 2, np.pi / 2]])
    >>> K.round(15).tolist()  # negative at the corner, zero on the surface cos w1 + cos w2 + cos w3 = -1
    [-0.5, 0.0]
    >>> centre_symbol("cubic", [[np.pi, np.pi, np.pi], [0.0, 0.0, 0.0]]).round(15).tolist()  # >= 0, zero at the corner
    [0.0, 1.0]
    """
    w = np.asarray(w, dtype=np.float64)
    K = centre_kernel(scheme)
    out = np.zeros(w.shape[:-1])
    for (ox, oy, oz) in STENCIL:
        k = K[oz + 1, oy + 1, ox + 1]
        if k:
            out = out + k * np.cos(ox * w[..., 0] + oy * w[..., 1] + oz * w[..., 2])
    return out


def centre_values(padded, scheme: str) -> np.ndarray:
    """The spline's values at the data points, ``(K * padded)`` on the interior: shape ``padded.shape - 2``.

    >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
    >>> centre_values(_pad(x ** 2, "quadratic"), "cubic")[0, 0]  # x^2 + 1/4: the schemes' shift
    array([0.25, 1.25, 4.25, 9.25])
    """
    P = np.asarray(padded, dtype=np.float64)
    K = centre_kernel(scheme)
    nz, ny, nx = (s - 2 for s in P.shape)
    out = np.zeros((nz, ny, nx))
    for dz in range(3):
        for dy in range(3):
            for dx in range(3):
                k = K[dz, dy, dx]
                if k:
                    out += k * P[dz:dz + nz, dy:dy + ny, dx:dx + nx]
    return out


def check_prefilter(prefilter) -> str:
    """``prefilter`` if it is one of :data:`PREFILTERS`, else ValueError.

    >>> check_prefilter("local")
    'local'
    """
    if prefilter not in PREFILTERS:
        raise ValueError(f"prefilter must be one of {PREFILTERS}, got {prefilter!r}.")
    return prefilter


def _check(scheme, prefilter, padding, shape):
    check_prefilter(prefilter)
    if prefilter == "interpolate" and scheme == "quadratic":
        raise ValueError(
            "prefilter='interpolate' needs scheme='cubic': the quadratic super spline's value at a data point, "
            "(1 + cos w1 + cos w2 + cos w3) / 4 in frequency, vanishes on a whole surface of frequencies, so no "
            "stable quadratic interpolant of the samples exists (docs/volume-schemes.md). Use prefilter='local' "
            "(reproduces quadratics, values of order 3) or scheme='cubic'.")
    check_padding(padding, shape)


def prefilter_data(values, scheme: str, prefilter: str = "local", padding: str = "quadratic", *,
                   rtol: float = 1e-13, progress: bool = False) -> np.ndarray:
    """The data ``d`` (same shape as ``values``) whose spline (padded by ``padding``) reproduces quadratics
    (``"local"``) or interpolates ``values`` (``"interpolate"``, cubic only); ``"none"`` returns a copy.

    ``"interpolate"`` solves ``K pad(d) = values`` by GMRES from the ``"local"`` data until the residual's
    2-norm is below ``rtol`` times that of the values (float64: the residual then sits a few units of
    roundoff times the condition number ~ n^2 above zero); a solve that does not get there raises
    RuntimeError with the residual reached.

    Examples
    --------
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> d = prefilter_data(x ** 2 + y * z, "quadratic", "local")
    >>> float(d[2, 2, 3]), float((x ** 2 + y * z)[2, 2, 3])  # the constant shift of x^2 removed
    (12.75, 13.0)
    >>> f = np.cos(x / 2) * np.sin(y / 3 + z / 4)
    >>> d = prefilter_data(f, "cubic", "interpolate", "cubic")
    >>> bool(np.abs(centre_values(_pad(d, "cubic"), "cubic") - f).max() < 1e-12)  # interpolates the samples
    True
    """
    f = _check_volume(values)
    _check(scheme, prefilter, padding, f.shape)
    if prefilter == "none":
        return f.copy()
    d = 2.0 * f - centre_values(_pad(f, padding), scheme)
    if prefilter == "local":
        return d
    return _interpolate(f, d, scheme, padding, rtol, progress)


def _interpolate(f, d0, scheme, padding, rtol, progress):
    from scipy.sparse.linalg import LinearOperator, gmres

    shape, N = f.shape, f.size

    def matvec(x):
        return centre_values(_pad(x.reshape(shape), padding), scheme).ravel()

    A = LinearOperator((N, N), matvec=matvec, dtype=np.float64)
    b = f.ravel()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(desc=f"interpolating {shape[2]}x{shape[1]}x{shape[0]} samples (GMRES)", unit="step")
    it = [0]

    def step(_):
        it[0] += 1
        if bar is not None:
            bar.update(1)

    maxiter = 20 + 4 * int(max(shape))  # GMRES needs O(sqrt(cond)) = O(n) iterations at worst
    x, info = gmres(A, b, x0=d0.ravel(), rtol=rtol, atol=0.0, restart=40, maxiter=maxiter, callback=step,
                    callback_type="pr_norm")
    if bar is not None:
        bar.close()
    res = float(np.linalg.norm(matvec(x) - b))
    scale = float(np.linalg.norm(b)) or 1.0
    if not math.isfinite(res) or res > 10 * rtol * scale:
        raise RuntimeError(f"interpolating the {shape} samples did not converge: relative residual {res / scale:.3g} "
                           f"after {it[0]} GMRES steps (goal {rtol:g}). Use prefilter='local'.")
    return x.reshape(shape)


def padded_data(values, scheme: str, prefilter: str = "none", padding: str = "linear", **options) -> np.ndarray:
    """The padded array ``(nz + 2, ny + 2, nx + 2)`` a scheme reads: ``pad(prefilter_data(values))``
    (:attr:`splinevis.volume.VolumeSpline.padded`; the GPU's data texture is it minus a reference value).

    >>> z, y, x = np.mgrid[0:4, 0:4, 0:4].astype(float)
    >>> padded_data(x, "quadratic").shape, float(padded_data(x, "quadratic")[1, 1, 0])  # linear padding
    ((6, 6, 6), -1.0)
    """
    return _padded(_check_volume(values), scheme, prefilter, padding, **options)


def _padded(f, scheme, prefilter, padding, **options):
    """:func:`padded_data` of a volume already checked (finite float64 3-D); the paper's case is exactly
    :func:`splinevis.volume.stencil._pad`."""
    _check(scheme, prefilter, padding, f.shape)
    d = f if prefilter == "none" else prefilter_data(f, scheme, prefilter, padding, **options)
    return _pad(d, padding)
