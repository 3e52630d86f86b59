"""Super-surfaces and culling for large spline models [Kumar1997, sec. 2.2, 3, 4.4, 5.2]: the pseudo-Gauss map's
Bezier form against the surface's derivatives, normal cones against sampled normals, the greedy growth on a
flat grid and on a refined sphere, the frustum hierarchy against brute force, and back-patch culling against
dense sampling. Timings for 40k patches are printed, not asserted (``pytest -s`` shows them)."""

from __future__ import annotations

import time
from math import comb

import numpy as np
import pytest

from splinevis.nurbs.exact import sphere
from splinevis.nurbs.lod.bvh import back_facing, build_bvh, frustum_cull, frustum_planes
from splinevis.nurbs.lod.gauss import grow_super_surfaces, merge_cones, normal_cone, pseudo_gauss_net, span
from splinevis.nurbs.operations import bezier_patches, refine_knots
from splinevis.nurbs.surface import NurbsSurface
from _camera import look_at as _look_at
from _camera import perspective as _perspective


def _bern(n, t):
    t = np.asarray(t, dtype=np.float64)[:, None]
    i = np.arange(n + 1)
    return np.array([comb(n, k) for k in i]) * t ** i * (1 - t) ** (n - i)


def _eval(net, u, v):
    """A tensor Bernstein form (a+1, b+1, ...) at the points (u, v)."""
    return np.einsum("ki,kj,ij...->k...", _bern(net.shape[0] - 1, u), _bern(net.shape[1] - 1, v), net)


def _surface(Pw):
    m, n = Pw.shape[0] - 1, Pw.shape[1] - 1
    w = Pw[..., 3]
    knots = ([0] * (m + 1) + [1] * (m + 1), [0] * (n + 1) + [1] * (n + 1))
    return NurbsSurface((m, n), knots, Pw[..., :3] / w[..., None], w)


def _random_nets(rng, N, m, n, curl=0.3, rational=True):
    """Gently curved random patches over the unit square (z up), randomly rotated, weights in [0.5, 2]."""
    x, y = np.meshgrid(np.linspace(0, 1, m + 1), np.linspace(0, 1, n + 1), indexing="ij")
    P = np.stack([np.broadcast_to(x, (N, m + 1, n + 1)), np.broadcast_to(y, (N, m + 1, n + 1)),
                  curl * rng.normal(size=(N, m + 1, n + 1))], axis=-1)
    P[..., :2] += 0.05 * rng.normal(size=(N, m + 1, n + 1, 2))
    q = rng.normal(size=(N, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    a, b, c, d = q.T
    R = np.stack([np.stack([a*a+b*b-c*c-d*d, 2*(b*c-a*d), 2*(b*d+a*c)], -1),
                  np.stack([2*(b*c+a*d), a*a-b*b+c*c-d*d, 2*(c*d-a*b)], -1),
                  np.stack([2*(b*d-a*c), 2*(c*d+a*b), a*a-b*b-c*c+d*d], -1)], 1)
    P = np.einsum("nij,nklj->nkli", R, P) + rng.normal(size=(N, 1, 1, 3)) * 3
    w = rng.uniform(0.5, 2.0, size=(N, m + 1, n + 1)) if rational else np.ones((N, m + 1, n + 1))
    return np.concatenate([P * w[..., None], w[..., None]], axis=-1)


def _angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


# ------------------------------------------------------------------------------------------------ the map
@pytest.mark.parametrize("m,n", [(1, 1), (1, 3), (2, 2), (2, 3), (3, 3), (4, 2)])
@pytest.mark.parametrize("rational", [True, False])
def test_gauss_net_is_w3_times_the_cross_product_of_the_derivatives(m, n, rational):
    rng = np.random.default_rng(10 * m + n + rational)
    Pw = _random_nets(rng, 4, m, n, curl=1.0, rational=rational)
    Pw[..., :3] += rng.normal(size=Pw[..., :3].shape) * Pw[..., 3:]  # wild nets too
    G = pseudo_gauss_net(Pw)
    assert G.shape[1:] == ((3 * m - 1, 3 * n - 1, 3) if rational else (2 * m, 2 * n, 3))
    u, v = rng.random(60), rng.random(60)
    u[:4], v[:4] = [0, 1, 0, 1], [0, 0, 1, 1]  # the corners
    for k in range(len(Pw)):
        d = _surface(Pw[k]).derivatives(u, v, 1)
        w = _eval(Pw[k][..., 3], u, v)
        ref = np.cross(d[:, 1, 0], d[:, 0, 1]) * w[:, None] ** 3
        got = _eval(G[k], u, v)
        assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()


def test_rational_formula_agrees_with_the_polynomial_one_for_constant_weights():
    rng = np.random.default_rng(3)
    Pw = _random_nets(rng, 5, 3, 2, rational=False) * 1.7  # constant weight 1.7 per patch
    u, v = rng.random(30), rng.random(30)
    Gp, Gr = pseudo_gauss_net(Pw), pseudo_gauss_net(Pw, rational=True)
    for k in range(5):
        a, b = _eval(Gp[k], u, v), _eval(Gr[k], u, v)
        assert np.abs(a - b).max() <= 1e-13 * np.abs(b).max()


def test_cones_contain_every_sampled_normal_and_spans_are_consistent():
    rng = np.random.default_rng(4)
    for m, n, rational in [(3, 3, True), (2, 3, True), (3, 3, False), (1, 2, True)]:
        Pw = _random_nets(rng, 40, m, n, curl=0.25, rational=rational)
        G = pseudo_gauss_net(Pw).reshape(40, -1, 3)
        axis, half = normal_cone(G)
        sp = span(G)
        assert (half < np.pi / 2).sum() > 20  # most gently curved patches have a cone
        u, v = np.meshgrid(np.linspace(0, 1, 25), np.linspace(0, 1, 25))
        for k in range(40):
            d = _surface(Pw[k]).derivatives(u.ravel(), v.ravel(), 1)
            nrm = np.cross(d[:, 1, 0], d[:, 0, 1])
            if half[k] < np.pi / 2:
                assert _angle(nrm, axis[k][None]).max() <= half[k] + 1e-12
                assert half[k] - 1e-12 <= sp[k]
                if sp[k] < np.pi / 2:
                    assert sp[k] <= 2 * half[k] + 1e-12  # the cone bounds the span
            if sp[k] < np.pi / 2:  # the span bounds every pair of sampled normals
                pairs = _angle(nrm[:, None], nrm[None, :])
                assert pairs.max() <= sp[k] + 1e-12
    # the cone of merged cones holds both
    a1, a2 = rng.normal(size=(200, 3)), rng.normal(size=(200, 3))
    a1 /= np.linalg.norm(a1, axis=1, keepdims=True)
    a2 = a1 + 0.5 * a2
    a2 /= np.linalg.norm(a2, axis=1, keepdims=True)
    h1, h2 = rng.uniform(0, 0.4, 200), rng.uniform(0, 0.4, 200)
    ax, h = merge_cones(a1, h1, a2, h2)
    ok = h < np.pi / 2
    assert ok.sum() > 150
    assert (_angle(ax, a1)[ok] + h1[ok] <= h[ok] + 1e-12).all() and (_angle(ax, a2)[ok] + h2[ok] <= h[ok] + 1e-12).all()


# ------------------------------------------------------------------------------------------- growth
def _grid_neighbours(nu, nv):
    idx = np.arange(nu * nv).reshape(nu, nv)
    nb = np.full((nu, nv, 4), -1)
    nb[1:, :, 0], nb[:-1, :, 1] = idx[:-1], idx[1:]
    nb[:, 1:, 2], nb[:, :-1, 3] = idx[:, :-1], idx[:, 1:]
    return nb.reshape(-1, 4)


def _matched_neighbours(nets):
    """Neighbours by shared boundary control points (orientation-free; collapsed sides such as poles skipped)."""
    P = nets[..., :3] / nets[..., 3:]
    sides = {}
    nb = np.full((len(P), 4), -1)
    for k, p in enumerate(P):
        for s, row in enumerate((p[0], p[-1], p[:, 0], p[:, -1])):
            if np.ptp(row, axis=0).max() < 1e-9:
                continue
            key = tuple(sorted(map(tuple, np.round(row, 9).tolist())))
            sides.setdefault(key, []).append((k, s))
    for pairs in sides.values():
        if len(pairs) == 2:
            (k1, s1), (k2, s2) = pairs
            nb[k1, s1], nb[k2, s2] = k2, k1
    return nb


def _connected(members, nb):
    inside = set(members.tolist())
    seen, stack = {int(members[0])}, [int(members[0])]
    while stack:
        for j in nb[stack.pop()]:
            if j in inside and j not in seen:
                seen.add(int(j))
                stack.append(int(j))
    return len(seen) == len(inside)


def test_a_flat_grid_is_one_super_surface():
    nu, nv, m = 20, 15, 3
    x, y = np.meshgrid(np.arange(nu * m + 1) / m, np.arange(nv * m + 1) / m, indexing="ij")
    nets = np.stack([x, y, np.zeros_like(x), np.ones_like(x)], axis=-1)
    Pw = np.stack([nets[i * m:i * m + m + 1, j * m:j * m + m + 1] for i in range(nu) for j in range(nv)])
    G = pseudo_gauss_net(Pw)
    ss = grow_super_surfaces(G, _grid_neighbours(nu, nv), np.radians(10.0))
    assert len(ss.members) == 1 and (ss.labels == 0).all() and sorted(ss.members[0].tolist()) == list(range(nu * nv))
    assert ss.half_angle[0] < 1e-12


def test_sphere_patches_give_several_super_surfaces_each_within_alpha():
    s = sphere(2.0)
    s = refine_knots(s, "u", [k / 24 for k in range(1, 24) if k % 6])
    s = refine_knots(s, "v", [k / 12 for k in range(1, 12) if k % 6])
    nets = np.stack([p.homogeneous() for p, _ in bezier_patches(s)])
    assert len(nets) == 24 * 12
    nb = _matched_neighbours(nets)
    assert (nb >= 0).sum() >= 2 * (24 * 11 + 24 * 12) - 1  # every interior side and the seam are matched
    G = pseudo_gauss_net(nets).reshape(len(nets), -1, 3)
    alpha = np.radians(60.0)
    ss = grow_super_surfaces(G, nb, alpha)
    assert 2 <= len(ss.members) < len(nets) // 4
    assert sorted(np.concatenate(ss.members).tolist()) == list(range(len(nets)))
    for k, mem in enumerate(ss.members):
        assert (ss.labels[mem] == k).all() and _connected(mem, nb)
        if len(mem) > 1:
            assert span(G[mem].reshape(1, -1, 3))[0] <= 2 * ss.half_angle[k] + 1e-12 <= alpha + 1e-9
    again = grow_super_surfaces(G, nb, alpha)  # deterministic
    assert np.array_equal(again.labels, ss.labels)


def _naive_grow(axes, halves, nb, alpha):
    """The growth of [Kumar1997, sec. 3] without a queue: every step re-merges every candidate."""
    P = len(halves)
    labels = np.full(P, -1)
    for seed in np.lexsort((np.arange(P), halves)):
        if labels[seed] >= 0:
            continue
        k = labels.max() + 1
        labels[seed] = k
        ax, h = axes[seed], halves[seed]
        while h <= alpha / 2:
            cand = sorted({int(j) for i in np.flatnonzero(labels == k) for j in nb[i] if j >= 0 and labels[j] < 0})
            if not cand:
                break
            ca, ch = merge_cones(np.broadcast_to(ax, (len(cand), 3)), np.full(len(cand), h), axes[cand], halves[cand])
            best = int(np.argmin(ch))
            if ch[best] > alpha / 2:
                break
            labels[cand[best]] = k
            ax, h = ca[best], ch[best]
    return labels


def test_growth_with_the_queue_equals_the_naive_greedy_growth():
    rng = np.random.default_rng(9)
    nu, nv = 14, 11
    gx, gy = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    ang = 0.08 * np.stack([gx.ravel(), gy.ravel()], 1) + 0.05 * rng.normal(size=(nu * nv, 2))
    axes = np.stack([np.sin(ang[:, 0]), np.sin(ang[:, 1]), np.cos(ang[:, 0]) * np.cos(ang[:, 1])], 1)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    halves = rng.uniform(0.0, 0.08, nu * nv)
    nb = _grid_neighbours(nu, nv)
    for alpha in np.radians([5.0, 15.0, 30.0]):
        ss = grow_super_surfaces((axes, halves), nb, alpha)
        assert np.array_equal(ss.labels, _naive_grow(axes, halves, nb, alpha))
        assert 1 < len(ss.members) < nu * nv


# ------------------------------------------------------------------------------------------- frustum


def _brute_visible(boxes, planes):
    """A box is dropped when all eight corners are outside one plane."""
    corners = np.stack([boxes[:, [i, 2 + j, 4 + k]] for i in (0, 1) for j in (0, 1) for k in (0, 1)], axis=1)
    val = np.einsum("nci,pi->ncp", corners, planes[:, :3]) + planes[:, 3]
    return np.flatnonzero(~(val < 0).all(axis=1).any(axis=1))


@pytest.mark.parametrize("leaf_size", [1, 4])
def test_frustum_cull_equals_brute_force_and_keeps_every_box_meeting_the_frustum(leaf_size):
    rng = np.random.default_rng(5 + leaf_size)
    S = 3000
    lo = rng.uniform(-20, 20, size=(S, 3))
    boxes = np.stack([lo, lo + rng.exponential(1.0, size=(S, 3))], axis=2).reshape(S, 6)
    t = build_bvh(boxes, leaf_size)
    assert sorted(t.order.tolist()) == list(range(S))
    inner = t.child[:, 0] >= 0
    for c in (0, 1):  # children inside their parent
        kids = t.box[t.child[inner, c]]
        assert (kids[:, 0::2] >= t.box[inner, 0::2]).all() and (kids[:, 1::2] <= t.box[inner, 1::2]).all()
    leaves = ~inner
    assert (t.count[leaves] <= leaf_size).all() and t.count[leaves].sum() == S
    eye = np.array([25.0, 5.0, -3.0])
    M = _perspective(np.radians(50), 1.3, 0.5, 40.0) @ _look_at(eye, [0, 0, 0], [0, 0, 1])
    planes = frustum_planes(M)
    to01 = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1.0]])  # depth range [0, 1]
    assert np.allclose(frustum_planes(to01 @ M, zero_to_one=True), planes, atol=1e-12)
    ndc = rng.uniform(-1, 1, size=(6000, 4))
    ndc[:, 3] = 1
    pts = ndc @ np.linalg.inv(M).T
    pts = pts[:, :3] / pts[:, 3:]
    assert (pts @ planes[:, :3].T + planes[:, 3] >= -1e-9).all()  # the planes bound the clip volume
    outside = np.array([[0, 0, 2, 1], [1.5, 0, 0, 1], [0, -1.2, 0.5, 1]]) @ np.linalg.inv(M).T
    assert ((outside[:, :3] / outside[:, 3:]) @ planes[:, :3].T + planes[:, 3] < 0).any(axis=1).all()
    vis, nodes = frustum_cull(t, planes, return_nodes=True)
    assert np.array_equal(vis, _brute_visible(boxes, planes))
    assert 0 < vis.size < S
    hit = ((pts[:, None, :] >= boxes[None, :, 0::2]) & (pts[:, None, :] <= boxes[None, :, 1::2])).all(axis=2)
    assert np.isin(np.flatnonzero(hit.any(axis=0)), vis).all()  # never drops a box meeting the frustum
    assert all(np.isin(t.order[t.start[k]:t.start[k] + t.count[k]], vis).all() for k in nodes)


# ------------------------------------------------------------------------------------------- back faces
def test_back_facing_never_culls_a_front_facing_sample():
    rng = np.random.default_rng(6)
    N = 300
    Pw = _random_nets(rng, N, 3, 3, curl=0.08)
    G = pseudo_gauss_net(Pw).reshape(N, -1, 3)
    axis, half = normal_cone(G)
    P = Pw[..., :3] / Pw[..., 3:]
    boxes = np.stack([P.min(axis=(1, 2)), P.max(axis=(1, 2))], axis=2).reshape(N, 6)
    centre = 0.5 * (boxes[:, 0::2] + boxes[:, 1::2])
    u, v = np.meshgrid(np.linspace(0, 1, 30), np.linspace(0, 1, 30))
    culled_total = 0
    for trial in range(6):
        # eyes behind the patches (against the cone axis) at several distances, plus random ones
        dist = rng.uniform(1.5, 12.0, size=(N, 1))
        dirs = -axis + 0.6 * rng.normal(size=(N, 3)) if trial < 4 else rng.normal(size=(N, 3))
        eyes = centre + dist * dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
        for k in range(N):
            if not back_facing(axis[k], half[k], boxes[k], eyes[k])[0]:
                continue
            culled_total += 1
            surf = _surface(Pw[k])
            d = surf.derivatives(u.ravel(), v.ravel(), 1)
            nrm = np.cross(d[:, 1, 0], d[:, 0, 1])
            assert (np.einsum("ij,ij->i", d[:, 0, 0] - eyes[k], nrm) > 0).all()
    assert culled_total > 200  # the test has teeth


def test_back_facing_bound_on_random_balls_and_cones():
    rng = np.random.default_rng(7)
    S = 4000
    axis = rng.normal(size=(S, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    half = rng.uniform(0, 0.6, S)
    c = rng.normal(size=(S, 3))
    ext = rng.uniform(0.01, 1.0, size=(S, 3))
    boxes = np.stack([c - ext, c + ext], axis=2).reshape(S, 6)
    eye = np.array([0.3, -0.2, 0.1])
    cull = back_facing(axis, half, boxes, eye)
    assert 100 < cull.sum() < S
    for k in np.flatnonzero(cull)[:300]:
        p = c[k] + ext[k] * rng.uniform(-1, 1, size=(500, 3))
        p[:8] = c[k] + ext[k] * np.array([[i, j, l] for i in (-1, 1) for j in (-1, 1) for l in (-1, 1)])
        t = rng.normal(size=(500, 3))
        t -= np.outer(t @ axis[k], axis[k])
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        ang = half[k] * np.sqrt(rng.random(500))
        ang[:50] = half[k]  # the rim of the cone
        n = np.cos(ang)[:, None] * axis[k] + np.sin(ang)[:, None] * t
        assert ((p - eye) @ n.T > 0).all()
    inside = back_facing([[0, 0, 1]], [0.1], [[-1, 1, -1, 1, -1, 1]], [0, 0, 0.5])  # eye in the ball
    assert not inside.any()
    assert not back_facing([[0, 0, 1]], [np.pi], [[-1, 1, -1, 1, -1, 1]], [0, 0, -50]).any()  # no cone


# ------------------------------------------------------------------------------------------- timings
def test_timings_for_40k_patches():
    """A torus cut into 200 x 200 rational biquadratic patches (knot insertion), plus 40k random bicubic ones."""
    from splinevis.nurbs.exact import torus

    nu = nv = 200
    N = nu * nv
    knots = [j / nu for j in range(1, nu) if j % (nu // 4)]  # the quarter knots are double already
    s = refine_knots(refine_knots(torus(2.0, 0.5), "u", sorted(knots * 2)), "v", sorted(knots * 2))
    H = s.homogeneous()
    idx = 2 * np.arange(nu)[:, None] + np.arange(3)
    Pw = H[idx[:, None, :, None], idx[None, :, None, :]].reshape(N, 3, 3, 4)
    grid = np.arange(N).reshape(nu, nv)
    nb = np.stack([np.roll(grid, 1, 0), np.roll(grid, -1, 0), np.roll(grid, 1, 1), np.roll(grid, -1, 1)], -1)
    nb = nb.reshape(N, 4)
    times = {}

    def clock(name, fn, *args):
        t0 = time.perf_counter()
        out = fn(*args)
        times[name] = time.perf_counter() - t0
        return out

    G = clock("pseudo_gauss_net (torus, biquadratic rational)", pseudo_gauss_net, Pw).reshape(N, -1, 3)
    axis, half = clock("normal_cone", normal_cone, G)
    clock("span (exact, pairwise per patch)", span, G)
    ss = clock("grow_super_surfaces (alpha 20 deg)", grow_super_surfaces, (axis, half), nb, np.radians(20.0))
    P = Pw[..., :3] / Pw[..., 3:]
    boxes = np.stack([P.min(axis=(1, 2)), P.max(axis=(1, 2))], axis=2).reshape(N, 6)
    t = clock("build_bvh (patches)", build_bvh, boxes)
    M = _perspective(np.radians(40), 1.3, 0.1, 20.0) @ _look_at(np.array([0.0, -4.0, 1.5]), [0, 0, 0], [0, 0, 1])
    planes = frustum_planes(M)
    vis = clock("frustum_cull (patches)", frustum_cull, t, planes)
    bf = clock("back_facing (patches)", back_facing, axis, half, boxes, np.array([0.0, -4.0, 1.5]))
    # per super-surface: its boxes and cones
    lab = ss.labels
    sb = np.empty((len(ss.members), 6))
    sb[:, 0::2] = np.full((len(ss.members), 3), np.inf)
    sb[:, 1::2] = -np.inf
    np.minimum.at(sb[:, 0::2], lab, boxes[:, 0::2])
    np.maximum.at(sb[:, 1::2], lab, boxes[:, 1::2])
    ts = build_bvh(sb)
    vis_s = frustum_cull(ts, planes)
    bf_s = back_facing(ss.axis, ss.half_angle, sb, np.array([0.0, -4.0, 1.5]))
    rng = np.random.default_rng(8)
    Pr = _random_nets(rng, N, 3, 3, curl=0.1)
    Gr = clock("pseudo_gauss_net (random, bicubic rational)", pseudo_gauss_net, Pr)
    clock("normal_cone (random bicubic)", normal_cone, Gr.reshape(N, -1, 3))
    print(f"\n{N} patches: {len(ss.members)} super-surfaces (alpha 20 deg), {vis.size} patches and "
          f"{vis_s.size} super-surfaces in the frustum, {int(bf.sum())} patches and {int(bf_s.sum())} "
          "super-surfaces back-facing")
    for k, v in times.items():
        print(f"  {k:50s} {v * 1e3:9.1f} ms")
    assert 1 < len(ss.members) < N // 20 and 0 < vis.size < N and bf.sum() > 0
    sizes = np.array([len(m) for m in ss.members])
    assert (2 * ss.half_angle[sizes > 1] <= np.radians(20.0) + 1e-12).all()
    assert np.isin(np.flatnonzero(np.isin(lab, vis_s, invert=True)), np.flatnonzero(~np.isin(np.arange(N), vis))).all()
