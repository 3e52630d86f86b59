"""Pre-filtering of height grids before spline fitting.

Measured elevation data (lidar, photogrammetry, scanned DEMs) carries sample noise that an interpolating
spline reproduces faithfully: every bump becomes a ripple of the surface, its normals and its shading.
A light low-pass filter before fitting removes it. :func:`smooth_heights` applies the separable binomial
filter ``[1, 2, 1] / 4`` along x and then along y, ``passes`` times, with the border replicated.

It is the first product user of the pass runner :mod:`splinevis.gl.passes`: on the GPU each direction is
one pass of ``glsl/passes/binomial3.glsl`` and all passes run as one chain with the intermediate grids
kept on the GPU. The numpy twin (``backend="numpy"``, float64) is the reference the GPU result is tested
against and the CPU fallback.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._validation import check_choice, check_finite
from ..errors import OpenGLUnavailableError
from ..io.heights import HeightGrid

__all__ = ["smooth_heights", "BINOMIAL3_SHADER"]

#: The pass shader (one direction of the filter), under ``glsl/``.
BINOMIAL3_SHADER = "passes/binomial3.glsl"

_BACKENDS = {"gl", "numpy"}


def smooth_heights(heights, passes: int = 1, *, backend: str = "gl"):
    """Smooth a height grid with the binomial filter ``[1, 2, 1] / 4`` in x, then y, ``passes`` times.

    At the borders the missing neighbour is replaced by the edge sample (clamping), so a constant grid
    stays constant and a plane stays a plane inside the border. The filter is linear with non-negative
    weights summing to one: it never leaves the range of the input.

    Parameters
    ----------
    heights : (ny, nx) array_like or HeightGrid
        ``heights[j, i]`` with rows along y; finite values; any size from 1 x 1.
    passes : int, default 1
        Number of repetitions (``>= 0``); 0 returns the heights unchanged (as float64, on every backend).
    backend : {"gl", "numpy"}, default "gl"
        ``"gl"``: one chain of ``2 * passes`` GPU passes in float32. The grid is shifted by the midpoint
        ``c`` of its range before the upload and back after the readback (in float64; exact for a linear
        filter whose weights sum to one), so the float32 rounding error scales with the relief
        ``max |h - c|``, not with ``|h|``: heights of 5e6 m with centimetre relief keep their
        centimetres. The error is at most ``(1 + 4 * passes) * 2**-24 * max|h - c|`` (one rounding of the
        upload, two additions per direction and pass) plus float64 rounding. A grid wider or taller than
        the GPU's ``GL_MAX_TEXTURE_SIZE`` (16384 on Mesa llvmpipe) raises a ValueError; it is not tiled.
        ``"numpy"``: the same filter in float64 on the CPU (the reference; no OpenGL needed).

    Returns
    -------
    (ny, nx) float64 ndarray, or HeightGrid
        A HeightGrid for a HeightGrid input, with the same spacing, origin, source, crs and units.

    Raises
    ------
    ValueError
        For a non-2-D or empty grid, non-finite heights, a negative ``passes``, an unknown backend, or a
        grid larger than the GPU's texture size limit.
    TypeError
        For a ``passes`` that is not an integer.
    OpenGLUnavailableError
        With ``backend="gl"`` when no OpenGL context can be made (use ``backend="numpy"``).

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.terrain.prefilter import smooth_heights
    >>> smooth_heights(np.array([[0.0, 4.0, 0.0]]))
    array([[1., 2., 1.]])
    >>> smooth_heights(np.array([[0.0, 4.0, 0.0]]), backend="numpy")
    array([[1., 2., 1.]])
    """
    grid = heights if isinstance(heights, HeightGrid) else None
    h = _checked_heights(grid.heights if grid is not None else heights)
    if isinstance(passes, bool) or not isinstance(passes, (int, np.integer)):
        raise TypeError(f"passes must be an integer >= 0 (the number of repetitions of the filter); "
                        f"got {type(passes).__name__} {passes!r}.")
    if passes < 0:
        raise ValueError(f"passes must be >= 0 (the number of repetitions of the filter); got {passes}. "
                         "Use passes=0 for no smoothing.")
    check_choice(backend, "backend", _BACKENDS)
    if passes == 0:
        out = h.copy()
    elif backend == "numpy":
        out = _smooth_numpy(h, int(passes))
    else:
        out = _smooth_gl(h, int(passes))
    return dataclasses.replace(grid, heights=out) if grid is not None else out


def _checked_heights(heights) -> np.ndarray:
    try:
        h = np.array(heights, dtype=np.float64)  # a copy: the result never aliases the caller's array
    except (TypeError, ValueError) as exc:
        raise TypeError(f"heights must be a 2-D array of real numbers or a HeightGrid; could not convert "
                        f"{type(heights).__name__}: {exc}") from None
    if h.ndim != 2:
        raise ValueError(f"heights must be a 2-D array (ny, nx) or a HeightGrid; got shape {h.shape}. "
                         "Pass one band of a multi-band raster, e.g. heights[:, :, 0].")
    if h.size == 0:
        raise ValueError(f"heights must have at least 1 x 1 samples; got shape {h.shape}.")
    try:
        check_finite(h, "heights")
    except ValueError as exc:
        raise ValueError(f"{exc} Fill gaps first, e.g. splinevis.io.read_heights(..., fill='nearest').") from None
    return h


def _smooth_numpy(h: np.ndarray, passes: int) -> np.ndarray:
    """The float64 twin of the GPU chain: same operations, same order, clamped borders."""
    for _ in range(passes):
        for axis in (1, 0):  # x (along a row) first, then y, like the GPU passes
            p = np.pad(h, [(1, 1) if a == axis else (0, 0) for a in range(2)], mode="edge")
            lo = p[:, :-2] if axis == 1 else p[:-2, :]
            hi = p[:, 2:] if axis == 1 else p[2:, :]
            h = (0.25 * lo + 0.25 * hi) + 0.5 * h
    return h


def _smooth_gl(h: np.ndarray, passes: int) -> np.ndarray:
    from ..gl.context import max_texture_size
    from ..gl.passes import Pass, run_passes

    try:
        limit = max_texture_size()
    except OpenGLUnavailableError as exc:
        raise OpenGLUnavailableError(f"{exc} smooth_heights: pass backend='numpy' to smooth on the CPU.") from None
    if max(h.shape) > limit:
        raise ValueError(
            f"heights has shape {h.shape} (rows, columns), larger than this GPU's GL_MAX_TEXTURE_SIZE "
            f"{limit}; smooth_heights does not tile: use backend='numpy', or smooth tiles that overlap by "
            "passes samples and drop the overlap."
        )
    # Filter h - c, c the midpoint of the range: float32 then carries the relief, not the absolute height.
    c = 0.5 * (float(h.min()) + float(h.max()))
    x_step = Pass(BINOMIAL3_SHADER, {"sv_src": "h"}, "h", uniforms={"sv_axis": (1, 0)})
    y_step = Pass(BINOMIAL3_SHADER, {"sv_src": "h"}, "h", uniforms={"sv_axis": (0, 1)})
    out = run_passes([x_step, y_step] * passes, {"h": (h - c).astype(np.float32)})
    return out[:, :, 0].astype(np.float64) + c
