"""Geometry-image subdivision as fragment passes (splinevis.geometry_image.gpu) against its float64 twin
(splinevis.geometry_image.subdivision), within float32 error bounds derived here, at every level up to 5 of a
65 x 65 image (2049 x 2049 limit points).

Derivation (unit roundoff u = 2^-24 for float32, 2^-53 for the twin's float64; gamma_c = c u / (1 - c u)):

* Upload: G is rounded to float32 once: error u max|G| per component (0 for the twin).
* Every control-point pass is a sum of K terms with nonnegative weights summing to 1. The weights are
  exact (powers of two times small integers), and a compiler may reassociate the sum (Mesa does), so the
  bound takes the worst order: at most c = K - 1 roundings on any path, error <= gamma_c sum|w x| <=
  gamma_c max|x|, plus rounded constants and products where a weight is not exact. Split L: K = 4 as
  written, c = 3. Average A: K = 16 as written ((a + b) + (b + c) per row, and across rows), c = 15.
  Limit E: K = 9 with integer weights, c = 8, times the rounded constant 1/36 (2 more): c = 10.
* The masks average, so an input error e passes through unamplified: e_out <= e_in + gamma_c (M + e_in)
  with M = max|G| (every exact intermediate value is a convex combination of G's components). Per level
  e_{k+1} = L-then-A applied to e_k; positions add the limit pass. GPU vs twin: the sum of both bounds.
* Tangents (T_s, T_t: 6 terms with weights of |sum| 1, c = 5 + 2 for the constant 1/12): per component
  e_T = e_g + gamma_7 (M + e_g); as vectors |dT| <= sqrt(3) e_T. The cross product v = T_s x T_t changes by
  |T_s||dT_t| + |dT_s||T_t| + |dT_s||dT_t| plus its own rounding (two products and a difference per
  component: gamma_2 |a||b| each, sqrt(3) gamma_2 |a||b| as a vector). The angle of v moves by at most
  arcsin(|dv| / |v|); normalizing (one rounded multiplication per component) adds u. |T| and |v| are taken
  from the twin (its own error bound added/subtracted).
* Cut vertices: P_ss, P_tt (9 terms, sum|w| = 4, c = 10), P_st (4 terms, sum|w| = 1, c = 3), and
  w = P_ss x P_st + P_st x P_tt: the same perturbation of the two cross products, their rounding gamma_3.
  At deep levels these second differences are a few ulps of the coordinates (the float32 resolution of
  g^k, not an error of the passes): the bound grows as 4^k and saturates at pi / 2, and the test reports it.
* Measuring the angle between the two normals in float64 (atan2 of |a x b| and a . b) adds <= 8 u_64.

Nothing is tuned: the bounds are these formulas with the level's magnitudes.
"""

import numpy as np
import pytest

from splinevis.geometry_image.gpu import displace_gpu, geomorph_gpu, subdivide_gpu
from splinevis.geometry_image.image import apply_cut_constraint, cut_vertices, image_uv, octahedral_to_sphere, pad, symmetrize
from splinevis.geometry_image.subdivision import (average, displace, geomorph, limit, normals, second_derivatives, split,
                                                  subsample, tangents)

pytestmark = pytest.mark.gl

U32, U64 = 2.0 ** -24, 2.0 ** -53
C_SPLIT, C_AVERAGE, C_LIMIT, C_TANGENT, C_PSS, C_PST = 3, 15, 10, 7, 10, 3
LEVELS = 5


def gamma(c, u):
    return c * u / (1.0 - c * u)


def control_bounds(levels, M, u, upload):
    """Componentwise bounds on |computed g^k - exact g^k|, k = 0..levels."""
    e = [upload * u * M]
    for _ in range(levels):
        x = e[-1] + gamma(C_SPLIT, u) * (M + e[-1])
        e.append(x + gamma(C_AVERAGE, u) * (M + x))
    return e


def cross_error(a, da, b, db, u, c=2):
    """Bound on |computed a' x b' - a x b| for |a' - a| <= da, |b' - b| <= db (norms, per texel)."""
    return a * db + da * b + da * db + np.sqrt(3.0) * gamma(c, u) * (a + da) * (b + db)


def _norm(x):
    return np.linalg.norm(x, axis=-1)


def normal_angle_bound(g, e_g, M, u):
    """Per texel bound on the angle between the computed and the exact normal (see the module docstring),
    ``g`` the twin's padded control image, ``e_g`` the componentwise bound on the computation's g^k."""
    e_t = e_g + gamma(C_TANGENT, u) * (M + e_g)
    ts, tt = tangents(g)
    dT = np.sqrt(3.0) * e_t
    dv = cross_error(_norm(ts), dT, _norm(tt), dT, u)
    v = np.cross(ts, tt)
    cut = cut_vertices(v.shape[0])
    e_ss = 4.0 * e_g + gamma(C_PSS, u) * 4.0 * (M + e_g)
    e_st = e_g + gamma(C_PST, u) * (M + e_g)
    for r, c in cut:
        pss, pst, ptt = (np.linalg.norm(d[0, 0]) for d in second_derivatives(g[r:r + 3, c:c + 3]))
        dss, dst = np.sqrt(3.0) * e_ss, np.sqrt(3.0) * e_st
        dv[r, c] = cross_error(pss, dss, pst, dst, u, 3) + cross_error(pst, dst, ptt, dss, u, 3)
        d2 = second_derivatives(g[r:r + 3, c:c + 3])
        v[r, c] = np.cross(d2[0][0, 0], d2[1][0, 0]) + np.cross(d2[1][0, 0], d2[2][0, 0])
    return dv, _norm(v)


def angle_bound(g, e32, e64, M):
    dv32, vn = normal_angle_bound(g, e32, M, U32)
    dv64, _ = normal_angle_bound(g, e64, M, U64)
    floor = vn - dv64  # |exact v| >= |twin v| - its error
    ratio = np.where(floor > 0, (dv32 + dv64) / np.where(floor > 0, floor, 1.0), 1.0)
    return np.arcsin(np.minimum(ratio, 1.0)) + U32 + U64 + 8 * U64


def _angle(a, b):
    a, b = a.astype(np.float64), b.astype(np.float64)
    return np.arctan2(_norm(np.cross(a, b)), (a * b).sum(axis=-1))


def _images():
    n = 65
    sphere = apply_cut_constraint(octahedral_to_sphere(image_uv(n)))
    rng = np.random.default_rng(20)
    bumpy = apply_cut_constraint(symmetrize(octahedral_to_sphere(image_uv(n)) + 0.02 * rng.normal(size=(n, n, 3))))
    return {"sphere": sphere, "bumpy": bumpy}


IMAGES = _images()


@pytest.mark.parametrize("name", sorted(IMAGES))
def test_gpu_subdivision_equals_the_twin_within_derived_bounds(name):
    G = IMAGES[name]
    M = float(np.abs(G).max())
    e32 = control_bounds(LEVELS, M, U32, upload=1)
    e64 = control_bounds(LEVELS, M, U64, upload=0)
    g = pad(G)
    rows = []
    for k in range(LEVELS + 1):
        if k:
            g = average(split(g))
        gpu = subdivide_gpu(G, k)
        assert gpu.g.shape == g.shape and gpu.p.shape == gpu.n.shape == (g.shape[0] - 2,) * 2 + (3,)
        # control points, padding included: no re-padding between levels
        dg = np.abs(gpu.g - g).max()
        assert dg <= e32[k] + e64[k]
        assert np.abs(gpu.g - pad(gpu.g[1:-1, 1:-1])).max() <= 2 * e32[k]
        # limit positions
        ep = e32[k] + gamma(C_LIMIT, U32) * (M + e32[k]) + e64[k] + gamma(C_LIMIT, U64) * (M + e64[k])
        dp = np.abs(gpu.p - limit(g)).max()
        assert dp <= ep
        # normals, per texel
        ang = _angle(gpu.n, normals(g))
        bound = angle_bound(g, e32[k], e64[k], M)
        assert (ang <= bound).all(), (k, float((ang - bound).max()))
        cv = cut_vertices(gpu.p.shape[0])
        regular = np.ones(ang.shape, bool)
        regular[cv[:, 0], cv[:, 1]] = False
        rows.append((k, dg / U32, ep / U32, dp / U32, float(ang[regular].max()), float(np.median(bound[regular])),
                     float((ang / bound)[regular].max()), float(ang[~regular].max()), float(bound[~regular].max())))
    print(f"\n{name}: level, max|dg|/u, position bound/u, max|dp|/u; normals: max angle, median bound, "
          "max angle/bound; at cut vertices: max angle, max bound")
    for r in rows:
        print("  %d  %5.2f  %6.2f  %5.2f   %.2e  %.2e  %.3f   %.2e  %.2e" % r)


def test_geomorph_and_displace_passes_equal_the_twin():
    G = IMAGES["bumpy"]
    k1 = subdivide_gpu(G, 3)
    pk1, nk1 = k1.p, k1.n
    pk, nk = subsample(pk1, 1), subsample(nk1, 1)  # the paper's way: the coarse level from the fine one
    inputs = [a.astype(np.float64) for a in (pk, pk1, nk, nk1)]
    for alpha in (0.0, 0.375, 1.0):  # exact in float32
        # lin: one rounding; blend: two products and a sum (1 - alpha exact): |error| <= gamma_4 max|x|
        for a, b, unit in ((inputs[0], inputs[1], False), (inputs[2], inputs[3], True)):
            out = geomorph_gpu(a.astype(np.float32), b.astype(np.float32), alpha, unit=unit)
            ref = geomorph(a, b, alpha, unit=unit)
            if unit:  # normalizing changes the direction by <= u; compare angles
                ok = _angle(out, ref) <= np.arcsin(np.minimum(1.0, 2 * np.sqrt(3) * gamma(4, U32)
                                                              / _norm(geomorph(a, b, alpha)))) + 2 * U32 + 8 * U64
                assert ok.all()
            else:
                assert np.abs(out - ref).max() <= gamma(4, U32) * np.abs(b).max()
    assert np.array_equal(geomorph_gpu(pk, pk1, 1.0), pk1)
    d = np.random.default_rng(21).uniform(-0.05, 0.05, size=pk1.shape[:2]).astype(np.float32)
    out = displace_gpu(pk1, nk1, d)
    ref = displace(inputs[1], inputs[3], d.astype(np.float64))
    # a product and a sum: gamma_2 (|p| + |d| |n|)
    assert np.abs(out - ref).max() <= gamma(2, U32) * (np.abs(pk1).max() + 0.05)


def test_results_can_stay_on_the_gpu():
    from splinevis.gl.context import current

    G = IMAGES["sphere"]
    with current():
        p, n, g = subdivide_gpu(G, 1, readback=False)
        sizes = p.size, n.size, g.size
        d = np.full((129, 129), 0.25, dtype=np.float32)
        moved = displace_gpu(p, n, d, readback=False)
        moved_size = moved.size
        for t in (p, n, g, moved):
            t.release()
    assert sizes == ((129, 129), (129, 129), (131, 131)) and moved_size == (129, 129)
