"""Faces on analytic surfaces (cylinders, cones, spheres, tori, revolutions, extrusions, ...) whose edges run
along parameter lines, converted to B-spline faces exactly and fast, for :func:`.nurbs_step.shape_faces`.

Why not OpenCASCADE's ``BRepBuilderAPI_NurbsConvert`` alone: it converts the surface in microseconds
(``GeomConvert::SurfaceToBSplineSurface``) but then re-approximates every pcurve in the new parameters, some
18 ms a face, and turns a straight edge of a cylinder into a cubic of 433 poles. Most faces CAD systems write
have edges along parameter lines (the fillets, holes and corners of a machined part); for them the new
pcurves are known exactly, and this module builds them itself. Every other face goes to NurbsConvert.

How
---
OpenCASCADE converts these surfaces direction by direction: the B-spline ``B`` of a face on ``S`` over
``[u0, u1] x [v0, v1]`` is ``B(f(u), g(v)) = S(u, v)`` with monotone one-dimensional maps ``f`` and ``g``
onto the B-spline's domain (a line keeps its parameter, a circular arc is parametrized by the rational
quadratic, ``tan`` of the half angle [PieglTiller1997, sec. 7.5]). The maps are not taken on trust:

1. ``g`` at the needed ``v`` (the trims' ends, the bounds and the middle) by Newton's method on the
   B-spline's parameter line through ``u0`` (or ``u1``, whichever is not degenerate), then ``f`` on a ``v``
   line (``v0``, ``v1`` or the middle one, the least degenerate), each from the linear guess.
2. **Check** every needed ``u`` across the rows ``v0``, ``v_mid``, ``v1``, every needed ``v`` across the
   columns ``u0``, ``u_mid``, ``u1``, and the trims' ends: ``|B(f(u), g(v)) - S(u, v)| <= tol``, and ``f``,
   ``g`` increasing. Off the lines the maps were solved on, this tests that the conversion separates. ``tol``
   is the rounding of the two evaluations, ``E = gamma_(3(p+q)+7) (w_max / w_min) R`` (``R`` the largest
   control point coordinate; de Boor's algorithm in homogeneous coordinates, a convex combination at each of
   ``p + q`` levels [MainarPena1999; Higham2002, sec. 3.4], the division by the weight and the analytic
   surface's own rotation), carried over by the Newton solutions: ``tol = E (1 + 2 kappa_u + 2 kappa_v)``,
   ``kappa`` the largest ratio of the B-spline's speed at a checked point to its speed on the line the map was
   solved on (Newton stops when its step moves the point by less than ``E``, so the parameter errs by at most
   ``2 E / speed``).
3. **Trims.** An edge whose pcurve keeps ``v`` (or ``u``) constant maps to the straight segment between its
   mapped ends, exactly (``B(t, g(v)) = S(f^-1(t), v)``): a degree-1 :class:`~splinevis.nurbs.TrimCurve`. A
   pcurve that holds its coordinate only to the file's precision (a spread ``d`` of the pole coordinates)
   lies within ``d max |S_v|`` of that segment's image (both run inside the band ``g(v_min) .. g(v_max)``);
   it is taken when that is within the edge's own tolerance (``BRep_Tool::Tolerance``), the file's
   statement of how exact the edge is. An end beyond the face's parameter bounds by the file's precision
   (OpenCASCADE's bounds leave degenerate edges out) is moved onto them under the same condition (the
   overshoot times the speed there).

A face fails any of this (a pcurve off the parameter lines, such as a hole's circle in a plane; a conversion
that is not exact; Newton not converging): :func:`iso_face` returns None and the caller converts the face with
NurbsConvert, as before.
"""

from __future__ import annotations

import math

from ..nurbs import TrimCurve
from .nurbs_common import checked

__all__ = ["iso_face"]

#: Unit roundoff of float64 [Higham2002, sec. 2.1].
_U = 2.0 ** -53
#: Newton iterations before a map is given up (quadratic convergence needs a handful).
_NEWTON = 40


def _gamma(m: int) -> float:
    """``gamma_m = m u / (1 - m u)`` [Higham2002, sec. 3.4]."""
    return m * _U / (1.0 - m * _U)


def iso_face(face, path="", name: str = ""):
    """``(Geom_BSplineSurface, loops, tol)``: the face's surface converted exactly, its trim loops in the new
    parameters (lists of degree-1 :class:`~splinevis.nurbs.TrimCurve`, edges in the wires' order, reversed
    edges reversed), as :func:`.nurbs_step.shape_faces` reads them, and the bound ``tol`` the check held the
    maps to (module notes, 2); or None when the face is not one of these (module notes). ``path`` and ``name``
    prefix errors in the curves.

    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    >>> from OCP.TopAbs import TopAbs_FACE
    >>> from OCP.TopExp import TopExp_Explorer
    >>> from OCP.TopoDS import TopoDS
    >>> side = TopoDS.Face(TopExp_Explorer(BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape(), TopAbs_FACE).Current())
    >>> surf, loops, tol = iso_face(side)
    >>> surf.DynamicType().Name(), [[c.degree for c in loop] for loop in loops], tol < 1e-13
    ('Geom_BSplineSurface', [[1, 1, 1, 1]], True)
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.Geom import Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert
    from OCP.gp import gp_Pnt, gp_Vec

    surf = BRep_Tool.Surface_s(face)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    if not (u0 < u1 and v0 < v1):
        return None
    work = (gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec())  # OpenCASCADE's output arguments, reused
    edges = _edges(face, surf, (u0, u1, v0, v1), work)
    if edges is None:
        return None
    try:
        bs = GeomConvert.SurfaceToBSplineSurface_s(Geom_RectangularTrimmedSurface(surf, u0, u1, v0, v1))
    except Exception:  # noqa: BLE001 -- OpenCASCADE refuses: NurbsConvert decides
        return None
    ends = {uv for loop in edges for ab, _ in loop for uv in ab}
    maps = _maps(surf, bs, (u0, u1, v0, v1), ends, work)
    if maps is None:
        return None
    f, g, tol = maps
    loops = []
    for loop in edges:
        curves = []
        for (a, b), (t0, t1) in loop:
            pts = [(f[a[0]], g[a[1]]), (f[b[0]], g[b[1]])]
            knots = [t0, t0, t1, t1] if t0 < t1 else [0.0, 0.0, 1.0, 1.0]
            curves.append(checked(path, f"{name} trim curve", lambda k=knots, q=pts: TrimCurve(1, k, q)))
        loops.append(curves)
    return bs, loops, tol


def _speeds(surf, u, v, work):
    """``(|S_u|, |S_v|)`` at ``(u, v)``."""
    P, du, dv, _ = work
    surf.D1(u, v, P, du, dv)
    return du.Magnitude(), dv.Magnitude()


def _onto(surf, uv, bounds, tol, work):
    """``uv`` moved onto the face's parameter bounds when it lies outside (a pcurve's end beyond them by the
    file's precision: OpenCASCADE's bounds leave degenerate edges out), or None when that moves its point by
    more than ``tol`` (the distance bounded by the overshoot times the speed there)."""
    (u, v), (u0, u1, v0, v1) = uv, bounds
    cu, cv = min(max(u, u0), u1), min(max(v, v0), v1)
    if (cu, cv) == (u, v):
        return uv
    su, sv = _speeds(surf, u, v, work)
    return (cu, cv) if abs(cu - u) * su + abs(cv - v) * sv <= tol else None


def _edges(face, surf, bounds, work):
    """Per wire, per edge ``((start, end), (t0, t1))`` of its pcurve in the surface's parameters (``start`` and
    ``end`` in the wire's direction, moved onto the face's ``bounds`` if they lie beyond them by less than the
    edge's tolerance), or None when an edge's pcurve is missing or leaves its parameter line by more than the
    edge's tolerance (module notes, 3)."""
    from OCP.BRep import BRep_Tool
    from OCP.Geom2d import Geom2d_TrimmedCurve
    from OCP.Geom2dConvert import Geom2dConvert
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED, TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    out = []
    wires = TopExp_Explorer(face, TopAbs_WIRE)
    while wires.More():
        loop = []
        explorer = TopExp_Explorer(wires.Current(), TopAbs_EDGE)
        wires.Next()
        while explorer.More():
            edge = TopoDS.Edge(explorer.Current())
            explorer.Next()
            curve = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
            if curve is None:
                return None
            t0, t1 = BRep_Tool.Range_s(edge, face)
            if curve.DynamicType().Name() == "Geom2d_Line":
                poles = [curve.Value(t0).Coord(), curve.Value(t1).Coord()]
            else:
                try:
                    bs = Geom2dConvert.CurveToBSplineCurve_s(Geom2d_TrimmedCurve(curve, t0, t1))
                except Exception:  # noqa: BLE001
                    return None
                poles = [bs.Pole(i).Coord() for i in range(1, bs.NbPoles() + 1)]
            xs, ys = [p[0] for p in poles], [p[1] for p in poles]
            # the coordinate held (the smaller spread) and the one run through, monotonically
            spread_u, spread_v = max(xs) - min(xs), max(ys) - min(ys)
            run = ys if spread_u < spread_v else xs
            steps = [b - a for a, b in zip(run, run[1:])]
            if not (all(s >= 0 for s in steps) or all(s <= 0 for s in steps)):
                return None
            a, b = poles[0], poles[-1]
            tol = BRep_Tool.Tolerance_s(edge)
            held = min(spread_u, spread_v)
            if held > 0.0:  # |S_u| (|S_v|) at the edge's ends and middle, times the spread
                mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
                if held * max(_speeds(surf, x, y, work)[spread_u >= spread_v] for x, y in (a, b, mid)) > tol:
                    return None
            a, b = _onto(surf, a, bounds, tol, work), _onto(surf, b, bounds, tol, work)
            if a is None or b is None:
                return None
            if edge.Orientation() == TopAbs_REVERSED:
                a, b = b, a
            loop.append(((a, b), (t0, t1)))
        out.append(loop)
    return out


def _maps(surf, bs, bounds, ends, work):
    """``(f, g, tol)``: dicts of the B-spline parameters of the trims' ``ends`` (and of the check values) and the
    bound they were checked to, or None when the check fails (module notes, 1-2)."""
    u0, u1, v0, v1 = bounds
    um, vm = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    us = sorted({u0, um, u1, *(u for u, _ in ends)})
    vs = sorted({v0, vm, v1, *(v for _, v in ends)})
    U0, U1, W0, W1 = bs.Bounds()
    R, wmin, wmax = 0.0, math.inf, 0.0
    for i in range(1, bs.NbUPoles() + 1):
        for j in range(1, bs.NbVPoles() + 1):
            x, y, z = bs.Pole(i, j).Coord()
            w = bs.Weight(i, j)
            R = max(R, abs(x), abs(y), abs(z))
            wmin, wmax = min(wmin, w), max(wmax, w)
    E = _gamma(3 * (bs.UDegree() + bs.VDegree()) + 7) * (wmax / wmin) * R
    # g on the column u0 or u1, the faster one (not a pole); f on the row v0, v1 or vm, the fastest
    col, Ucol = (u0, U0) if _speeds(surf, u0, vm, work)[1] >= _speeds(surf, u1, vm, work)[1] else (u1, U1)
    g = _solve(bs.UIso(Ucol), [surf.Value(col, v) for v in vs], vs, (v0, v1), (W0, W1), E, work)
    if g is None:
        return None
    g, gspeed = g
    row = max((v0, v1, vm), key=lambda v: _speeds(surf, um, v, work)[0])
    f = _solve(bs.VIso(g[row]), [surf.Value(u, row) for u in us], us, (u0, u1), (U0, U1), E, work)
    if f is None:
        return None
    f, fspeed = f
    # the check: every needed u across the rows v0, vm, v1, every needed v across the columns, the trims' ends
    points = {(u, v) for u in us for v in (v0, vm, v1)} | {(u, v) for u in (u0, um, u1) for v in vs} | ends
    P, du, dv, _ = work
    worst, kappa_u, kappa_v = 0.0, 0.0, 0.0
    for u, v in points:
        S = surf.Value(u, v)
        bs.D1(f[u], g[v], P, du, dv)
        worst = max(worst, S.Distance(P))
        kappa_u = max(kappa_u, du.Magnitude() / fspeed)
        kappa_v = max(kappa_v, dv.Magnitude() / gspeed)
    tol = E * (1.0 + 2.0 * kappa_u + 2.0 * kappa_v)
    if not worst <= tol:
        return None
    return f, g, tol


def _solve(curve, targets, params, ends, domain, E, work):
    """``({param: t}, min speed)``: the parameters ``t`` of ``curve`` (a Geom_BSplineCurve) at the points
    ``targets`` of the original parameters ``params``, by Newton's method on ``|C(t) - X|^2`` from the linear
    guess (``ends`` onto ``domain``) kept in the domain; None when a solution does not converge or the map is
    not increasing (beyond the solutions' own error)."""
    (a, b), (lo, hi) = ends, domain
    P, d1, d2, _ = work
    out, slowest = {}, math.inf
    for x, X in zip(params, targets):
        X = X.Coord()
        t = min(max(lo + (x - a) / (b - a) * (hi - lo), lo), hi)
        for _ in range(_NEWTON):
            curve.D2(t, P, d1, d2)
            (px, py, pz), (ax, ay, az), (bx, by, bz) = P.Coord(), d1.Coord(), d2.Coord()
            rx, ry, rz = px - X[0], py - X[1], pz - X[2]
            g2 = ax * ax + ay * ay + az * az + rx * bx + ry * by + rz * bz
            if not g2 > 0.0:
                return None
            new = min(max(t - (rx * ax + ry * ay + rz * az) / g2, lo), hi)
            moved = abs(new - t) * math.sqrt(ax * ax + ay * ay + az * az)
            t = new
            if moved <= E:
                break
        else:
            return None
        curve.D1(t, P, d1)
        slowest = min(slowest, d1.Magnitude())
        out[x] = t
    values = [out[x] for x in sorted(out)]
    if not slowest > 0.0:
        return None
    slack = 2.0 * E / slowest  # what each solution may err by (module notes, 2)
    if any(q < p - slack for p, q in zip(values, values[1:])):
        return None
    return out, slowest
