"""GoTools ``.g2`` bounded surfaces (class 210) and their trim loops (splinevis.io.nurbs_g2.read_g2).

The files are written here in GoTools' layout (BoundedSurface / CurveOnSurface / SplineCurve / Plane / Circle
``write``: one number group per line, numbers as ``repr`` so they round-trip exactly); splipy's own G2 parser
reads the same text as an independent reader, and splipy's G2 writer produces an underlying surface.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from splinevis.io.nurbs_g2 import read_g2
from splinevis.nurbs.pullback import curve_evaluator
from splinevis.nurbs.trim import inside, trim_pieces

EPS = np.finfo(np.float64).eps


def num(x) -> str:
    return " ".join(repr(float(v)) for v in np.atleast_1d(x))


def spline_body(degree, knots, P, W=None) -> str:
    """SplineCurve::write: ``dim rational``, ``n order``, the knots, one coefficient per line."""
    P = np.asarray(P, dtype=np.float64)
    rows = P if W is None else np.column_stack([P * np.asarray(W)[:, None], W])
    return (f"{P.shape[1]} {int(W is not None)}\n{len(P)} {degree + 1}\n{num(knots)}\n"
            + "".join(num(r) + "\n" for r in rows))


def surface_body(P, U, V, order=(4, 4)) -> str:
    """SplineSurface::write, 3-D polynomial: coefficients with u varying fastest."""
    nu, nv = P.shape[:2]
    rows = P.transpose(1, 0, 2).reshape(-1, 3)
    return (f"3 0\n{nu} {order[0]}\n{num(U)}\n{nv} {order[1]}\n{num(V)}\n"
            + "".join(num(r) + "\n" for r in rows))


def bounded(surface_cls: int, body: str, loops, header="210 1 0 0") -> str:
    """BoundedSurface::write: the surface's class and body, the loop count, per loop ``n eps`` and the curves
    (each ``prefer pclass sclass`` then the bodies)."""
    out = f"{header}\n{surface_cls}\n{body}\n{len(loops)}\n"
    for eps, curves in loops:
        out += f"{len(curves)} {eps!r}\n"
        for pcls, pbody, scls, sbody in curves:
            out += f"{int(pcls != 0)} {pcls} {scls}\n{pbody}{sbody}\n"
    return out


def line_curve(a, b) -> tuple:
    return 1, [0.0, 0.0, 1.0, 1.0], np.array([a, b], dtype=np.float64), None


def patch():
    """A bicubic patch on [0, 1]^2 with bumps (Bezier: knots 0^4 1^4)."""
    g = np.linspace(0.0, 1.0, 4)
    P = np.stack([*np.meshgrid(g, g, indexing="ij"), np.zeros((4, 4))], axis=-1)
    P[1:3, 1:3, 2] = [[0.3, -0.2], [0.2, 0.1]]
    P[0, 1, 2], P[3, 2, 2] = 0.1, -0.1
    return P, [0.0] * 4 + [1.0] * 4


def signed_area(loop, n=400) -> float:
    pts = np.concatenate([c.evaluate(np.linspace(*c.domain, n)) for c in loop])
    x, y = pts[:, 0], pts[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


# Outer loop: the domain's border counter-clockwise (GoTools' convention). Hole: a square [0.3, 0.7]^2 run
# clockwise, as a rational quadratic (its middle weight != 1), a cubic with an interior knot and two lines.
OUTER = [line_curve(a, b) for a, b in [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
HOLE = [
    (2, [0.0, 0.0, 0.0, 2.0, 2.0, 2.0], np.array([[0.3, 0.3], [0.3, 0.5], [0.3, 0.7]]), np.array([1.0, 0.7, 1.0])),
    (3, [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
     np.array([[0.3, 0.7], [0.4, 0.7], [0.5, 0.7], [0.6, 0.7], [0.7, 0.7]]), None),
    line_curve((0.7, 0.7), (0.7, 0.3)),
    line_curve((0.7, 0.3), (0.3, 0.3)),
]


def square_hole_text(header="210 1 0 0") -> str:
    P, U = patch()
    loops = [(1e-6, [(100, spline_body(*c), 0, "") for c in OUTER]),
             (1e-6, [(100, spline_body(*c), 0, "") for c in HOLE])]
    return bounded(200, surface_body(P, U, U), loops, header)


def test_square_hole_loops_read_back_exactly(tmp_path):
    f = tmp_path / "hole.g2"
    f.write_text(square_hole_text(header="210 1 0 4 255 0 0 255"))  # with a colour in the header
    m = read_g2(f)
    assert len(m) == 1 and m.skipped == {}
    P, U = patch()
    assert np.array_equal(m.surfaces[0].control_points, P)
    outer, hole = m.trims[0]
    for got, (p, knots, cps, w) in zip(list(outer) + list(hole), OUTER + HOLE):
        assert got.degree == p
        assert np.array_equal(got.knots, knots) and np.array_equal(got.control_points, cps)
        assert (got.weights is None and w is None) or np.array_equal(got.weights, w)
    assert len(outer) == 4 and len(hole) == 4
    assert signed_area(outer) > 0 > signed_area(hole)  # the file's orientation kept: outer ccw, hole cw
    assert signed_area(outer) == pytest.approx(1.0, rel=1e-12)
    pieces = trim_pieces(m.trims)
    d = 1e-9  # a step far above rounding (the corners are exact binary fractions of 0.1 steps: ~1e-16)
    u = np.array([0.5, 0.3 + d, 0.3 - d, 0.7 - d, 0.7 + d, 0.1, 0.95, 0.5, 0.5, 0.5, 0.5])
    v = np.array([0.5, 0.5, 0.5, 0.5, 0.5, 0.1, 0.95, 0.7 - d, 0.7 + d, 0.3 + d, 0.3 - d])
    assert inside(pieces, 0, u, v).tolist() == [False, False, True, False, True, True, True,
                                                False, True, False, True]


def test_splipy_reads_the_same_loops(tmp_path):
    """splipy's G2 parser as an independent reader: both curves given, its TrimmedSurface keeps the parameter
    curves; splipy's G2 writer makes the underlying surface's body."""
    splipy_io = pytest.importorskip("splipy.io")
    from splipy import surface_factory

    s = surface_factory.square(size=(2, 3))
    s.raise_order(2, 1)
    s.refine(1, 1)
    s.set_dimension(3)
    s.controlpoints[..., 2] = np.random.default_rng(5).normal(size=s.controlpoints.shape[:2])
    w = tmp_path / "base.g2"
    with splipy_io.G2(str(w)) as g:
        g.write(s)
    body = w.read_text().split("\n", 1)[1]  # splipy's 200 without its header
    (u0, v0), (u1, v1) = s.start(), s.end()
    corners = [(u0, v0), (u1, v0), (u1, v1), (u0, v1), (u0, v0)]
    curves = []
    for a, b in zip(corners[:-1], corners[1:]):
        p, knots, uv, _ = line_curve(a, b)
        xyz = np.array([s(*x) for x in uv]).reshape(2, 3)
        curves.append((100, spline_body(p, knots, uv), 100, spline_body(p, knots, xyz)))
    f = tmp_path / "both.g2"
    f.write_text(bounded(200, body, [(1e-6, curves)]))
    with splipy_io.G2(str(f)) as g:
        ref = g.read()[0]
    m = read_g2(f)
    ours = m.trims[0][0]
    theirs = ref.boundaries[0]
    assert len(ours) == len(theirs) == 4
    for a, b in zip(ours, theirs):
        assert np.array_equal(a.control_points, b.controlpoints)
        assert np.array_equal(a.knots, b.knots(0, with_multiplicities=True))
    uu, vv = np.meshgrid(np.linspace(u0, u1, 5), np.linspace(v0, v1, 4))
    close = np.array([ref(a, b) for a, b in zip(uu.ravel(), vv.ravel())]).reshape(-1, 3)
    np.testing.assert_allclose(m.surfaces[0].evaluate(uu.ravel(), vv.ravel()), close, rtol=0, atol=1e-14)


def test_space_curves_only_pulled_back(tmp_path):
    """Loops given by space curves alone: the outer border and a hole whose sides are iso-curves of the patch
    (exact cubic space curves: S(u, v0) has the control points sum_j N_j(v0) P_ij)."""
    from splinevis.nurbs.basis import ders_basis_funs, find_span

    P, U = patch()
    Uk = np.asarray(U, dtype=np.float64)

    def iso(fixed: float, along_u: bool, reverse: bool):
        span = find_span(3, Uk, np.array([fixed]))
        N = ders_basis_funs(span, np.array([fixed]), 3, 0, Uk)[0, 0]
        idx = span[0] - 3 + np.arange(4)
        Q = np.einsum("j,ijc->ic", N, P[:, idx]) if along_u else np.einsum("i,ijc->jc", N, P[idx])
        return 3, U, Q[::-1] if reverse else Q, None

    def piece(c, lo, hi):  # the part [lo, hi] of a cubic Bezier (de Casteljau twice), on [0, 1]
        def split(Q, t):
            rows = [Q]
            while len(rows[-1]) > 1:
                rows.append((1 - t) * rows[-1][:-1] + t * rows[-1][1:])
            return np.array([r[0] for r in rows]), np.array([r[-1] for r in rows[::-1]])

        left, _ = split(c[2], hi)
        _, mid = split(left, lo / hi)
        return 3, U, mid, None

    eps = 1e-9
    border = [iso(0.0, True, False), iso(1.0, False, False), iso(1.0, True, True), iso(0.0, False, True)]
    # the hole [0.3, 0.7]^2, clockwise: up the left side, right along the top, down, back along the bottom
    hole = [piece(iso(0.3, False, False), 0.3, 0.7), piece(iso(0.7, True, False), 0.3, 0.7),
            piece(iso(0.7, False, True), 0.3, 0.7), piece(iso(0.3, True, True), 0.3, 0.7)]
    loops = [(eps, [(0, "", 100, spline_body(*c)) for c in border]),
             (eps, [(0, "", 100, spline_body(*c)) for c in hole])]
    f = tmp_path / "space.g2"
    f.write_text(bounded(200, surface_body(P, U, U), loops))
    m = read_g2(f)
    outer, inner = m.trims[0]
    assert "8 trim curve(s) pulled back" in m.source
    s = m.surfaces[0]
    for loop, given in ((outer, border), (inner, hole)):
        assert len(loop) == 4  # one piece per curve (no corners inside a Bezier curve)
        for c, (p, knots, Q, _) in zip(loop, given):
            t = np.linspace(*c.domain, 401)
            uv = np.clip(c.evaluate(t), 0.0, 1.0)
            ev, _, _ = curve_evaluator(p, knots, Q)
            assert np.abs(s.evaluate(uv[:, 0], uv[:, 1]) - ev(t)).max() <= eps  # the loop's epsilon, in space
        for a, b in zip(loop, loop[1:] + loop[:1]):  # joints one point, bit for bit
            assert np.array_equal(a.control_points[-1], b.control_points[0])
    assert signed_area(outer) > 0 > signed_area(inner)
    # |S_u|, |S_v| >= 0.5 on this patch, so eps in space is at most 2 eps in (u, v)
    assert signed_area(outer) == pytest.approx(1.0, abs=8 * eps)
    assert signed_area(inner) == pytest.approx(-0.16, abs=8 * eps)
    pieces = trim_pieces(m.trims)
    d = 1e-6
    u = np.array([0.5, 0.3 + d, 0.3 - d, 0.01, 0.99, 0.5])
    v = np.array([0.5, 0.5, 0.5, 0.99, 0.01, 0.7 + d])
    assert inside(pieces, 0, u, v).tolist() == [False, False, True, True, True, True]


def circle_body(dim, r, centre, normal, xaxis, bounds, reversed_=False, domain=None) -> str:
    """Circle::write: ``dim, r, centre, normal, x axis, bounds``, the flag (+10 with a domain)."""
    flag = int(reversed_) + (10 if domain is not None else 0)
    out = f"{dim}\n{num(r)}\n{num(centre)}\n{num(normal)}\n{num(xaxis)}\n{num(bounds)}\n{flag}\n"
    return out + (f"{num(domain)}\n" if domain is not None else "")


def test_plane_space_curves_exact_and_swapped_domain(tmp_path):
    """A bounded, swapped plane with a domain (Plane::write's flag 11): space curves only, mapped by the plane's
    inverse exactly; the patch is GoTools' point() over the domain."""
    loc, normal, xaxis = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 2.0]), np.array([1.0, 1.0, 0.0])
    bounds, domain = [0.0, 4.0, -1.0, 1.0], [0.0, 1.0, 10.0, 12.0]
    x = xaxis / np.linalg.norm(xaxis)
    y = np.cross([0.0, 0.0, 1.0], x)

    def gotools(u, v):  # Plane::point: swap, then the domain onto the bounds
        a = bounds[0] + (v - domain[0]) * (bounds[1] - bounds[0]) / (domain[1] - domain[0])
        b = bounds[2] + (u - domain[2]) * (bounds[3] - bounds[2]) / (domain[3] - domain[2])
        return loc + a * x + b * y

    body = f"3\n{num(loc)}\n{num(normal)}\n{num(xaxis)}\n11\n{num(bounds[:2])}\n{num(bounds[2:])}\n" \
           f"{num(domain[:2])}\n{num(domain[2:])}\n1\n"
    # outer: the domain's border through 3-D lines; hole: a 3-D circle of radius 0.5 about the middle
    uv = [(10.0, 0.0), (12.0, 0.0), (12.0, 1.0), (10.0, 1.0), (10.0, 0.0)]
    outer = [(0, "", 100, spline_body(*line_curve(gotools(*a), gotools(*b)))) for a, b in zip(uv[:-1], uv[1:])]
    centre = gotools(11.0, 0.5)
    hole = [(0, "", 130, circle_body(3, 0.5, centre, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 2 * np.pi]))]
    f = tmp_path / "plane.g2"
    f.write_text(bounded(250, body, [(1e-9, outer), (1e-9, hole)]))
    m = read_g2(f)
    s = m.surfaces[0]
    assert s.domain == ((10.0, 12.0), (0.0, 1.0))  # outer u is the swapped internal v
    uu, vv = np.meshgrid(np.linspace(10, 12, 5), np.linspace(0, 1, 3))
    want = np.array([gotools(a, b) for a, b in zip(uu.ravel(), vv.ravel())])
    np.testing.assert_allclose(s.evaluate(uu.ravel(), vv.ravel()), want, rtol=0, atol=8 * EPS * 4)
    border, ring = m.trims[0]
    corners = np.array([c.control_points[0] for c in border])
    np.testing.assert_allclose(corners, uv[:-1], rtol=0, atol=8 * EPS * 12)  # an affine map: rounding only
    # the circle: exact arcs; in (u, v) a circle of radius 0.5 / 2 (u: 2 units over 4) x 0.5 (v: 1 over 2)
    c = ring[0]
    t = np.linspace(*c.domain, 101)
    X = s.evaluate(*c.evaluate(t).T)
    np.testing.assert_allclose(np.linalg.norm(X - centre, axis=1), 0.5, rtol=0, atol=1e-14)
    assert "pulled back" not in m.source
    p = trim_pieces(m.trims)
    assert inside(p, 0, [11.0, 11.0, 11.3, 10.05], [0.5, 0.76, 0.5, 0.05]).tolist() == [False, True, False, True]


def test_cylinder_with_a_circular_hole_in_parameter_space(tmp_path):
    """A half cylinder (Cylinder::write, bounded, with a domain): the hole is a 2-D circle in GoTools' (u, v);
    the patch becomes exact NURBS, the hole is pulled back within the loop's epsilon, and points are classified
    as GoTools' parameters say."""
    r, loc, z, xa = 2.0, np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    bounds, domain = [0.0, np.pi, 0.0, 3.0], [0.0, 1.0, 0.0, 1.0]
    body = (f"3\n{r!r}\n{num(loc)}\n{num(z)}\n{num(xa)}\n11\n{num(bounds[:2])}\n{num(bounds[2:])}\n"
            f"{num(domain[:2])}\n{num(domain[2:])}\n0\n")
    uv = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
    outer = [(100, spline_body(*line_curve(a, b)), 0, "") for a, b in zip(uv[:-1], uv[1:])]
    hole = [(130, circle_body(2, 0.2, [0.5, 0.5], [0.0, 0.0], [1.0, 0.0], [0.0, 2 * np.pi], reversed_=True), 0, "")]
    eps = 1e-8
    f = tmp_path / "cyl.g2"
    P, U = patch()
    f.write_text(bounded(260, body, [(eps, outer), (eps, hole)]) + "200 1 0 0\n" + surface_body(P, U, U))
    m = read_g2(f)
    assert len(m) == 2 and m.skipped == {}  # the 200 after the 210 is read: the 210 was parsed to its end
    s = m.surfaces[0]
    su, sv = np.meshgrid(np.linspace(*s.domain[0], 9), np.linspace(*s.domain[1], 7))
    X = s.evaluate(su.ravel(), sv.ravel())
    np.testing.assert_allclose(np.hypot(X[:, 0] - loc[0], X[:, 1] - loc[1]), r, rtol=0, atol=1e-14)
    assert X[:, 1].min() >= loc[1] - 1e-14 and X[:, 2].min() >= -1e-15 and X[:, 2].max() <= 3.0 + 1e-15

    def gotools_uv(X):  # GoTools' outer parameters of points on the cylinder
        ang = np.mod(np.arctan2(X[:, 1] - loc[1], X[:, 0] - loc[0]), 2 * np.pi)
        return np.column_stack([ang / np.pi, X[:, 2] / 3.0])

    border, ring = m.trims[0]
    for c in border + ring:  # every pulled-back curve maps onto GoTools' curve within eps
        t = np.linspace(*c.domain, 301)
        Y = s.evaluate(*np.clip(c.evaluate(t), [s.domain[0][0], s.domain[1][0]], [s.domain[0][1], s.domain[1][1]]).T)
        w = gotools_uv(Y)
        if c in ring:  # eps in space is eps / 3 in v and eps / (2 pi) in u: within eps in (u, v)
            np.testing.assert_allclose(np.hypot(w[:, 0] - 0.5, w[:, 1] - 0.5), 0.2, rtol=0, atol=eps)
        else:  # on the border of GoTools' domain [0, 1]^2
            assert np.abs(np.minimum(np.minimum(w, 1.0 - w).min(axis=1), 1.0)).max() <= eps
    assert signed_area(ring) < 0 < signed_area(border)  # GoTools: the reversed circle runs clockwise
    rng = np.random.default_rng(1)
    st = rng.uniform([s.domain[0][0], s.domain[1][0]], [s.domain[0][1], s.domain[1][1]], size=(400, 2))
    w = gotools_uv(s.evaluate(st[:, 0], st[:, 1]))
    rho = np.hypot(w[:, 0] - 0.5, w[:, 1] - 0.5)
    keep = np.abs(rho - 0.2) > 1e-6  # away from the trim by far more than eps
    got = inside(trim_pieces(m.trims), 0, st[keep, 0], st[keep, 1])
    assert got.tolist() == (rho[keep] > 0.2).tolist()


def test_sphere_cap_from_a_space_circle(tmp_path):
    """A sphere (Sphere::write, swapped flag 10 with a domain) trimmed by one 3-D circle: the cap of points
    within 0.3 rad of a direction; NURBS parameters classified as the cap says."""
    R, loc = 1.5, np.array([0.0, 0.0, 0.0])
    body = (f"3\n{R!r}\n{num(loc)}\n0.0 0.0 1.0\n1.0 0.0 0.0\n{num([0.0, 2 * np.pi])}\n"
            f"{num([-np.pi / 2, np.pi / 2])}\n10\n0.0 1.0\n0.0 1.0\n")
    n = np.array([np.cos(0.4) * np.cos(1.0), np.cos(0.4) * np.sin(1.0), np.sin(0.4)])
    e1 = np.cross([0.0, 0.0, 1.0], n)
    e1 /= np.linalg.norm(e1)
    cap = 0.3
    circle = circle_body(3, R * np.sin(cap), R * np.cos(cap) * n, n, e1, [0.0, 2 * np.pi])
    eps = 1e-8
    f = tmp_path / "sphere.g2"
    f.write_text(bounded(270, body, [(eps, [(0, "", 130, circle)])]))
    m = read_g2(f)
    s = m.surfaces[0]
    assert "270 (sphere) converted to NURBS" in m.source and "1 trim curve(s) pulled back" in m.source
    rng = np.random.default_rng(2)
    st = rng.uniform([s.domain[0][0], s.domain[1][0]], [s.domain[0][1], s.domain[1][1]], size=(2000, 2))
    X = s.evaluate(st[:, 0], st[:, 1])
    np.testing.assert_allclose(np.linalg.norm(X, axis=1), R, rtol=0, atol=1e-14)
    ang = np.arccos(np.clip(X @ n / R, -1, 1))
    keep = np.abs(ang - cap) > 1e-6
    got = inside(trim_pieces(m.trims), 0, st[keep, 0], st[keep, 1])
    assert (ang[keep] < cap).sum() > 20
    assert got.tolist() == (ang[keep] < cap).tolist()


def test_skipped_classes_are_named_and_parsed_to_their_end(tmp_path):
    """A 210 on a surface of linear extrusion (261) is skipped by name with its line; a cone and a torus with
    domains, a bounded curve, a line and a spline volume are consumed; the patch after them is read."""
    crv = spline_body(*line_curve((0, 0, 0), (1, 0, 0)))
    ext = f"261\n3\n{crv}0 0 1\n1\n0 1 0 1\n0\n"  # dim, curve, axis, bounded, u0 u1 v0 v1, swapped
    loops = [(1e-6, [(100, spline_body(*line_curve(a, b)), 0, "")
                     for a, b in [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]])]
    text = bounded(261, ext.split("\n", 1)[1], loops)
    text += "280 1 0 0\n3\n1.0\n0 0 0\n0 0 1\n1 0 0\n0.2\n10\n0 6.28\n0 1\n0\n"
    text += "290 1 0 0\n3\n2.0\n0.5\n0 0 0\n0 0 1\n1 0 0\n0\n0 6.28\n0 6.28\n10\n0 1\n0 1\n"
    text += "150 1 0 0\n120\n1 0 1\n3 0 0 0 1 0 0\n3\n0 0 0\n1 0 0\n11\n0 2\n0 1\n0\n"
    text += "700 1 0 0\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n" + "0 0 0\n" * 8
    P, U = patch()
    text += "200 1 0 0\n" + surface_body(P, U, U)
    f = tmp_path / "mixed.g2"
    f.write_text(text)
    with pytest.warns(UserWarning) as caught:
        m = read_g2(f)
    said = [str(w.message) for w in caught]
    key = "210 (bounded surface) on 261 (linear extrusion)"
    assert any(f"object 0 (class 210, line 1) skipped: {key}" in w for w in said)
    assert any("skipped unsupported entities: 1 x 210 (bounded surface) on 261 (linear extrusion)" in w for w in said)
    assert len(m) == 1 and np.array_equal(m.surfaces[0].control_points, P)
    assert m.skipped == {"210 (bounded surface) on 261 (linear extrusion)": 1, "280 (cone)": 1, "290 (torus)": 1,
                         "150 (bounded curve)": 1, "700 (spline volume)": 1}


def test_bounded_curve_and_old_spline_class_as_trim_curves(tmp_path):
    """A 150 (bounded curve) of a line, and class 1 (the old name of 100) as parameter curves."""
    P, U = patch()
    # the line (a, 0) with bounds a in [0, 2] and domain t in [0, 4] (a = t / 2): its part t in [0, 2]
    seg = "120\n1 0 2\n2 0 0 1 0\n2\n0 0\n1 0\n11\n0 2\n0 4\n0\n"
    rest = [line_curve(a, b) for a, b in [((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]]
    curves = [(150, seg, 0, "")] + [(1, spline_body(*c), 0, "") for c in rest]
    f = tmp_path / "bc.g2"
    f.write_text(bounded(200, surface_body(P, U, U), [(1e-6, curves)]))
    m = read_g2(f)
    first = m.trims[0][0][0]
    assert first.degree == 1 and np.array_equal(first.control_points, [[0.0, 0.0], [1.0, 0.0]])
    assert signed_area(m.trims[0][0]) == pytest.approx(1.0, rel=1e-12)


def test_loop_gaps_snapped_within_epsilon_else_bridged(tmp_path):
    P, U = patch()
    sides = [((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]

    def text(shift):
        cs = [line_curve(a, b) for a, b in sides]
        cs[1] = line_curve((1.0, shift), (1, 1))  # starts `shift` above the previous end
        return bounded(200, surface_body(P, U, U), [(1e-6, [(100, spline_body(*c), 0, "") for c in cs])])

    f = tmp_path / "gap.g2"
    f.write_text(text(1e-8))  # 1e-8 in (u, v) is about 1e-8 in space here: within the epsilon 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loop = read_g2(f).trims[0][0]
    assert len(loop) == 4 and np.array_equal(loop[1].control_points[0], [1.0, 0.0])
    f.write_text(text(1e-3))
    with pytest.warns(UserWarning, match=r"loop\(s\) not closed within their epsilon, bridged by segments: loop 0 gap"):
        m = read_g2(f)
    loop = m.trims[0][0]
    assert len(loop) == 5 and np.array_equal(loop[1].control_points, [[1.0, 0.0], [1.0, 1e-3]])
    assert "open loops bridged" in m.source


@pytest.mark.parametrize("text, message", [
    ("200 1 0 0\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0 0 0\n1 0 0\n", r"the file ends \(line 8\) inside object 0"),
    ("200 1 0 0\n3 0\n2 2\n0 0 x 1\n", r"line 4: object 0 \(class 200, line 1\): the 4 knots of direction 0: "
                                        r"expected a number, got 'x'"),
    ("999 1 0 0\n1\n", r"line 1: object 0 \(class 999, line 1\): unknown G2 class 999"),
    ("210 1 0 0\n200\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n1\n1 1e-6\n1 0 0\n",
     r"line 14: .*loop 0 curve 0: neither a parameter curve nor a space curve"),
    ("210 1 0 0\n200\n3 0\n2 2\n0 0 1 1\n2 2\n0 0 1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n1\n1 1e-6\n1 100 0\n3 0\n",
     r"loop 0 curve 0's parameter curve: the number of coefficients"),
])
def test_damaged_files_name_line_and_expectation(tmp_path, text, message):
    f = tmp_path / "bad.g2"
    f.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_g2(f)


def test_the_documented_plane_example(tmp_path):
    """The layout of the bounded-surface example in GoTools' g2 format documentation: a plane (bounded flag 1,
    bounds -3..3 twice, not swapped) trimmed by one loop of three space curves ``0 0 100`` (space curve the
    master, no parameter curve) with the loop tolerance 1e-4. The plane is z = 0 with x along x, so each
    trim curve in (u, v) is its space curve's (x, y), exactly."""
    body = "3\n0 0 0\n0 0 1\n1 0 0\n1\n-3 3\n-3 3\n0\n"
    given = [line_curve((-1, 0, 0), (0, -1, 0)), line_curve((0, -1, 0), (-0.5, 2, 0)),
             (2, [0, 0, 0, 0.5, 1, 1, 1], np.array([[-0.5, 2, 0], [-1, 2, 0], [-2, 1, 0], [-1, 0, 0]], float), None)]
    f = tmp_path / "doc.g2"
    f.write_text(bounded(250, body, [(1e-4, [(0, "", 100, spline_body(*c)) for c in given])]))
    m = read_g2(f)
    s = m.surfaces[0]
    assert s.domain == ((-3.0, 3.0), (-3.0, 3.0)) and s.degree == (1, 1)
    np.testing.assert_allclose(s.evaluate([-3.0, 3.0, 1.5], [-3.0, 3.0, -0.5]),
                               [[-3, -3, 0], [3, 3, 0], [1.5, -0.5, 0]],
                               rtol=0, atol=4 * EPS * 3)  # the bilinear basis' rounding on coordinates <= 3
    loop, = m.trims[0]
    for c, (p, knots, P, _) in zip(loop, given):
        assert c.degree == p and np.array_equal(c.knots, knots) and np.array_equal(c.control_points, P[:, :2])
    assert inside(trim_pieces(m.trims), 0, [-0.5, -2.5, 0.5], [0.5, 0.0, 0.5]).tolist() == [True, False, False]


def test_untrimmed_bounded_surface_and_unbounded_plane_without_loops(tmp_path):
    P, U = patch()
    f = tmp_path / "none.g2"
    f.write_text(bounded(200, surface_body(P, U, U), []))
    m = read_g2(f)
    assert m.trims == (None,) and np.array_equal(m.surfaces[0].control_points, P)
    f.write_text(bounded(250, "3\n0 0 0\n0 0 1\n1 0 0\n0\n0\n", []))
    with pytest.raises(ValueError, match=r"none.g2: object 0 \(class 210, line 1\): the underlying 250 \(plane\) is "
                                         r"unbounded and the bounded surface has no trim loops"):
        read_g2(f)


def test_space_curve_off_the_surface_drawn_with_its_deviation_or_skipped(tmp_path):
    """A space curve 5 epsilons off the patch is pulled back as closely as it allows (face drawn, deviation
    reported and warned); 1000 epsilons off it is no boundary of the surface: the face is skipped by name."""
    P, U = patch()
    eps = 1e-6

    def text(lift):
        # the patch's border rows of control points: its boundary curves, exactly; the first one lifted
        curves = [(3, U, Q, None) for Q in (P[:, 0] + [0.0, 0.0, lift], P[3, :], P[::-1, 3], P[0, ::-1])]
        return bounded(200, surface_body(P, U, U), [(eps, [(0, "", 100, spline_body(*c)) for c in curves])])

    f = tmp_path / "off.g2"
    f.write_text(text(5 * eps))
    with pytest.warns(UserWarning) as caught:
        m = read_g2(f)
    said = [str(w.message) for w in caught]
    assert any("pulled back beyond their loop's epsilon, drawn with the best fit: loop 0 curve 0: 5e-06 > epsilon "
               "1e-06" in w for w in said)
    assert not any("bridged" in w for w in said)  # its ends are joined within the deviation accepted
    assert len(m) == 1 and "beyond the epsilon: loop 0 curve 0" in m.source
    f.write_text(text(1000 * eps) + "200 1 0 0\n" + surface_body(P, U, U))
    with pytest.warns(UserWarning) as caught:
        m = read_g2(f)
    key = "210 (bounded surface) with a trim curve more than 100 x its loop's epsilon off the surface"
    assert m.skipped == {key: 1} and len(m) == 1
    assert any(f"object 0 (class 210, line 1) skipped: {key} (" in str(w.message) for w in caught)
