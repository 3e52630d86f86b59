"""Cubic C1 spline on the type-6 partition and the generic scheme interface (splinevis.volume).

Rounding bounds (unit roundoff u = 2^-53, gamma_m = m u / (1 - m u)); M = max |padded data| (|padded|
<= 3 max|f|): every coefficient is a dot product of 27 nonnegative weights summing to 1 (exact multiples
of 1/192 rounded to float64, checked), accurate to gamma_28 M plus the padding's gamma_2; cubic de Casteljau is 3 levels of
4-term convex combinations (gamma_12; barycentrics >= -1e-15 on shared faces keep the absolute weight
sum ~1). Values: error <= gamma_60 M, a jump <= 2 gamma_60 M. Gradients: sum_i (3 * degree-2 de
Casteljau of coefficients <= M) * grad lam_i, |grad lam_i| components <= G = 2: error per component
<= 4 * 3 * G * gamma_64 M, a jump twice that.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from splinevis.bb import simplex as bb
from splinevis.volume import (
    STENCIL,
    barycentric_matrices,
    cube_coefficients,
    cubic_c1_spline,
    evaluate,
    evaluate_volume,
    locate,
    pad_volume,
    spline_coefficients,
    tet_weights,
    type6_tetrahedra,
)
from splinevis.volume import cubic as vc

U = 2.0**-53
G = float(np.abs(barycentric_matrices()[:, :, :3]).max())


def gamma(m):
    return m * U / (1 - m * U)


def val_bound(M):
    return 2 * gamma(60) * M


def grad_bound(M):
    return 2 * 4 * 3 * G * gamma(64) * M


def padded_max(vol):
    return float(np.abs(pad_volume(vol)).max())


def _patch(coef, cell, t, local):
    """Value and gradient of patch t of cube `cell` at local points (its polynomial extended)."""
    B = barycentric_matrices()[t]
    lam = np.einsum("...ij,...j->...i", B[..., :3], local) + B[..., 3]
    c = coef[cell[..., 2], cell[..., 1], cell[..., 0], t]
    n = 2 if c.shape[-1] == 10 else 3
    val = bb.de_casteljau(c, lam, d=3)
    dl = bb._decasteljau(bb.gradient(c, d=3), n - 1, 3, lam[..., None, :])
    return val, np.einsum("...i,...ij->...j", dl, B[..., :3])


# ----------------------------------------------------------------------------------------------------
# derivation
# ----------------------------------------------------------------------------------------------------

def test_derivation_weights_and_diagnostics():
    d = vc.derive_weights()
    W = d["W"]
    assert W.shape == (175, 27)
    N = W * 192  # nonnegative multiples of 1/192 (the float64 nearest to them): integer numerators
    assert W.min() >= 0 and np.array_equal(N, np.round(N))
    assert np.array_equal(np.round(N).sum(axis=1), np.full(175, 192.0))  # rows sum to 1
    assert d["consistency_conditions"] == 4  # C1 cubics on one cube: dimension 52 = 56 - 4
    assert d["mask_parameters"] == 7
    assert d["inner_residual"] < 1e-14 and d["cube_face_residual"] < 1e-14
    assert len(d["exact_faces"]) == 36  # C1 across every inner face
    assert abs(d["square_shift"] - 0.25) < 1e-14
    assert d["quadratic_reproduction_residual"] > 0.1  # exact quadratic reproduction is impossible
    pts, tmap = vc.domain_points()
    assert pts.shape == (175, 3) and tmap.shape == (24, 20) and len(np.unique(tmap)) == 175


def test_determining_set_masks_are_the_fractions_of_fig4():
    W = vc.derive_weights()["W"]
    pts, _ = vc.domain_points()
    det = vc.determining_set()
    assert len(det) == 56
    g = pts[det] - 0.5
    kinds = (np.abs(g) == 0.5).sum(axis=1)
    assert (kinds == 3).sum() == 8 and (kinds == 2).sum() == 24 and (kinds == 1).sum() == 24
    fr = {}
    for m, gg, kind in zip(det, g, kinds):
        w = W[m]
        nz = w[w > 0]
        fr.setdefault(int(kind), set()).update(np.round(nz * 96, 9).tolist())
        if kind == 3:  # vertex: mean of the 8 data values around it
            assert np.array_equal(np.sort(nz), np.full(8, 1 / 8))
            assert np.allclose(STENCIL[w > 0].mean(axis=0), gg)
    assert fr[3] == {12.0}  # 1/8
    assert fr[2] == {20.0, 4.0}  # 5/24, 1/24
    assert fr[1] == {26.0, 14.0, 3.0, 1.0}  # 13/48, 7/48, 1/32, 1/96
    # the centroid mask in detail: triangle centroid (1/2, 1/3, 0) of the +x face
    c = vc._idx(np.array([1.0, 5 / 6, 0.5]))
    w = {tuple(int(v) for v in STENCIL[j]): W[c, j] * 96 for j in np.flatnonzero(W[c])}
    assert w == {(0, 0, 0): 26, (1, 0, 0): 26, (0, 1, 0): 14, (1, 1, 0): 14, (0, 0, 1): 3, (0, 0, -1): 3,
                 (1, 0, 1): 3, (1, 0, -1): 3, (0, 1, 1): 1, (0, 1, -1): 1, (1, 1, 1): 1, (1, 1, -1): 1}


def test_check_value_17_8():
    """f = 1 + x + xy + xyz on the 3x3x3 grid (h = 1), cube centred at (1, 1, 1): c0030 = 17/8 at the cube
    vertex (1/2, 1/2, 3/2) (local (0, 0, 1)), i.e. f there (the scheme reproduces trilinear f)."""
    z, y, x = np.meshgrid(*[np.arange(3.0)] * 3, indexing="ij")
    f = 1 + x + x * y + x * y * z
    coef = cubic_c1_spline(f)[1, 1, 1]
    v = type6_tetrahedra()
    q0030 = bb.index_of(3, 3)[(0, 0, 3, 0)]
    hits = [t for t in range(24) if np.array_equal(v[t, 2], [0, 0, 1])]
    assert hits
    for t in hits:
        assert coef[t, q0030] == 17 / 8
    assert evaluate(cubic_c1_spline(f), [0.5, 0.5, 1.5]) == pytest.approx(17 / 8, abs=1e-14)


# ----------------------------------------------------------------------------------------------------
# the generic interface
# ----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("scheme,m", [("quadratic", 10), ("cubic", 20)])
def test_tet_weights_format_and_coefficient_paths_agree(scheme, m):
    rng = np.random.default_rng(7)
    vol = rng.normal(size=(3, 4, 5))
    W = tet_weights(scheme)
    assert W.shape == (24, m, 27) and W.dtype == np.float64
    full = spline_coefficients(vol, scheme)
    assert full.shape == (3, 4, 5, 24, m)
    P = pad_volume(vol)
    assert P.shape == (5, 6, 7) and np.array_equal(P[1:-1, 1:-1, 1:-1], vol)
    cubes = np.array([[0, 0, 0], [4, 3, 2], [2, 1, 1], [4, 0, 2]])
    sub = cube_coefficients(vol, cubes, scheme)
    for r, (i, j, k) in enumerate(cubes):
        data = np.array([P[k + 1 + oz, j + 1 + oy, i + 1 + ox] for ox, oy, oz in STENCIL])  # the GPU formula
        np.testing.assert_allclose(np.einsum("tqs,s->tq", W, data), full[k, j, i], rtol=0, atol=1e-14)
        np.testing.assert_allclose(sub[r], full[k, j, i], rtol=0, atol=1e-14)
    p = rng.random((200, 3)) * np.array([5, 4, 3]) - 0.5
    v1, g1 = evaluate(full, p, gradient=True)
    v2, g2 = evaluate_volume(vol, p, scheme, gradient=True)
    np.testing.assert_allclose(v1, v2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(g1, g2, rtol=0, atol=1e-13)


# ----------------------------------------------------------------------------------------------------
# reproduction
# ----------------------------------------------------------------------------------------------------

def _grid(shape):
    z, y, x = np.meshgrid(*[np.arange(n, dtype=float) for n in shape], indexing="ij")
    return x, y, z


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cubic_reproduces_trilinear_polynomials_everywhere(seed):
    """Span of 1, x, y, z, xy, yz, zx, xyz: exact in every cube, the padded boundary ones included (axis-
    wise linear extrapolation keeps multilinear data multilinear)."""
    rng = np.random.default_rng(seed)
    shape = tuple(int(s) for s in rng.integers(2, 7, size=3))
    a = rng.normal(size=8)

    def f(x, y, z):
        return a[0] + a[1] * x + a[2] * y + a[3] * z + a[4] * x * y + a[5] * y * z + a[6] * z * x + a[7] * x * y * z

    def grad(x, y, z):
        return np.stack([a[1] + a[4] * y + a[6] * z + a[7] * y * z, a[2] + a[4] * x + a[5] * z + a[7] * x * z,
                         a[3] + a[5] * y + a[6] * x + a[7] * x * y], axis=-1)

    vol = f(*_grid(shape))
    coef = cubic_c1_spline(vol)
    assert coef.shape == shape + (24, 20)
    hi = np.array(shape[::-1]) - 0.5
    p = rng.random((3000, 3)) * (hi + 0.5) - 0.5
    p = np.vstack([p, [[-0.5, -0.5, -0.5], hi]])
    val, g = evaluate(coef, p, gradient=True)
    M = padded_max(vol) + np.abs(a).sum() * (max(shape) + 1) ** 3  # polynomial magnitude on the domain
    assert np.abs(val - f(*p.T)).max() <= val_bound(M)
    assert np.abs(g - grad(*p.T)).max() <= grad_bound(M)


@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_quadratics_reproduced_up_to_a_constant_gradients_exact(scheme):
    """For q = sum a_ij x_i x_j + linear: spline = q + (a_xx + a_yy + a_zz) / 4 (spacing 1) in every cube
    whose stencil reads no padded data, so gradients of quadratics are exact (order 2 for gradients).
    Holds for both schemes; the quadratic scheme does not reproduce xyz (cubic does, test above)."""
    rng = np.random.default_rng(11)
    shape = (6, 5, 7)
    A = rng.normal(size=(3, 3))
    A = A + A.T
    b = rng.normal(size=4)
    x, y, z = _grid(shape)
    X = np.stack([x, y, z], axis=-1)
    vol = b[0] + X @ b[1:] + np.einsum("...i,ij,...j->...", X, A, X)
    coef = spline_coefficients(vol, scheme)
    lo, hi = np.array([0.5, 0.5, 0.5]), np.array(shape[::-1]) - 1.5  # cubes 1 .. n-2: no padded data
    p = lo + rng.random((3000, 3)) * (hi - lo)
    val, g = evaluate(coef, p, gradient=True)
    M = np.abs(vol).max() + np.abs(A).sum() * max(shape) ** 2
    q = b[0] + p @ b[1:] + np.einsum("pi,ij,pj->p", p, A, p)
    assert np.abs(val - q - np.trace(A) / 4).max() <= val_bound(M)
    assert np.abs(g - (b[1:] + 2 * p @ A)).max() <= grad_bound(M)
    if scheme == "quadratic":  # xyz is not reproduced by the quadratic scheme: a measurable error
        c2 = spline_coefficients(x * y * z, scheme)
        assert np.abs(evaluate(c2, p) - np.prod(p, axis=1)).max() > 1e-3


# ----------------------------------------------------------------------------------------------------
# smoothness
# ----------------------------------------------------------------------------------------------------

def _inner_face_jumps(coef, cell, rng):
    out = []
    for t, s, shared in vc._inner_faces():
        q = rng.dirichlet(np.ones(3), size=40) @ shared
        vt, gt = _patch(coef, cell, t, q)
        vs_, gs = _patch(coef, cell, s, q)
        out.append((np.abs(vt - vs_).max(), np.abs(gt - gs).max()))
    return np.array(out)


def test_c1_across_all_36_inner_faces_and_negative_control():
    rng = np.random.default_rng(5)
    vol = rng.normal(size=(3, 4, 3))
    coef = cubic_c1_spline(vol)
    M = padded_max(vol)
    for cell in ([1, 1, 1], [0, 0, 0], [2, 3, 2], [1, 2, 0]):
        j = _inner_face_jumps(coef, np.array(cell), rng)
        assert len(j) == 36
        assert j[:, 0].max() <= val_bound(M)
        assert j[:, 1].max() <= grad_bound(M)
    # negative control: the same harness detects a broken rule (one inner coefficient perturbed by 1e-3)
    pts, tmap = vc.domain_points()
    centre = int(np.flatnonzero((pts == 0.5).all(axis=1))[0])
    bad = coef.copy()
    bad[1, 1, 1][tmap == centre] += 1e-3
    j = _inner_face_jumps(bad, np.array([1, 1, 1]), rng)
    assert j[:, 0].max() <= val_bound(M)  # vQ's coefficient is common to all 24 patches: still C0 ...
    assert j[:, 1].max() > 1e-5  # ... but no longer C1
    assert (j[:, 1] > 1e6 * grad_bound(M)).sum() >= 12


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_c1_across_cube_faces(axis):
    rng = np.random.default_rng(20 + axis)
    vol = rng.normal(size=(4, 5, 6))
    coef = cubic_c1_spline(vol)
    M = padded_max(vol)
    nz, ny, nx = vol.shape
    lim = np.array([nx, ny, nz])
    for _ in range(20):
        lo = np.array([rng.integers(0, n) for n in lim])
        lo[axis] = rng.integers(0, lim[axis] - 1)
        up = lo.copy()
        up[axis] += 1
        q = rng.random((64, 3))
        q[:, axis] = 1.0
        q_up = q.copy()
        q_up[:, axis] = 0.0
        t_lo, _ = locate(q)
        t_up, _ = locate(q_up)
        v1, g1 = _patch(coef, np.broadcast_to(lo, q.shape), t_lo, q)
        v2, g2 = _patch(coef, np.broadcast_to(up, q.shape), t_up, q_up)
        assert np.abs(v1 - v2).max() <= val_bound(M)
        assert np.abs(g1 - g2).max() <= grad_bound(M)


def test_cube_edges_and_vertices_gradients_agree_between_all_cubes():
    """At a cube vertex shared by 8 cubes all 8 gradients agree (C1 as a whole, not face by face)."""
    rng = np.random.default_rng(3)
    vol = rng.normal(size=(3, 3, 3))
    coef = cubic_c1_spline(vol)
    M = padded_max(vol)
    vals, grads = [], []
    for d in itertools.product((0, 1), repeat=3):
        cell = np.array([0, 0, 0]) + np.array(d)  # cubes around the vertex (1/2, 1/2, 1/2)
        local = np.array([[1.0 - d[0], 1.0 - d[1], 1.0 - d[2]]])
        t, _ = locate(local)
        v, g = _patch(coef, cell[None], t, local)
        vals.append(v[0])
        grads.append(g[0])
    assert np.ptp(vals) <= val_bound(M)
    assert np.ptp(np.array(grads), axis=0).max() <= grad_bound(M)


# ----------------------------------------------------------------------------------------------------
# input errors
# ----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_bad_inputs(scheme):
    vol = np.zeros((3, 4, 5))
    vol[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"voxel \[k, j, i\] = \[1, 2, 3\] \(x=3, y=2, z=1\)"):
        spline_coefficients(vol, scheme)
    with pytest.raises(ValueError, match=r"at least 2 samples along every axis .*27-point stencil.*\(4, 1, 4\) "
                                         r"with 1 along y"):
        spline_coefficients(np.zeros((4, 1, 4)), scheme)
    with pytest.raises(ValueError, match=r"3-D array"):
        spline_coefficients(np.zeros((4, 4)), scheme)
    with pytest.raises(ValueError, match=r"cubes\[1\] = \[5, 0, 0\] is outside the volume"):
        cube_coefficients(np.zeros((3, 4, 5)), [[0, 0, 0], [5, 0, 0]], scheme)
    with pytest.raises(ValueError, match=r"cubes must be an \(n, 3\) integer array"):
        cube_coefficients(np.zeros((3, 4, 5)), [[0.5, 0, 0]], scheme)
    # the smallest accepted grid: 2 samples per axis (one real neighbour, one extrapolated layer)
    coef = spline_coefficients(np.arange(8.0).reshape(2, 2, 2), scheme)
    assert evaluate(coef, [1.5, 1.5, 1.5]) == pytest.approx(1.5 + 2 * 1.5 + 4 * 1.5, abs=1e-13)
    with pytest.raises(ValueError, match=r"spline domain .* index \(1,\)"):
        evaluate(coef, [[0.0, 0.0, 0.0], [1.6, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"spline domain"):
        evaluate_volume(np.zeros((2, 2, 2)), [[0.0, 0.0, -0.7]], scheme)


def test_bad_scheme_and_coef_shape():
    with pytest.raises(ValueError, match=r"scheme 'quartic' is not known; choose one of: 'quadratic'.*'cubic'"):
        tet_weights("quartic")
    with pytest.raises(ValueError, match=r"scheme 'Cubic' is not known"):
        spline_coefficients(np.zeros((2, 2, 2)), "Cubic")
    with pytest.raises(ValueError, match=r"coef must have shape \(nz, ny, nx, 24, 10\) .* \(nz, ny, nx, 24, 20\)"):
        evaluate(np.zeros((2, 2, 2, 24, 19)), [[0.0, 0.0, 0.0]])
