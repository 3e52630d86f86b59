"""Catmull–Clark nets as bicubic patches (splinevis.io.subd): exact regular patches, approximate ones near
extraordinary vertices, creases and boundaries, cracks and closedness. No files, no GL.

The regular patches are checked against formulas written out here (the valence-4 limit point, the periodic
uniform bicubic B-spline), not against the module's own subdivision.
"""

from __future__ import annotations

import numpy as np
import pytest

from splinevis.io.subd import catmull_clark, limit_points, make_net, subd_patches, subd_to_surfaces


def _cube():
    V = [[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)]
    F = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
    return np.array(V), F


def _torus(nu=6, nv=8, R=3.0, r=1.0, wobble=0.3):
    """An all-quad torus-like net (valence 4 everywhere), perturbed so that nothing is symmetric."""
    a = 2 * np.pi * np.arange(nu) / nu
    b = 2 * np.pi * np.arange(nv) / nv
    A, B = np.meshgrid(a, b, indexing="ij")
    rr = r * (1 + wobble * np.sin(3 * A + B))
    V = np.stack([(R + rr * np.cos(B)) * np.cos(A), (R + rr * np.cos(B)) * np.sin(A), rr * np.sin(B)], axis=-1)
    idx = np.arange(nu * nv).reshape(nu, nv)
    F = [[idx[i, j], idx[(i + 1) % nu, j], idx[(i + 1) % nu, (j + 1) % nv], idx[i, (j + 1) % nv]]
         for i in range(nu) for j in range(nv)]
    return V.reshape(-1, 3), F, idx


def _bspline_basis(t):
    t = np.asarray(t, dtype=np.float64)
    return np.stack([(1 - t) ** 3, 3 * t ** 3 - 6 * t ** 2 + 4, -3 * t ** 3 + 3 * t ** 2 + 3 * t + 1, t ** 3], -1) / 6


def test_torus_every_patch_exact_and_equal_to_the_periodic_bspline():
    V, F, idx = _torus()
    G = V.reshape(6, 8, 3)
    res = subd_patches(V, F, levels=1)
    assert len(res.surfaces) == 48 and res.exact.all() and (res.level == 0).all()
    scale = np.abs(V).max()
    t = np.linspace(0, 1, 7)
    Bt = _bspline_basis(t)
    worst = 0.0
    for p, (i, j) in enumerate((i, j) for i in range(6) for j in range(8)):
        net = G[np.ix_((np.arange(-1, 3) + i) % 6, (np.arange(-1, 3) + j) % 8)]  # 4 x 4 around face (i, j)
        want = np.einsum("ua,abk,vb->uvk", Bt, net, Bt)
        u, v = np.meshgrid(t, t, indexing="ij")
        got = res.surfaces[p].evaluate(u.ravel(), v.ravel()).reshape(7, 7, 3)
        worst = max(worst, np.abs(got - want).max())
    assert worst <= 1e-12 * scale


def test_regular_patch_corners_are_valence4_limit_points():
    V, F, idx = _torus()
    G = V.reshape(6, 8, 3)
    surfaces = subd_to_surfaces(V, F, levels=1)
    scale = np.abs(V).max()
    for p, (i, j) in enumerate((i, j) for i in range(6) for j in range(8)):
        # limit point of vertex (i, j): (16 V + 4 sum E + sum D) / 36
        E = G[(i + 1) % 6, j] + G[i - 1, j] + G[i, (j + 1) % 8] + G[i, j - 1]
        D = G[(i + 1) % 6, (j + 1) % 8] + G[(i + 1) % 6, j - 1] + G[i - 1, (j + 1) % 8] + G[i - 1, j - 1]
        lim = (16 * G[i, j] + 4 * E + D) / 36
        assert np.abs(surfaces[p].evaluate([0.0], [0.0])[0] - lim).max() <= 1e-12 * scale


def test_regular_patches_reproduce_deep_limit_points():
    """Exact patches at dyadic parameters = limit points of the vertices three steps deeper."""
    V, F, _ = _torus(4, 5)
    res = subd_patches(V, F, levels=1, fit_depth=2)
    assert res.exact.all()
    assert res.deviation.max() <= 1e-12 * res.diagonal
    assert res.gap_exact <= 1e-12 * res.diagonal


def test_torus_shared_edges_equal():
    V, F, _ = _torus()
    s = subd_to_surfaces(V, F, levels=1)
    P = [x.control_points for x in s]
    scale = np.abs(V).max()
    for i in range(6):
        for j in range(8):
            a, right, up = P[i * 8 + j], P[((i + 1) % 6) * 8 + j], P[i * 8 + (j + 1) % 8]
            assert np.abs(a[3, :] - right[0, :]).max() <= 1e-12 * scale
            assert np.abs(a[:, 3] - up[:, 0]).max() <= 1e-12 * scale


def test_cube_closed_and_crack_free():
    V, F = _cube()
    res = subd_patches(V, F, levels=2)
    # level 1: 24 quads, each touching a valence-3 corner; level 2: 96 quads, 24 touch a corner
    assert len(res.surfaces) == 96
    assert int(res.exact.sum()) == 72 and (res.level == 2).all()
    assert res.open_samples == 0  # every boundary sample is shared: a closed set of patches
    assert res.gap <= 1e-12 * res.diagonal  # shared sides are fitted once per edge
    assert res.deviation[res.exact].max() <= 1e-12 * res.diagonal


def test_cube_deviation_decreases_with_the_subdominant_eigenvalue():
    """Near a valence-n vertex the net contracts by the subdominant eigenvalue lambda_n per step
    [Stam1998]; the approximate patches' deviation follows: lambda_3 = 0.4106 for the cube."""
    V, F = _cube()
    dev = []
    for k in (1, 2, 3):
        res = subd_patches(V, F, levels=k)
        dev.append(res.deviation[~res.exact].max() / res.diagonal)
    lam3 = (5 + np.cos(2 * np.pi / 3) + np.cos(np.pi / 3) * np.sqrt(2 * (9 + np.cos(2 * np.pi / 3)))) / 16
    assert dev[0] < 2e-3
    for a, b in zip(dev, dev[1:]):
        assert 0.8 * lam3 < b / a < 1.2 * lam3


def test_crease_ring_on_torus_is_exact_and_interpolates_the_crease_spline():
    V, F, idx = _torus()
    ring = [(idx[i, 0], idx[(i + 1) % 6, 0]) for i in range(6)]  # a crease around the tube
    res = subd_patches(V, F, creases=ring, levels=1)
    assert res.exact.all() and res.gap <= 1e-12 * res.diagonal and res.open_samples == 0
    # the crease is the periodic cubic B-spline of its vertices; patch (i, 0) has it as its v = 0 side
    C = V.reshape(6, 8, 3)[:, 0]
    t = np.linspace(0, 1, 5)
    Bt = _bspline_basis(t)
    for i in range(6):
        want = Bt @ C[(np.arange(-1, 3) + i) % 6]
        got = res.surfaces[i * 8].evaluate(t, np.zeros_like(t))
        assert np.abs(got - want).max() <= 1e-12 * np.abs(V).max()


def test_open_grid_boundary_phantoms_and_corners():
    n = 5
    x, y = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    z = 0.3 * np.sin(x) * np.cos(0.7 * y)
    V = np.stack([x, y, z], -1).reshape(-1, 3)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    F = [[idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]] for i in range(n) for j in range(n)]
    res = subd_patches(V, F, levels=2)
    assert res.open_samples > 0  # an open net has a free boundary
    assert res.gap <= 1e-12 * res.diagonal
    assert res.deviation[res.exact].max() <= 1e-12 * res.diagonal
    # faces touching a grid corner (valence 2, a one-face crease sector) are approximate
    assert (~res.exact).any()
    # a boundary face in the middle of a side is exact at level 0, its side the B-spline of the boundary row
    first = [s for s, e, lv in zip(res.surfaces, res.exact, res.level) if e and lv == 0]
    assert first
    row = V.reshape(n + 1, n + 1, 3)[:, 0]
    t = np.linspace(0, 1, 5)
    s = next(s for s in first if np.allclose(s.evaluate([0.0], [0.0])[0, :2], [2.0, 0.0]))
    want = _bspline_basis(t) @ row[1:5]
    assert np.abs(s.evaluate(t, np.zeros_like(t)) - want).max() <= 1e-12 * np.abs(V).max()


def test_limit_points_of_subdivided_net_agree_with_deeper_subdivision():
    """Limit points do not move under subdivision (the old vertices come first in the finer net)."""
    V, F = _cube()
    n1 = catmull_clark(make_net(V, F))
    n2 = catmull_clark(n1)
    L1, e1 = limit_points(n1)
    L2, _ = limit_points(n2)
    assert e1.all()
    assert np.abs(L1 - L2[: L1.shape[0]]).max() <= 1e-14


def test_non_quad_faces_and_rules():
    # a square pyramid: 4 triangles and a quad, an apex of valence 4 surrounded by triangles
    V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]]
    F = [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    a = subd_patches(V, F, levels=2)
    b = subd_patches(V, F, levels=2, rule="rhino")
    for r in (a, b):
        assert r.open_samples == 0 and r.gap <= 1e-12 * r.diagonal
    assert not np.allclose(a.surfaces[0].control_points, b.surfaces[0].control_points)


@pytest.mark.parametrize("creases, faces, message", [
    ([(0, 1)], None, "dart"),
    ([(0, 1), (0, 2), (0, 4)], None, "corner"),
    (None, [[0, 1, 3, 2], [0, 1, 5, 4], [0, 1, 7, 6]], "non-manifold"),
    (None, [[0, 1, 3, 2], [0, 1, 5, 4]], "consistently oriented"),
])
def test_refusals(creases, faces, message):
    V, F = _cube()
    with pytest.raises(ValueError, match=message):
        subd_patches(V, faces or F, creases=creases, levels=1)


def test_bad_arguments():
    V, F = _cube()
    with pytest.raises(ValueError, match="levels"):
        subd_patches(V, F, levels=0)
    with pytest.raises(ValueError, match="fit_depth"):
        subd_patches(V, F, levels=1, fit_depth=1)
    with pytest.raises(ValueError, match="rule"):
        subd_patches(V, F, levels=1, rule="loop")
