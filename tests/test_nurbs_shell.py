"""The GPU shell of the NURBS program (splinevis/nurbs/shell.py) and the build's fast paths: straight directions
get one cell per knot span (span_turning bounds the tangents' turn), curved ones keep all their cells; the cached
patch facts, the lean trim-piece cuts and the grouped trim evaluation give the same bits as the plain code."""

import numpy as np
import pytest

from splinevis.nurbs import shell
from splinevis.nurbs.exact import box_faces, cylinder, saddle, sphere, torus
from splinevis.nurbs.hard_cases import bumpy, degree7
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.surface import NurbsSurface
from splinevis.nurbs.tessellate import span_grid


def _random_patch(rng, p, q, nu, nv, rational=True):
    P = rng.normal(size=(nu, nv, 3))
    P[..., 0] += np.arange(nu)[:, None] * 2.0
    P[..., 1] += np.arange(nv)[None, :] * 2.0
    U = np.r_[np.zeros(p), np.linspace(0, 1, nu - p + 1), np.ones(p)]
    V = np.r_[np.zeros(q), np.linspace(0, 1, nv - q + 1), np.ones(q)]
    w = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return NurbsSurface((p, q), (U, V), P, w)


@pytest.mark.parametrize("seed", range(6))
def test_span_turning_bounds_the_sampled_turn_of_the_tangents(seed):
    # non-rational and product-weight patches: the tangents inside a span stay in the cone of the span's legs
    rng = np.random.default_rng(seed)
    p, q = rng.integers(1, 4, 2)
    s = _random_patch(rng, int(p), int(q), int(p) + 3, int(q) + 3, rational=False)
    for axis in (0, 1):
        bound = shell.span_turning(s, axis)
        knots, (lo, hi) = s.knots[axis], s.domain[axis]
        k = np.unique(knots[(knots >= lo) & (knots <= hi)])
        for i, (a, b) in enumerate(zip(k[:-1], k[1:])):
            t = np.linspace(a, b, 41)[:-1]
            o = np.linspace(*s.domain[1 - axis], 13)
            T, O = np.meshgrid(t, o, indexing="ij")
            uu, vv = (T, O) if axis == 0 else (O, T)
            d = s.derivatives(uu.ravel(), vv.ravel(), 1)[:, 1, 0] if axis == 0 else \
                s.derivatives(uu.ravel(), vv.ravel(), 1)[:, 0, 1]
            e = d / np.linalg.norm(d, axis=-1, keepdims=True)
            worst = np.arccos(np.clip(e @ e.T, -1, 1)).max()  # angular diameter of the sampled tangents
            assert worst <= bound[i] + 1e-9, (axis, i, worst, bound[i])


def test_straight_directions_get_one_cell_curved_ones_all():
    assert shell.span_turning(cylinder(), 1).tolist() == [0.0]
    assert np.allclose(np.degrees(shell.span_turning(cylinder(), 0)), 90.0)
    us, vs = shell.shell_grid(cylinder(), 8)
    assert len(us) == len(span_grid(cylinder(), 8)[0]) and vs.tolist() == [0.0, 1.0]
    for face in box_faces():  # planes: one cell
        assert [len(g) for g in shell.shell_grid(face, 8)] == [2, 2]
    for s in (sphere(), torus(), saddle(), degree7(), bumpy(3, 1, 6, 2)):  # curved: the uniform grid
        got, want = shell.shell_grid(s, 8), span_grid(s, 8)
        for axis in (0, 1):
            if shell.span_turning(s, axis).max() > shell.STRAIGHT:
                assert np.array_equal(got[axis], want[axis]), (s.name, axis)


def test_adaptive_shell_is_still_certified_and_the_uniform_one_unchanged():
    model = NurbsModel([cylinder(), sphere(), *box_faces()])
    pts, tris, uv, patch = shell.tessellate(model, 8, adaptive=True)
    full = shell.tessellate(model, 8)
    assert len(tris) < len(full[1])
    for s in model.surfaces:
        us, vs = shell.shell_grid(s, 8)
        bound, dense = shell.certified_deviation(s, us, vs), shell._chord_deviation(s, us, vs, 1.0, k=32)
        assert (bound >= dense).all()
    # the uniform shell: span_grid's lines, as before the adaptive option existed
    us, vs = span_grid(sphere(), 8)
    assert shell.tessellate(NurbsModel([sphere()]), 8)[0].shape[0] == 2 * len(us) * len(vs)


def test_patch_facts_are_computed_once_per_model():
    model = NurbsModel([sphere(), torus(), cylinder()])
    first = shell.patch_facts(model)
    assert model in shell._FACTS
    again = shell.patch_facts(model)
    assert again == first and again is not first  # a fresh list: callers may not change the cache
    assert [f["closed"] for f in first] == [(shell._closed(s, 0), shell._closed(s, 1)) for s in model.surfaces]


EPS = np.finfo(float).eps
Pn = np.polynomial.polynomial


def _numerator(seg):
    """Y' W - Y W' in power form (numpy.polynomial), trailing zeros trimmed; its t^(2p-1) coefficient is zero in
    exact arithmetic (the leading terms cancel) and dropped."""
    from math import comb

    p = len(seg) - 1
    M = np.array([[comb(p, i) * comb(p - i, k - i) * (-1) ** (k - i) if k >= i else 0 for i in range(p + 1)]
                  for k in range(p + 1)], dtype=np.float64)
    Y, W = M @ seg[:, 1], M @ seg[:, 2]
    num = Pn.polysub(Pn.polymul(Pn.polyder(Y), W), Pn.polymul(Y, Pn.polyder(W)))
    return np.trim_zeros(num[: 2 * p - 1], "b")


def _v_turns_plain(seg):
    """The plain numpy.polynomial version of trim._v_turns."""
    num = _numerator(seg)
    if num.size <= 1:
        return []
    roots = Pn.polyroots(num)
    return sorted(float(r.real) for r in roots if abs(r.imag) < 1e-12 and 1e-12 < r.real < 1 - 1e-12)


def test_trim_cuts_match_numpy_polynomial_and_the_evaluation_the_plain_code():
    from splinevis.nurbs import trim

    rng = np.random.default_rng(7)
    for p in (1, 2, 3):
        for k in range(200):
            seg = np.column_stack([rng.normal(size=(p + 1, 2)), rng.uniform(0.3, 2.0, p + 1)])
            if k % 3 == 0:
                seg[:, 2] = 1.0  # polynomial: the top coefficients cancel exactly (trailing zeros trimmed)
            seg[:, :2] *= seg[:, 2:]
            c = _numerator(seg)
            got, want = trim._v_turns(seg), _v_turns_plain(seg)
            assert len(got) == len(want)
            # both are eigenvalues of a companion matrix, backward stable: each root is exact for coefficients
            # perturbed by about n eps |c|, so it moves by at most that over |c'(t)| (first order), twice over
            for t, r in zip(got, want):
                assert abs(t - r) <= 2 * 8 * len(c) * EPS * np.abs(c).sum() / abs(Pn.polyval(r, Pn.polyder(c)))
    segs = np.array([np.column_stack([rng.normal(size=(3, 2)), rng.uniform(0.3, 2.0, 3)]) for _ in range(50)])
    assert trim._v_turns_all(segs) == [trim._v_turns(s) for s in segs]  # batched = one by one, bit for bit
    ctrl = np.zeros((60, 4, 3))
    deg = rng.integers(1, 4, 60)
    for i, d in enumerate(deg):
        ctrl[i, : d + 1, :2] = rng.normal(size=(d + 1, 2))
        ctrl[i, : d + 1, 2] = rng.uniform(0.5, 2.0, d + 1)
    t = rng.uniform(0, 1, 60)
    f = trim._evaluator(ctrl, deg)
    ref = trim._eval(ctrl, deg, t)
    assert np.array_equal(f(t, 0), ref[:, 0]) and np.array_equal(f(t, 1), ref[:, 1])


def _gpu_and_twin_hits(model, camera):
    """Pixels the GPU program covers (depth < 1) and those the float64 twin hits, 160 x 120 from ``camera``."""
    import splinevis
    from splinevis.gl.camera import pixel_rays
    from splinevis.nurbs.program import PROGRAM

    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    pl.add_nurbs(model, lights=1)
    pl.camera_position = camera
    pl.reset_camera_clipping_range()
    img = pl.screenshot()
    depth, matrix = pl.depth_buffer(), pl.camera_matrix()
    pl.close()
    o, d = pixel_rays(matrix, *img.shape[1::-1])
    return depth < 1.0, PROGRAM.raycast(model, o, d).hit


@pytest.mark.gl
def test_gpu_cylinder_and_box_on_the_adaptive_shell_match_the_twin():
    model = NurbsModel([cylinder(1.0, 2.0, (3.0, 0.0, 0.0)), *box_faces(1.5, 1.0, 0.8)])
    gpu_hit, twin_hit = _gpu_and_twin_hits(model, [(8.0, -9.0, 6.0), (1.5, 0.0, 0.5), (0, 0, 1)])
    assert gpu_hit.mean() > 0.05
    assert (gpu_hit != twin_hit).sum() <= 0.002 * gpu_hit.size


def _bunched_ruled(rows=(0.0, 0.05, 0.1, 1.0)):
    """A ruled patch whose rulings are straight lines traced at varying speed: cubic in u with collinear
    control points bunched 0, 0.05, 0.1, 1 (like a real fuselage's: speed ratio ~7), a half circle in v."""
    from splinevis.nurbs.exact import circle_net

    xy, w = circle_net()
    xy, w = xy[:5], w[:5]  # two quarter arcs: half the circle
    V = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0])
    P = np.array([[[x, y, 4.0 * a] for x, y in xy] for a in rows])
    W = np.tile(w, (len(rows), 1))
    return NurbsSurface((3, 2), (np.array([0, 0, 0, 0, 1, 1, 1, 1.0]), V), P, W, name="bunched ruling")


def test_a_straight_span_at_varying_speed_keeps_its_cells():
    # the fuselage regression: turn 0 (straight) but not affine in the parameter: all cells, not one
    s = _bunched_ruled()
    assert shell.span_turning(s, 0).max() <= shell.STRAIGHT
    assert shell.span_affine(s, 0).tolist() == [False]
    assert len(shell.shell_grid(s, 8)[0]) == 9
    even = _bunched_ruled((0.0, 1 / 3, 2 / 3, 1.0))  # the same line at constant speed: one cell
    assert shell.span_affine(even, 0).tolist() == [True] and len(shell.shell_grid(even, 8)[0]) == 2


@pytest.mark.gl
def test_gpu_finds_every_hit_on_rulings_traced_at_varying_speed():
    camera = [(5.0, -6.0, 6.0), (0.0, 0.5, 2.0), (0, 0, 1)]
    gpu_hit, twin_hit = _gpu_and_twin_hits(NurbsModel([_bunched_ruled()]), camera)
    assert twin_hit.mean() > 0.05
    assert (gpu_hit != twin_hit).sum() <= 0.002 * gpu_hit.size
