"""The analytic patch: exact values, float64 ray caster, bad input (no GPU)."""

import numpy as np
import pytest

from splinevis.analytic import QuarticTrianglePatch
from splinevis.bb import simplex

TRI = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]


def test_interpolates_a_quartic_exactly():
    f = lambda x, y: 1 + x - 2 * y + x**4 - 3 * x**2 * y**2 + y**3  # noqa: E731
    p = QuarticTrianglePatch.from_function(f, TRI)
    rng = np.random.default_rng(1)
    xy = rng.random((200, 2)) * 0.5
    # Quartic reproduction: error is rounding only (solve + de Casteljau on O(1) values): 1e-12 is
    # ~4500 u, far above the ~100 u such a 15x15 solve and evaluation accumulate.
    assert np.allclose(p.evaluate(xy), f(xy[:, 0], xy[:, 1]), atol=1e-12, rtol=0)
    g = p.gradient(xy)
    fx = 1 + 4 * xy[:, 0] ** 3 - 6 * xy[:, 0] * xy[:, 1] ** 2
    fy = -2 - 6 * xy[:, 0] ** 2 * xy[:, 1] + 3 * xy[:, 1] ** 2
    assert np.allclose(g, np.c_[fx, fy], atol=1e-11, rtol=0)


def test_vertical_ray_hits_graph_at_function_value():
    p = QuarticTrianglePatch.demo()
    xy = np.array([[0.0, -0.2], [0.1, 0.1], [-0.5, -0.6]])
    o = np.c_[xy, np.full(3, 5.0)]
    h = p.raycast(o, np.array([0.0, 0.0, -1.0]), 0.0)
    assert h.hit.all()
    assert np.allclose(h.points[:, 2], p.evaluate(xy), atol=1e-13)
    assert np.allclose(5.0 - h.t, p.evaluate(xy), atol=1e-12)


def test_ray_outside_triangle_misses_and_gpu_twin_agrees_with_reference():
    p = QuarticTrianglePatch.demo()
    h = p.raycast([5.0, 5.0, 5.0], [0.0, 0.0, -1.0])
    assert not h.hit
    rng = np.random.default_rng(2)
    xy = rng.uniform(-0.3, 0.3, (500, 2))
    o = np.c_[xy, np.full(500, 3.0)]
    d = np.c_[rng.uniform(-0.2, 0.2, (500, 2)), -np.ones(500)]
    a = p.raycast(o, d, method="reference")
    b = p.raycast(o, d, method="bracketed", iterations=8)
    assert a.hit.mean() > 0.5  # most rays of this bundle cross the patch (some leave the triangle)
    assert np.array_equal(a.hit, b.hit)
    # 8 safeguarded Newton steps from the Fourier end point converge quadratically on these simple
    # roots; in float64 the remaining error is a few ulps of t (|t| < 4).
    assert np.allclose(a.t[a.hit], b.t[b.hit], atol=1e-12)


def test_flat_patch_has_a_proxy_with_volume():
    p = QuarticTrianglePatch(np.full(15, 2.0), TRI)
    pts, tris = p.proxy()
    assert pts[:, 2].max() > pts[:, 2].min()
    assert tris.shape == (8, 3)


def test_triangulate_counts_and_lies_on_surface():
    p = QuarticTrianglePatch.demo()
    pts, tris = p.triangulate(10)
    assert tris.shape == (100, 3) and len(pts) == 66
    assert np.allclose(pts[:, 2], p.evaluate(pts[:, :2]), atol=1e-14)


@pytest.mark.parametrize("coef, verts, exc, match", [
    (np.r_[np.nan, np.zeros(14)], TRI, ValueError, r"coefficients must have finite values; found 1 non-finite, the first nan at index \(0,\)"),
    (np.zeros(10), TRI, ValueError, r"must have shape \(15,\), got \(10,\)"),
    (np.zeros(15), [[0, 0], [1, 1], [2, 2]], ValueError, "degenerate triangle"),
    (np.zeros(15), [[0, 0], [1, 0]], ValueError, r"vertices must have shape \(\.\.\., 3, 2\)"),
    (np.zeros(15), [[0, 0], [1, 0], [0, np.inf]], ValueError, "vertices must have finite values"),
    ("abc", TRI, TypeError, "coefficients must be an array of real numbers"),
])
def test_bad_input_is_named(coef, verts, exc, match):
    with pytest.raises(exc, match=match):
        QuarticTrianglePatch(coef, verts)


def test_bad_raycast_method_and_iterations():
    p = QuarticTrianglePatch.demo()
    with pytest.raises(ValueError, match="method 'bisect' is not known"):
        p.raycast([0, 0, 1], [0, 0, -1], method="bisect")
    with pytest.raises(ValueError, match="iterations"):
        p.raycast([0, 0, 1], [0, 0, -1], method="bracketed", iterations=0)


def test_patch_coefficient_order_matches_multi_indices():
    idx = simplex.multi_indices(4, 2)
    assert idx[:4].tolist() == [[4, 0, 0], [3, 1, 0], [3, 0, 1], [2, 2, 0]]
