"""The C2 terrain schemes: the quartic box spline with directions (1,0), (0,1), (1,1) each twice, with the
data as coefficients (``C2``, smoothing) or with a cubic-exact prefilter (``C2-cubic``)."""

from __future__ import annotations

import functools

import numpy as np

from .cell import _IDX, _MI
from .engine import _offsets, _Stencil

# 24 x the BB coefficients on T0 of the translates M(. - j) of the quartic box spline with directions
# (1,0), (0,1), (1,1) each twice (from the notes; verified by tests: partition of unity, C2, M(0) = 1/2).
_BOX_T0 = {
    (-1, -1): (2, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    (-1, 0): (2, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0),
    (0, -1): (2, 3, 1, 4, 1, 0, 3, 1, 0, 0, 2, 1, 0, 0, 0),
    (0, 0): (12, 12, 12, 8, 10, 8, 4, 6, 6, 4, 2, 3, 4, 3, 2),
    (0, 1): (2, 1, 3, 0, 1, 4, 0, 0, 1, 3, 0, 0, 0, 1, 2),
    (1, -1): (0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 0),
    (1, 0): (2, 4, 3, 8, 6, 4, 12, 10, 6, 3, 12, 12, 8, 4, 2),
    (1, 1): (2, 3, 4, 4, 6, 8, 3, 6, 10, 12, 2, 4, 8, 12, 12),
    (1, 2): (0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2),
    (2, 0): (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 1, 0, 0, 0),
    (2, 1): (0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 3, 4, 3, 2),
    (2, 2): (0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 2),
}


def _box_weights():
    """{offset j: (30,) weights} of M(. - j) on T0 and T1 of the cell at the origin."""
    swap_q = [_IDX[(int(a[0]), int(a[2]), int(a[1]))] for a in _MI]  # T1 (a,b,c) <- T0 (a,c,b)
    out = {}
    for (jx, jy), row in _BOX_T0.items():
        out.setdefault((jx, jy), np.zeros(30))[:15] += np.array(row, float) / 24.0
        # T1 is the mirror image of T0 under x <-> y (with vertices 1, 2 exchanged):
        # coefficient (a,b,c) of M(. - j) on T1 = coefficient (a,c,b) of M(. - swap(j)) on T0.
        out.setdefault((jy, jx), np.zeros(30))[15:] += np.array(row, float)[swap_q] / 24.0
    return out


@functools.lru_cache(maxsize=None)
def _c2():
    """The C2 scheme: the box spline with the heights as coefficients, on the window ``[-1, 2]^2``."""
    offs = _offsets(-1, -1, 4, 4)
    W = np.zeros((16, 30))
    for j, w in _box_weights().items():
        W[offs.index(j)] += w
    return _Stencil(-1, -1, 4, 4, 1, W)


#: The cubic-exact prefilter of C2-cubic: c_j = 3/2 z_j - 1/12 (sum of z at the 6 mesh neighbours).
_PREFILTER = {(0, 0): 1.5, **{n: -1.0 / 12.0 for n in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)]}}


@functools.lru_cache(maxsize=None)
def _c2_cubic():
    """The C2-cubic scheme: the box spline with prefiltered coefficients, on the window ``[-2, 3]^2``."""
    offs = _offsets(-2, -2, 6, 6)
    W = np.zeros((36, 30))
    for j, w in _box_weights().items():
        for n, p in _PREFILTER.items():
            W[offs.index((j[0] + n[0], j[1] + n[1]))] += p * w
    return _Stencil(-2, -2, 6, 6, 1, W)
