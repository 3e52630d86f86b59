"""Large spline models, first stages [Kumar1997, sec. 2-3]: the Bezier decomposition by degree
(``splinevis.nurbs.lod.bezier``), the patch edges (``splinevis.nurbs.lod.adjacency``) and the large synthetic
models (``datasets_synthetic.large_models``). No GL needed.

Tolerance of the evaluator test
-------------------------------
Both sides evaluate a sum of ``(p + 1)(q + 1)`` products ``B_i(u) B_j(v) Pw_ij`` whose basis values are
non-negative and sum to 1, each basis value to ``O(p + q)`` ulps: each sum is off by at most
``gamma_((p+1)(q+1) + p + q) max |Pw|`` [Higham2002, sec. 3.4]. The Bezier control points come from knot
insertion, convex combinations of the B-spline ones, a few ulps of ``max |Pw|`` more. For a rational surface
the quotient ``A / w`` scales the error of ``A`` by ``1 / w`` and that of ``w`` by ``|S| / w``: at most
``max w / min w`` times the polynomial bound with ``|P|`` in place of ``|Pw|``. We allow
``4 (p + 1)(q + 1) eps max |P| (max w / min w)`` (~1.4e-14 relative for degree 7 x 7): the observed worst is
1.6 of the ``(p + 1)(q + 1) eps`` unit, a wrong Bernstein index or a patch's wrong rectangle is ``O(1)``.
The parent is evaluated at ``u = u0 + s (u1 - u0)``, rounded by up to an ulp of ``|u|``: on a short knot
span that moves the point by ``eps |u| |S_u|``, more than the sums' error, so that term is added.
"""

import time

import numpy as np
import pytest

from datasets_synthetic.large_models import hull, hull_spans, teapot_field
from datasets_synthetic.teapot import newell_teapot
from splinevis.nurbs.exact import cylinder, sphere, torus
from splinevis.nurbs.hard_cases import trimmed_plate
from splinevis.nurbs.lod.adjacency import SIDE_NAMES, cluster_points, find_edges, side_curves
from splinevis.nurbs.lod.bezier import BezierSet, bernstein, bezier_set, evaluate
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.surface import NurbsSurface

EPS = np.finfo(float).eps


def random_surface(rng, p, q, rational, name="random"):
    """Unclamped knots in both directions, a repeated interior knot (multiplicity 2, C0 for p = 2) where
    the degree allows it, and a domain that does not start at 0."""
    nu, nv = p + 3, q + 4
    U = np.sort(rng.uniform(0.0, 1.0, nu + p + 1))
    V = np.sort(rng.uniform(-1.0, 2.0, nv + q + 1))
    if p > 1:
        U[p + 2] = U[p + 1]
    if q > 1:
        V[q + 2] = V[q + 1]
    P = rng.normal(size=(nu, nv, 3))
    W = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return NurbsSurface((p, q), (U, V), P, W, name=name)


def samples(b, rng, k=9):
    """``k`` local parameters per patch, the corners (0, 0) and (1, 1) among them."""
    s, t = rng.uniform(0.0, 1.0, (len(b), k)), rng.uniform(0.0, 1.0, (len(b), k))
    s[:, :2], t[:, :2] = [0.0, 1.0], [0.0, 1.0]
    ids = np.repeat(np.arange(len(b)), k)
    r = b.rect[ids]
    s, t = s.ravel(), t.ravel()
    return ids, s, t, r[:, 0] + s * (r[:, 1] - r[:, 0]), r[:, 2] + t * (r[:, 3] - r[:, 2])


def point_tolerance(s, u, v, d=None):
    """The evaluation bound of the module docstring, plus the rounding of the mapped parameters
    ``u = u0 + s (u1 - u0)`` (half an ulp of ``|u|`` each, times the parent's tangent): ``(len(u),)``."""
    d = s.derivatives(u, v, 1) if d is None else d
    W = np.ones(1) if s.weights is None else s.weights
    p, q = s.degree
    tol = 4 * (p + 1) * (q + 1) * EPS * np.abs(s.control_points).max() * W.max() / W.min()
    return tol + EPS * (np.abs(u) * np.abs(d[:, 1, 0]).max(axis=1) + np.abs(v) * np.abs(d[:, 0, 1]).max(axis=1))


# ----------------------------------------------------------------------------------------------------
# bezier_set and evaluate
@pytest.mark.parametrize("rational", [False, True])
@pytest.mark.parametrize("p, q", [(p, q) for p in range(1, 8) for q in range(1, 8)])
def test_patches_evaluate_like_their_parent(p, q, rational):
    rng = np.random.default_rng(100 * p + 10 * q + rational)
    s = random_surface(rng, p, q, rational)
    b = bezier_set(s)
    U, V = s.knots
    nsu = np.unique(U[p:s.shape[0] + 1]).size - 1
    nsv = np.unique(V[q:s.shape[1] + 1]).size - 1
    assert len(b) == nsu * nsv and b.groups[0].control.shape == (nsu * nsv, p + 1, q + 1, 4)
    assert (b.groups[0].control[..., 3] == 1.0).all() != rational  # weight 1 exactly when polynomial
    ids, sl, tl, u, v = samples(b, rng)
    S = evaluate(b, ids, sl, tl)
    d = s.derivatives(u, v, 1)
    np.testing.assert_array_less(np.abs(S - d[:, 0, 0]).max(axis=1), point_tolerance(s, u, v, d) + 1e-300)
    # first derivatives (local parameters scaled to the parent's) inside the patches, where the parent's
    # one-sided derivative at a C0 knot cannot differ
    inside = (sl > 0) & (sl < 1) & (tl > 0) & (tl < 1)
    _, Su, Sv = evaluate(b, ids[inside], sl[inside], tl[inside], derivatives=True)
    d = d[inside]
    r = b.rect[ids[inside]]
    scale = np.abs(d[:, 1:, 0]).max() + np.abs(d[:, 0, 1:]).max()
    np.testing.assert_allclose(Su / (r[:, 1] - r[:, 0])[:, None], d[:, 1, 0], rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(Sv / (r[:, 3] - r[:, 2])[:, None], d[:, 0, 1], rtol=0, atol=1e-11 * scale)


def test_mixed_degrees_are_grouped_and_evaluated_through_the_flat_ids():
    rng = np.random.default_rng(7)
    surfaces = [random_surface(rng, p, q, r, f"s{k}") for k, (p, q, r) in
                enumerate([(3, 3, False), (1, 2, True), (3, 3, True), (7, 5, False), (1, 2, False)])]
    m = NurbsModel(surfaces)
    b = bezier_set(m)
    assert [g.degree for g in b.groups] == [(1, 2), (3, 3), (7, 5)]
    assert b.parent.tolist() == sorted(b.parent.tolist())  # flat ids: surface by surface
    assert b.degrees[b.parent == 3].tolist() == [[7, 5]] * int((b.parent == 3).sum())
    for g in b.groups:  # each group's rows are its patches, in flat order
        assert np.all(np.diff(g.ids) > 0) and (b.group[g.ids] == b.groups.index(g)).all()
        assert b.row[g.ids].tolist() == list(range(len(g)))
    order = rng.permutation(len(b))  # ids in any order, groups interleaved
    ids, sl, tl, u, v = samples(b, rng, 5)
    ids, sl, tl, u, v = ids[order], sl[order], tl[order], u[order], v[order]
    S = evaluate(b, ids, sl, tl)
    for k, s in enumerate(surfaces):
        sel = b.parent[ids] == k
        err = np.abs(S[sel] - s.evaluate(u[sel], v[sel])).max(axis=1)
        np.testing.assert_array_less(err, point_tolerance(s, u[sel], v[sel]) + 1e-300)
    # a group's rows give the same points
    g = b.groups[2]
    np.testing.assert_array_equal(evaluate(g, [0, 1], 0.25, 0.5), evaluate(b, g.ids[:2], 0.25, 0.5))


def test_exact_sphere_patches_lie_on_the_sphere():
    r = 2.5
    s = sphere(r, (1.0, -2.0, 0.5))
    b = bezier_set(s)
    assert len(b) == 8 and b.rect.tolist() == [[a / 4, (a + 1) / 4, c / 2, (c + 1) / 2] for a in range(4) for c in range(2)]
    ids, sl, tl, u, v = samples(b, np.random.default_rng(2), 50)
    S = evaluate(b, ids, sl, tl)
    # 9 terms with weights in [1/sqrt 2, 1]: |S - c| = r to a few ulps of |S| <= 3.4
    np.testing.assert_allclose(np.linalg.norm(S - [1.0, -2.0, 0.5], axis=1), r, rtol=0, atol=16 * EPS * 3.4)
    np.testing.assert_allclose(S, s.evaluate(u, v), rtol=0, atol=4 * 9 * EPS * 3.5 * np.sqrt(2))


def test_set_structure_rects_trims_boxes_and_size():
    m = NurbsModel([torus(), trimmed_plate().surfaces[0], cylinder()], trims=[None, trimmed_plate().trims[0], None])
    b = bezier_set(m)
    assert isinstance(b, BezierSet) and len(b) == 16 + 1 + 4
    assert b.names == ("torus", "plate", "cylinder") and b.trimmed.tolist() == [False] * 16 + [True] + [False] * 4
    # the torus's rectangles tile its domain u-major
    assert b.rect[:16].tolist() == [[a / 4, (a + 1) / 4, c / 4, (c + 1) / 4] for a in range(4) for c in range(4)]
    # every sampled point lies in its patch's box; the model's box is the union
    ids, sl, tl, _, _ = samples(b, np.random.default_rng(3), 30)
    S = evaluate(b, ids, sl, tl)
    box = b.bbox[ids]
    assert np.all((S >= box[:, 0::2] - 1e-15) & (S <= box[:, 1::2] + 1e-15))
    assert b.bbox[:16, 4].min() == -0.5 and b.bbox[:16, 1].max() == 2.5
    t = bezier_set(newell_teapot())
    assert t.size == float(np.linalg.norm([3.525 + 3.0, 4.0, 3.15]))
    np.testing.assert_array_equal(t.groups[0].control[5, ..., :3], newell_teapot().surfaces[5].control_points)
    # one patch as a NurbsSurface on [0, 1]^2
    p = b.surface(5)
    assert p.name == "torus[5]" and p.rational and p.domain == ((0.0, 1.0), (0.0, 1.0))
    np.testing.assert_allclose(p.evaluate([0.3], [0.8]), evaluate(b, 5, 0.3, 0.8), rtol=0, atol=1e-15)
    assert not b.surface(16).rational and b.surface(16).name == "plate[0]"
    assert b.control(18).shape == (3, 2, 4)


def test_bernstein_basis():
    t = np.linspace(0.0, 1.0, 11)
    for n in range(8):
        B, D = bernstein(n, t, derivative=True)
        np.testing.assert_allclose(B.sum(axis=1), 1.0, rtol=0, atol=4 * n * EPS)
        i = np.arange(n + 1)
        binom = np.array([np.prod(np.arange(n - k + 1, n + 1)) / np.prod(np.arange(1, k + 1)) for k in i])
        np.testing.assert_allclose(B, binom * t[:, None] ** i * (1 - t[:, None]) ** (n - i), rtol=0, atol=1e-15 * 2 ** n)
        np.testing.assert_allclose(D.sum(axis=1), 0.0, rtol=0, atol=1e-12)
    assert bernstein(3, [0.5], derivative=True)[1].tolist() == [[-0.75, -0.75, 0.75, 0.75]]


def test_bad_input():
    b = bezier_set(torus())
    with pytest.raises(IndexError, match="patch ids must lie in 0..15"):
        evaluate(b, [16], 0.5, 0.5)
    with pytest.raises(TypeError, match="BezierSet or a BezierGroup"):
        evaluate(torus(), [0], 0.5, 0.5)
    with pytest.raises(TypeError, match="NurbsModel or a NurbsSurface"):
        bezier_set([torus()])
    with pytest.raises(TypeError, match="needs a BezierSet"):
        find_edges(torus())
    with pytest.raises(ValueError, match="tol must be"):
        find_edges(b, tol=-1.0)


# ----------------------------------------------------------------------------------------------------
# edges
def brute_clusters(X, tol):
    n = len(X)
    lab = list(range(n))

    def root(i):
        while lab[i] != i:
            i = lab[i]
        return i

    for i in range(n):
        for j in range(i + 1, n):
            if np.abs(X[i] - X[j]).max() <= tol:
                lab[root(i)] = root(j)
    return [root(i) for i in range(n)]


def same_partition(a, b):
    pa = {frozenset(np.flatnonzero(np.asarray(a) == x)) for x in set(a)}
    pb = {frozenset(np.flatnonzero(np.asarray(b) == x)) for x in set(b)}
    return pa == pb


def test_clusters_match_all_pairs_also_across_grid_cells():
    rng = np.random.default_rng(5)
    tol = 1e-3
    h = 4 * tol
    centres = rng.integers(-5, 5, (40, 3)) * h  # points jittered around cell faces and corners
    X = np.repeat(centres, 4, axis=0) + rng.uniform(-0.5 * tol, 0.5 * tol, (160, 3))
    X = np.vstack([X, rng.uniform(-0.02, 0.02, (60, 3))])
    labels = cluster_points(X, tol)
    assert same_partition(labels, brute_clusters(X, tol))
    assert labels.max() + 1 == len(set(brute_clusters(X, tol)))
    chain = np.array([[0.0, 0, 0], [0.9e-3, 0, 0], [1.8e-3, 0, 0], [5e-3, 0, 0]])  # transitive
    assert cluster_points(chain, 1e-3).tolist() == [0, 0, 0, 1]
    assert cluster_points(chain, 0.0).tolist() == [0, 1, 2, 3]


def group_of(names, k):
    return names[k].rsplit(" ", 1)[0]


def test_teapot_edges():
    m = newell_teapot()
    e = find_edges(bezier_set(m))
    assert e.counts() == {"edges": 68, "open": 16, "shared": 52, "nonmanifold": 0, "collapsed": 8}
    pairs = {}
    for k in range(len(e)):
        s = e.sides(k)
        key = tuple(sorted({group_of(m.names, p) for p in s[:, 0]}))
        pairs.setdefault((key, len(s)), []).append(s)
    counted = {k: len(v) for k, v in pairs.items()}
    # rings of 4 close around the axis; the body stacks rim | upper | lower | bottom, the lid under the knob
    assert counted == {
        (("rim",), 2): 4, (("upper body",), 2): 4, (("lower body",), 2): 4, (("bottom",), 2): 4,
        (("lid knob",), 2): 4, (("lid",), 2): 4,
        (("rim", "upper body"), 2): 4, (("lower body", "upper body"), 2): 4, (("bottom", "lower body"), 2): 4,
        (("lid", "lid knob"), 2): 4,
        # the handle and the spout: two mirror halves meet at y = 0 (2 edges per pair), pairs along the tube
        (("handle",), 2): 6, (("spout",), 2): 6,
        # open: the rim's lip (the lid does not touch it), the lid's outer edge, both ends of each tube
        (("rim",), 1): 4, (("lid",), 1): 4, (("handle",), 1): 4, (("spout",), 1): 4,
    }
    for s in pairs[(("rim",), 2)]:  # each ring edge joins neighbours k, k + 1 (mod 4)
        assert (s[1, 0] - s[0, 0]) % 4 in (1, 3)
    opened = [(m.names[p], SIDE_NAMES[s]) for p, s in e.open_sides()]
    assert opened == [(f"rim {k}", "v=0") for k in range(4)] + [
        ("handle 0", "v=0"), ("handle 1", "v=0"), ("handle 2", "v=1"), ("handle 3", "v=1"),
        ("spout 0", "v=0"), ("spout 1", "v=0"), ("spout 2", "v=1"), ("spout 3", "v=1")] + [
        (f"lid {k}", "v=1") for k in range(4)]
    poles = [(m.names[p], SIDE_NAMES[s]) for p, s in np.argwhere(e.collapsed)]
    assert poles == [(f"lid knob {k}", "v=0") for k in range(4)] + [(f"bottom {k}", "v=0") for k in range(4)]
    assert (e.side_edge[e.collapsed] == -1).all() and (e.side_edge[~e.collapsed] >= 0).all()
    # orientation: the lower body meets the bottom against its direction, every other shared edge with it
    rev = {(group_of(m.names, a), group_of(m.names, b)): ra != rb
           for k in range(len(e)) if len(s := e.sides(k)) == 2 for (a, _, ra), (b, _, rb) in [s]}
    assert rev[("lower body", "bottom")] and not rev[("rim", "upper body")] and not rev[("rim", "rim")]
    # mates agree with the edges
    mate = e.mate
    f = np.flatnonzero(mate.ravel() >= 0)
    assert (mate.ravel()[mate.ravel()[f]] == f).all() and f.size == 2 * 52


def test_closed_surfaces_have_no_open_edge():
    e = find_edges(bezier_set(sphere(3.0)))
    assert e.counts() == {"edges": 12, "open": 0, "shared": 12, "nonmanifold": 0, "collapsed": 8}
    assert np.argwhere(e.collapsed).tolist() == [[0, 0], [1, 2], [2, 0], [3, 2], [4, 0], [5, 2], [6, 0], [7, 2]]
    assert e.sides(e.side_edge[0, 3]).tolist() == [[0, 3, 0], [6, 1, 0]]  # the seam u = 0 | u = 1
    t = find_edges(bezier_set(torus()))
    assert t.counts() == {"edges": 32, "open": 0, "shared": 32, "nonmanifold": 0, "collapsed": 0}
    assert set(t.edge_degree.tolist()) == {2}
    # a periodic (unclamped, wrapped) bicubic tube: the seams are computed from other control points than
    # their neighbours', equal only to rounding
    n, m = 8, 6
    a, c = np.linspace(0, 2 * np.pi, n, endpoint=False), np.linspace(0, 2 * np.pi, m, endpoint=False)
    R = 3.0 + 0.7 * np.cos(c)[None, :] + 0.1 * np.sin(3 * a)[:, None]
    P = np.stack([R * np.cos(a)[:, None], R * np.sin(a)[:, None], 0.7 * np.sin(c)[None, :] + 0 * a[:, None]], -1)
    P = np.concatenate([P, P[:3]], axis=0)
    P = np.concatenate([P, P[:, :3]], axis=1)
    s = NurbsSurface((3, 3), (np.arange(n + 7) / 10.0, np.arange(m + 7) - 2.0), P, name="periodic")
    b = bezier_set(s)
    assert len(b) == n * m
    ring = find_edges(b)
    assert ring.counts() == {"edges": 2 * n * m, "open": 0, "shared": 2 * n * m, "nonmanifold": 0, "collapsed": 0}
    seam = side_curves(b.groups[0], 3)[0], side_curves(b.groups[0], 1)[(n - 1) * m]  # first | last u patch
    assert 0 < np.abs(seam[0] - seam[1]).max() < 1e-14  # not bitwise equal: found within the tolerance
    assert ring.sides(ring.side_edge[0, 3])[:, :2].tolist() == [[0, 3], [(n - 1) * m, 1]]
    strict = find_edges(b, tol=0.0)  # exact comparison misses the u seam (the v seam rounds alike here)
    assert strict.open_sides().tolist() == [[j, 3] for j in range(m)] + [[(n - 1) * m + j, 1] for j in range(m)]


def test_default_tolerance_follows_the_coordinates_far_from_the_origin():
    near, far = bezier_set(torus()), bezier_set(torus(2.0, 0.5, (1e6, -2e6, 5e5)))
    assert find_edges(near).tol == 1e-9 * near.size
    e = find_edges(far)  # 1e-9 of the size (6e-9) is below the rounding of 2e6 (4.7e-10 a ulp): 64 ulps
    assert e.tol == 64 * EPS * (2e6 + 2.5) and e.counts()["open"] == 0
    with pytest.raises(ValueError, match="below the rounding of coordinates"):
        find_edges(bezier_set(torus(2.0, 0.5, (1e12, 0.0, 0.0))), tol=1e-9)


def edge_set(model, e, b):
    """Edges as sets of (surface name, patch index within the surface, side), with relative orientations."""
    first = {k: int(np.searchsorted(b.parent, k)) for k in set(b.parent.tolist())}
    out = set()
    for k in range(len(e)):
        s = e.sides(k)
        key = [(model.names[b.parent[p]], int(p) - first[int(b.parent[p])], int(sd), bool(r)) for p, sd, r in s]
        key.sort()
        out.add(tuple((n, i, sd, r != key[0][3]) for n, i, sd, r in key))
    return out


@pytest.mark.parametrize("make", [lambda: teapot_field(3, seed=4), lambda: hull(300)])
def test_edges_do_not_depend_on_the_patch_order(make):
    m = make()
    b = bezier_set(m)
    e = find_edges(b)
    order = np.random.default_rng(11).permutation(len(m))
    pm = NurbsModel([m.surfaces[k] for k in order], trims=[m.trims[k] for k in order])
    pb = bezier_set(pm)
    pe = find_edges(pb)
    assert pe.counts() == e.counts()
    assert edge_set(pm, pe, pb) == edge_set(m, e, b)


def test_nonmanifold_weights_and_degrees():
    # three pages of a book on one spine; the third rational with all weights 3 (the same curves)
    spine = ([0.0, 0, 0], [0.0, 0, 1])
    pages = [NurbsSurface.bilinear(spine, ([1.0, 0, 0], [1.0, 0, 1]), name="a"),
             NurbsSurface.bilinear(([0.0, 1, 0], [0.0, 1, 1]), spine, name="b")]
    P = pages[0].control_points * [-1.0, 1.0, 1.0]
    pages.append(NurbsSurface((1, 1), pages[0].knots, P, np.full((2, 2), 3.0), name="c"))
    e = find_edges(bezier_set(NurbsModel(pages)))
    assert e.counts() == {"edges": 10, "open": 9, "shared": 0, "nonmanifold": 1, "collapsed": 0}
    k = int(e.nonmanifold()[0])
    assert e.sides(k).tolist() == [[0, 0, 0], [1, 2, 0], [2, 0, 0]]  # v = 0 of a and c, v = 1 of b
    assert (e.mate[:, :] == -1).all()
    # the same segment as a degree-1 and a degree-2 curve: different degrees, different edges
    quad = NurbsSurface((2, 1), ([0, 0, 0, 1, 1, 1], [0, 0, 1, 1]),
                        [[[0, 0, 0], [0, 0, 1]], [[0.5, 0, 0], [0.5, 0, 1]], [[1, 0, 0], [1, 0, 1]]])
    flat = NurbsSurface.bilinear(([0.0, 0, 0], [1.0, 0, 0]), ([0.0, -1, 0], [1.0, -1, 0]))
    assert find_edges(bezier_set(NurbsModel([quad, flat]))).counts()["shared"] == 0


# ----------------------------------------------------------------------------------------------------
# large models
def test_teapot_field_copies():
    m = teapot_field(5, seed=2)
    assert len(m) == 160 and m.names[32 * 3 + 20] == "teapot 3: lid knob 0"
    base = newell_teapot()
    for i in range(5):  # each copy: the teapot turned about its vertical axis and scaled, on the grid
        P = np.stack([s.control_points for s in m.surfaces[32 * i:32 * i + 32]])
        Q = np.stack([s.control_points for s in base.surfaces])
        knob = P[20, 0, 0]  # the knob's pole is on the axis
        assert knob[:2].tolist() == [10.0 * (i % 3), 10.0 * (i // 3)]
        scale = knob[2] / 3.15
        assert 0.6 <= scale <= 1.4
        np.testing.assert_allclose(np.linalg.norm(P[..., :2] - knob[:2], axis=-1), scale * np.linalg.norm(Q[..., :2], axis=-1),
                                   rtol=0, atol=1e-13)
        np.testing.assert_allclose(P[..., 2], scale * Q[..., 2], rtol=0, atol=1e-14)
    e = find_edges(bezier_set(m))  # copies never touch: five times the teapot's edges
    assert e.counts() == {"edges": 5 * 68, "open": 5 * 16, "shared": 5 * 52, "nonmanifold": 0, "collapsed": 5 * 8}


def test_forty_thousand_teapot_patches(capsys):
    t0 = time.perf_counter()
    m = teapot_field(1250)
    t1 = time.perf_counter()
    b = bezier_set(m)
    t2 = time.perf_counter()
    e = find_edges(b)
    t3 = time.perf_counter()
    with capsys.disabled():
        print(f"\n40,000 teapot patches: teapot_field {t1 - t0:.2f} s, bezier_set {t2 - t1:.2f} s, "
              f"find_edges {t3 - t2:.2f} s")
    assert len(b) == 40000 and [g.degree for g in b.groups] == [(3, 3)]
    assert e.counts() == {"edges": 85000, "open": 20000, "shared": 65000, "nonmanifold": 0, "collapsed": 10000}


def test_hull_is_closed_with_portholes():
    assert hull_spans(20000) == (195, 31, 35)
    for N in (630, 1000, 4321, 20000, 40000):
        nu, nv, nd = hull_spans(N)
        assert nu * (2 * nv + nd) + nd * nv == N
    h = hull(20000)
    b = bezier_set(h)
    e = find_edges(b)
    nu, nv, nd = 195, 31, 35
    assert len(b) == 20000 and [g.degree for g in b.groups] == [(3, 3)]
    # closed: every side shared by exactly two patches, but the deck's stem and the transom's keel collapse
    assert e.counts() == {"edges": 2 * 20000 - nd, "open": 0, "shared": 2 * 20000 - nd, "nonmanifold": 0,
                          "collapsed": 2 * nd}
    names = [h.names[b.parent[p]] for p, s in np.argwhere(e.collapsed)]
    assert names == ["deck"] * nd + ["transom bilge"] * nd
    # portholes: the two porthole bands are trimmed, one hole inside every few of their patches
    assert [n for n, t in zip(h.names, h.trims) if t] == ["port portholes", "starboard portholes"]
    assert b.trimmed.sum() == 2 * nu
    loops = h.trims[1]
    assert len(loops) == 1 + 32 and h.source.endswith("32 portholes a side")
    rects = b.rect[b.parent == 1]
    for loop in loops[1:]:
        xy = loop[0].evaluate(np.linspace(0, 1, 33))
        inside = np.all((xy[:, :1] > rects[:, 0]) & (xy[:, :1] < rects[:, 1]) & (xy[:, 1:] > rects[:, 2])
                        & (xy[:, 1:] < rects[:, 3]), axis=0)
        assert inside.sum() == 1  # the hole stays within one patch
    # the normals point out of the hull
    for s in h.surfaces:
        (u0, u1), (v0, v1) = s.domain
        uv = np.linspace(0.1, 0.9, 5)
        U, V = u0 + uv * (u1 - u0), v0 + uv[::-1] * (v1 - v0)
        P, N = s.evaluate(U, V), s.normal(U, V)
        centre = np.array([50.0, 0.0, 5.0])
        assert np.all(np.einsum("ij,ij->i", N, P - centre) > 0), s.name
    assert all(t is None for t in hull(1000, portholes=False).trims)
