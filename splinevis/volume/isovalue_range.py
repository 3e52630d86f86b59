"""What a volume spline can reach: the range of its values bounded by its BB coefficients, and whether the
isosurface of an isovalue is empty, proven non-empty, or neither (then the user is told).

Two facts of the BB form on each tetrahedron [Farin2002, ch. 17; Kalbe2008, sec. 4] decide it:

* **Convex hull**: the spline's values on a tetrahedron lie between the smallest and the largest of its BB
  coefficients. So the spline's range lies in ``[min, max]`` of all coefficients (:func:`coefficient_range`),
  and an isovalue outside it has an empty isosurface: proven, no picture can show anything.
* **Vertex interpolation**: the coefficient of index ``d e_i`` is the spline's value at vertex ``i``. So the
  largest vertex coefficient is a value the spline takes: the spline's maximum lies in ``[max vertex
  coefficient, max coefficient]`` (the same for the minimum). When the vertices of the tetrahedra that can hold
  the isosurface carry values on both sides of the isovalue, the spline (continuous on the box, which is
  connected) takes the isovalue between them: the isosurface is proven non-empty.

Between the two (an isovalue inside the coefficients' range but no vertex value beyond it) the isosurface may
be empty, or a few points or small bubbles: the quasi-interpolant [Roessl2004] smooths a peak below its
sample, so an isovalue at the data's maximum, or at 0.95 of it, can lie above everything the spline reaches
while inside the data's range. :func:`isovalue_verdict` tells the three cases apart;
:func:`splinevis.volume.program.check_isovalue_in_range` turns them into an error (outside the data's range
and empty) or a warning giving the spline's range and the options (``prefilter="interpolate"`` makes the
spline reach the samples: [Kalbe2008] with the interpolating prefilter of :mod:`.prefilter`).

Cost: the coefficients of every cube would be 24 m values per cube; :func:`coefficient_range` computes them
only for the cubes whose float32 bounds (:meth:`VolumeSpline.cube_ranges`, which enclose the float64
coefficients) can still beat the running extreme, largest bound first: a few chunks on smooth data.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..bb import simplex as bb

__all__ = ["coefficient_range", "vertex_value_range", "IsovalueVerdict", "isovalue_verdict"]


def _extreme(spline, bound, sign: float, chunk: int) -> float:
    """The largest (``sign = 1``) or smallest (``-1``) BB coefficient of all cubes, float64: cubes visited by
    their float32 bound ``bound`` (``(nz, ny, nx)``; it encloses their coefficients), best bound first, until no
    remaining bound can beat the running extreme."""
    key = (sign * bound.astype(np.float64)).ravel()
    order = np.argsort(-key, kind="stable")
    best = -np.inf
    nz, ny, nx = bound.shape
    for s in range(0, len(order), chunk):
        idx = order[s:s + chunk]
        if key[idx[0]] < best:  # sorted: no cube from here on can hold a larger coefficient
            break
        k, j, i = np.unravel_index(idx, (nz, ny, nx))
        coef = spline.cube_coefficients(np.column_stack([i, j, k]))
        best = max(best, float((sign * coef).max()))
    return sign * best


def coefficient_range(spline, *, chunk: int = 4096) -> tuple:
    """``(lo, hi)``: the smallest and largest BB coefficient of the spline (float64): its values lie within
    (module notes: convex hull). Cached on the spline.

    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> coefficient_range(VolumeSpline(x, "quadratic", order="zyx"))  # linear data and padding: x over the domain
    (-0.5, 5.5)
    """
    cached = getattr(spline, "_coefficient_range", None)
    if cached is None:
        lo, hi = spline.cube_ranges()
        cached = (_extreme(spline, lo, -1.0, chunk), _extreme(spline, hi, 1.0, chunk))
        spline._coefficient_range = cached
    return cached


def _vertex_slots(spline) -> np.ndarray:
    """Indices, among a tetrahedron's ``m`` BB coefficients, of the four at its vertices (``d e_i``)."""
    d = spline.degree
    index = bb.index_of(d, 3)
    return np.array([index[tuple(d if q == i else 0 for q in range(4))] for i in range(4)])


def vertex_value_range(spline, relevant, *, stop_at: float | None = None, chunk: int = 32768) -> tuple:
    """``(lo, hi)`` of the spline's values at the vertices of the tetrahedra of ``relevant`` (a
    :class:`~splinevis.volume.model.Relevant`): values the spline takes (module notes: vertex interpolation);
    ``(nan, nan)`` when there are none. ``stop_at``: stop as soon as values on both sides of it are found (the
    range of the tetrahedra seen so far is returned; it proves an isosurface non-empty).

    >>> from splinevis.volume.model import VolumeSpline
    >>> z, y, x = np.mgrid[0:6, 0:6, 0:6].astype(float)
    >>> s = VolumeSpline(x, "quadratic", order="zyx")
    >>> vertex_value_range(s, s.relevant(2.25))  # x = 2.25 lies in the cube of sample 2: x in [1.5, 2.5]
    (1.5, 2.5)
    """
    cubes, masks = relevant.cubes, relevant.masks
    if len(cubes) == 0:
        return float("nan"), float("nan")
    slots = _vertex_slots(spline)
    lo, hi = np.inf, -np.inf
    bits = np.int64(1) << np.arange(24, dtype=np.int64)
    for s in range(0, len(cubes), chunk):
        coef = spline.cube_coefficients(cubes[s:s + chunk])[:, :, slots]  # (n, 24, 4)
        use = (masks[s:s + chunk, None] & bits[None, :]) != 0  # the relevant tetrahedra only
        v = coef[use]
        lo, hi = min(lo, float(v.min())), max(hi, float(v.max()))
        if stop_at is not None and lo < stop_at < hi:
            break
    return lo, hi


@dataclass(frozen=True)
class IsovalueVerdict:
    """What is known of the isosurface ``s = isovalue`` before drawing it (:func:`isovalue_verdict`).

    ``status``: ``"non-empty"`` (proven: vertex values on both sides), ``"empty"`` (proven: outside the
    coefficients' range, no tetrahedron can hold it) or ``"unproven"`` (may be empty, a few points or small
    bubbles); ``data_range``: of the samples; ``coefficient_range``: encloses every value of the spline;
    ``vertex_range``: values the spline takes at the vertices of the tetrahedra that can hold it (NaN when
    there are none; when proven non-empty, of the tetrahedra checked until the proof); ``tetrahedra``: how many
    can hold it. ``coefficient_range`` is computed only when not proven non-empty (else NaN): it costs the
    coefficients of the cubes near the extremes.

    >>> v = IsovalueVerdict(0.9, "empty", (0.0, 1.0), (0.0, 0.78), (float("nan"),) * 2, 0)
    >>> v.status, v.isovalue > v.coefficient_range[1]  # above everything the spline reaches
    ('empty', True)
    """

    isovalue: float
    status: str
    data_range: tuple
    coefficient_range: tuple
    vertex_range: tuple
    tetrahedra: int


def isovalue_verdict(surface) -> IsovalueVerdict:
    """Decide (module notes) whether the isosurface of an :class:`~splinevis.volume.isosurface.Isosurface` is
    empty, proven non-empty, or unproven.

    >>> from splinevis.volume.model import VolumeSpline
    >>> from splinevis.volume.isosurface import Isosurface
    >>> spike = np.zeros((5, 5, 5)); spike[2, 2, 2] = 1.0  # one sample of 1 among zeros
    >>> s = VolumeSpline(spike)  # the quasi-interpolant spreads it: its peak is 1/4, at the spike's centre
    >>> coefficient_range(s), [isovalue_verdict(Isosurface(s, v)).status for v in (0.1, 0.25, 0.5)]
    ((0.0, 0.25), ['non-empty', 'unproven', 'empty'])
    """
    spline, iso = surface.spline, float(surface.isovalue)
    rel = surface.relevant
    tets = int(sum(bin(int(m)).count("1") for m in rel.masks))
    vrange = vertex_value_range(spline, rel, stop_at=iso)
    if vrange[0] < iso < vrange[1]:
        return IsovalueVerdict(iso, "non-empty", tuple(float(v) for v in spline.value_range),
                               (float("nan"), float("nan")), vrange, tets)
    crange = coefficient_range(spline)
    status = "empty" if tets == 0 or not crange[0] <= iso <= crange[1] else "unproven"
    return IsovalueVerdict(iso, status, tuple(float(v) for v in spline.value_range), crange, vrange, tets)
