"""The smooth geometry image's bicubic surface [Losasso2003, sec. 3] in float64: scipy's NdBSpline as the
reference, closed and C2 across the X-cut, C1 at the four cut vertices only with the centroid constraint, and the
least-squares fit with fairness (exact recovery, order of convergence, what fairness trades)."""

import numpy as np
import pytest
from scipy.interpolate import NdBSpline

from _cut_vertex import cone_measure
from datasets_synthetic.closed_meshes import star_blob_normals, star_blob_radius
from splinevis.geometry_image.fit import fit_geometry_image, free_variables
from splinevis.geometry_image.image import (apply_cut_constraint, image_uv, octahedral_to_sphere, pad, symmetrize,
                                            symmetry_defect)
from splinevis.geometry_image.model import GeometryImage


def _blob(d, eps=0.25):
    return d * star_blob_radius(d, eps)[:, None]


def _random_image(n, seed=0):
    G = octahedral_to_sphere(image_uv(n)) * [2.0, 1.0, 0.7]
    G = G + 0.05 * np.random.default_rng(seed).normal(size=G.shape)
    return GeometryImage(symmetrize(G), constrain=True)


def _reference(G):
    """scipy's tensor-product B-spline on the padded image (rows: t, columns: s)."""
    N = G.shape[0] - 1
    knots = np.arange(-3.0, N + 4.0)
    return NdBSpline((knots, knots), pad(G, 1), 3)


def test_evaluation_equals_scipy_ndbspline():
    gi = _random_image(17)
    ref = _reference(gi.control)
    st = np.random.default_rng(1).uniform(0, 16, size=(500, 2))
    st = np.vstack([st, [[0, 0], [16, 16], [16, 0], [8, 0]]])
    P, Ps, Pt, Pss, Pst, Ptt = gi.evaluate(st, derivatives=2)
    ts = st[:, ::-1]
    scale = np.abs(gi.control).max()
    for got, nu in [(P, (0, 0)), (Ps, (0, 1)), (Pt, (1, 0)), (Pss, (0, 2)), (Pst, (1, 1)), (Ptt, (2, 0))]:
        np.testing.assert_allclose(got, ref(ts, nu=nu), atol=1e-13 * scale, rtol=0)


def test_closed_and_c2_across_the_x_cut():
    """Crossing a border is a half turn about its midpoint: P(s, -e) = P(N - s, e) with every derivative of order
    k multiplied by (-1)^k (the chain rule of (s, t) -> (N - s, -t)); the same for the other three borders."""
    gi = _random_image(17)
    N = 16
    rng = np.random.default_rng(2)
    s = rng.uniform(0, N, 200)
    e = rng.uniform(0, 0.9, 200)
    scale = np.abs(gi.control).max()
    pairs = [(np.column_stack([s, -e]), np.column_stack([N - s, e])),
             (np.column_stack([s, N + e]), np.column_stack([N - s, N - e])),
             (np.column_stack([-e, s]), np.column_stack([e, N - s])),
             (np.column_stack([N + e, s]), np.column_stack([N - e, N - s]))]
    for outside, inside in pairs:
        a = gi.evaluate(outside, derivatives=2)
        b = gi.evaluate(inside, derivatives=2)
        for k, (x, y) in enumerate(zip(a, b)):
            sign = -1.0 if k in (1, 2) else 1.0
            np.testing.assert_allclose(x, sign * y, atol=1e-13 * scale, rtol=0)


def test_c2_at_knot_lines():
    """One-sided second derivatives from the cells on both sides of the knot line s = 5 agree."""
    gi = _random_image(17)
    t = np.linspace(0.1, 15.9, 50)
    st = np.column_stack([np.full_like(t, 5.0), t])
    left = gi.evaluate(st, 2, cells=np.column_stack([np.full(t.size, 4), np.floor(t)]))
    right = gi.evaluate(st, 2, cells=np.column_stack([np.full(t.size, 5), np.floor(t)]))
    for x, y in zip(left, right):
        np.testing.assert_allclose(x, y, atol=1e-12 * np.abs(gi.control).max(), rtol=0)


def test_cut_vertices_are_c1_only_with_the_centroid_constraint():
    """[Losasso2003, appendix]: without the constraint the subdominant eigenvalue 1/4 is triple and the three
    second-order terms are independent (a cusp); with it they are coplanar. Rounding bound for the constrained
    case: each term is a sum of ~16 products of values <= |G|, so the normalized determinant is ~1e-14."""
    G = symmetrize(octahedral_to_sphere(image_uv(17)) * [2.0, 1.0, 0.7]
                   + 0.05 * np.random.default_rng(3).normal(size=(17, 17, 3)))
    free = cone_measure(G)
    constrained = cone_measure(apply_cut_constraint(G))
    assert free.min() > 1e-3, free
    assert constrained.max() < 1e-12, constrained


def test_normals_converge_to_the_cut_vertex_normal():
    """Tangent-plane continuity at the cut vertices: normals on a circle of radius rho around them approach the
    vertex normal linearly in rho (the normal is C0 with bounded derivative along rays: the angle halves with rho)."""
    gi = _random_image(17, seed=4)
    theta = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    for (s0, t0), n0 in zip(gi.cut_vertices, gi.normals(gi.cut_vertices)):
        angles = []
        for rho in (0.02, 0.01, 0.005):
            st = np.column_stack([s0 + rho * np.cos(theta), t0 + rho * np.sin(theta)])
            n = gi.normals(st)
            angles.append(np.degrees(np.arccos(np.clip(n @ n0, -1, 1))).max())
        assert angles[0] < 5.0
        assert angles[1] < 0.6 * angles[0] and angles[2] < 0.6 * angles[1], angles


def test_invalid_images_are_refused():
    G = octahedral_to_sphere(image_uv(9))
    with pytest.raises(ValueError, match="identified by the X-cut"):
        GeometryImage(G + np.random.default_rng(0).normal(size=G.shape) * 1e-3)
    with pytest.raises(ValueError, match="cut vertices are off"):
        GeometryImage(G)
    with pytest.raises(ValueError, match="odd number"):
        GeometryImage(np.zeros((8, 8, 3)))
    bad = G.copy()
    bad[3, 4] = np.nan
    with pytest.raises(ValueError, match=r"\(3, 4\) is not finite"):
        GeometryImage(bad, constrain=True)


def test_free_variables_map_keeps_the_invariants():
    S, free = free_variables(33)
    x = np.random.default_rng(5).normal(size=(free.size, 3))
    G = (S @ x).reshape(33, 33, 3)
    assert symmetry_defect(G) == 0.0
    np.testing.assert_allclose(apply_cut_constraint(G), G, atol=1e-15)


def test_fit_recovers_a_spline_exactly():
    """Samples of a bicubic geometry image lie in the fitting space: with fairness 0 the least-squares solution is
    that image (up to CG's relative residual 1e-10 times the condition of the normal equations, ~1e2)."""
    gi = _random_image(17, seed=6)
    M = 4 * 16 + 1
    w = np.linspace(0, 16, M)
    s, t = np.meshgrid(w, w, indexing="xy")
    X = gi.evaluate(np.stack([s, t], axis=-1))
    r = fit_geometry_image(None, 17, fairness=0.0, samples=X, rtol=1e-12)
    np.testing.assert_allclose(r.image.control, gi.control, atol=1e-8 * np.abs(gi.control).max(), rtol=0)
    assert r.max < 1e-9


def test_fit_converges_at_order_two_on_the_star_blob():
    """The distance to the exact surface (radial error of the star-shaped blob) falls ~4x per doubling of n: the
    bicubic space approximates smooth surfaces at order 2 even where the octahedral map has kinks (the fit places
    points along the surface, the kinks cost tangential, not normal, accuracy). Asserted: ratio > 3 (order > 1.58)."""
    errors = []
    for n in (17, 33, 65):
        gi = fit_geometry_image(_blob, n, fairness=0.0).image
        P = gi.evaluate(gi.sample_grid(2).reshape(-1, 2))
        r = np.linalg.norm(P, axis=1)
        errors.append(np.abs(r - np.linalg.norm(_blob(P / r[:, None]), axis=1)).max())
    assert errors[0] / errors[1] > 3 and errors[1] / errors[2] > 3, errors
    assert errors[2] < 1e-3


def test_fairness_trades_distance_for_smoothness():
    """Tikhonov regularization: as lambda grows the data term cannot fall and the fairness term cannot rise."""
    fits = [fit_geometry_image(_blob, 33, fairness=lam, rtol=1e-12) for lam in (0.0, 1e-3, 1e-2, 1e-1, 1.0)]
    rms = [f.rms for f in fits]
    rough = [f.roughness for f in fits]
    assert all(b >= a * (1 - 1e-9) for a, b in zip(rms, rms[1:])), rms
    assert all(b <= a * (1 + 1e-9) for a, b in zip(rough, rough[1:])), rough
    assert rough[-1] < 0.5 * rough[0] and rms[-1] > 1.05 * rms[0]


def test_fitted_normals_converge_to_the_exact_normals():
    """Normals of the fitted blob against the exact normals at the same surface points. The largest errors sit next
    to the cut vertices (C1 with unbounded curvature [Losasso2003, appendix]) and fall at order 1 in h: the max
    angle must halve (ratio > 1.6) from n = 33 to 65; the RMS falls faster (ratio > 2.2, order > 1.1)."""
    worst, rms = [], []
    for n in (33, 65):
        gi = fit_geometry_image(_blob, n, fairness=0.0).image
        st = gi.sample_grid(1).reshape(-1, 2)
        P, nrm = gi.evaluate(st), gi.normals(st)
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", nrm, star_blob_normals(P, eps=0.25)), -1, 1)))
        worst.append(angle.max())
        rms.append(np.sqrt((angle ** 2).mean()))
    assert worst[0] / worst[1] > 1.6 and rms[0] / rms[1] > 2.2, (worst, rms)
