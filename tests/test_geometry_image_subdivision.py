"""The float64 twin of geometry-image subdivision [Losasso2003, sec. 5, Table 1] against scipy's B-splines and
the paper's exact properties: L is the floor formula, one step A[L[g]] is knot insertion of the bicubic
B-spline on the padded image, the padding stays the X-cut padding bit for bit, E and the tangent masks are
the B-spline and its derivatives at the samples, subsampling the next level gives this level, geomorph's
ends are exact, the normal at a cut vertex (unit(P_ss x P_st + P_st x P_tt)) is the limit of the normals
around it and the same at every level, and the curvatures are those of the float64 surface
(splinevis.geometry_image.model.GeometryImage) with the NURBS programs' sign convention."""

import numpy as np
import pytest
from scipy.interpolate import NdBSpline

from splinevis.geometry_image.image import (apply_cut_constraint, cut_neighbours, cut_vertices, image_uv,
                                            octahedral_to_sphere, pad, symmetrize)
from splinevis.geometry_image.model import GeometryImage
from splinevis.geometry_image.subdivision import (average, curvature, cut_normals, displace, geomorph, grid_faces, limit,
                                                  linear_subdivide, normals, second_derivatives, split, subdivide,
                                                  subsample, tangents)
from splinevis.nurbs.surface import fundamental_curvature


def _sphere(n):
    return apply_cut_constraint(octahedral_to_sphere(image_uv(n)))


def _bumpy(n, seed=0, amount=0.05):
    """The sphere image with random control points (border symmetry and cut constraint restored)."""
    rng = np.random.default_rng(seed)
    return apply_cut_constraint(symmetrize(octahedral_to_sphere(image_uv(n)) + amount * rng.normal(size=(n, n, 3))))


def _spline(Gp, level=0):
    """scipy's bicubic B-spline of a padded image of level ``level``, in level-0 image coordinates
    ``(t, s) = (row, column)``: padded samples -1..N_k+1 of spacing 2^-level, knots -3..N_k+3."""
    h = 2.0 ** -level
    Nk = Gp.shape[0] - 3
    t = np.arange(-3, Nk + 4) * h
    return NdBSpline((t, t), Gp, 3)


def _grid(n_samples, level0_N):
    x = np.linspace(0.0, level0_N, n_samples)
    R, C = np.meshgrid(x, x, indexing="ij")
    return np.stack([R, C], axis=-1)


def _angle(a, b):
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), (a * b).sum(axis=-1))


# --- the masks ---------------------------------------------------------------------------------------------------
def test_split_is_the_papers_floor_formula_bit_for_bit():
    g = np.random.default_rng(1).normal(size=(6, 6, 3))
    m = g.shape[0] - 1
    ref = np.empty((2 * m + 1, 2 * m + 1, 3))
    for i in range(2 * m + 1):
        for j in range(2 * m + 1):
            I, J = i // 2, j // 2
            a, b = i / 2 - I, j / 2 - J
            I1, J1 = min(I + 1, m), min(J + 1, m)  # weight 0 where I + 1 leaves the image
            ref[i, j] = ((1 - a) * (1 - b) * g[I, J] + a * b * g[I1, J1]) + (a * (1 - b) * g[I1, J] + (1 - a) * b * g[I, J1])
    # the weights are 0, 1/4, 1/2, 1: scaling is exact, so pairing the terms the same way gives the same bits
    assert np.array_equal(split(g), ref)


def test_average_and_limit_are_their_masks_with_the_crop():
    g = np.random.default_rng(2).normal(size=(7, 7, 2))
    A = np.outer([1, 2, 1], [1, 2, 1]) / 16.0
    E = np.outer([1, 4, 1], [1, 4, 1]) / 36.0
    windows = np.lib.stride_tricks.sliding_window_view(g, (3, 3), axis=(0, 1))  # (5, 5, 2, 3, 3)
    assert np.allclose(average(g), np.einsum("rcxij,ij->rcx", windows, A), rtol=0, atol=1e-15)
    assert np.allclose(limit(g), np.einsum("rcxij,ij->rcx", windows, E), rtol=0, atol=1e-15)
    assert average(g).shape == limit(g).shape == (5, 5, 2)


def test_one_step_is_knot_insertion_of_the_bicubic_b_spline():
    G = _bumpy(9, seed=3)
    g0 = pad(G)
    g1 = average(split(g0))
    assert g1.shape == (2 * g0.shape[0] - 3,) * 2 + (3,)
    x = np.random.default_rng(4).uniform(0.0, 8.0, size=(500, 2))
    assert np.abs(_spline(g1, 1)(x) - _spline(g0)(x)).max() < 1e-13


@pytest.mark.parametrize("level", [0, 1, 2])
def test_limit_and_derivative_masks_are_the_b_spline_at_the_samples(level):
    G = _bumpy(9, seed=5)
    g = pad(G)
    for _ in range(level):
        g = average(split(g))
    sp = _spline(pad(G))
    x = _grid(8 * 2 ** level + 1, 8)
    h = 2.0 ** -level  # derivatives in sample units of the level: d/ds_k = h d/ds_0
    assert np.abs(limit(g) - sp(x)).max() < 1e-14
    ts, tt = tangents(g)
    assert np.abs(ts - h * sp(x, nu=(0, 1))).max() < 1e-14  # T_s: along columns (s = column index)
    assert np.abs(tt - h * sp(x, nu=(1, 0))).max() < 1e-14  # T_t: along rows
    pss, pst, ptt = second_derivatives(g)
    assert np.abs(pss - h * h * sp(x, nu=(0, 2))).max() < 1e-13
    assert np.abs(pst - h * h * sp(x, nu=(1, 1))).max() < 1e-13
    assert np.abs(ptt - h * h * sp(x, nu=(2, 0))).max() < 1e-13


@pytest.mark.parametrize("G", [_sphere(17), _bumpy(17, seed=6), symmetrize(_bumpy(9, seed=7) * 3.0 + 1.0)],
                         ids=["sphere", "bumpy", "unconstrained"])
def test_padding_stays_the_x_cut_padding_exactly(G):
    g = pad(G)
    for _ in range(4):
        g = average(split(g))
        assert np.array_equal(g, pad(g[1:-1, 1:-1]))


def test_subdivide_shapes_and_level_zero():
    G = _sphere(9)
    p, n, g = subdivide(G, 0)
    assert np.array_equal(g, pad(G)) and np.array_equal(p, limit(pad(G)))
    p, n, g = subdivide(G, 3)
    assert p.shape == n.shape == (65, 65, 3) and g.shape == (67, 67, 3)
    with pytest.raises(ValueError):
        subdivide(G, -1)
    with pytest.raises(ValueError):
        normals(np.zeros((6, 6, 3)))  # interior 4 x 4: no cut vertices


# --- levels of detail --------------------------------------------------------------------------------------------
def test_subsampling_the_next_level_gives_this_level():
    # integer control points: every split, average and limit sum is exact, the limit one rounding of x / 36
    rng = np.random.default_rng(8)
    G = apply_cut_constraint(symmetrize(rng.integers(-1000, 1000, size=(9, 9, 3)).astype(float)))
    levels = [subdivide(G, k).p for k in range(5)]
    for k in range(4):
        assert np.array_equal(subsample(levels[k + 1], 1), levels[k])
        assert np.array_equal(subsample(levels[k + 1 + (k < 3)], 1 + (k < 3)), levels[k])
    # any data: within rounding
    G = _bumpy(9, seed=9)
    assert np.abs(subsample(subdivide(G, 2).p, 1) - subdivide(G, 1).p).max() < 1e-15


def test_negative_subdivision_ends_in_the_octahedron():
    p = subdivide(_sphere(65), 0).p
    octa = subsample(p, 5)
    assert octa.shape == (3, 3, 3)
    assert (np.sort(np.abs(octa), axis=-1)[..., :2] < 1e-12).all()  # the six vertices lie on the axes
    with pytest.raises(ValueError):
        subsample(p, 6)


def test_geomorph_ends_are_exact_and_the_diagonal_is_r_c_to_r1_c1():
    pk, pk1 = subdivide(_bumpy(9, seed=10), 1).p, subdivide(_bumpy(9, seed=10), 2).p
    lin = linear_subdivide(pk)
    assert np.array_equal(geomorph(pk, pk1, 0.0), lin)
    assert np.array_equal(geomorph(pk, pk1, 1.0), pk1)
    assert np.array_equal(lin[1::2, 1::2], 0.5 * pk[:-1, :-1] + 0.5 * pk[1:, 1:])
    assert np.allclose(geomorph(pk, pk1, 0.25), 0.75 * lin + 0.25 * pk1, rtol=0, atol=1e-15)
    nk, nk1 = subdivide(_bumpy(9, seed=10), 1).n, subdivide(_bumpy(9, seed=10), 2).n
    assert np.allclose(np.linalg.norm(geomorph(nk, nk1, 0.5, unit=True), axis=-1), 1.0)
    with pytest.raises(ValueError):
        geomorph(pk, pk, 0.5)


def test_displace_moves_along_the_normal():
    p, n, _ = subdivide(_sphere(9), 1)
    d = np.random.default_rng(11).uniform(-0.1, 0.1, size=p.shape[:2])
    assert np.allclose(((displace(p, n, d) - p) * n).sum(axis=-1), d, rtol=0, atol=1e-15)


# --- normals -----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("level", [0, 1, 3])
def test_normals_are_unit_and_outward_and_agree_with_the_grid_triangles(level):
    p, n, _ = subdivide(_sphere(17), level)
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0)
    assert ((n * p).sum(axis=-1) > 0.5).all()  # the limit surface is a convex-ish closed surface around 0
    faces = grid_faces(p.shape[0])
    v = p.reshape(-1, 3)
    fn = np.cross(v[faces[:, 1]] - v[faces[:, 0]], v[faces[:, 2]] - v[faces[:, 0]])
    centre = v[faces].mean(axis=1)
    # every triangle is counterclockwise seen from outside; the triangles at a cut vertex, where the
    # opened mesh folds (valence 2), are edge-on: their planes contain the origin
    assert ((fn * centre).sum(axis=-1) >= 0).all()


@pytest.mark.parametrize("G", [_sphere(17), _bumpy(17, seed=12), _bumpy(17, seed=13, amount=0.1)],
                         ids=["sphere", "bumpy", "bumpier"])
def test_tangents_vanish_at_cut_vertices_and_the_cut_normal_is_the_limit_of_its_neighbours(G):
    worst = []
    for level in range(6):
        p, n, g = subdivide(G, level)
        m = p.shape[0]
        ts, tt = tangents(g)
        cv = cut_vertices(m)
        assert not ts[cv[:, 0], cv[:, 1]].any() and not tt[cv[:, 0], cv[:, 1]].any()  # eq. 1, exactly
        angles = []
        for r, c in cv:
            pss, pst, ptt = (d[0, 0] for d in second_derivatives(g[r:r + 3, c:c + 3]))
            # the centroid constraint (appendix) makes P_ss + P_tt vanish here, so the three are coplanar
            assert np.linalg.norm(pss + ptt) <= 1e-10 * np.linalg.norm(pss)
            around = [(r + dr, c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
                      if (dr, dc) != (0, 0) and 0 <= r + dr < m and 0 <= c + dc < m]
            angles.append(max(_angle(n[a, b], n[r, c]) for a, b in around))
            assert (n[r, c] * p[r, c]).sum() > 0.0  # outward
        worst.append(max(angles))
    worst = np.array(worst)
    # the neighbours are 2^-k apart: once the level resolves the bumps, the angle to them halves with the
    # distance (C^1 at the cut vertex, with a well-defined normal there)
    assert (worst[3:] < 0.6 * worst[2:-1] + 1e-12).all(), worst
    assert worst[-1] < 0.04, worst


U64 = 2.0 ** -53


def _gamma(c):
    return c * U64 / (1.0 - c * U64)


def _cut_normal_angle_bound(g, e_g, M):
    """Bound on the angle between the computed and the exact unit(P_ss x P_st + P_st x P_tt) at each cut vertex
    of the padded image g (float64, componentwise error bound e_g on g): P_ss, P_tt are 9-term sums with
    sum|w| = 4 (8 roundings, 2 more for the constant 1/6), P_st 4 terms with sum|w| = 1 (3 roundings); a cross
    product of a, b (norms) with errors da, db changes by a db + da b + da db and rounds by sqrt(3) gamma_2
    (a + da)(b + db), the sum of the two by gamma_3 in all; the angle of w moves by arcsin(|dw| / (|w| - |dw|)),
    normalizing adds 2 u."""
    dss = np.sqrt(3.0) * (4.0 * e_g + _gamma(10) * 4.0 * (M + e_g))
    dst = np.sqrt(3.0) * (e_g + _gamma(3) * (M + e_g))
    out = []
    for r, c in cut_vertices(g.shape[0] - 2):
        pss, pst, ptt = (np.linalg.norm(d[0, 0]) for d in second_derivatives(g[r:r + 3, c:c + 3]))
        dw = sum(a * db + da * b + da * db + np.sqrt(3.0) * _gamma(3) * (a + da) * (b + db)
                 for a, da, b, db in ((pss, dss, pst, dst), (pst, dst, ptt, dss)))
        w = np.linalg.norm(_cut_w(g, r, c))
        out.append(np.arcsin(min(1.0, dw / (w - dw))) + 2 * U64)
    return np.array(out)


def _cut_w(g, r, c):
    pss, pst, ptt = (d[0, 0] for d in second_derivatives(g[r:r + 3, c:c + 3]))
    return np.cross(pss, pst) + np.cross(pst, ptt)


@pytest.mark.parametrize("G", [_sphere(17), _bumpy(17, seed=12), _bumpy(17, seed=13, amount=0.1)],
                         ids=["sphere", "bumpy", "bumpier"])
def test_the_cut_vertex_normal_is_the_same_at_every_level(G):
    """The level-k formula in float64 equals the level-0 value within the derived rounding bound (the second
    differences of g^k are 4^-k of level 0's, so the bound grows as 4^k: 1e-13 at level 0, 8e-10 at level 5), and
    subdivide uses the level-0 value at every level."""
    M = float(np.abs(G).max())
    g = pad(G)
    level0 = cut_normals(g)
    e_g, rows = 0.0, []
    bound0 = _cut_normal_angle_bound(g, 0.0, M)
    for k in range(6):
        if k:
            g = average(split(g))
            x = e_g + _gamma(3) * (M + e_g)  # split, then average (tests/test_geometry_image_gpu.py)
            e_g = x + _gamma(15) * (M + x)
        cv = cut_vertices(g.shape[0] - 2)
        at_k = cut_normals(g)
        assert np.array_equal(normals(g)[cv[:, 0], cv[:, 1]], at_k)
        assert np.array_equal(subdivide(G, k).n[cv[:, 0], cv[:, 1]], level0)
        angle = _angle(at_k, level0)
        bound = _cut_normal_angle_bound(g, e_g, M) + bound0 + 8 * U64
        assert (angle <= bound).all(), (k, angle, bound)
        rows.append((k, angle.max(), bound.max()))
    assert rows[-1][2] < 1e-9, rows  # measured <= 7e-13


def _reference_curvature(G, level):
    """H, K (and the larger |principal curvature|) of the float64 surface at the samples of a level, from its
    derivatives, by the NURBS model's formula."""
    gi = GeometryImage(G)
    st = gi.sample_grid(level)
    m = st.shape[0]
    SKL = np.zeros((m * m, 3, 3, 3))
    for (i, j), d in zip([(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)], gi.evaluate(st, derivatives=2)):
        SKL[:, i, j] = d.reshape(-1, 3)  # (u, v) = (s, t): the normal is unit(P_s x P_t), as the twin's
    c = fundamental_curvature(SKL)
    kappa = np.maximum(np.abs(c["k1"]), np.abs(c["k2"]))
    return c["H"].reshape(m, m), c["K"].reshape(m, m), kappa.reshape(m, m)


@pytest.mark.parametrize("G", [_sphere(17), _bumpy(17, seed=15), _bumpy(17, seed=16, amount=0.1)],
                         ids=["sphere", "bumpy", "bumpier"])
@pytest.mark.parametrize("level", [0, 1, 2, 3])
def test_curvature_is_the_float64_surfaces(G, level):
    """Relative to the larger principal curvature |k| (K to k^2): ~1e-14 at level 0; both float64 sides lose
    digits near the cut vertices, where the tangents shrink (measured 1e-11 at level 3)."""
    H, K = curvature(subdivide(G, level).g)
    Hr, Kr, kappa = _reference_curvature(G, level)
    cv = cut_vertices(H.shape[0])
    regular = np.ones(H.shape, bool)
    regular[cv[:, 0], cv[:, 1]] = False
    assert not np.isnan(Hr[regular]).any()
    assert (np.abs(H - Hr)[regular] <= 1e-10 * kappa[regular]).all()
    assert (np.abs(K - Kr)[regular] <= 1e-10 * kappa[regular] ** 2).all()
    # at the cut vertices the first fundamental form is singular (the reference divides rounding noise there);
    # the twin returns the mean of the four closed-mesh neighbours, a stand-in, not the surface's curvature
    for (r, c), nb in zip(cv, cut_neighbours(H.shape[0])):
        for a in (H, K):
            v = a[nb[:, 0], nb[:, 1]]
            assert a[r, c] == ((v[0] + v[1]) + (v[2] + v[3])) / 4.0


@pytest.mark.parametrize("level", [0, 2, 4])
def test_sphere_curvature_signs_are_the_nurbs_programs(level):
    """Outward normals on a convex surface: K > 0 and both principal curvatures negative (H < 0), as the NURBS
    model's unit sphere has H = -1, K = 1 (tests/test_nurbs_model.py); near 1 in size where the octahedral
    image is smooth."""
    H, K = curvature(subdivide(_sphere(33), level).g)
    assert np.isfinite(H).all() and np.isfinite(K).all()
    assert (K > 0).all() and (H < 0).all() and (H * H >= K * (1 - 1e-12)).all()
    assert 0.8 < -np.median(H) < 1.25 and 0.8 < np.median(K) < 1.6
    # parametrization-invariant: the same curvature at the same surface point on every level
    H0, K0 = curvature(subdivide(_sphere(33), 0).g)
    s = 1 << level
    cv = cut_vertices(H0.shape[0])
    regular = np.ones(H0.shape, bool)
    regular[cv[:, 0], cv[:, 1]] = False
    assert np.allclose(H[::s, ::s][regular], H0[regular], rtol=1e-10, atol=0)
    assert np.allclose(K[::s, ::s][regular], K0[regular], rtol=1e-10, atol=0)


def test_curvature_needs_xyz_and_an_odd_image():
    with pytest.raises(ValueError):
        curvature(np.zeros((7, 7)))
    with pytest.raises(ValueError):
        curvature(np.zeros((6, 6, 3)))
    with pytest.raises(ValueError):
        normals(pad(_sphere(9)), at_cut=np.zeros((3, 3)))


def test_without_the_centroid_constraint_the_second_derivatives_are_not_coplanar():
    """The appendix's eigenvector (-4, 1, 1, 1, 1) is what P_ss + P_tt sees at a cut vertex: without the
    constraint it survives and the three second derivatives span space (a cusp)."""
    G = symmetrize(octahedral_to_sphere(image_uv(9)) + 0.1 * np.random.default_rng(14).normal(size=(9, 9, 3)))
    g = pad(G)
    r, c = cut_vertices(9)[0]
    pss, pst, ptt = (d[0, 0] for d in second_derivatives(g[r:r + 3, c:c + 3]))
    assert abs(np.linalg.det([pss, pst, ptt])) > 1e-3 * np.linalg.norm(pss) * np.linalg.norm(pst) * np.linalg.norm(ptt)
    gc = pad(apply_cut_constraint(G))
    pss, pst, ptt = (d[0, 0] for d in second_derivatives(gc[r:r + 3, c:c + 3]))
    assert np.linalg.norm(pss + ptt) <= 1e-12 * np.linalg.norm(pss)


def test_grid_faces_cover_the_grid_once():
    f = grid_faces(4)
    assert f.shape == (18, 3) and set(np.unique(f)) == set(range(16))
    edges = {tuple(sorted(e)) for t in f for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert (0, 5) in edges and (1, 4) not in edges  # the (r, c)-(r+1, c+1) diagonal
