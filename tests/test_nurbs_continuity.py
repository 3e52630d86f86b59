"""Seams of multi-patch models classified G0/G1/G2 with known answers (graphs of polynomials joined at x = 0)."""

import numpy as np
import pytest

from datasets_synthetic.nurbs_joins import joined_pair
from splinevis.nurbs.continuity import find_seams, seam_lines


@pytest.mark.parametrize("join, level", [("G2", "G2"), ("G1", "G1"), ("G0", "G0"), ("gap", "open")])
def test_known_joins_are_classified(join, level):
    a = 0.5
    seams = find_seams(joined_pair(join, a))
    assert len(seams) == 1
    s = seams[0]
    assert s.level == level and {s.side_a, s.side_b} == {"u=u1", "u=u0"}
    # known values at the seam x = 0: z' of A is 0, z'' of A is 2a (kappa = 2a across the seam, along x)
    if join == "G2":
        assert s.gap.max() == 0 and s.angle.max() < 1e-9 and s.curvature_jump.max() < 1e-12
    if join == "G1":
        assert s.angle.max() < 1e-9 and s.curvature_jump == pytest.approx(4 * a, rel=1e-12)
    if join == "G0":  # slopes 0 and a: angle atan(a)
        assert s.angle == pytest.approx(np.degrees(np.arctan(a)), rel=1e-12)
    if join == "gap":
        assert s.gap == pytest.approx(0.02, rel=1e-12)


def test_unrelated_patches_have_no_seam_and_lines_carry_classes():
    A, _ = joined_pair("G2")
    _, far = joined_pair("G1")
    from splinevis.nurbs.surface import NurbsSurface

    moved = NurbsSurface(far.degree, far.knots, far.control_points + [5.0, 0.0, 0.0])
    assert find_seams([A, moved]) == []
    lines = seam_lines(find_seams(joined_pair("G1")) + find_seams(joined_pair("G2")))
    assert sorted(set(lines.point_data["level"].tolist())) == [0, 1]


def test_vase_seams_are_g2_around_and_g1_along_the_profile():
    # the quarter circles meet with equal tangents and (by symmetry) equal end curvatures: G2, 4 x 8 seams;
    # the Catmull-Rom profile is C1 with curvature jumps: G1, 4 x 7 seams; the collapsed bottom row is a point
    from datasets_synthetic.nurbs_models import vase

    seams = find_seams(vase().surfaces)
    levels = {}
    for s in seams:
        levels.setdefault((s.side_a[0], s.level), 0)
        levels[(s.side_a[0], s.level)] += 1
    assert len(seams) == 60
    assert levels == {("u", "G2"): 32, ("v", "G1"): 28}


def test_normal_curvature_on_known_surfaces():
    # sphere: every direction bends by 1/r; torus: across the tube 1/r, around the axis cos(phi) / (R + r cos(phi))
    # (signs with respect to the surface's normal); the 2 x 2 solve is vectorized over the points
    from splinevis.nurbs.continuity import normal_curvature
    from splinevis.nurbs.exact import sphere, torus

    rng = np.random.default_rng(5)
    u, v = rng.uniform(0.05, 0.95, 50), rng.uniform(0.1, 0.9, 50)
    s = sphere(2.0)
    SKL, n = s.derivatives(u, v, 2), s.normal(u, v)
    c = np.cross(n, rng.normal(size=(50, 3)))  # random tangent directions
    k = normal_curvature(SKL, n, c)
    assert np.abs(np.abs(k) - 0.5).max() <= 1e-12 and np.ptp(np.sign(k)) == 0
    R, r = 2.0, 0.5
    t = torus(R, r)
    SKL, n = t.derivatives(u, v, 2), t.normal(u, v)
    p = t.evaluate(u, v)
    rho = np.hypot(p[:, 0], p[:, 1])
    cos_phi = (rho - R) / r
    around = np.column_stack([-p[:, 1], p[:, 0], np.zeros(50)])  # the circle about the axis
    across = np.cross(n, around)
    assert np.abs(np.abs(normal_curvature(SKL, n, across)) - 1 / r).max() <= 1e-11
    assert np.abs(np.abs(normal_curvature(SKL, n, around)) - np.abs(cos_phi / rho)).max() <= 1e-11
