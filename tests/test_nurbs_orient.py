"""Consistent outward orientation of a model's faces and the seams' continuity (splinevis.nurbs.orient), on
shapes whose outside, volume and seams are known exactly."""

import numpy as np
import pytest

from datasets_synthetic.nurbs_joins import joined_pair
from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net, cylinder
from splinevis.nurbs.model import NurbsModel, TrimCurve
from splinevis.nurbs.occ_faces import occ_outward
from splinevis.nurbs.orient import flip_u, orient_faces
from splinevis.nurbs.shell_volume import signed_volumes
from splinevis.nurbs.surface import NurbsSurface
from splinevis.nurbs.trim import inside, trim_pieces

EPS = np.finfo(float).eps


def _box(a=2.0, b=1.5, c=1.0):
    """The six faces of the box [0, a] x [0, b] x [0, c] as bilinear patches, each with S_u x S_v outward,
    and each face's outward axis (for the check)."""
    x0, x1, y0, y1, z0, z1 = 0.0, a, 0.0, b, 0.0, c
    P = lambda x, y, z: [x, y, z]  # noqa: E731
    faces = [  # (p00, p10, p01, p11) with (p10 - p00) x (p01 - p00) outward
        ((P(x0, y0, z0), P(x0, y1, z0), P(x1, y0, z0), P(x1, y1, z0)), (0, 0, -1)),
        ((P(x0, y0, z1), P(x1, y0, z1), P(x0, y1, z1), P(x1, y1, z1)), (0, 0, 1)),
        ((P(x0, y0, z0), P(x1, y0, z0), P(x0, y0, z1), P(x1, y0, z1)), (0, -1, 0)),
        ((P(x0, y1, z0), P(x0, y1, z1), P(x1, y1, z0), P(x1, y1, z1)), (0, 1, 0)),
        ((P(x0, y0, z0), P(x0, y0, z1), P(x0, y1, z0), P(x0, y1, z1)), (-1, 0, 0)),
        ((P(x1, y0, z0), P(x1, y1, z0), P(x1, y0, z1), P(x1, y1, z1)), (1, 0, 0)),
    ]
    surfaces = [NurbsSurface.bilinear(p00, p10, p01, p11, name=f"box {k}") for k, ((p00, p10, p01, p11), _) in
                enumerate(faces)]
    return surfaces, np.array([n for _, n in faces], dtype=np.float64), a * b * c


def _disk(radius, z, name):
    """The disk of ``radius`` at height ``z`` (a radius revolved; its centre a collapsed row), normal +z."""
    xy, w = circle_net()
    rho = np.array([0.0, radius])
    P = np.empty((9, 2, 3))
    P[..., 0] = xy[:, None, 0] * rho
    P[..., 1] = xy[:, None, 1] * rho
    P[..., 2] = z
    s = NurbsSurface((2, 1), (CIRCLE_KNOTS, [0.0, 0.0, 1.0, 1.0]), P, np.outer(w, [1.0, 1.0]), name=name)
    # u around, v outwards: S_u x S_v = (tangent) x (radial) = -z; flip so the surface's normal is +z
    return flip_u(s)[0]


def _closed_cylinder(r=1.5, h=2.0):
    side = cylinder(r, h)  # u around, v up: S_u x S_v points outwards
    bottom = flip_u(_disk(r, 0.0, "bottom"))[0]  # normal -z
    top = _disk(r, h, "top")
    return [side, bottom, top]


def _normals_outward(model, outward_of):
    """For every face, the sign of normal . (known outward direction) at 7 x 7 interior points."""
    signs = []
    t = np.linspace(0.1, 0.9, 7)
    for k, s in enumerate(model.surfaces):
        (u0, u1), (v0, v1) = s.domain
        U, V = np.meshgrid(u0 + t * (u1 - u0), v0 + t * (v1 - v0))
        u, v = U.ravel(), V.ravel()
        d = np.einsum("ij,ij->i", s.normal(u, v), outward_of(k, s.evaluate(u, v)))
        signs.append(np.sign(d))
    return signs


# -------------------------------------------------------------------------------------------------
def test_flip_u_is_the_same_face_backwards():
    rng = np.random.default_rng(7)
    U = np.r_[0, 0, 0, np.sort(rng.uniform(0.1, 2.9, 3)), 3, 3, 3] * 1.7 - 0.3
    V = np.r_[0, 0, 0, 0, 0.4, 1, 1, 1, 1]
    P, W = rng.normal(size=(6, 5, 3)), rng.uniform(0.5, 2.0, (6, 5))
    s = NurbsSurface((2, 3), (U, V), P, W, name="random")
    loop = [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in
            [((0.2, 0.1), (3.5, 0.2)), ((3.5, 0.2), (3.0, 0.9)), ((3.0, 0.9), (0.2, 0.1))]]
    f, loops = flip_u(s, [loop])
    # the knots are negated and reversed (negation is exact), the net reversed along u
    assert np.array_equal(f.knots[0], -U[::-1]) and np.array_equal(f.control_points, P[::-1])
    assert f.domain[0] == (-s.domain[0][1], -s.domain[0][0]) and np.array_equal(f.weights, W[::-1])
    # twice is the identity, bit for bit
    g, loops2 = flip_u(f, loops)
    assert np.array_equal(g.knots[0], U) and np.array_equal(g.control_points, P) and np.array_equal(g.weights, W)
    assert all(np.array_equal(c.control_points, d.control_points) for c, d in zip(loops2[0], loop))
    # the same points at u -> -u; the sums run in the other order, so equal up to rounding: each point is a
    # convex combination of <= 12 control points with weights in [0.5, 2] (relative error <= 4 * 12 eps)
    u = rng.uniform(*s.domain[0], 2000)
    v = rng.uniform(*s.domain[1], 2000)
    bound = 4 * 12 * EPS * np.abs(P).max() * (W.max() / W.min())
    assert np.abs(f.evaluate(-u, v) - s.evaluate(u, v)).max() <= bound
    # normals negated (to rounding of the derivatives: |S_u x S_v| is far from 0 on this net)
    assert np.abs(f.normal(-u, v) + s.normal(u, v)).max() <= 1e-12
    # the trimmed region is mirrored: the inside test agrees at mirrored parameters
    a, b = trim_pieces([[loop]]), trim_pieces([loops])
    assert np.array_equal(inside(a, 0, u, v), inside(b, 0, -u, v))
    assert inside(a, 0, u, v).any() and not inside(a, 0, u, v).all()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_box_with_random_flips_is_turned_outward(seed):
    surfaces, axes, volume = _box()
    rng = np.random.default_rng(seed)
    flipped = rng.random(6) < 0.5
    flipped[rng.integers(6)] = True  # at least one
    model = NurbsModel([flip_u(s)[0] if f else s for s, f in zip(surfaces, flipped)], source="box")
    out, report = orient_faces(model)
    centre = np.array([1.0, 0.75, 0.5])
    for signs in _normals_outward(out, lambda k, p: axes[k] + 0 * p):
        assert (signs == 1).all()
    # either the flipped faces are flipped back, or (no preferred parametrization) all the others
    assert sorted(report["flipped"]) == np.flatnonzero(flipped).tolist()
    (comp,) = report["components"]
    assert comp["closed"] and comp["faces"] == list(range(6)) and report["conflicts"] == []
    # bilinear faces: (S - c) . (S_u x S_v) is biquadratic, integrated exactly by the Gauss rule; what is left
    # is rounding in sums of 6 x 1024 terms (Higham2002, sec. 3.1: n eps sum |terms|)
    shares = signed_volumes(out.surfaces)
    assert abs(comp["signed_volume"] - volume) <= 6 * 1024 * EPS * np.abs(shares).sum() * 3
    assert out.report["orientation"] is report and out.source == "box"
    # every box edge is a sharp seam: G0 at 90 degrees between the outward normals
    seams = report["seams"]
    assert len(seams) == 12 and report["seam_levels"] == {"G0": 12}
    for s in seams:
        assert s.angle == pytest.approx(90.0, abs=1e-9) and s.gap.max() <= 1e-15
    assert centre is not None


def test_closed_cylinder_outward_and_its_volume():
    r, h = 1.5, 2.0
    faces = _closed_cylinder(r, h)
    model = NurbsModel([faces[0], faces[1], flip_u(faces[2])[0]], source="can")  # the lid upside down
    out, report = orient_faces(model)
    axes = [None, np.array([0, 0, -1.0]), np.array([0, 0, 1.0])]

    def outward(k, p):
        if k == 0:
            return p * [1.0, 1.0, 0.0]  # radial
        return np.broadcast_to(axes[k], p.shape)

    for signs in _normals_outward(out, outward):
        assert (signs == 1).all()
    assert report["flipped"] == [2]
    (comp,) = report["components"]
    assert comp["closed"]
    # rational faces: Gauss-Legendre converges geometrically on each quarter-circle span; the error of the
    # 8-point rule is below the difference between the 4- and 8-point rules
    v8 = signed_volumes(out.surfaces).sum()
    v4 = signed_volumes(out.surfaces, gauss=4).sum()
    assert comp["signed_volume"] == pytest.approx(v8, rel=1e-15)
    assert abs(v8 - np.pi * r * r * h) <= abs(v8 - v4)
    assert abs(v4 - np.pi * r * r * h) > 0  # the estimate is not vacuous
    # rims: sharp (90 degrees); the side's own seam (u = 0 meets u = 1) is no seam between faces
    assert sorted((s.a, s.b) for s in report["seams"]) == [(0, 1), (0, 2)]
    for s in report["seams"]:
        assert s.level == "G0" and s.angle == pytest.approx(90.0, abs=1e-7)


def test_trimmed_face_in_a_closed_shell():
    # the box's top is a larger plane trimmed to the box's top square; the loop runs clockwise (the face on its
    # right): its direction must be read from the inside test, not from the file
    surfaces, axes, volume = _box()
    big = NurbsSurface.bilinear([-1.0, -1.0, 1.0], [3.0, -1.0, 1.0], [-1.0, 2.5, 1.0], [3.0, 2.5, 1.0], name="top")
    # (u, v) of the square [0, 2] x [0, 1.5]: u = (x + 1) / 4, v = (y + 1) / 3.5
    corners = [(0.25, 1 / 3.5), (0.25, 2.5 / 3.5), (0.75, 2.5 / 3.5), (0.75, 1 / 3.5)]  # clockwise
    loop = [TrimCurve(1, [0, 0, 1, 1], [corners[i], corners[(i + 1) % 4]]) for i in range(4)]
    faces = list(surfaces)
    faces[1] = flip_u(big)[0]  # and upside down
    trims = [None] * 6
    trims[1] = flip_u(big, [loop])[1]
    out, report = orient_faces(NurbsModel(faces, trims, source="trimmed box"))
    assert report["flipped"] == [1] and report["components"][0]["closed"]
    assert report["ambiguous_trims"] == 0
    top = out.surfaces[1]
    assert top.domain[0] == (0.0, 1.0)  # flipped back: the original face
    assert np.allclose(top.normal([0.5], [0.5]), [[0.0, 0.0, 1.0]], rtol=0, atol=1e-15)
    # the midpoint grid over the loop's box covers the square exactly, the integrand is constant on a plane
    comp = report["components"][0]
    assert abs(comp["signed_volume"] - volume) <= 1e-12 * volume
    assert len(report["seams"]) == 12 and all(s.level == "G0" for s in report["seams"])


@pytest.mark.parametrize("flip_b", [False, True])
def test_tangent_pair_is_g1_and_open(flip_b):
    a = 0.5
    A, B = joined_pair("G1", a)
    model = NurbsModel([A, flip_u(B)[0] if flip_b else B])
    out, report = orient_faces(model)
    assert len(report["flipped"]) == (1 if flip_b else 0)
    (comp,) = report["components"]
    assert not comp["closed"] and comp["signed_volume"] is None and comp["open_length_fraction"] > 0.5
    (seam,) = report["seams"]
    # tangent planes agree (kink 0 with the normals oriented alike), the curvature across jumps by 4a
    assert seam.level == "G1" and seam.angle.max() <= 1e-6 and seam.gap.max() <= 1e-15
    assert seam.curvature_jump == pytest.approx(4 * a, rel=1e-9)
    n0 = out.surfaces[0].normal([1.0], [0.5])
    n1 = out.surfaces[1].normal([out.surfaces[1].domain[0][0] if not flip_b else -0.0], [0.5])
    assert float(np.dot(n0[0], n1[0])) == pytest.approx(1.0, abs=1e-12)


def test_sharp_edge_is_g0_with_its_angle():
    A, B = joined_pair("G0", a=1.0)  # slopes 0 and 1: 45 degrees
    out, report = orient_faces(NurbsModel([flip_u(A)[0], B]))
    (seam,) = report["seams"]
    assert seam.level == "G0" and seam.angle == pytest.approx(45.0, abs=1e-9)
    assert len(report["flipped"]) == 1


def test_open_surface_is_reported_open():
    s = joined_pair("G2")[0]
    out, report = orient_faces(NurbsModel([s]))
    (comp,) = report["components"]
    assert not comp["closed"] and comp["signed_volume"] is None and report["flipped"] == []
    assert report["seams"] == [] and len(report["free_edges"]) == 4


@pytest.mark.parametrize("shape", ["box", "cylinder"])
def test_agrees_with_opencascade_shell_fixing(shape):
    # OpenCASCADE sews the faces and fixes the shell (ShapeFix_Shell, ShapeFix_Solid): an independent answer
    surfaces = _box()[0] if shape == "box" else _closed_cylinder()
    rng = np.random.default_rng(3)
    flipped = rng.random(len(surfaces)) < 0.5
    flipped[0] = True
    model = NurbsModel([flip_u(s)[0] if f else s for s, f in zip(surfaces, flipped)])
    occ = occ_outward(model, 1e-7)
    _, report = orient_faces(model)
    ours = np.ones(len(surfaces))
    ours[report["flipped"]] = -1
    assert occ.tolist() == ours.tolist() and (occ == np.where(flipped, -1, 1)).all()


def test_moebius_band_is_reported_non_orientable():
    # 8 bilinear quads along a band that turns half a turn: no orientation agrees across all 8 edges, so one
    # adjacency contradicts the rest (a conflict) and the band is open
    n, R, w = 8, 2.0, 0.5
    ang = 2 * np.pi * np.arange(n + 1) / n

    def ruling(a):  # the band's cross-section at angle a: a segment turned by a / 2 about the circle's tangent
        c = np.array([R * np.cos(a), R * np.sin(a), 0.0])
        d = np.array([np.cos(a) * np.cos(a / 2), np.sin(a) * np.cos(a / 2), np.sin(a / 2)]) * w
        return c - d, c + d

    quads = []
    for k in range(n):
        (p00, p01), (p10, p11) = ruling(ang[k]), ruling(ang[k + 1])
        quads.append(NurbsSurface.bilinear(p00, p10, p01, p11, name=f"band {k}"))
    _, report = orient_faces(NurbsModel(quads))
    assert len(report["conflicts"]) == 1 and report["adjacent_pairs"] == n
    (comp,) = report["components"]
    assert not comp["closed"] and comp["signed_volume"] is None
