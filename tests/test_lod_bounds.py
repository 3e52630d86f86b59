"""Proven deviation bounds and the adaptive tessellation of one Bezier patch [Kumar1997, sec. 4.1, 4.2].

Tolerance of the sampled checks
-------------------------------
A bound is a statement about exact numbers; the test measures ``|F(p) - L(p)|`` in float64. ``F(p)`` is a
sum of ``(m + 1)(n + 1)`` products with non-negative basis values summing to 1, then a quotient by ``w``: off
by at most ``4 (m + 1)(n + 1) eps max |P| (max w / min w)`` (the evaluator tolerance of the Bezier module's
tests, [Higham2002, sec. 3.4]); ``L(p)`` is a convex combination of three computed points, a few ulps of
``max |P|`` more. So a sampled deviation may exceed the true one by ``SLACK = (4 (m + 1)(n + 1) + 4) eps
max |P| (max w / min w)``, and every check reads ``sampled <= bound + SLACK`` (the bound's own rounding term
is inside ``bound``). No check is tuned to what it measured: the factors stated below are quality
statements, each asserted with the measured value rounded up.
"""

import numpy as np
import pytest

from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.lod.adaptive import adaptive_tessellation, barycentric_grid, curve_chain
from splinevis.nurbs.lod.bounds import (box_bound, collapsed_point, curve_chord_bounds, curve_points, kumar_bound,
                                        patch_points, second_derivative_bounds, side_net, triangle_bounds,
                                        waldron_bound)
from splinevis.nurbs.operations import bezier_patches
from splinevis.nurbs.surface import NurbsSurface

EPS = np.finfo(float).eps
GRID40 = barycentric_grid(40)  # 861 points per triangle for the bound checks
GRID9 = barycentric_grid(9)  # 55 points per triangle (edges and vertices included) for the tessellations


def homogeneous(P, w=None):
    w = np.ones(P.shape[:-1]) if w is None else w
    return np.concatenate([P * w[..., None], w[..., None]], axis=-1)


def random_patch(rng, m, n, rational):
    P = rng.normal(size=(m + 1, n + 1, 3))
    return homogeneous(P, rng.uniform(0.3, 3.0, (m + 1, n + 1)) if rational else None)


def slack(Pw):
    m, n = Pw.shape[0] - 1, Pw.shape[1] - 1
    w = Pw[..., 3]
    size = np.abs(Pw[..., :3] / w[..., None]).max()
    return (4 * (m + 1) * (n + 1) + 4) * EPS * size * w.max() / w.min()


def random_triangles(rng, k, lo=-2.5, hi=0.0):
    """``k`` triangles in [0, 1]^2 of sizes 10^lo..10^hi, any shape short of degenerate."""
    out = []
    while len(out) < k:
        h = 10 ** rng.uniform(lo, hi)
        c = rng.uniform(0, 1, 2)
        t = np.clip(c + h * rng.uniform(-1, 1, (3, 2)), 0.0, 1.0)
        e1, e2 = t[1] - t[0], t[2] - t[0]
        if abs(e1[0] * e2[1] - e1[1] * e2[0]) > 1e-2 * max(e1 @ e1, e2 @ e2):
            out.append(t)
    return np.array(out)


def sampled_deviation(Pw, tri, grid=GRID40):
    """``(T,)`` largest ``|F - L|`` over a barycentric grid of each triangle (vertices from patch_points)."""
    P = grid @ tri
    F = patch_points(Pw, P.reshape(-1, 2)).reshape(P.shape[:2] + (3,))
    X = patch_points(Pw, tri.reshape(-1, 2)).reshape(-1, 3, 3)
    return np.linalg.norm(F - grid @ X, axis=-1).max(axis=1)


# ---------------------------------------------------------------------------------------------------------
# (a) the bounds hold, and how far above the sampled deviation they are
@pytest.mark.parametrize("rational", [False, True])
def test_triangle_bound_holds_on_random_patches_and_triangles(rational):
    rng = np.random.default_rng(7 + rational)
    ratios = {"net": [], "split": [], "best": []}
    for m in range(1, 6):
        for n in range(1, 6):
            Pw = random_patch(rng, m, n, rational)
            tri = random_triangles(rng, 12)
            dev = sampled_deviation(Pw, tri)
            for method in ratios:
                b = triangle_bounds(Pw, tri, method=method)
                assert (dev <= b + slack(Pw)).all(), (m, n, method, (dev - b).max())
                ratios[method].append(b / np.maximum(dev, 1e-300))
    r = {k: np.concatenate(v) for k, v in ratios.items()}
    best = r["best"]
    assert (best <= np.minimum(r["net"], r["split"]) * (1 + 1e-12)).all()
    # bound / sampled, measured (seeds 7, 8; 300 triangles each): polynomial median 1.86, 90 % 4.8, max 26;
    # rational (weights 0.3..3) median 1.94, 90 % 8.0, max 183. The tail: large triangles, where the net's
    # hull of D^2 G and 1 / min w are far from the values near the maximum of |F - L|.
    assert np.median(best) <= 3.0
    assert np.quantile(best, 0.9) <= 10.0


def test_small_triangles_approach_the_sharp_constant():
    """On small equilateral triangles the bound tends to (1/2) R^2 sup |D^2_d F| / (true deviation): for a
    paraboloid z = u^2 + v^2 (isotropic) Waldron's bound is attained, the ratio tends to 1."""
    g = np.linspace(0.0, 1.0, 3)
    P = np.zeros((3, 3, 3))
    P[..., 0], P[..., 1] = g[:, None], g[None, :]
    P[..., 2] = np.array([0.0, 0.0, 1.0])[:, None] + np.array([0.0, 0.0, 1.0])[None, :]  # u^2 + v^2
    Pw = homogeneous(P)
    h = 1e-2
    tri = np.array([[0.4, 0.4], [0.4 + h, 0.4], [0.4 + h / 2, 0.4 + h * np.sqrt(3) / 2]])[None]
    ratio = triangle_bounds(Pw, tri)[0] / sampled_deviation(Pw, tri, barycentric_grid(60))[0]
    assert 1.0 <= ratio <= 1.01


def test_second_derivative_bounds_and_subdivision():
    rng = np.random.default_rng(3)
    for m, n in [(2, 2), (3, 5), (5, 4)]:
        P = rng.normal(size=(m + 1, n + 1, 3))
        s = NurbsSurface((m, n), ([0.0] * (m + 1) + [1.0] * (m + 1), [0.0] * (n + 1) + [1.0] * (n + 1)), P)
        box = np.array([0.2, 0.45, 0.6, 0.7])
        u, v = np.meshgrid(np.linspace(box[0], box[1], 30), np.linspace(box[2], box[3], 30))
        d = s.derivatives(u.ravel(), v.ravel(), 2)
        true = np.array([np.linalg.norm(d[:, 2, 0], axis=1).max(), np.linalg.norm(d[:, 1, 1], axis=1).max(),
                         np.linalg.norm(d[:, 0, 2], axis=1).max()])
        whole, local = second_derivative_bounds(P), second_derivative_bounds(P, box)
        assert (true <= local * (1 + 1e-12)).all() and (local <= whole * (1 + 1e-12)).all()


def test_kumar_formula_against_waldron():
    """Which is tighter where (same M): the paper's formula on axis-aligned right triangles, always (there
    R^2 = (l1^2 + l2^2)/4 and l^T M l <= |l|^2 lambda_max); Waldron's on equilateral triangles with isotropic
    curvature (R^2 = s^2/3 against the box's (s^2 + 3 s^2/4)/4), and on any triangle with isotropic M."""
    rng = np.random.default_rng(11)
    M = rng.uniform(0, 5, (200, 3))
    l1, l2 = rng.uniform(0.01, 1, 200), rng.uniform(0.01, 1, 200)
    right = np.zeros((200, 3, 2))
    right[:, 1, 0], right[:, 2, 1] = l1, l2
    k, w = kumar_bound(l1, l2, M), waldron_bound(right, M)
    assert (k <= w * (1 + 1e-12)).all() and (k < 0.9 * w).mean() > 0.5
    assert np.allclose(box_bound(right, M), k)
    equi = np.array([[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]])
    iso = np.array([1.0, 0.0, 1.0])
    assert waldron_bound(equi, iso) == pytest.approx(1 / 6) and box_bound(equi, iso) == pytest.approx(7 / 32)
    # any triangle with isotropic M: Waldron's never larger (R <= half the box diagonal), equal on right ones
    tri = random_triangles(rng, 200)
    assert (waldron_bound(tri, iso) <= box_bound(tri, iso) * (1 + 1e-12)).all()
    # on a patch: both are proven for a right triangle (M over its box), the paper's no larger
    Pw = random_patch(rng, 3, 3, False)
    tri = np.array([[[0.2, 0.3], [0.5, 0.3], [0.2, 0.4]]])
    box = np.array([0.2, 0.5, 0.3, 0.4])
    Mp = second_derivative_bounds(Pw[..., :3], box)
    dev = sampled_deviation(Pw, tri)[0]
    assert dev <= kumar_bound(0.3, 0.1, Mp) <= waldron_bound(tri[0], Mp)


def test_curve_chord_bound_holds():
    rng = np.random.default_rng(5)
    s = np.linspace(0, 1, 201)
    ratios = []
    for p in range(1, 6):
        for rational in (False, True):
            w = rng.uniform(0.3, 3.0, p + 1) if rational else np.ones(p + 1)
            X = rng.normal(size=(p + 1, 3))
            Pw = np.column_stack([X * w[:, None], w])
            t = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 6)]))
            b = curve_chord_bounds(Pw, t)
            tt = t[:-1, None] + s * np.diff(t)[:, None]
            C = curve_points(Pw, tt.ravel()).reshape(tt.shape + (3,))
            E0, E1 = curve_points(Pw, t[:-1]), curve_points(Pw, t[1:])
            dev = np.linalg.norm(C - (E0[:, None] + s[:, None] * (E1 - E0)[:, None]), axis=-1).max(axis=1)
            tol = (4 * (p + 1) + 4) * EPS * np.abs(X).max() * w.max() / w.min()
            assert (dev <= b + tol).all()
            if p == 1 and not rational:
                assert (b < 1e-13).all()  # a line is its chord
            else:
                ratios.append(b / dev)
    assert np.median(np.concatenate(ratios)) <= 3.0


def test_non_positive_weights_are_refused():
    Pw = homogeneous(np.zeros((3, 3, 3)), np.array([[1.0, 1, 1], [1, -3, 1], [1, 1, 1]]))
    with pytest.raises(ValueError, match="weights are not positive"):
        triangle_bounds(Pw, np.array([[[0, 0], [1, 0], [0, 1]]]))


# ---------------------------------------------------------------------------------------------------------
# (b) adaptive tessellation: the dense sampled deviation never exceeds delta, the mesh is conforming
def bump():
    g = np.linspace(0, 1, 4)
    P = np.zeros((4, 4, 3))
    P[..., 0], P[..., 1] = g[:, None], g[None, :]
    P[1:3, 1:3, 2] = 0.8
    return homogeneous(P)


def polynomial_pole():
    """Bicubic, side u = 0 collapsed to the apex of a curved cone."""
    a = np.linspace(0, np.pi / 2, 4)
    r = np.array([0.0, 0.4, 0.8, 1.2])
    P = np.stack([r[:, None] * np.cos(a), r[:, None] * np.sin(a), (r ** 2)[:, None] * np.ones(4)], axis=-1)
    return homogeneous(P)


def sphere_patches():
    return [s.homogeneous() for s, _ in bezier_patches(sphere(2.0))]


def check_conforming(t):
    """Every triangle counter-clockwise with positive area, the areas sum to 1 (the domain is covered),
    each interior edge in exactly two triangles with opposite orientation, boundary edges on the sides."""
    V = t.uv[t.triangles]
    e1, e2 = V[:, 1] - V[:, 0], V[:, 2] - V[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert (area > 0).all() and area.sum() == pytest.approx(1.0, abs=1e-12)
    a, b = t.triangles.ravel(), np.roll(t.triangles, -1, axis=1).ravel()
    directed = set(zip(a.tolist(), b.tolist()))
    assert len(directed) == a.size
    for x, y in directed:
        if (y, x) not in directed:  # a boundary edge: both ends on one side
            ux, uy = t.uv[x], t.uv[y]
            assert (ux[0] == uy[0] and ux[0] in (0.0, 1.0)) or (ux[1] == uy[1] and ux[1] in (0.0, 1.0))


def check_within(Pw, t, delta):
    dev = sampled_deviation(Pw, t.uv[t.triangles], GRID9)
    assert (dev <= t.bound + slack(Pw)).all()
    assert t.converged and (t.bound <= delta).all()
    assert dev.max() <= delta + slack(Pw)
    return dev


@pytest.mark.parametrize("delta", [1e-2, 1e-3])
def test_adaptive_bump(delta):
    t = adaptive_tessellation(bump(), delta)
    check_conforming(t)
    check_within(bump(), t, delta)


def test_adaptive_exact_sphere_with_poles():
    for Pw in sphere_patches():
        t = adaptive_tessellation(Pw, 2e-3)
        check_conforming(t)
        check_within(Pw, t, 2e-3)
        X = patch_points(Pw, t.uv)
        assert np.allclose(np.linalg.norm(X, axis=1), 2.0, rtol=0, atol=1e-14)
        # the pole: every point of the collapsed side is the pole exactly; the degenerate triangles in space
        # are exactly those with an edge on it
        pole_side = [k for k in range(4) if collapsed_point(side_net(Pw, k)) is not None]
        assert pole_side in ([0], [2])  # the south pole at v = 0 or the north pole at v = 1
        on = t.uv[:, 1] == (0.0 if pole_side == [0] else 1.0)
        assert (X[on] == X[on][0]).all()
        T = X[t.triangles]
        area3 = np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1)
        touching = on[t.triangles].sum(axis=1) == 2
        assert (area3[touching] == 0).all() and (area3[~touching] > 0).all()


def test_adaptive_polynomial_pole():
    Pw = polynomial_pole()
    t = adaptive_tessellation(Pw, 1e-3, chains=[None, None, None, np.array([0.0, 1.0])])
    check_conforming(t)
    check_within(Pw, t, 1e-3)
    assert t.limits == {}


def test_adaptive_with_given_chains_uses_them_exactly():
    Pw = bezier_patches(torus())[0][0].homogeneous()
    delta = 1e-3
    chains = [curve_chain(side_net(Pw, k), delta) for k in range(4)]
    for k, c in enumerate(chains):
        assert (curve_chord_bounds(side_net(Pw, k), c) <= delta).all()
    t = adaptive_tessellation(Pw, delta, chains=chains)
    check_conforming(t)
    check_within(Pw, t, delta)
    assert t.limits == {}
    for k, (axis, value, run) in enumerate(((1, 0.0, 0), (0, 1.0, 1), (1, 1.0, 0), (0, 0.0, 1))):
        on = t.uv[:, axis] == value
        assert np.array_equal(np.sort(t.uv[on, run]), chains[k])


def test_a_too_coarse_chain_limits_and_is_reported():
    Pw = bezier_patches(torus())[0][0].homogeneous()
    delta = 1e-3
    coarse = np.array([0.0, 0.5, 1.0])
    t = adaptive_tessellation(Pw, delta, chains=[coarse, None, None, None])
    b = curve_chord_bounds(side_net(Pw, 0), coarse)
    assert set(t.limits) == {0} and t.limits[0] == b.max() > delta
    check_conforming(t)
    # above delta only next to the coarse side: on its segments, or in the band along it at their ends
    assert t.converged
    high = t.bound > delta
    assert (t.uv[t.triangles[high], 1].min(axis=1) == 0.0).all()
    assert (t.uv[t.triangles[high], 1].max(axis=1) <= 0.5 / 8).all()
    # the triangles on a segment: their bound settled near the segment's curve bound (their L tilts across
    # the segment toward the curve: the (D_d w)(D_d L) term of a rational patch adds to it)
    assert t.bound.max() <= 1.2 * b.max()
    dev = sampled_deviation(Pw, t.uv[t.triangles], GRID9)
    assert (dev <= t.bound + slack(Pw)).all()
    on = t.uv[:, 1] == 0.0
    assert np.array_equal(np.sort(t.uv[on, 0]), coarse)


# ---------------------------------------------------------------------------------------------------------
# (c) neighbours given the same chain share their boundary points bitwise
def test_neighbours_share_boundary_vertices_bitwise():
    patches = bezier_patches(torus())
    A, B = patches[0][0].homogeneous(), patches[1][0].homogeneous()  # A's v = 1 is B's v = 0
    assert np.array_equal(side_net(A, 2), side_net(B, 0))
    delta = 1e-3
    chain = curve_chain(side_net(A, 2), delta)
    ta = adaptive_tessellation(A, delta, chains=[None, None, chain, None])
    tb = adaptive_tessellation(B, delta, chains=[chain, None, None, None])
    on_a, on_b = ta.uv[:, 1] == 1.0, tb.uv[:, 1] == 0.0
    ua, ub = ta.uv[on_a, 0], tb.uv[on_b, 0]
    assert np.array_equal(np.sort(ua), chain) and np.array_equal(np.sort(ub), chain)
    Xa = patch_points(A, ta.uv[on_a])[np.argsort(ua)]
    Xb = patch_points(B, tb.uv[on_b])[np.argsort(ub)]
    assert np.array_equal(Xa, Xb)
    assert np.array_equal(Xa, curve_points(side_net(A, 2), chain))


# ---------------------------------------------------------------------------------------------------------
# (d) more triangles for a smaller delta
def test_triangle_count_grows_as_delta_shrinks():
    counts = [adaptive_tessellation(bump(), d).triangles.shape[0] for d in (1e-2, 1e-3, 1e-4)]
    assert counts[0] < counts[1] < counts[2]
