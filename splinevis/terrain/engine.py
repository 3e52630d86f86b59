"""The stencil engine shared by every terrain scheme: one weight matrix applied to a window of heights
around each cell.

Every scheme is linear in ``z`` and translation invariant, so one engine serves all of them: a rectangular
window of the (padded) grid around each cell, flattened to ``S`` values, times a weight matrix ``W`` of
shape ``(S, 30)`` (15 coefficients of T0, then 15 of T1), done as a matrix product over sliding windows
(:func:`numpy.lib.stride_tricks.sliding_window_view`) in chunks of rows. Heights are padded by cubic
extrapolation where a window reaches outside the grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import as_float64_array


@dataclass(frozen=True)
class _Stencil:
    """A scheme's weights on a rectangular window of data points around a cell."""

    x0: int      # window's first data offset (x) relative to the cell corner (in data indices)
    y0: int
    kw: int      # window width/height in data points
    kh: int
    step: int    # data points per cell (4 for C0)
    W: np.ndarray  # (kh * kw, 30); row a * kw + b <-> offset (x0 + b, y0 + a)

    def pads(self):
        """(left, right, bottom, top) padding the window needs beyond the grid."""
        lo_x, lo_y = max(0, -self.x0), max(0, -self.y0)
        hi_x = max(0, self.x0 + self.kw - 1 - self.step)
        hi_y = max(0, self.y0 + self.kh - 1 - self.step)
        return lo_x, hi_x, lo_y, hi_y


def _offsets(x0, y0, kw, kh):
    """Data offsets of a window, row by row (x fastest): ``(x0 + b, y0 + a)``."""
    return [(x0 + b, y0 + a) for a in range(kh) for b in range(kw)]


def _check_height_grid(z):
    """``z`` as a 2-D float64 array of finite heights; ValueError naming the first non-finite value."""
    z = as_float64_array(z, "z (heights)", finite=False)
    if z.ndim != 2:
        raise ValueError(f"z (heights) must be a 2-D array of shape (ny, nx) with z[j, i] at index point (i, j); "
                         f"got {z.ndim}-D shape {z.shape}.")
    bad = ~np.isfinite(z)
    if bad.any():
        r, c = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"z (heights) must be finite; found {int(bad.sum())} non-finite value(s), the first, "
                         f"{float(z[r, c])!r}, at row {r}, column {c} (z[{r}, {c}], index point x={c}, y={r}).")
    return z


def _pad_cubic(z, lo_x, hi_x, lo_y, hi_y):
    """Pad by cubic extrapolation f[-1] = 4 f[0] - 6 f[1] + 4 f[2] - f[3] (x first, then y)."""
    ny, nx = z.shape
    out = np.empty((ny + lo_y + hi_y, nx + lo_x + hi_x))
    out[lo_y:lo_y + ny, lo_x:lo_x + nx] = z
    rows = slice(lo_y, lo_y + ny)
    for k in range(lo_x - 1, -1, -1):
        c = out[rows, k + 1:k + 5]
        out[rows, k] = 4 * c[:, 0] - 6 * c[:, 1] + 4 * c[:, 2] - c[:, 3]
    for k in range(lo_x + nx, lo_x + nx + hi_x):
        c = out[rows, k - 4:k]
        out[rows, k] = 4 * c[:, 3] - 6 * c[:, 2] + 4 * c[:, 1] - c[:, 0]
    for k in range(lo_y - 1, -1, -1):
        c = out[k + 1:k + 5]
        out[k] = 4 * c[0] - 6 * c[1] + 4 * c[2] - c[3]
    for k in range(lo_y + ny, lo_y + ny + hi_y):
        c = out[k - 4:k]
        out[k] = 4 * c[3] - 6 * c[2] + 4 * c[1] - c[0]
    return out


_CHUNK_CELLS = 1 << 13   # cells per gather (np.take) of the stencil values
# OpenBLAS runs a GEMM on one thread when M * N * K <= 65536 * 4; larger skinny products (K = S <= 30,
# N = 30) got *slower* with its threads on a loaded 2-core machine. So the products are kept below that
# size and the two cores are used by two Python threads working on alternate row chunks instead.
_GEMM_SINGLE = 65536 * 4
_THREADS = 2


def _apply(z, st: _Stencil):
    """coef[j, i] = W^T (heights at the cell's stencil points), for all cells, in chunks of rows."""
    lo_x, hi_x, lo_y, hi_y = st.pads()
    zp = _pad_cubic(z, lo_x, hi_x, lo_y, hi_y) if (lo_x or hi_x or lo_y or hi_y) else np.ascontiguousarray(z)
    ny, nx = z.shape
    return _apply_padded(zp, st, (ny - 1) // st.step, (nx - 1) // st.step, (lo_x, lo_y))


def _apply_padded(zp, st: _Stencil, ncy, ncx, corner, threads=_THREADS):
    """The cells ``(ncy, ncx)`` of an already padded grid ``zp`` whose cell (0, 0) has its lower-left corner at
    ``zp[corner[1], corner[0]]`` (the out-of-core tiles call this on a tile plus its halo, ``threads=1``)."""
    zp = np.ascontiguousarray(zp)
    lo_x, lo_y = corner
    # Only the stencil points with a nonzero weight are gathered: a sliding window of the padded grid,
    # read through flat indices: cell (i, j)'s corner is (step i + lo_x, step j + lo_y) in the padded grid,
    # its window starts at corner + (x0, y0) (never negative: lo_x >= -x0, lo_y >= -y0).
    keep = np.flatnonzero(np.any(st.W != 0.0, axis=1))
    offs = np.array(_offsets(st.x0, st.y0, st.kw, st.kh))[keep] - (st.x0, st.y0)  # >= 0: window-relative
    W = np.ascontiguousarray(st.W[keep])
    S = len(keep)
    wp = zp.shape[1]
    zflat = zp.reshape(-1)
    rows = max(1, min(ncy, _CHUNK_CELLS // max(ncx, 1)))
    jj, ii = np.meshgrid(np.arange(rows), np.arange(ncx), indexing="ij")
    rel = ((st.step * jj * wp + st.step * ii).reshape(-1, 1) + (offs[:, 1] * wp + offs[:, 0])[None, :])
    out = np.empty((ncy, ncx, 2, 15))
    flat = out.reshape(ncy * ncx, 30)
    sub = max(16, _GEMM_SINGLE // (30 * S))

    def work(r0):
        r1 = min(ncy, r0 + rows)
        m = (r1 - r0) * ncx
        base = (st.step * r0 + lo_y + st.y0) * wp + lo_x + st.x0  # window start of cell (0, r0)
        blk = np.take(zflat[base:], rel[:m])
        dst = flat[r0 * ncx:r1 * ncx]
        for k in range(0, m, sub):
            np.matmul(blk[k:k + sub], W, out=dst[k:k + sub])

    starts = range(0, ncy, rows)
    if ncy * ncx >= 4 * _CHUNK_CELLS and threads > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(threads) as ex:
            list(ex.map(work, starts))
    else:
        for r0 in starts:
            work(r0)
    return out
