"""Shading averaged over a pixel's footprint, the float64 twins of ``glsl/lib/effects/footprint.glsl`` (the
stripes of reflection lines, isophotes and highlight lines) and of the filtered specular of
``glsl/lib/effects/lights.glsl`` (:func:`toksvig_factor`).

A stripe effect shades by a step function of a smooth stripe coordinate ``x`` (dark where ``fract(x) < 1/2``).
One sample per pixel aliases it wherever a stripe is narrower than about two pixels (a moire on a teapot's
spout, sawtooth where reflection lines bunch up). Filtering the step analytically over the pixel, as shaders
filter procedural pulses [ApodacaGritz2000, ch. 11], removes that: over a box of width ``w`` (in units of
``x``) the average is the difference of the step's antiderivative

    B(x) = floor(x) / 2 + max(fract(x) - 1/2, 0)

at the box's ends divided by ``w``. The box's width is the footprint of a square pixel in ``x``:
``w = |dx/dX| + |dx/dY|``, the support of a linear ``x`` over the pixel (what GLSL's ``fwidth`` gives). A box
over ``m + r`` periods (``0 <= r < 1``) holds ``m / 2`` bright plus between ``max(0, r - 1/2)`` and
``min(r, 1/2)``, so the average lies within ``min(r, 1 - r) / (2 w) <= 1 / (4 w)`` of the mean ``1/2``
(:func:`mean_deviation_bound`): a stripe pattern finer than the pixel fades to grey.

Why our own code: a closed formula of two lines, which has to match the shader's operation for operation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["stripe_bright", "stripe_width", "mean_deviation_bound", "float32_bound", "toksvig_factor", "MIN_WIDTH",
           "MAX_WIDTH"]

#: Footprints below this (stripe units) use the plain step; above :data:`MAX_WIDTH` (or not finite) the mean.
#: The same constants as ``SV_STRIPE_MIN_WIDTH`` / ``SV_STRIPE_MAX_WIDTH`` in ``glsl/lib/effects/footprint.glsl``.
MIN_WIDTH = 1.0 / 1024.0
MAX_WIDTH = 1048576.0


def _integral(x):
    return 0.5 * np.floor(x) + np.maximum(x - np.floor(x) - 0.5, 0.0)


def stripe_bright(x, w, antialias: bool = True) -> np.ndarray:
    """Share of bright (0 dark .. 1 bright) of the stripe coordinate ``x`` over a footprint of width ``w``
    (the module docstring's box average; the plain step ``fract(x) >= 1/2`` where ``antialias`` is False or
    ``w < MIN_WIDTH``). Float64; arrays broadcast.

    Examples
    --------
    >>> stripe_bright([0.25, 0.75], 0.0).tolist()   # the step: dark, bright
    [0.0, 1.0]
    >>> stripe_bright(0.5, 0.5).item()              # a box astride an edge: half of each
    0.5
    >>> stripe_bright(0.3, 10.0).item(), stripe_bright(0.3, 10.0, antialias=False).item()  # ten stripes a pixel
    (0.5, 0.0)
    """
    x = np.asarray(x, dtype=np.float64)
    w = np.asarray(w, dtype=np.float64)
    frac = x - np.floor(x)
    step = np.where(frac < 0.5, 0.0, 1.0)
    if not antialias:
        return np.broadcast_to(step, np.broadcast_shapes(x.shape, w.shape)).copy()
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        box = (_integral(frac + 0.5 * w) - _integral(frac - 0.5 * w)) / w
    out = np.where(w >= MIN_WIDTH, box, step)
    return np.where(np.less(w, MAX_WIDTH), out, 0.5)


def stripe_width(dx_dX, dx_dY) -> np.ndarray:
    """The footprint ``|dx/dX| + |dx/dY|`` of a square pixel in the stripe coordinate, from its screen-space
    derivatives (GLSL's ``fwidth``).

    >>> stripe_width(0.3, -0.4).item()
    0.7
    """
    return np.abs(np.asarray(dx_dX, dtype=np.float64)) + np.abs(np.asarray(dx_dY, dtype=np.float64))


def mean_deviation_bound(w) -> np.ndarray:
    """Largest ``|stripe_bright(x, w) - 1/2|`` over all ``x``: ``1 / (4 w)`` (module docstring), capped at 1/2.

    >>> mean_deviation_bound([0.5, 4.0]).tolist()
    [0.5, 0.0625]
    """
    return np.minimum(0.25 / np.asarray(w, dtype=np.float64), 0.5)


def float32_bound(w) -> np.ndarray:
    """Bound on ``|GLSL float32 stripe_bright - float64 twin|`` for the same float32 inputs ``x, w`` with
    ``MIN_WIDTH <= w < MAX_WIDTH``: ``(4 / w + 8) u``, ``u = 2^-24``.

    Derivation, operation by operation: ``fract(x)`` is exact in float32 and ``w / 2`` too. Each end
    ``e = fract(x) +- w/2`` rounds by at most ``u |e| <= u (1 + w/2)``; ``B`` has slope at most 1 (it is
    continuous), and its own evaluation is exact but for the final sum, which rounds by ``u |B(e)| <= u (1 + w/4)``:
    ``u (2 + 3w/4)`` per end. The difference (at most ``w`` in size) rounds by ``u w``: the numerator is off by
    ``u (4 + 2.5 w)``, the quotient by that over ``w``, ``u (4 / w + 2.5)``, plus the division's 2.5 ulp (GLSL
    ES 3.0 sec. 4.5.1; the ulp of a share ``<= 1`` is at most ``2 u``): ``u (4 / w + 7.5)``.

    >>> bool(float32_bound(MIN_WIDTH) < 1 / 255)
    True
    """
    return (4.0 / np.asarray(w, dtype=np.float64) + 8.0) * 2.0**-24


def toksvig_factor(dn_dX, dn_dY, power) -> np.ndarray:
    """Toksvig's factor ``ft = |Na| / (|Na| + s (1 - |Na|))`` [Toksvig2005, eq. 4-5] for unit normals whose
    screen-space derivatives are ``dn_dX``, ``dn_dY`` (``(..., 3)``) and a Phong exponent ``s = power``: the
    highlight's exponent becomes ``ft s``, its height is scaled by ``(1 + ft s) / (1 + s)``.

    ``|Na|``, the length of the mean unit normal over the pixel, is ``1 - sigma^2 / 2`` to second order, with
    ``sigma^2 = E|n - n0|^2 = (|dn/dX|^2 + |dn/dY|^2) / 12`` for a normal varying linearly over a unit box (the
    variance of a uniform variable on ``[-1/2, 1/2]`` is 1/12).

    >>> float(toksvig_factor([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 40.0))   # a flat pixel: the highlight unchanged
    1.0
    >>> round(float(toksvig_factor([0.3, 0.0, 0.0], [0.0, 0.3, 0.0], 40.0)), 4)  # 0.3 rad a pixel: widened
    0.7679
    """
    dx = np.asarray(dn_dX, dtype=np.float64)
    dy = np.asarray(dn_dY, dtype=np.float64)
    variance = (np.einsum("...i,...i", dx, dx) + np.einsum("...i,...i", dy, dy)) / 12.0
    na = np.maximum(1.0 - variance / 2.0, 0.0)
    return na / (na + power * (1.0 - na))
