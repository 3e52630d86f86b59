"""The geometry of GoTools ``.g2`` bounded surfaces (:mod:`.nurbs_g2`): exact NURBS forms of GoTools' planes,
cylinders, spheres, cones, tori and discs and of its lines, circles and ellipses [PieglTiller1997, A7.1], and
the trim loops of a bounded surface (parameter curves kept, space curves pulled back within the loop's
epsilon). See :mod:`.nurbs_g2` for the format."""

from __future__ import annotations

import warnings

import numpy as np

from ..nurbs import NurbsSurface, TrimCurve
from ..nurbs.pullback import _Inverter, curve_evaluator, pull_back
from .nurbs_common import checked

_G2_NAMES = {100: "100 (spline curve)", 120: "120 (line)", 130: "130 (circle)", 140: "140 (ellipse)",
             150: "150 (bounded curve)", 200: "200 (spline surface)", 210: "210 (bounded surface)",
             250: "250 (plane)", 260: "260 (cylinder)", 261: "261 (linear extrusion)", 270: "270 (sphere)",
             280: "280 (cone)", 290: "290 (torus)", 291: "291 (surface of revolution)", 292: "292 (disc)",
             700: "700 (spline volume)"}


#: A trim curve up to this many loop epsilons off its surface is still pulled back, as closely as its distance
#: allows, and the face drawn with the deviation reported (as the Rhino reader does for edges); farther, it is
#: not the surface's boundary and the face is skipped by name.
_CURVE_SLACK = 100.0
#: Distances below this fraction of the surface's size are rounding, whatever the epsilon.
_ROUNDING = 1e-10


class _Obj:
    """One parsed G2 object (or sub-object of a 210 / 150): its class, first line and fields."""

    def __init__(self, cls: int, line: int, **data):
        self.cls, self.line, self.data = cls, line, data


class _Unsupported(Exception):
    """A 210 this reader cannot turn into a patch: ``args[0]`` is the key it is counted under in ``skipped``,
    ``args[1]`` (optional) the details for the warning."""


def _g2_name(cls: int) -> str:
    return _G2_NAMES.get(cls, f"{cls}")



def _spline_surface(path, entity: str, obj: _Obj, name: str) -> NurbsSurface:
    d = obj.data
    if d["dim"] != 3:
        raise ValueError(f"{path}: {entity}: only 3-D surfaces are read, this one has dimension {d['dim']}.")
    (nu, ou, U), (nv, ov, V) = d["bases"]
    H = d["cps"].reshape(nv, nu, -1).transpose(1, 0, 2)  # u varies fastest in the file
    W = H[..., 3].copy() if d["rational"] else None
    if W is not None and not (W > 0).all():
        i, j = (int(v) for v in np.argwhere(~(W > 0))[0])
        raise ValueError(f"{path}: {entity}: weights must be positive and finite; weights[{i}, {j}] = "
                         f"{float(W[i, j])!r} (a zero or negative weight puts the surface at infinity).")
    P = H[..., :3] / W[..., None] if W is not None else H[..., :3]
    return checked(path, entity, lambda: NurbsSurface((ou - 1, ov - 1), (U, V), P, W, name=name))



# ---- curves to NURBS ------------------------------------------------------------------------------
def _frame(d: dict):
    """GoTools' spanning vectors of a circle/ellipse: 3-D ``x`` made normal to the (unit) normal, ``y = n x x``;
    2-D ``y`` = ``x`` turned by +90 degrees; both unit."""
    x = np.asarray(d["xaxis"], dtype=np.float64)
    if d["dim"] == 3:
        n = np.asarray(d["normal"], dtype=np.float64)
        n = n / np.linalg.norm(n)
        x = x - (x @ n) * n
        y = np.cross(n, x)
    else:
        y = np.array([-x[1], x[0]])
    return x / np.linalg.norm(x), y / np.linalg.norm(y)


def _arc(centre, x, y, r1: float, r2: float, a0: float, a1: float):
    """Exact rational quadratic arc ``c + r1 cos(a) x + r2 sin(a) y`` for a from a0 to a1 (either way), in pieces
    of at most 90 degrees: the affine image of the unit-circle arc [PieglTiller1997, A7.1]."""
    span = a1 - a0
    k = max(1, int(np.ceil(abs(span) / (np.pi / 2) - 1e-12)))
    half = span / (2 * k)
    pts, w = [], []
    for i in range(k):
        s = a0 + 2 * i * half
        m = s + half
        if i == 0:
            pts.append((np.cos(s), np.sin(s)))
            w.append(1.0)
        pts += [(np.cos(m) / np.cos(half), np.sin(m) / np.cos(half)), (np.cos(s + 2 * half), np.sin(s + 2 * half))]
        w += [np.cos(half), 1.0]
    cs = np.array(pts)
    P = centre + (r1 * cs[:, :1]) * x + (r2 * cs[:, 1:]) * y
    inner = np.repeat(np.arange(1, k) / k, 2)
    knots = np.concatenate([[0.0] * 3, inner, [1.0] * 3])
    return 2, knots, P, np.array(w)


def _curve_nurbs(obj: _Obj, what: str, t0=None, t1=None):
    """``(degree, knots, points, weights or None)`` of a G2 curve (exact), optionally of its piece [t0, t1]."""
    d = obj.data
    if obj.cls == 150:
        return _curve_nurbs(d["curve"], what, d["start"], d["end"])
    if obj.cls == 100:
        (n, order, U), = d["bases"]
        H = d["cps"]
        if t0 is not None and (t0, t1) != (U[order - 1], U[n]):
            raise _Unsupported("210 (bounded surface) with a trim curve 150 (bounded curve) on part of a 100 (spline "
                               "curve)", f"{what} (line {obj.line}): the part [{t0:g}, {t1:g}] of the domain "
                               f"[{U[order - 1]:g}, {U[n]:g}]")
        if not d["rational"]:
            return order - 1, U, H, None
        W = H[:, -1]
        if not (W > 0).all():
            raise ValueError(f"{what} (line {obj.line}): weights must be positive, got {W.min()!r}.")
        return order - 1, U, H[:, :-1] / W[:, None], W
    s, e = d["domain"]
    b0, b1 = d["bounds"]
    t0, t1 = (s, e) if t0 is None else (t0, t1)
    if not (np.isfinite(t0) and np.isfinite(t1)) or t0 == t1:
        raise _Unsupported(f"210 (bounded surface) with a trim curve {_g2_name(obj.cls)} without finite distinct "
                           "parameter bounds", f"{what} (line {obj.line}): [{t0:g}, {t1:g}]")

    def inner(t):  # GoTools' point(): reversal, then the domain mapped onto the bounds
        t = s + e - t if d["reversed"] else t
        return b0 + (t - s) * (b1 - b0) / (e - s) if np.isfinite(b0) and np.isfinite(b1) else t

    a0, a1 = inner(t0), inner(t1)
    if obj.cls == 120:
        P = np.array([d["location"] + a * np.asarray(d["direction"]) for a in (a0, a1)])
        return 1, np.array([t0, t0, t1, t1], dtype=np.float64), P, None
    x, y = _frame(d)
    r = d["radii"]
    return _arc(np.asarray(d["centre"], dtype=np.float64), x, y, r[0], r[-1], a0, a1)


# ---- bounded surfaces ------------------------------------------------------------------------------
def _plane(d: dict):
    """``(point(u, v) -> xyz, to_uv(xyz) -> (u, v), (umin, umax, vmin, vmax) or None, normal)`` of a 250 plane in
    its outer parameters (swap, then the domain mapped onto the bounds: GoTools' Plane::point)."""
    loc = np.asarray(d["location"], dtype=np.float64)
    n = np.asarray(d["normal"], dtype=np.float64)
    n = n / np.linalg.norm(n)
    x = np.asarray(d["xaxis"], dtype=np.float64)
    x = x - (x @ n) * n
    x = x / np.linalg.norm(x)
    y = np.cross(n, x)
    y = y / np.linalg.norm(y)
    b = np.asarray(d["bounds"], dtype=np.float64)
    dom = np.asarray(d.get("domain", b), dtype=np.float64)
    bounded = b.size == 4
    scale = (b[[1, 3]] - b[[0, 2]]) / (dom[[1, 3]] - dom[[0, 2]]) if bounded else np.ones(2)
    lo_b, lo_d = (b[[0, 2]], dom[[0, 2]]) if bounded else (np.zeros(2), np.zeros(2))
    sw = [1, 0] if d["swapped"] else [0, 1]

    def point(uv):
        uv = np.asarray(uv, dtype=np.float64)[..., sw]
        ab = lo_b + (uv - lo_d) * scale
        return loc + ab[..., :1] * x + ab[..., 1:] * y

    def to_uv(X):
        r = np.asarray(X, dtype=np.float64) - loc
        ab = np.stack([r @ x, r @ y], axis=-1)
        return (lo_d + (ab - lo_b) / scale)[..., sw]

    box = None
    if bounded:
        box = np.concatenate([dom[0:2], dom[2:4]]) if not d["swapped"] else np.concatenate([dom[2:4], dom[0:2]])
    return point, to_uv, box, n, loc


class _Revolved:
    """A 260 cylinder, 270 sphere, 280 cone, 290 torus or 292 disc: GoTools' ``point(u, v)`` in the outer
    parameters (swap, then the domain mapped linearly onto the bounds), all of the form ``location + rho (cos a
    x + sin a y) + h z`` with ``y = z x x`` (the disc: radius u, angle v), and its exact NURBS form: the
    profile ``(rho, h)`` (a line, or a circular arc for the sphere and torus) revolved by a rational quadratic
    arc [PieglTiller1997, A7.1, A8.1], knots spread over the bounds so that its parameters stay near the
    angles. The NURBS patch runs in the outer parameter order, so its normal is GoTools' normal."""

    def __init__(self, cls: int, d: dict):
        self.cls, self.d = cls, d
        z = np.asarray(d["zaxis"], dtype=np.float64)
        self.z = z / np.linalg.norm(z)
        x = np.asarray(d["xaxis"], dtype=np.float64)
        x = x - (x @ self.z) * self.z
        self.x = x / np.linalg.norm(x)
        y = np.cross(self.z, self.x)
        self.y = y / np.linalg.norm(y)
        self.loc = np.asarray(d["location"], dtype=np.float64)
        b = np.asarray(d["bounds"], dtype=np.float64)
        self.bounds = b if b.size == 4 else np.concatenate([b, [np.nan, np.nan]])  # cylinder/cone open in v
        dom = np.asarray(d.get("domain", b), dtype=np.float64)
        self.dom = dom if dom.size == 4 else np.concatenate([dom, [np.nan, np.nan]])
        self.order = [1, 0] if d["swapped"] else [0, 1]

    def internal(self, uv) -> np.ndarray:
        """GoTools' internal parameters (angle, height / latitude / radius) of outer ``uv`` (m, 2)."""
        ab = np.asarray(uv, dtype=np.float64)[..., self.order]
        b, dom = self.bounds, self.dom
        out = ab.copy()
        for k in range(2):
            if np.isfinite(b[2 * k]):
                scale = (b[2 * k + 1] - b[2 * k]) / (dom[2 * k + 1] - dom[2 * k])
                out[..., k] = b[2 * k] + (ab[..., k] - dom[2 * k]) * scale
        return out

    def _profile(self, t):
        d, c = self.d, self.cls
        if c == 260:
            return np.full_like(t, d["radius"]), t
        if c == 280:
            return d["radius"] + t * np.tan(d["angle"]), t
        if c == 270:
            return d["radius"] * np.cos(t), d["radius"] * np.sin(t)
        if c == 290:
            return d["major"] + d["minor"] * np.cos(t), d["minor"] * np.sin(t)
        return t, np.zeros_like(t)  # 292: the radius

    def point(self, uv) -> np.ndarray:
        ab = self.internal(uv)
        angle, t = (ab[..., 1], ab[..., 0]) if self.cls == 292 else (ab[..., 0], ab[..., 1])
        rho, h = self._profile(t)
        return (self.loc + rho[..., None] * (np.cos(angle)[..., None] * self.x + np.sin(angle)[..., None] * self.y)
                + h[..., None] * self.z)

    def height(self, X) -> np.ndarray:
        """The internal v of points on a cylinder or cone: their height along the axis."""
        return (np.asarray(X, dtype=np.float64) - self.loc) @ self.z

    def nurbs(self, name: str, vrange=None) -> NurbsSurface:
        b = self.bounds.copy()
        if not np.isfinite(b[2]):
            b[2:] = vrange
        k_angle, k_prof = (2, 0) if self.cls == 292 else (0, 2)
        a0, a1 = b[k_angle], b[k_angle + 1]
        t0, t1 = b[k_prof], b[k_prof + 1]
        if not (a0 < a1 <= a0 + 2 * np.pi * (1 + 1e-12)) or not t0 < t1:
            raise _Unsupported(f"210 (bounded surface) on {_g2_name(self.cls)} with an angle range over 2 pi or an "
                               "empty parameter range", f"parameter bounds {b.tolist()}")
        _, ka, C, wa = _arc(np.zeros(2), np.array([1.0, 0.0]), np.array([0.0, 1.0]), 1.0, 1.0, a0, a1)
        if self.cls in (270, 290):
            centre = np.array([0.0 if self.cls == 270 else self.d["major"], 0.0])
            r = self.d["radius"] if self.cls == 270 else self.d["minor"]
            _, kp, prof, wp = _arc(centre, np.array([1.0, 0.0]), np.array([0.0, 1.0]), r, r, t0, t1)
            kp = t0 + kp * (t1 - t0)
        else:
            rho, h = self._profile(np.array([t0, t1]))
            prof, wp, kp = np.column_stack([rho, h]), np.ones(2), np.array([t0, t0, t1, t1])
        ka = a0 + ka * (a1 - a0)
        P = (self.loc + prof[None, :, :1] * (C[:, None, :1] * self.x + C[:, None, 1:] * self.y)
             + prof[None, :, 1:] * self.z)  # (angle, profile, 3)
        W = wa[:, None] * wp[None, :]
        deg, knots = [2, 1 if len(wp) == 2 else 2], [ka, kp]
        if self.cls == 292:  # internal u is the radius
            P, W, deg, knots = P.transpose(1, 0, 2), W.T, deg[::-1], knots[::-1]
        if self.d["swapped"]:
            P, W, deg, knots = P.transpose(1, 0, 2), W.T, deg[::-1], knots[::-1]
        rational = not np.all(W == 1.0)
        return NurbsSurface(tuple(deg), tuple(knots), P, W if rational else None, name=name)

    def seed(self, uv) -> np.ndarray:
        """Near the NURBS parameters of outer ``uv``: the internal values in outer order."""
        return self.internal(uv)[..., self.order]


def _bounded_patch(path, entity: str, obj: _Obj, name: str):
    """A 210 as ``(NurbsSurface, loops, note)``; raises _Unsupported (the skipped key) for what is not read."""
    base = obj.data["surface"]
    plane = revolved = surf = None
    if base.cls == 200:
        surf = _spline_surface(path, f"{entity}'s underlying surface", base, name)
    elif base.cls in (250, 260, 270, 280, 290, 292):
        if base.data["dim"] != 3:
            raise ValueError(f"{path}: {entity}: only 3-D surfaces are read, this {_g2_name(base.cls)} has "
                             f"dimension {base.data['dim']}.")
        if base.cls == 250:
            plane = _plane(base.data)
        else:
            revolved = _Revolved(base.cls, base.data)
    else:
        raise _Unsupported(f"210 (bounded surface) on {_g2_name(base.cls)}")
    # First every loop's curves: parameter curves as they are, space curves on a plane mapped by the plane's
    # inverse (exact); the rest is pulled back once the patch is known.
    raw = []
    for i, (eps, curves) in enumerate(obj.data["loops"]):
        items = []
        for j, c in enumerate(curves):
            what = f"{path}: {entity}: loop {i} curve {j} (line {c.line})"
            pc, sc = c.data["pcurve"], c.data["scurve"]
            if pc is not None:
                if pc.data["dim"] != 2:
                    raise ValueError(f"{what}: the parameter curve has dimension {pc.data['dim']}, expected 2.")
                items.append(("uv" if revolved is None else "uv on revolved", _curve_nurbs(pc, what), what))
                continue
            if sc.data["dim"] != 3:
                raise ValueError(f"{what}: the space curve has dimension {sc.data['dim']}, expected 3.")
            deg, U, P, W = _curve_nurbs(sc, what)
            if plane is None:
                items.append(("xyz", (deg, U, P, W), what))
                continue
            point, to_uv, _, normal, loc = plane
            off = float(np.abs((P - loc) @ normal).max())
            if off > eps:
                raise ValueError(f"{what}: the space curve's control points are up to {off:.3g} off the plane "
                                 f"(loop epsilon {eps:g}); the curve does not lie on the bounded surface's plane.")
            items.append(("uv", (deg, U, to_uv(P), W), what))
        raw.append((eps, items))
    unbounded = ((plane is not None and plane[2] is None)
                 or (revolved is not None and not np.isfinite(revolved.bounds[2])))
    if unbounded and not raw:
        raise ValueError(f"{path}: {entity}: the underlying {_g2_name(base.cls)} is unbounded and the bounded surface "
                         "has no trim loops: it has no extent to draw.")
    if plane is not None:
        point, to_uv, box, _, _ = plane
        if box is None:  # an unbounded plane: the patch is the box of the trim curves' control points
            Q = np.concatenate([c[2] for _, items in raw for _, c, _ in items])
            box = np.array([Q[:, 0].min(), Q[:, 0].max(), Q[:, 1].min(), Q[:, 1].max()])
            if not (box[1] > box[0] and box[3] > box[2]):
                raise ValueError(f"{path}: {entity}: the trim curves of the unbounded plane span no area "
                                 f"(u {box[0]:g}..{box[1]:g}, v {box[2]:g}..{box[3]:g}).")
        corners = point(np.array([[[box[0], box[2]], [box[0], box[3]]], [[box[1], box[2]], [box[1], box[3]]]]))
        knots = ([box[0]] * 2 + [box[1]] * 2, [box[2]] * 2 + [box[3]] * 2)
        surf = checked(path, entity, lambda: NurbsSurface((1, 1), knots, corners, name=name))
    if revolved is not None:
        vrange = None
        if not np.isfinite(revolved.bounds[2]):  # a cylinder or cone open along its axis: the trims' heights
            h = np.concatenate([revolved.internal(c[2])[:, 1] if kind == "uv on revolved" else revolved.height(c[2])
                                for _, items in raw for kind, c, _ in items])
            vrange = (float(h.min()), float(h.max()))
        surf = revolved.nurbs(name, vrange)
    loops, pulled, bridged, beyond, inverter = [], [], [], [], None
    for i, (eps, items) in enumerate(raw):
        loop, reach = [], eps  # reach: the epsilon, or the deviation of a curve accepted beyond it
        for kind, (deg, U, P, W), what in items:
            if kind == "uv":
                loop.append([checked(path, what.split(": ", 1)[1], lambda: TrimCurve(deg, U, P, W))])
                continue
            f, dom, breaks = curve_evaluator(deg, U, P, W)
            if kind == "uv on revolved":  # the parameter curve mapped into space by GoTools' point()
                start = revolved.seed(f(np.array([dom[0]]))[0])
                g = f
                f = lambda t, g=g: revolved.point(g(t))  # noqa: E731
            else:
                start = None
                if loop:
                    last = loop[-1][-1]
                    start = last.evaluate([last.domain[1]])[0]
            if inverter is None:
                inverter = _Inverter(surf)
            try:
                r = pull_back(surf, f, dom, eps, name=what, breaks=breaks, start=start, strict=False,
                              max_distance=max(_CURVE_SLACK * eps, _ROUNDING * inverter.scale), inverter=inverter)
            except ValueError as err:
                raise _Unsupported(f"210 (bounded surface) with a trim curve more than {_CURVE_SLACK:g} x its loop's "
                                   "epsilon off the surface", str(err)) from None
            pulled.append(r.deviation)
            reach = max(reach, r.deviation)
            if r.deviation > eps:
                beyond.append(f"loop {i} curve {len(loop)}: {r.deviation:.3g} > epsilon {eps:g}"
                              + (f" ({r.note})" if r.note else ""))
            loop.append(list(r.curves))
        curves, gap = _closed_loop(surf, [c for group in loop for c in group], reach)
        if gap is not None:
            bridged.append(f"loop {i} gap {gap:.3g}")
        loops.append(curves)
    note = []
    if revolved is not None:
        note.append(f"{_g2_name(revolved.cls)} converted to NURBS")
    if pulled:
        note.append(f"{len(pulled)} trim curve(s) pulled back, max deviation {max(pulled):.3g}")
    if beyond:
        warnings.warn(f"{path}: {entity}: trim curves pulled back beyond their loop's epsilon, drawn with the best "
                      f"fit: {', '.join(beyond)}", UserWarning, stacklevel=3)
        note.append("beyond the epsilon: " + ", ".join(beyond))
    if bridged:
        warnings.warn(f"{path}: {entity}: loop(s) not closed within their epsilon, bridged by segments: "
                      f"{', '.join(bridged)}", UserWarning, stacklevel=3)
        note.append("open loops bridged: " + ", ".join(bridged))
    return surf, (loops or None), ", ".join(note)


def _clamped_start(c: TrimCurve) -> bool:
    return bool(np.all(c.knots[: c.degree + 1] == c.knots[0]))


def _clamped_end(c: TrimCurve) -> bool:
    return bool(np.all(c.knots[-c.degree - 1:] == c.knots[-1]))


def _closed_loop(surf: NurbsSurface, curves: list, eps: float):
    """The loop with each joint one point bit for bit (the even-odd test counts a shared end once): a curve's
    start moved onto the previous end where the two map within ``eps`` of each other in space, else the gap
    bridged by a segment. Returns ``(curves, largest bridged gap in space or None)``."""
    out = list(curves)
    (u0, u1), (v0, v1) = surf.domain
    worst = None
    inserted = []
    for k in range(len(out)):
        a_curve, b_curve = out[k], out[(k + 1) % len(out)]
        a = a_curve.evaluate([a_curve.domain[1]])[0]
        b = b_curve.evaluate([b_curve.domain[0]])[0]
        if np.array_equal(a, b):
            continue
        ends = np.clip(np.array([a, b]), [u0, v0], [u1, v1])
        gap = float(np.linalg.norm(np.diff(surf.evaluate(ends[:, 0], ends[:, 1]), axis=0)))
        if gap <= eps and _clamped_end(a_curve) and _clamped_start(b_curve):
            a = a_curve.control_points[-1]
            out[(k + 1) % len(out)] = TrimCurve(b_curve.degree, b_curve.knots,
                                                np.concatenate([a[None], b_curve.control_points[1:]]), b_curve.weights)
        else:
            inserted.append((k, TrimCurve(1, [0.0, 0.0, 1.0, 1.0], [a, b])))
            worst = gap if worst is None else max(worst, gap)
    for k, seg in reversed(inserted):
        out.insert(k + 1, seg)
    return out, worst
