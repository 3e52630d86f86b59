"""splinevis.nurbs.pullback: 3-D curves on exact NURBS surfaces pull back to their known (u, v) curves, across
seams and through poles, within bounds derived from the refinement criterion (``|S(c(t)) - C(t)| <= tol`` at
the test points ``checked_at``); and the Rhino reader rebuilds trim loops of non-affine faces with it.

How the parameter bounds follow from the criterion: on a surface of revolution ``S_u`` is horizontal and
``S_v`` lies in the meridian plane, so two points of the same latitude circle (radius ``rho``) at chord
``<= tol`` differ in angle by ``<= 2 asin(tol / (2 rho))`` and in ``u`` by at most that over
``min dtheta/du = min |S_u| / rho``; on the cylinder the height difference ``H dv`` is a component of the
3-D difference, so ``|dv| <= tol / H``.
"""

import warnings

import numpy as np
import pytest

from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net, cylinder, sphere, torus
from splinevis.nurbs.pullback import curve_evaluator, pull_back, reverse_curve
from splinevis.nurbs.trim import inside, trim_pieces

EPS = np.finfo(float).eps


def on_pieces(curves, t):
    """Evaluate consecutive 2-D pieces at curve parameters t (each t in the piece whose domain holds it)."""
    t = np.asarray(t, float)
    out = np.empty((t.size, 2))
    for k, c in enumerate(curves):
        a, b = c.domain
        sel = (t >= a) & ((t < b) | (k == len(curves) - 1))
        out[sel] = c.evaluate(t[sel])
    return out


def deviation(surface, curves, curve, t):
    uv = on_pieces(curves, t)
    for d, ((a, b), closed) in enumerate(zip(surface.domain, seams(surface))):
        if closed:  # an unwrapped curve: the same points one period on
            uv[:, d] = a + np.mod(uv[:, d] - a, b - a)
    return np.linalg.norm(surface.evaluate(uv[:, 0], uv[:, 1]) - curve(t), axis=1)


def seams(surface):
    """Closed in u, in v: S(u0, v) = S(u1, v) (resp. in v) at a few parameters."""
    (u0, u1), (v0, v1) = surface.domain
    a = np.linspace(0, 1, 7)
    u, v = u0 + a * (u1 - u0), v0 + a * (v1 - v0)
    return (np.allclose(surface.evaluate(np.full(7, u0), v), surface.evaluate(np.full(7, u1), v), atol=1e-12),
            np.allclose(surface.evaluate(u, np.full(7, v0)), surface.evaluate(u, np.full(7, v1)), atol=1e-12))


def exact_u(surface, theta, v):
    """The u of angle theta on the latitude v of a surface of revolution (u in [0, 1)), by bisection on the
    monotone angle of the rational circle: exact to rounding."""
    theta = np.mod(theta, 2 * np.pi)
    lo, hi = np.zeros_like(theta), np.ones_like(theta)
    for _ in range(60):
        m = 0.5 * (lo + hi)
        p = surface.evaluate(m, np.full_like(m, v))
        below = np.mod(np.arctan2(p[:, 1], p[:, 0]), 2 * np.pi) < theta
        lo, hi = np.where(below, m, lo), np.where(below, hi, m)
    return 0.5 * (lo + hi)


def u_bound(surface, v, rho, tol):
    """Largest u error of a point on latitude v whose image is within tol of the true point (see the notes)."""
    u = np.linspace(0, 1, 4097)  # holds the speed's extremes (quarter ends and middles, u = k / 8)
    speed = np.linalg.norm(surface.derivatives(u, np.full_like(u, v), 1)[:, 1, 0], axis=1)
    return 2 * np.arcsin(tol / (2 * rho)) * rho / speed.min()


def check_criterion(surface, r, curve, tol):
    """The reported deviation is what the returned curves give at checked_at, and within tol."""
    assert r.closed == seams(surface)
    d = deviation(surface, r.curves, curve, r.checked_at)
    assert r.deviation <= tol and d.max() <= tol, (r.deviation, d.max(), tol)
    assert abs(d.max() - r.deviation) <= 64 * EPS * max(1.0, np.abs(surface.control_points).max())
    assert r.distance <= 64 * EPS * np.abs(surface.control_points).max()  # exact curves lie on the surface


def test_latitude_circle_on_the_sphere_is_v_const():
    radius, tol = 2.0, 1e-9
    s = sphere(radius)
    z, rho = -radius * np.sqrt(0.5), radius * np.sqrt(0.5)  # v = 1/4: the middle of the south quarter arc

    def ring(t):
        return np.column_stack([rho * np.cos(t), rho * np.sin(t), np.full_like(t, z)])

    r = pull_back(s, ring, (0.0, 2 * np.pi), tol, name="ring")
    check_criterion(s, r, ring, tol)
    assert r.closed == (True, False)
    (c,) = r.curves
    assert np.abs(c.control_points[:, 1] - 0.25).max() <= 8 * EPS  # constants interpolated: v = 1/4 exactly
    t = r.checked_at
    du = on_pieces(r.curves, t)[:, 0] - exact_u(s, t, 0.25)
    du -= np.round(du)  # u = 1 and u = 0 are the same seam point
    assert np.abs(du).max() <= u_bound(s, 0.25, rho, tol)
    assert np.allclose(c.evaluate([0.0, 2 * np.pi])[:, 0], [0.0, 1.0], atol=1e-12)  # once round, from the seam


def test_arc_on_the_cylinder_at_constant_height():
    R, H, z, tol = 1.5, 3.0, 1.2, 1e-9
    s = cylinder(R, H)

    def arc(t):
        return np.column_stack([R * np.cos(t), R * np.sin(t), np.full_like(t, z)])

    r = pull_back(s, arc, (0.3, 2.0), tol, name="arc")
    check_criterion(s, r, arc, tol)
    uv = on_pieces(r.curves, r.checked_at)
    assert np.abs(uv[:, 1] - z / H).max() <= tol / H
    assert np.abs(uv[:, 0] - exact_u(s, r.checked_at, 0.0)).max() <= u_bound(s, 0.0, R, tol)


def test_ellipse_plane_section_of_the_cylinder_pulls_back_to_its_known_relation():
    # The plane z = h0 + a x cuts the cylinder x^2 + y^2 = R^2 in an ellipse. Applied to the control points
    # of the cylinder's own unit circle (affine maps commute with rational B-splines), the map
    # (X, Y) -> (R X, R Y, h0 + a R X) gives it exactly as a rational quadratic C(t) with the cylinder's
    # angular parametrisation, so its pull-back is u = t, v = (h0 + a R X(t)) / H.
    R, H, h0, a, tol = 1.5, 4.0, 2.0, 0.5, 1e-10
    s = cylinder(R, H)
    xy, w = circle_net()
    f, dom, breaks = curve_evaluator(2, CIRCLE_KNOTS, np.column_stack([R * xy, h0 + a * R * xy[:, 0]]), w)
    unit, _, _ = curve_evaluator(2, CIRCLE_KNOTS, xy, w)
    r = pull_back(s, f, dom, tol, name="ellipse", breaks=breaks)
    assert len(r.curves) == 4 and dom == (0.0, 1.0)  # one piece per quarter arc (double knots)
    check_criterion(s, r, f, tol)
    t = r.checked_at
    uv = on_pieces(r.curves, t)
    assert np.abs(uv[:, 1] - (h0 + a * R * unit(t)[:, 0]) / H).max() <= tol / H
    assert np.abs(uv[:, 0] - t).max() <= u_bound(s, 0.0, R, tol)
    ends = on_pieces(r.curves, [0.0, 1.0])  # starts on the seam, goes once round, ends on it: continuous
    assert ends[0, 0] == pytest.approx(0.0, abs=1e-12) and ends[1, 0] == pytest.approx(1.0, abs=1e-12)


def test_a_curve_across_the_seam_stays_continuous():
    R, H, tol = 1.5, 3.0, 1e-9
    s = cylinder(R, H)

    def helix(t):  # from -1 rad to 1 rad: across u = 0 = 1
        return np.column_stack([R * np.cos(t), R * np.sin(t), 1.0 + 0.3 * t])

    r = pull_back(s, helix, (-1.0, 1.0), tol, name="helix")
    check_criterion(s, r, helix, tol)
    t = np.linspace(-1.0, 1.0, 2001)
    u = on_pieces(r.curves, t)[:, 0]
    du = u - np.unwrap(exact_u(s, t, 0.0), period=1.0)  # the exact u, made continuous
    assert np.ptp(np.round(du)) == 0  # one period shift along the whole curve: no jump at the seam
    assert np.abs(du - np.round(du)).max() <= u_bound(s, 0.0, R, tol)
    assert (np.diff(u) > 0).all() and u[0] < 1.0 < u[-1]  # unwrapped through u = 1

    # the (2, 3) torus knot winds twice round the axis and three times round the tube: across both seams
    def knot(t):
        rr = 2.0 + 0.5 * np.cos(3 * t)
        return np.column_stack([rr * np.cos(2 * t), rr * np.sin(2 * t), 0.5 * np.sin(3 * t)])

    tor = torus(2.0, 0.5)
    r = pull_back(tor, knot, (0.0, 2 * np.pi), 1e-8, name="knot")
    check_criterion(tor, r, knot, 1e-8)
    assert r.closed == (True, True)
    uv = on_pieces(r.curves, np.linspace(0, 2 * np.pi, 4001))
    assert (np.diff(uv, axis=0) > 0).all()  # both parameters grow monotonically: never wrapped back
    assert np.allclose(uv[-1] - uv[0], [2.0, 3.0], atol=1e-12)


def test_a_meridian_through_the_poles_takes_u_from_its_neighbours():
    radius, tol = 1.0, 1e-9
    s = sphere(radius)
    c45 = np.sqrt(0.5)

    def meridian(t):  # the longitude 45 degrees: u = 1/8 by the symmetry of the quarter arc
        return np.column_stack([radius * np.cos(t) * c45, radius * np.cos(t) * c45, radius * np.sin(t)])

    r = pull_back(s, meridian, (-np.pi / 2, np.pi / 2), tol, name="meridian")
    check_criterion(s, r, meridian, tol)
    P = np.concatenate([c.control_points for c in r.curves])
    assert np.abs(P[:, 0] - 0.125).max() <= 8 * EPS  # also at both poles, where S_u = 0
    ends = on_pieces(r.curves, [-np.pi / 2, np.pi / 2])
    assert np.allclose(ends, [[0.125, 0.0], [0.125, 1.0]], atol=8 * EPS)


def test_image_of_a_known_parameter_curve_on_the_saddle():
    # C(t) = S(c(t)) for a circle c in (u, v): the pull-back is c itself. S(a) - S(b) = J (a - b) + O(|a - b|^2)
    # with J = [S_u S_v], so the criterion |S(fit) - C| <= tol gives |fit - c| <= tol / sigma_min(J) up to the
    # second-order term (|a - b| ~ 1e-9 here: a relative 1e-8 at most, allowed as the factor 1 + 1e-6).
    from splinevis.nurbs.exact import saddle

    s, tol = saddle(2.0), 1e-9

    def c(t):
        return np.column_stack([0.5 + 0.3 * np.cos(t), 0.5 + 0.2 * np.sin(t)])

    def image(t):
        uv = c(t)
        return s.evaluate(uv[:, 0], uv[:, 1])

    r = pull_back(s, image, (0.0, 2 * np.pi), tol, name="ellipse in (u, v)")
    check_criterion(s, r, image, tol)
    t = r.checked_at
    D = s.derivatives(*c(t).T, 1)
    sigma = np.linalg.svd(np.stack([D[:, 1, 0], D[:, 0, 1]], axis=2), compute_uv=False)[:, -1]
    err = np.linalg.norm(on_pieces(r.curves, t) - c(t), axis=1)
    assert (err <= tol / sigma * (1 + 1e-6)).all(), (err / (tol / sigma)).max()


def test_errors_name_the_curve():
    s = sphere()

    def halo(t):
        return 1.01 * np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])

    with pytest.raises(ValueError, match=r"halo: the curve is 0.01 from surface 'sphere'.*does not lie on the surface"):
        pull_back(s, halo, (0.0, 1.0), 1e-3, name="halo")

    def equator(t):
        return np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])

    with pytest.raises(ValueError, match=r"equator: the pulled-back curve .* not refined further \(max_samples = 12\)"):
        pull_back(s, equator, (0.0, 6.0), 1e-12, name="equator", max_samples=12)
    with pytest.raises(ValueError, match="tolerance must be positive"):
        pull_back(s, equator, (0.0, 1.0), 0.0)


def test_reverse_curve_runs_backwards():
    xy, w = circle_net()
    from splinevis.nurbs.model import TrimCurve

    c = TrimCurve(2, CIRCLE_KNOTS, xy, w)
    t = np.linspace(0, 1, 17)
    assert np.allclose(reverse_curve(c).evaluate(t), c.evaluate(1 - t), atol=1e-15)


# ---- Rhino: the reader's code path ------------------------------------------------------------------
# rhino3dm cannot build a trimmed face on a CURVED surface: the side faces of Brep.CreateFromCylinder,
# CreateFromSphere, CreateQuadSphere, CreateFromRevSurface and Extrusion.ToBrep are all untrimmed (their
# duplicates are plain surfaces; Cone has no constructor). What it can build is a trimmed face whose NURBS
# form is not an affine parallelogram: a trimmed plane under a projective transform (a rational bilinear
# surface), which the reader used to skip. That one runs end to end through a file; the loop builder runs on
# the curved faces' own loops (seam edges used twice, singular trims at the poles), whose known trims are
# the domain's boundary.


def lens_file(path, tol):
    import rhino3dm

    P = rhino3dm.Point3d
    circle = rhino3dm.Circle(P(0.5, 0.5, 0), 0.25).ToNurbsCurve()
    disc = rhino3dm.Brep.CreateTrimmedPlane(rhino3dm.Plane.WorldXY(), circle)
    T = rhino3dm.Transform(1.0)
    T.M30, T.M31 = 0.3, 0.2  # w' = 1 + 0.3 x + 0.2 y: a projective map, the plane's NURBS form turns rational
    assert disc.Transform(T)
    f = rhino3dm.File3dm()
    f.Settings.ModelAbsoluteTolerance = tol
    attr = rhino3dm.ObjectAttributes()
    attr.Name = "lens"
    f.Objects.AddBrep(disc, attr)
    bump = rhino3dm.NurbsSurface.Create(3, False, 2, 2, 2, 2)
    for i in range(2):
        bump.KnotsU[i], bump.KnotsV[i] = float(i), float(i)
    for i in range(2):
        for j in range(2):
            bump.Points[i, j] = rhino3dm.Point4d(i, j, 0.1 * i * j, 1.0)
    attr = rhino3dm.ObjectAttributes()
    attr.Name = "quad"
    f.Objects.AddSurface(bump, attr)
    assert f.Write(str(path), 8)
    return disc


def test_3dm_trimmed_face_in_rational_form_end_to_end(tmp_path):
    from splinevis.io import read_nurbs

    tol = 1e-7
    disc = lens_file(tmp_path / "lens.3dm", tol)
    m = read_nurbs(tmp_path / "lens.3dm")
    assert m.names == ("lens", "quad") and m.skipped == {}
    s, loops = m.surfaces[0], m.trims[0]
    assert s.rational and len(loops) == 1
    assert "trim curves pulled back onto 1 face(s) within 1e-07 (the file's model tolerance)" in m.source
    dev = float(m.source.split("'lens' ")[1].split(" ")[0])
    assert dev <= tol
    face = disc.Faces[0]
    u, v = np.array([0.3, 0.5, 0.7]), np.array([0.6, 0.5, 0.35])
    assert np.allclose(s.evaluate(u, v), [[(q := face.PointAt(a, b)).X, q.Y, q.Z] for a, b in zip(u, v)], atol=1e-14)
    # the projective image of the circle (u - 1/2)^2 + (v - 1/2)^2 = 1/16 pulls back to that circle: at the
    # fit's knots (interpolated feet of edge points) within tol / sigma_min of the surface's Jacobian
    knots = np.concatenate([np.unique(c.knots) for c in loops[0]])
    uv = np.concatenate([c.evaluate(np.unique(c.knots)) for c in loops[0]])
    D = s.derivatives(*np.clip(uv, 0.25, 0.75).T, 1)  # the domain: the circle's box
    assert s.domain == ((0.25, 0.75), (0.25, 0.75))
    sigma = np.linalg.svd(np.stack([D[:, 1, 0], D[:, 0, 1]], axis=2), compute_uv=False)[:, -1]
    assert knots.size > 8
    assert (np.abs(np.hypot(uv[:, 0] - 0.5, uv[:, 1] - 0.5) - 0.25) <= tol / sigma).all()
    pieces = trim_pieces([loops])
    a = np.linspace(0, 2 * np.pi, 13)
    for rad, expect in ((0.2475, True), (0.2525, False)):  # 1 % inside and outside
        assert (inside(pieces, 0, 0.5 + rad * np.cos(a), 0.5 + rad * np.sin(a)) == expect).all()


def test_3dm_face_beyond_the_tolerance_is_drawn_with_its_deviation(tmp_path):
    from splinevis.io import read_nurbs

    lens_file(tmp_path / "tight.3dm", 1e-18)  # below rounding: the edge cannot lie that close
    with pytest.warns(UserWarning) as record:
        m = read_nurbs(tmp_path / "tight.3dm")
    assert m.names == ("lens", "quad") and m.skipped == {} and len(m.trims[0]) == 1  # drawn, not dropped
    messages = [str(w.message) for w in record]
    # the fit stops at rounding (~1e-13), farther than the edges (~5e-16) plus the tolerance: warned as the
    # reader's shortfall; the source says the face is beyond the model tolerance
    text = "1 face(s) drawn with trim loops farther from their edges than the edges are from the surface plus the " \
           "tolerance 1e-18"
    assert any(text in t for t in messages), messages
    assert "1 face(s) drawn with trim loops beyond the model tolerance 1e-18" in m.source
    assert m.report["trim_fit"]["short_of_edges"] == ["lens"] and m.report["trim_fit"]["beyond_tolerance"] == ["lens"]
    assert "trim curves pulled back onto 1 face(s) 1 of them beyond the tolerance 1e-18" in m.source
    dev, off = m.source.split("'lens' ")[1].split(" (edges ")
    dev, off = float(dev), float(off.split(" ")[0])
    # measured: the edge is rounding off the surface, the fit within the rounding floor of the surface's size
    scale = np.abs(m.surfaces[0].control_points).max()
    assert 1e-18 < dev <= off + 1e-12 * scale and off <= 64 * EPS * scale
    lens_file(tmp_path / "none.3dm", 0.0)  # no model tolerance: 1e-6 of the model's bounding-box diagonal
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = read_nurbs(tmp_path / "none.3dm")
    assert "1e-06 of the model's bounding-box diagonal" in m.source and len(m.trims[0]) == 1


def rhino_faces():
    import rhino3dm

    P = rhino3dm.Point3d
    axis = rhino3dm.Line(P(0, 0, 0), P(0, 0, 1))
    cylinder = rhino3dm.Cylinder(rhino3dm.Circle(P(0, 0, 0), 1.0), 2.0)
    yield "cylinder", rhino3dm.Brep.CreateFromCylinder(cylinder, True, True)
    yield "sphere", rhino3dm.Brep.CreateFromSphere(rhino3dm.Sphere(P(0, 0, 1), 1.5))
    yield "quad sphere", rhino3dm.Brep.CreateQuadSphere(rhino3dm.Sphere(P(0, 0, 0), 1.0))
    yield "cone", rhino3dm.Brep.CreateFromRevSurface(
        rhino3dm.RevSurface.Create(rhino3dm.LineCurve(P(1, 0, 0), P(0, 0, 2)), axis, 0.0, 2 * np.pi), True, True)


def test_3dm_loops_of_curved_faces_are_their_domain_boundaries():
    from splinevis.io.nurbs_3dm import _planar_loops, _pulled_loops, _surface

    tol = 1e-9
    for kind, brep in rhino_faces():
        for k, face in enumerate(brep.Faces):
            s = _surface(face.UnderlyingSurface().ToNurbsSurface(), f"{kind} {k}")
            loops, dev, dist, notes = _pulled_loops(brep, face, s, tol, s.name)
            assert dev <= tol and dist <= tol and len(loops) == 1 and notes == [], (s.name, dev, dist)
            if not face.DuplicateFace(False).IsSurface:  # a planar cap: the pull-back meets the exact loops
                exact = _planar_loops(brep, face, s, "caps.3dm", s.name)
                D = s.derivatives(*np.array(s.domain).mean(axis=1)[:, None], 1)[0]
                slack = tol / np.linalg.svd(np.stack([D[1, 0], D[0, 1]], axis=1), compute_uv=False)[-1]
                for c in loops[0]:
                    t = np.linspace(*c.domain, 33)
                    uv = c.evaluate(t)
                    ref = np.concatenate([e.evaluate(np.linspace(*e.domain, 2001)) for e in exact[0]])
                    gap = np.linalg.norm(uv[:, None] - ref[None], axis=2).min(axis=1)
                    assert gap.max() <= slack + np.abs(np.diff(ref, axis=0)).max(), s.name
                continue
            (u0, u1), (v0, v1) = dom = np.array(s.domain)
            # every curve runs along one side of the domain: each point within the parameter error of a
            # side, tol / (the smallest tangent length along that side)
            uu, vv = np.meshgrid(np.linspace(u0, u1, 65), np.linspace(v0, v1, 65))
            D = s.derivatives(uu.ravel(), vv.ravel(), 1)
            speed = np.minimum(np.linalg.norm(D[:, 1, 0], axis=1), np.linalg.norm(D[:, 0, 1], axis=1))
            slack = tol / speed[speed > 1e-7 * speed.max()].min()
            length = 0.0
            for c in loops[0]:
                uv = c.evaluate(np.linspace(*c.domain, 33))
                side = np.abs(np.stack([uv[:, 0] - u0, uv[:, 0] - u1, uv[:, 1] - v0, uv[:, 1] - v1])).max(axis=1)
                assert side.min() <= slack, (s.name, uv[[0, -1]])
                length += np.linalg.norm(np.diff(uv, axis=0), axis=1).sum()
            assert abs(length - 2 * np.ptp(dom, axis=1).sum()) <= 4 * len(loops[0]) * slack, s.name
            rng = np.random.default_rng(k)
            inner = dom[:, 0] + (dom[:, 1] - dom[:, 0]) * rng.uniform(0.01, 0.99, (50, 2))
            assert inside(trim_pieces([loops]), 0, inner[:, 0], inner[:, 1]).all(), s.name
