"""Type-6 partition and the quadratic super spline of volume data (splinevis.volume).

Rounding bounds (unit roundoff u = 2^-53, gamma_m = m u / (1 - m u)); M = max |padded data|:

* the padding 2 f[0] - f[1] and every coefficient (a dot product of 27 nonnegative weights summing to 1,
  exact multiples of 1/16) are accurate to gamma_32 * 3 M (|padded| <= 3 max|f|, folded into M);
* de Casteljau of degree 2 is a convex combination inside a tetrahedron; slightly outside (points on a
  shared face evaluated in the neighbour, barycentrics >= -1e-15) its absolute weight sum stays ~1:
  value error <= gamma_(32 + 8) * M.  Hence value jumps <= 2 gamma_40 M.
* gradient = sum_i (2 sum_j c_(e_i+e_j) lam_j) * grad lam_i with |grad lam_i| components <= G (the largest
  entry of barycentric_matrices, 2): error <= 4 * 2 * G * gamma_44 * M per component, doubled for a jump.
"""

from __future__ import annotations

import numpy as np
import pytest

from splinevis.bb import simplex as bb
from splinevis.volume import (
    barycentric_matrices,
    derive_weights,
    evaluate,
    inner_face_conditions,
    locate,
    quadratic_super_spline,
    type6_tetrahedra,
)
from splinevis.volume import schemes as vs

U = 2.0**-53


def gamma(m):
    return m * U / (1 - m * U)


G = float(np.abs(barycentric_matrices()[:, :, :3]).max())


def val_bound(M):
    return 2 * gamma(40) * M


def grad_bound(M):
    return 2 * 4 * 2 * G * gamma(44) * M


def padded_max(vol):
    return float(np.abs(vs._pad(np.asarray(vol, float))).max())


# ----------------------------------------------------------------------------------------------------
# partition
# ----------------------------------------------------------------------------------------------------

def test_partition_volumes_orientation_and_order():
    v = type6_tetrahedra()
    assert v.shape == (24, 4, 3)
    vol = np.linalg.det(v[:, 1:] - v[:, :1]) / 6
    assert np.all(vol > 0)
    np.testing.assert_allclose(vol, 1 / 24, rtol=0, atol=1e-15)
    assert abs(vol.sum() - 1) < 1e-14
    # documented order: face f = 4 t // 4 in -x, +x, -y, +y, -z, +z; vQ first, then the face centre
    centres = np.array([[0, .5, .5], [1, .5, .5], [.5, 0, .5], [.5, 1, .5], [.5, .5, 0], [.5, .5, 1]])
    for t in range(24):
        assert np.array_equal(v[t, 0], [.5, .5, .5])
        assert np.array_equal(v[t, 1], centres[t // 4])
        a = (t // 4) // 2
        assert v[t, 2, a] == v[t, 3, a] == (t // 4) % 2  # the edge lies in the face
        assert np.abs(v[t, 2] - v[t, 3]).sum() == 1  # ... and is an edge of the cube
        assert np.array_equal(v[t, 3], v[4 * (t // 4) + (t + 1) % 4, 2])  # cyclic order of the edges
    # the 24 tetrahedra use the 24 distinct (face, edge) pairs
    assert len({(t // 4, tuple(sorted(map(tuple, v[t, 2:])))) for t in range(24)}) == 24


def test_locate_unique_and_reproduces_points():
    rng = np.random.default_rng(1)
    p = rng.random((4000, 3))
    t, lam = locate(p)
    v = type6_tetrahedra()
    np.testing.assert_allclose(lam.sum(axis=-1), 1, atol=1e-14)
    np.testing.assert_allclose(np.einsum("pi,pij->pj", lam, v[t]), p, atol=1e-14)
    assert lam.min() >= -1e-14
    # exactly one tetrahedron contains each point (up to points within 1e-9 of a boundary)
    B = barycentric_matrices()
    all_lam = np.einsum("tij,pj->pti", B[:, :, :3], p) + B[:, :, 3]
    inside = (all_lam.min(axis=-1) > 1e-9).sum(axis=1)
    near = (np.abs(all_lam).min(axis=-1) <= 1e-9).any(axis=1)
    assert np.all(inside[~near] == 1)
    assert np.all(inside >= 0) and (~near).sum() > 3900
    # the pyramid is that of the face the point is closest to (largest |p - 1/2| component)
    d = p - 0.5
    a = np.abs(d).argmax(axis=1)
    f = 2 * a + (d[np.arange(len(p)), a] > 0)
    assert np.array_equal(t // 4, f)


def test_locate_rejects_points_outside():
    with pytest.raises(ValueError, match=r"unit cube .* index \(1,\)"):
        locate([[0.5, 0.5, 0.5], [0.5, 1.2, 0.5]])
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        locate([[0.5, 0.5]])


# ----------------------------------------------------------------------------------------------------
# the derivation
# ----------------------------------------------------------------------------------------------------

def test_derivation_weights_and_exact_conditions():
    d = derive_weights()
    W = d["W"]
    assert W.shape == (65, 27)
    assert W.min() >= 0 and np.array_equal(W * 16, np.round(W * 16))  # nonnegative multiples of 1/16
    assert np.array_equal(W.sum(axis=1), np.ones(65))
    assert d["face_residual"] < 1e-14 and d["hard_residual"] < 1e-14
    # C1 across the 24 faces [vQ, wF, u] inside the pyramids; across the 12 faces [vQ, u, u'] between
    # pyramids only the condition through vQ holds: 24 * 3 + 12 = 84 of 108
    A, pairs = inner_face_conditions()
    assert A.shape == (108, 65) and len(pairs) == 36
    assert d["exact_conditions"].sum() == 84
    assert len(d["exact_faces"]) == 24 and all(t // 4 == s // 4 for t, s in d["exact_faces"])
    # the cube centre coefficient is 1/4 f(centre) + 1/8 (sum of the 6 face neighbours)
    pts, _ = vs.domain_points()
    centre = int(np.flatnonzero((pts == 0.5).all(axis=1))[0])
    expect = np.where(np.abs(vs.STENCIL).sum(axis=1) == 1, 1 / 8, 0.0)
    expect[13] = 1 / 4
    assert np.array_equal(W[centre], expect)
    # ring point (vQ + u)/2 towards the corner u = (1, 1, 1): mean of f0 and the 3 neighbours towards u
    ring = vs._idx(np.array([0.75, 0.75, 0.75]))
    expect = np.where([tuple(o) in {(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)} for o in vs.STENCIL], 0.25, 0.0)
    assert np.array_equal(W[ring], expect)


# ----------------------------------------------------------------------------------------------------
# reproduction and smoothness
# ----------------------------------------------------------------------------------------------------

def _patch(coef, cell, t, local):
    """Value and gradient of patch t of cube `cell` (x, y, z ints) at local points (its polynomial extended)."""
    B = barycentric_matrices()[t]
    lam = np.einsum("...ij,...j->...i", B[..., :3], local) + B[..., 3]
    c = coef[cell[..., 2], cell[..., 1], cell[..., 0], t]
    val = bb.de_casteljau(c, lam, d=3)
    dl = bb._decasteljau(bb.gradient(c, d=3), 1, 3, lam[..., None, :])
    return val, np.einsum("...i,...ij->...j", dl, B[..., :3])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_reproduces_linear_functions(seed):
    rng = np.random.default_rng(seed)
    shape = tuple(rng.integers(2, 7, size=3))  # (nz, ny, nx)
    a = rng.normal(size=4) * 10
    z, y, x = np.meshgrid(*[np.arange(n, dtype=float) for n in shape], indexing="ij")
    f = a[0] + a[1] * x + a[2] * y + a[3] * z
    coef = quadratic_super_spline(f)
    assert coef.shape == shape + (24, 10)
    hi = np.array(shape[::-1]) - 0.5
    p = rng.random((3000, 3)) * (hi + 0.5) - 0.5
    val, grad = evaluate(coef, p, gradient=True)
    M = padded_max(f) + np.abs(a).sum() * max(shape)
    assert np.abs(val - (a[0] + p @ a[1:])).max() <= val_bound(M)
    assert np.abs(grad - a[1:]).max() <= grad_bound(M)
    # the domain corners are inside the domain
    corners = np.array([[-0.5, -0.5, -0.5], hi])
    np.testing.assert_allclose(evaluate(coef, corners), a[0] + corners @ a[1:], atol=val_bound(M))


def _shared_face_points(rng, shared, n):
    w = rng.dirichlet(np.ones(3), size=n)
    return w @ shared


def test_inner_faces_c0_everywhere_c1_where_derived():
    rng = np.random.default_rng(5)
    vol = rng.normal(size=(3, 3, 3))
    coef = quadratic_super_spline(vol)
    M = padded_max(vol)
    exact = set(derive_weights()["exact_faces"])
    v = type6_tetrahedra()
    cell = np.array([1, 1, 1])
    nonsmooth = []
    for t, s, shared in vs._inner_faces():
        q = _shared_face_points(rng, shared, 50)
        vt, gt = _patch(coef, cell, t, q)
        vs_, gs = _patch(coef, cell, s, q)
        assert np.abs(vt - vs_).max() <= val_bound(M)  # C0 across every inner face
        jump = np.abs(gt - gs).max()
        if (t, s) in exact:
            assert jump <= grad_bound(M)  # C1 across the faces inside the pyramids
        else:
            nonsmooth.append(jump)
            # the derivative along the face does not jump (C0); the normal derivative jumps by a linear
            # function on the face that vanishes at vQ (the one C1 condition that holds: the one through vQ)
            normal = np.cross(shared[1] - shared[0], shared[2] - shared[0])
            normal /= np.linalg.norm(normal)
            tang = (gt - gs) - np.outer((gt - gs) @ normal, normal)
            assert np.abs(tang).max() <= grad_bound(M)
            assert np.array_equal(shared[0], v[t, 0])  # vQ
            g0t = _patch(coef, cell, t, shared[:1])[1]
            g0s = _patch(coef, cell, s, shared[:1])[1]
            assert np.abs(g0t - g0s).max() <= grad_bound(M)
    assert len(nonsmooth) == 12
    assert min(nonsmooth) > 1e-3  # documented limitation: these 12 faces are only C0 for general data
    assert len(v) == 24


def _cube_face_points(rng, axis, n):
    q = rng.random((n, 3))
    q[:, axis] = 1.0  # on the + face of the lower cube, the - face of the upper one
    return q


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_cube_faces_c0_and_c1(axis):
    rng = np.random.default_rng(10 + axis)
    vol = rng.normal(size=(4, 5, 6))
    coef = quadratic_super_spline(vol)
    M = padded_max(vol)
    nz, ny, nx = vol.shape
    for _ in range(20):  # random pairs of neighbouring cubes
        lo = np.array([rng.integers(0, nx), rng.integers(0, ny), rng.integers(0, nz)])
        hi_lim = np.array([nx, ny, nz])
        lo[axis] = rng.integers(0, hi_lim[axis] - 1)
        up = lo.copy()
        up[axis] += 1
        q = _cube_face_points(rng, axis, 64)
        q_up = q.copy()
        q_up[:, axis] = 0.0
        t_lo, _ = locate(q)
        t_up, _ = locate(q_up)
        v1, g1 = _patch(coef, np.broadcast_to(lo, q.shape), t_lo, q)
        v2, g2 = _patch(coef, np.broadcast_to(up, q.shape), t_up, q_up)
        assert np.abs(v1 - v2).max() <= val_bound(M)
        assert np.abs(g1 - g2).max() <= grad_bound(M)


def test_inner_c1_faces_through_evaluate_are_consistent():
    """evaluate() picks one patch on shared boundaries; the value agrees with the neighbour's (C0)."""
    rng = np.random.default_rng(3)
    vol = rng.normal(size=(3, 4, 5))
    coef = quadratic_super_spline(vol)
    p = np.array([[1.5, 1.0, 1.0], [2.0, 1.5, 0.25], [0.5, 0.5, 0.5], [1.0, 2.0, 1.5]])
    eps = 1e-9
    a = evaluate(coef, p - eps)
    b = evaluate(coef, p + eps)
    c = evaluate(coef, p)
    assert np.abs(a - c).max() < 1e-6 and np.abs(b - c).max() < 1e-6


# ----------------------------------------------------------------------------------------------------
# input errors
# ----------------------------------------------------------------------------------------------------

def test_bad_volume_inputs():
    vol = np.zeros((3, 4, 5))
    vol[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"voxel \[k, j, i\] = \[1, 2, 3\] \(x=3, y=2, z=1\)"):
        quadratic_super_spline(vol)
    with pytest.raises(ValueError, match=r"3-D array of shape \(nz, ny, nx\).*2-D"):
        quadratic_super_spline(np.zeros((4, 4)))
    with pytest.raises(ValueError, match=r"at least 2 samples along every axis.*\(1, 4, 4\)"):
        quadratic_super_spline(np.zeros((1, 4, 4)))
    with pytest.raises(TypeError, match="volume must be an array of real numbers"):
        quadratic_super_spline([["a"]])


def test_bad_evaluate_inputs():
    coef = quadratic_super_spline(np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match=r"spline domain .* index \(1,\)"):
        evaluate(coef, [[0.0, 0.0, 0.0], [1.6, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"coef must have shape \(nz, ny, nx, 24, 10\)"):
        evaluate(coef[..., :9], [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match=r"points must have shape \(\.\.\., 3\)"):
        evaluate(coef, [[0.0, 0.0]])
