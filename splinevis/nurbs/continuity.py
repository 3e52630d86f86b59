"""Continuity across the seams of a multi-patch NURBS model: positional gap (G0), normal angle (G1) and jump
of the normal curvature across the seam (G2), measured in float64 at points along each shared boundary.

Seams are found, not declared: each patch's four boundary curves are sampled and two boundaries form a seam
when their samples coincide (same or opposite direction) within ``match`` (relative to the model's size).
At every sample the three measures are [Farin2002, ch. 14 (geometric continuity)]:

* ``gap``: ``|S_a - S_b|`` between the points of equal arc-length fraction;
* ``angle``: the angle between the unit normals, orientation ignored (degrees);
* ``curvature_jump``: ``|kappa_a - kappa_b|``, the normal curvatures of both patches in the direction
  across the seam (``c = n x T``, T the boundary tangent), with the normals oriented alike.

A seam is G2 when all three are within tolerance, G1 when gap and angle are, G0 when the gap is, else open.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .basis import at_fraction
from .surface import NurbsSurface

__all__ = ["Seam", "find_seams", "seam_lines", "classify", "normal_curvature", "CLASS_COLORS"]

#: Colour of each continuity class in :func:`seam_lines` (RGB in [0, 1]).
CLASS_COLORS = {"G2": (0.1, 0.7, 0.2), "G1": (0.95, 0.8, 0.1), "G0": (0.95, 0.45, 0.05), "open": (0.85, 0.0, 0.0)}
_SIDES = ("u=u0", "u=u1", "v=v0", "v=v1")


@dataclass
class Seam:
    """One shared boundary between patches ``a`` and ``b`` with its measures per sample.

    >>> from datasets_synthetic.nurbs_joins import joined_pair
    >>> s = find_seams(joined_pair("G0", a=1.0))[0]
    >>> s.level, round(float(s.angle.max()), 6)  # slopes 0 and 1 meet at 45 degrees
    ('G0', 45.0)
    """

    a: int
    side_a: str
    b: int
    side_b: str
    points: np.ndarray
    gap: np.ndarray
    angle: np.ndarray
    curvature_jump: np.ndarray
    level: str = "open"

    def summary(self) -> dict:
        """Largest values and the class.

        >>> s = Seam(0, "u=u1", 1, "u=u0", np.zeros((2, 3)), np.zeros(2), np.array([0.0, 0.5]), np.zeros(2), "G1")
        >>> s.summary()["max_angle_deg"]
        0.5
        """
        return {"patches": (self.a, self.b), "sides": (self.side_a, self.side_b), "level": self.level,
                "max_gap": float(self.gap.max()), "max_angle_deg": float(self.angle.max()),
                "max_curvature_jump": float(self.curvature_jump.max())}


def _boundary_params(s: NurbsSurface, side: str, t: np.ndarray):
    (u0, u1), (v0, v1) = s.domain
    if side.startswith("u"):
        u = np.full_like(t, u0 if side.endswith("0") else u1)
        return u, at_fraction(v0, v1, t)
    v = np.full_like(t, v0 if side.endswith("0") else v1)
    return at_fraction(u0, u1, t), v


def normal_curvature(SKL: np.ndarray, n: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Normal curvature ``II(c) / I(c)`` in tangent directions ``c`` (3-D, one per point) with respect to the
    unit normals ``n``, from derivatives ``SKL`` (as :meth:`NurbsSurface.derivatives`, order 2); ``c`` is
    written as ``du S_u + dv S_v`` by the 2 x 2 normal equations (vectorized) [DoCarmo1976, sec. 3-2].

    >>> SKL = np.zeros((1, 3, 3, 3)); SKL[0, 1, 0] = [1, 0, 0]; SKL[0, 0, 1] = [0, 1, 0]
    >>> SKL[0, 2, 0] = [0, 0, 2.0]  # z = u^2: curvature 2 along x, 0 along y
    >>> normal_curvature(np.repeat(SKL, 2, 0), np.array([[0, 0, 1.0]] * 2), np.array([[3.0, 0, 0], [0, 1.0, 0]]))
    array([2., 0.])
    """
    Su, Sv = SKL[:, 1, 0], SKL[:, 0, 1]
    E, F, G = (np.einsum("ij,ij->i", a, b) for a, b in ((Su, Su), (Su, Sv), (Sv, Sv)))
    cu, cv = np.einsum("ij,ij->i", c, Su), np.einsum("ij,ij->i", c, Sv)
    det = E * G - F * F
    with np.errstate(invalid="ignore", divide="ignore"):
        du, dv = (G * cu - F * cv) / det, (E * cv - F * cu) / det
    L, M, N = (np.einsum("ij,ij->i", SKL[:, k, l], n) for k, l in ((2, 0), (1, 1), (0, 2)))
    second = L * du * du + 2 * M * du * dv + N * dv * dv
    with np.errstate(invalid="ignore", divide="ignore"):
        return second / np.einsum("ij,ij->i", c, c)


def classify(gap, angle, jump_rel, size: float, tol_gap: float, tol_angle: float, tol_curv: float) -> str:
    """The class of a seam from its samples: ``open`` when a gap exceeds ``tol_gap * size``, ``G0`` when an
    angle (degrees) exceeds ``tol_angle``, ``G1`` when a relative curvature jump exceeds ``tol_curv``, else
    ``G2``.

    >>> classify([0.0], [0.01], [0.5], 1.0, 1e-6, 0.05, 1e-3)
    'G1'
    """
    if np.max(gap) > tol_gap * size:
        return "open"
    if np.max(angle) > tol_angle:
        return "G0"
    if np.max(jump_rel) > tol_curv:
        return "G1"
    return "G2"


def _cross_curvature(s: NurbsSurface, u, v, along_u: bool, n_ref):
    """Normal curvature across the boundary, the normal oriented like ``n_ref``; and the oriented normal."""
    SKL = s.derivatives(u, v, 2)
    Su, Sv = SKL[:, 1, 0], SKL[:, 0, 1]
    n = s.normal(u, v)  # unit; the limit normal at a pole
    sign = np.where(np.einsum("ij,ij->i", n, n_ref) < 0, -1.0, 1.0)
    n *= sign[:, None]
    T = Sv if along_u else Su  # the boundary's tangent: a u = const side runs along v
    return normal_curvature(SKL, n, np.cross(n, T)), n


def find_seams(surfaces, samples: int = 33, match: float = 1e-6, tol_gap: float = 1e-6,
               tol_angle_deg: float = 0.05, tol_curvature: float = 1e-3) -> list:
    """Seams between the patches of ``surfaces`` (a list of NurbsSurface or a NurbsModel's ``surfaces``).

    ``match`` and ``tol_gap`` are relative to the model's size (bounding-box diagonal), ``tol_curvature``
    relative to the larger of the two curvatures plus one over that size.

    Examples
    --------
    >>> from datasets_synthetic.nurbs_joins import joined_pair
    >>> [s.level for s in find_seams(joined_pair("G1"))]  # z = x^2/2 meets z = -x^2/2: tangent, curvature jumps
    ['G1']
    """
    surfaces = list(surfaces)
    P = np.concatenate([s.control_points.reshape(-1, 3) for s in surfaces])
    size = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0))) or 1.0
    t = np.linspace(0.0, 1.0, samples)
    edges = []
    for k, s in enumerate(surfaces):
        for side in _SIDES:
            u, v = _boundary_params(s, side, t)
            pts = s.evaluate(u, v)
            if np.ptp(pts, axis=0).max() <= match * size:
                continue  # a collapsed boundary (a pole): a point, not a seam
            edges.append((k, side, u, v, pts))
    seams = []
    for i in range(len(edges)):
        for j in range(i + 1, len(edges)):
            ka, sa, ua, va, pa = edges[i]
            kb, sb, ub, vb, pb = edges[j]
            if ka == kb:
                continue
            dist = [np.abs(pa - pb).max(), np.abs(pa - pb[::-1]).max()]
            rev = bool(dist[1] < dist[0])
            # coincident boundaries, or boundaries only near each other (a gap to report) within 1 % of the size
            if min(dist) <= max(match, 1e-2) * size:
                ubb, vbb = (ub[::-1], vb[::-1]) if rev else (ub, vb)
                seams.append(_measure(surfaces, ka, sa, ua, va, kb, sb, ubb, vbb, size,
                                      tol_gap, tol_angle_deg, tol_curvature))
    return seams


def _measure(surfaces, ka, sa, ua, va, kb, sb, ub, vb, size, tol_gap, tol_angle, tol_curv) -> Seam:
    A, B = surfaces[ka], surfaces[kb]
    pa, pb = A.evaluate(ua, va), B.evaluate(ub, vb)
    na = A.normal(ua, va)
    ka_c, na = _cross_curvature(A, ua, va, sa.startswith("u"), na)
    kb_c, nb = _cross_curvature(B, ub, vb, sb.startswith("u"), na)
    gap = np.linalg.norm(pa - pb, axis=-1)
    angle = np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", na, nb)), -1.0, 1.0)))
    # across the seam the two patches' "across" directions point opposite ways (n x T with T along the seam
    # in both): the normal curvature of a direction and of its opposite are equal, so compare directly
    jump = np.abs(ka_c - kb_c)
    scale = np.maximum(np.maximum(np.abs(ka_c), np.abs(kb_c)), 1.0 / size)
    level = classify(gap, angle, jump / scale, size, tol_gap, tol_angle, tol_curv)
    return Seam(ka, sa, kb, sb, 0.5 * (pa + pb), gap, angle, jump, level)


def seam_lines(seams):
    """A pyvista PolyData of the seams as polylines, with point array ``level`` (0 G2, 1 G1, 2 G0, 3 open)
    and ``rgb`` colours from :data:`CLASS_COLORS`, to draw over the surfaces (``add_mesh(..., rgb=True)``).

    >>> s = Seam(0, "u=u1", 1, "u=u0", np.array([[0.0, 0, 0], [0, 1, 0]]), np.zeros(2), np.zeros(2), np.zeros(2), "G2")
    >>> lines = seam_lines([s])
    >>> lines.n_points, lines.point_data["level"].tolist()
    (2, [0, 0])
    """
    import pyvista as pv

    order = list(CLASS_COLORS)
    pts, cells, level, rgb = [], [], [], []
    start = 0
    for s in seams:
        m = len(s.points)
        pts.append(s.points)
        cells.append(np.concatenate([[m], start + np.arange(m)]))
        level += [order.index(s.level)] * m
        rgb += [CLASS_COLORS[s.level]] * m
        start += m
    poly = pv.PolyData(np.concatenate(pts), lines=np.concatenate(cells)) if pts else pv.PolyData()
    if pts:
        poly.point_data["level"] = np.asarray(level)
        poly.point_data["rgb"] = (np.asarray(rgb) * 255).astype(np.uint8)
    return poly
