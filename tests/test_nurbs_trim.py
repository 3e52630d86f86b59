"""The per-fragment trim test's float64 twin against known regions: circles (exact rational curves), nested
loops, a cubic B-spline loop, and points exactly level with vertices."""

import numpy as np
import pytest

from splinevis.nurbs.exact import CIRCLE_KNOTS, circle_net
from splinevis.nurbs.model import TrimCurve
from splinevis.nurbs.trim import inside, trim_pieces


def _polygon(pts):
    pts = [tuple(p) for p in pts]
    return [TrimCurve(1, [0, 0, 1, 1], [a, b]) for a, b in zip(pts, pts[1:] + pts[:1])]


def _circle(cx, cy, r):
    xy, w = circle_net()
    return [TrimCurve(2, CIRCLE_KNOTS, np.array([cx, cy]) + r * xy, w)]


BORDER = _polygon([(0, 0), (1, 0), (1, 1), (0, 1)])


def test_hole_with_island_matches_the_exact_circles():
    p = trim_pieces([[BORDER, _circle(0.5, 0.5, 0.35), _circle(0.5, 0.5, 0.15)]])
    rng = np.random.default_rng(1)
    u, v = rng.uniform(0, 1, 20000), rng.uniform(0, 1, 20000)
    r = np.hypot(u - 0.5, v - 0.5)
    want = (r > 0.35) | (r < 0.15)
    # the curves are the exact circles (rational quadratics); bisection leaves 2^-60 of t: only points within
    # 1e-12 of a circle could differ, and none of the random ones is that close
    keep = (np.abs(r - 0.35) > 1e-12) & (np.abs(r - 0.15) > 1e-12)
    assert np.array_equal(inside(p, 0, u[keep], v[keep]), want[keep])


def test_points_level_with_vertices_and_on_the_border_are_counted_once():
    tri = _polygon([(0.2, 0.2), (0.8, 0.5), (0.2, 0.8)])  # vertex (0.8, 0.5) level with v0 = 0.5
    p = trim_pieces([[tri]])
    got = inside(p, 0, [0.5, 0.79, 0.81, 0.1, 0.5], [0.5, 0.5, 0.5, 0.5, 0.2])
    assert got.tolist() == [True, True, False, False, False]  # v = 0.2 is the bottom vertex row: half-open


def test_cubic_unclamped_loop_against_dense_sampling():
    # a closed uniform cubic B-spline (periodic: the first 3 control points repeated, unclamped knots)
    ang = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    rad = 0.3 + 0.1 * np.cos(3 * ang)
    ctrl = np.column_stack([0.5 + rad * np.cos(ang), 0.5 + rad * np.sin(ang)])
    ctrl = np.vstack([ctrl, ctrl[:3]])
    curve = TrimCurve(3, np.arange(ctrl.shape[0] + 4, dtype=float), ctrl)
    p = trim_pieces([[[curve]]])
    assert (p.degree == 3).all() and p.count[0] >= 8  # 8 spans, some split where v turns
    poly = curve.evaluate(np.linspace(*curve.domain, 20001))
    from matplotlib.path import Path

    rng = np.random.default_rng(2)
    pts = rng.uniform(0.1, 0.9, size=(5000, 2))
    want = Path(poly).contains_points(pts)
    got = inside(p, 0, pts[:, 0], pts[:, 1])
    # the polygon of 20001 samples is within ~1e-8 of the curve: only points that close may differ
    d = np.min(np.linalg.norm(pts[:, None, :] - poly[None, ::4, :], axis=-1), axis=1)
    far = d > 1e-3
    assert far.sum() > 4000 and np.array_equal(got[far], want[far])


def test_untrimmed_patch_is_inside_everywhere_and_high_degree_is_refused():
    p = trim_pieces([None, [BORDER]])
    assert inside(p, 0, [0.3, 5.0], [0.3, -1.0]).all()
    curve = TrimCurve(4, [0] * 5 + [1] * 5, np.random.default_rng(0).uniform(size=(5, 2)))
    with pytest.raises(ValueError, match="degree 4: the per-fragment trim test handles degree <= 3"):
        trim_pieces([[[curve]]])


@pytest.mark.gl
def test_glsl_trim_test_matches_the_twin_and_has_no_staircase_at_1000x_zoom():
    from splinevis.gl.harness import run_glsl
    from splinevis.gl.proxies import pack_rgba32f

    p = trim_pieces([[BORDER, _circle(0.5, 0.5, 0.35), _circle(0.5, 0.5, 0.15)]])
    table = pack_rgba32f(p.table(), name="trim")
    rng = np.random.default_rng(3)
    uv = rng.uniform(0, 1, size=(20000, 2))
    # and a 1000x zoom onto the hole's boundary: a 200 x 200 window 1e-3 wide at (0.85, 0.5)
    g = np.linspace(-5e-4, 5e-4, 200)
    zu, zv = np.meshgrid(0.85 + g, 0.5 + g)
    uv = np.vstack([uv, np.column_stack([zu.ravel(), zv.ravel()])]).astype(np.float32).astype(np.float64)
    body = "sv_out[0] = sv_trim_inside(0, int(sv_in[2]), vec2(sv_in[0], sv_in[1])) ? 1.0 : 0.0;"
    inputs = np.column_stack([uv, np.full(len(uv), p.count[0])])
    functions = 'uniform sampler2D sv_trim_table;\n#include "lib/core/table.glsl"\n#include "lib/nurbs/trim.glsl"\n'
    gpu = run_glsl(functions, body, inputs, 1,
                   tables={"sv_trim_table": table})[:, 0] > 0.5
    want = inside(p, 0, uv[:, 0], uv[:, 1])
    r = np.hypot(uv[:, 0] - 0.5, uv[:, 1] - 0.5)
    # float32: control points and the bisection's t carry ~2^-24 relative error, moving the boundary by about
    # 1e-7 in (u, v); only points that close to a circle may differ
    near = (np.abs(r - 0.35) < 4e-7) | (np.abs(r - 0.15) < 4e-7)
    assert np.array_equal(gpu[~near], want[~near])
    # in the zoomed window (a pixel is 5e-6 wide) the inside region is bounded by the circle: the boundary
    # column per row follows sqrt(0.35^2 - dv^2) to within a pixel (no steps of the size of a chord)
    zoom = gpu[-40000:].reshape(200, 200)
    assert 0 < zoom.sum() < zoom.size
    first_inside = np.argmax(zoom, axis=1)  # u index where "inside" (outside the hole) starts per row
    want_u = 0.5 + np.sqrt(0.35**2 - (zv[:, 0] - 0.5) ** 2)
    want_col = np.searchsorted(g + 0.85, want_u)
    assert np.abs(first_inside - want_col).max() <= 1
