"""Rhino faces: every trimmed face drawn. The loop of a face on a closed surface closes whichever trim it
starts with (a seam edge's two uses on the two sides of the domain), edges off their surface by less than
100 model tolerances give the best loop with the measured deviation, farther ones an error saying what to
do, and the batched point inversion finds the exact feet across both seams of a torus.

The known values: the rhino3dm cylinder, sphere, quad sphere and cone faces have the domain's boundary as
their loop (their side faces are untrimmed, their loops are still there); on a surface scaled about the
centre by ``1 + e`` (cylinder: about its axis) every edge point is ``e R`` from it along the normal, so the
edge-to-surface distance is ``e R`` to rounding and the fitted loop can do no better than that and, by the
lenient criterion, no worse than ``e R + tol / 4`` at the test points.
"""

import numpy as np
import pytest

from splinevis.nurbs.exact import torus
from splinevis.nurbs.pullback import _Inverter, pull_back
from splinevis.nurbs.surface import NurbsSurface
from splinevis.nurbs.trim import inside, trim_pieces

EPS = np.finfo(float).eps


class _Loop:
    def __init__(self, trims):
        self.Trims = trims


class _Face:
    """A face with one loop of the given trims (what _pulled_loops reads of a face)."""

    def __init__(self, trims):
        self.Loops = [_Loop(trims)]


def faces():
    import rhino3dm

    P = rhino3dm.Point3d
    axis = rhino3dm.Line(P(0, 0, 0), P(0, 0, 1))
    cyl = rhino3dm.Cylinder(rhino3dm.Circle(P(0, 0, 0), 1.0), 2.0)
    yield "cylinder", rhino3dm.Brep.CreateFromCylinder(cyl, False, False), (0.0, 0.0, None), 1.0
    yield "sphere", rhino3dm.Brep.CreateFromSphere(rhino3dm.Sphere(P(0, 0, 0), 1.5)), (0.0, 0.0, 0.0), 1.5
    yield "cone", rhino3dm.Brep.CreateFromRevSurface(
        rhino3dm.RevSurface.Create(rhino3dm.LineCurve(P(1, 0, 0), P(0, 0, 2)), axis, 0.0, 2 * np.pi), False, False), \
        None, None


def scaled(s: NurbsSurface, centre, factor):
    """The surface scaled by ``factor`` about ``centre`` (a coordinate None: not scaled, e.g. along an axis)."""
    c = np.array([0.0 if x is None else x for x in centre])
    f = np.array([1.0 if x is None else factor for x in centre])
    return NurbsSurface(s.degree, s.knots, c + (s.control_points - c) * f, s.weights, name=s.name + " scaled")


def domain_loop_checks(s, loop, tol, name):
    """The loop runs along the domain's boundary (length: its perimeter) and holds the domain's inside."""
    dom = np.array(s.domain)
    (u0, u1), (v0, v1) = dom
    uu, vv = np.meshgrid(np.linspace(u0, u1, 65), np.linspace(v0, v1, 65))
    D = s.derivatives(uu.ravel(), vv.ravel(), 1)
    speed = np.minimum(np.linalg.norm(D[:, 1, 0], axis=1), np.linalg.norm(D[:, 0, 1], axis=1))
    slack = tol / speed[speed > 1e-7 * speed.max()].min()  # the parameter error of a point within tol
    length = 0.0
    for c in loop:
        uv = c.evaluate(np.linspace(*c.domain, 33))
        assert ((uv >= dom[:, 0] - slack) & (uv <= dom[:, 1] + slack)).all(), (name, uv[[0, -1]])
        side = np.abs(np.stack([uv[:, 0] - u0, uv[:, 0] - u1, uv[:, 1] - v0, uv[:, 1] - v1])).min(axis=0)
        assert side.max() <= slack, (name, side.max(), slack)
        length += np.linalg.norm(np.diff(uv, axis=0), axis=1).sum()
    assert abs(length - 2 * np.ptp(dom, axis=1).sum()) <= 4 * len(loop) * slack, (name, length)
    inner = dom[:, 0] + (dom[:, 1] - dom[:, 0]) * np.random.default_rng(7).uniform(0.01, 0.99, (50, 2))
    assert inside(trim_pieces([[loop]]), 0, inner[:, 0], inner[:, 1]).all(), name


def test_a_loop_on_a_closed_surface_closes_from_any_starting_trim():
    """v4_MechPartA's face 39 started its loop with a seam edge whose first use was placed at u0 while the
    next edge (a full circle run backwards) starts at u1: "the pulled-back loop does not close"."""
    from splinevis.io.nurbs_3dm import _pulled_loops, _surface

    tol = 1e-9
    for kind, brep, _, _ in faces():
        for k, face in enumerate(brep.Faces):
            s = _surface(face.UnderlyingSurface().ToNurbsSurface(), f"{kind} {k}")
            trims = list(face.Loops[0].Trims)
            assert len(trims) >= 3
            for shift in range(len(trims)):
                for order in (1, -1):  # also in the other direction (a loop read backwards: reversed trims)
                    ring = trims[shift:] + trims[:shift]
                    if order < 0:
                        ring = [_Reversed(t) for t in ring[::-1]]
                    loops, dev, dist, notes = _pulled_loops(brep, _Face(ring), s, tol, s.name)
                    assert dev <= tol and dist <= tol and notes == [] and len(loops) == 1, (s.name, shift)
                    loop = loops[0]
                    for a, b in zip(loop, loop[1:] + loop[:1]):  # one vertex: one point, bit for bit
                        assert (a.control_points[-1] == b.control_points[0]).all(), (s.name, shift, order)
                    domain_loop_checks(s, loop, tol, f"{s.name} from trim {shift}, order {order}")


class _Reversed:
    """A trim run the other way (its edge reversed): what a loop read backwards holds."""

    def __init__(self, trim):
        self.EdgeIndex, self.IsReversed = trim.EdgeIndex, not trim.IsReversed


def test_edges_off_their_surface_give_the_best_loop_and_its_measured_deviation():
    from splinevis.io.nurbs_3dm import _pulled_loops, _surface

    tol, e = 1e-4, 3e-4  # edges 3 tolerances off: drawn, beyond the tolerance
    for kind, brep, centre, radius in faces():
        if centre is None:
            continue
        face = brep.Faces[0]
        s = scaled(_surface(face.UnderlyingSurface().ToNurbsSurface(), kind), centre, 1 + e)
        loops, dev, dist, notes = _pulled_loops(brep, face, s, tol, s.name)
        assert abs(dist - e * radius) <= 64 * EPS * radius, (kind, dist)
        assert dist <= dev <= dist + 0.25 * tol, (kind, dev)
        assert notes == [] and len(loops) == 1
        domain_loop_checks(s, loops[0], dev, kind)
        with pytest.raises(ValueError, match=r"edge \d+: the curve is 0.00\d+ from surface .* more than the largest "
                                             r"distance allowed 1e-05.*more than 100 x the model tolerance off its "
                                             r"face: the Brep is damaged \(Rhino: Check"):
            _pulled_loops(brep, face, s, 1e-7, s.name)


def test_batched_inversion_finds_the_feet_across_both_seams_of_the_torus():
    """Points S(u(t), v(t)) along a curve winding twice around both directions: the feet are the exact
    parameters plus whole periods, continuous along the curve (unwrapped), from the grid and the neighbours."""
    s = torus()
    inv = _Inverter(s)
    assert tuple(inv.closed) == (True, True)
    t = np.linspace(0, 1, 301)
    (u0, u1), (v0, v1) = s.domain
    U, V = u0 + (u1 - u0) * (0.1 + 2.0 * t), v0 + (v1 - v0) * (0.3 + 1.0 * t + 0.05 * np.sin(9 * t))
    wrap = np.column_stack([u0 + np.mod(U - u0, u1 - u0), v0 + np.mod(V - v0, v1 - v0)])
    X = s.evaluate(wrap[:, 0], wrap[:, 1])
    uv = inv.invert_along(X)
    assert np.abs(np.diff(uv, axis=0)).max() < 0.05 * (u1 - u0)  # continuous: no jump by a period
    shift = np.round((uv - np.column_stack([U, V]))[0] / [u1 - u0, v1 - v0]) * [u1 - u0, v1 - v0]
    D = s.derivatives(wrap[:, 0], wrap[:, 1], 1)
    sigma = np.linalg.svd(np.stack([D[:, 1, 0], D[:, 0, 1]], axis=2), compute_uv=False)[:, -1]
    err = np.linalg.norm(uv - shift - np.column_stack([U, V]), axis=1)
    assert (err * sigma <= 1e-12 * np.abs(s.control_points).max()).all(), (err * sigma).max()
    # and what pull_back builds from them on that surface: within the tolerance at its test points
    def f(tt):
        uu, vv = u0 + (u1 - u0) * (0.1 + 2 * tt), v0 + (v1 - v0) * (0.3 + tt + 0.05 * np.sin(9 * tt))
        return s.evaluate(u0 + np.mod(uu - u0, u1 - u0), v0 + np.mod(vv - v0, v1 - v0))

    r = pull_back(s, f, (0.0, 1.0), 1e-8, inverter=inv)
    assert r.deviation <= 1e-8 and r.closed == (True, True) and r.note == ""


def test_lenient_pull_back_returns_the_best_fit_with_the_reason():
    from splinevis.nurbs.exact import sphere

    s = sphere()

    def equator(t):
        return np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])

    r = pull_back(s, equator, (0.0, 6.0), 1e-12, name="equator", max_samples=12, strict=False)
    assert "equator: the pulled-back curve" in r.note and "max_samples = 12" in r.note
    c = r.curves[0]
    uv = c.evaluate(r.checked_at)
    uv[:, 0] = np.mod(uv[:, 0], 1.0)
    measured = np.linalg.norm(s.evaluate(uv[:, 0], uv[:, 1]) - equator(r.checked_at), axis=1).max()
    assert r.deviation > 1e-12 and abs(measured - r.deviation) <= 64 * EPS
    assert r.samples <= 12
