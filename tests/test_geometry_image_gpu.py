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
* Cut vertices: the normal is the float64 cut_normals of the level-0 image (the twin uses the same), rounded
  to float32 as a uniform: each component within u of its value, so the angle is <= arcsin(u).
* Curvature (gi_curvature.glsl and the twin's curvature), per texel, propagating absolute error bounds
  through every operation with the twin's magnitudes (|exact x| <= |twin x| + the twin's own bound):
  derivatives as above (|dT| <= sqrt(3) e_T, P_ss and P_tt: 9 terms with sum|w| = 4, c = 10; P_st: 4 terms,
  sum|w| = 1, c = 3); v = T_s x T_t as for the normals; a dot product of 3-vectors changes by
  |a| db + da |b| + da db and rounds by gamma_3 |a'| |b'|; D = v . v; n = v inversesqrt(D): |dn| <= 2 |dv| / |v|
  plus gamma_{4 + r} (the rounding of D, r u for the reciprocal square root, one product); a product by
  |x| dy + dx |y| + dx dy; the numerators E N - 2 F M + G L and L N - M^2 by the sum of their terms' errors
  plus gamma_3 (gamma_2) of the sum of their magnitudes (any order, FMA or not); a quotient A / D by
  (dA + |A / D| dD) / (D - dD) plus the division's rounding q u |quotient|. r and q: GLSL 4.50 allows
  inversesqrt 2 ulp and x / y 2.5 ulp (an ulp <= 2 u relative): r = 4, q = 5 for float32; float64 numpy
  rounds correctly: r = 2 (sqrt, then a division), q = 1. Where dD >= D the derivation bounds nothing (the
  float32 second differences no longer resolve the curvature): the bound is infinite and the test reports
  how many texels that is. The cut vertices hold the mean of four neighbours: their bounds / 4 plus gamma_2
  of the magnitudes / 4.
* Measuring the angle between the two normals in float64 (atan2 of |a x b| and a . b) adds <= 8 u_64.

Nothing is tuned: the bounds are these formulas with the level's magnitudes.
Curvature's sign convention is the NURBS programs' (H = -1/r on a sphere with outward normals).
"""

import numpy as np
import pytest

from splinevis.geometry_image.gpu import curvature_gpu, displace_gpu, geomorph_gpu, subdivide_gpu
from splinevis.geometry_image.image import (apply_cut_constraint, cut_neighbours, cut_vertices, image_uv,
                                            octahedral_to_sphere, pad, symmetrize)
from splinevis.geometry_image.subdivision import (average, curvature, cut_normals, displace, geomorph, limit, normals,
                                                  second_derivatives, split, subsample, tangents)

from _subdivision_bounds import C_LIMIT, C_PSS, C_PST, C_TANGENT, U32, U64, control_bounds, gamma

pytestmark = pytest.mark.gl

LEVELS = 5


def cross_error(a, da, b, db, u, c=2):
    """Bound on |computed a' x b' - a x b| for |a' - a| <= da, |b' - b| <= db (norms, per texel)."""
    return a * db + da * b + da * db + np.sqrt(3.0) * gamma(c, u) * (a + da) * (b + db)


def _norm(x):
    return np.linalg.norm(x, axis=-1)


def normal_angle_bound(g, e_g, M, u):
    """Per texel bound on |computed v - exact v| for v = T_s x T_t (see the module docstring) and |twin v|,
    ``g`` the twin's padded control image, ``e_g`` the componentwise bound on the computation's g^k."""
    e_t = e_g + gamma(C_TANGENT, u) * (M + e_g)
    ts, tt = tangents(g)
    dT = np.sqrt(3.0) * e_t
    dv = cross_error(_norm(ts), dT, _norm(tt), dT, u)
    return dv, _norm(np.cross(ts, tt))


def angle_bound(g, e32, e64, M):
    dv32, vn = normal_angle_bound(g, e32, M, U32)
    dv64, _ = normal_angle_bound(g, e64, M, U64)
    floor = vn - dv64  # |exact v| >= |twin v| - its error
    ratio = np.where(floor > 0, (dv32 + dv64) / np.where(floor > 0, floor, 1.0), 1.0)
    bound = np.arcsin(np.minimum(ratio, 1.0)) + U32 + U64 + 8 * U64
    # cut vertices: the twin's float64 normal rounded to float32 (the uniform), measured in float64
    cv = cut_vertices(bound.shape[0])
    bound[cv[:, 0], cv[:, 1]] = np.arcsin(U32) + 8 * U64
    return bound


def _dot_error(a, da, b, db, u):
    """|computed a' . b' - a . b| for 3-vectors of norms a, b (exact) and errors da, db."""
    return a * db + da * b + da * db + gamma(3, u) * (a + da) * (b + db)


def _product_error(x, dx, y, dy):
    return x * dy + dx * y + dx * dy


def _quotient_error(A, dA, D, dD, u, q):
    """|A' / D' - A / D| with the division's rounding (q u relative); infinite where dD >= D."""
    ok = dD < D
    Dl = np.where(ok, D - dD, 1.0)
    d = (dA + A / np.where(D > 0, D, 1.0) * dD) / Dl
    d = d + q * u * (A / np.where(D > 0, D, 1.0) + d)
    return np.where(ok, d, np.inf)


def _twin_forms(g):
    """The twin's intermediate values of the curvature formula (absolute values and norms), per texel."""
    ts, tt = tangents(g)
    pss, pst, ptt = second_derivatives(g)
    v = np.cross(ts, tt)
    D = (v * v).sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = v / np.sqrt(D)[..., None]
    E, F, G = (ts * ts).sum(-1), (ts * tt).sum(-1), (tt * tt).sum(-1)
    L, M, N = ((x * n).sum(-1) for x in (pss, pst, ptt))
    x = {"ts": _norm(ts), "tt": _norm(tt), "pss": _norm(pss), "pst": _norm(pst), "ptt": _norm(ptt), "v": _norm(v),
         "D": D, "E": E, "F": F, "G": G, "L": L, "M": M, "N": N, "EN": E * N, "2FM": 2 * F * M, "GL": G * L,
         "LN": L * N, "MM": M * M}
    with np.errstate(invalid="ignore", divide="ignore"):
        x["A"] = x["EN"] - x["2FM"] + x["GL"]
        x["B"] = x["LN"] - x["MM"]
    return {k: np.nan_to_num(np.abs(a), nan=0.0, posinf=0.0) for k, a in x.items()}


def curvature_errors(x, e_g, M, u, r, q):
    """Per texel bounds on |computed H - exact H| and |computed K - exact K| (module docstring), ``x`` the
    magnitudes of the exact intermediate values, ``e_g`` the componentwise bound on the computation's g^k;
    with every intermediate error (dict)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # NaN at the cut vertices: replaced there
        return _curvature_errors(x, e_g, M, u, r, q)


def _curvature_errors(x, e_g, M, u, r, q):
    d = {}
    d["ts"] = d["tt"] = np.sqrt(3.0) * (e_g + gamma(C_TANGENT, u) * (M + e_g))
    d["pss"] = d["ptt"] = np.sqrt(3.0) * (4.0 * e_g + gamma(C_PSS, u) * 4.0 * (M + e_g))
    d["pst"] = np.sqrt(3.0) * (e_g + gamma(C_PST, u) * (M + e_g))
    d["v"] = cross_error(x["ts"], d["ts"], x["tt"], d["tt"], u)
    d["D"] = _dot_error(x["v"], d["v"], x["v"], d["v"], u)
    dn = np.where(d["v"] < x["v"], 2.0 * d["v"] / x["v"], np.inf) + gamma(4 + r, u)
    for a, p in (("L", "pss"), ("M", "pst"), ("N", "ptt")):
        d[a] = _dot_error(x[p], d[p], 1.0, dn, u)
    for a, (b, c) in (("E", ("ts", "ts")), ("F", ("ts", "tt")), ("G", ("tt", "tt"))):
        d[a] = _dot_error(x[b], d[b], x[c], d[c], u)
    d["EN"] = _product_error(x["E"], d["E"], x["N"], d["N"])
    d["2FM"] = 2.0 * _product_error(x["F"], d["F"], x["M"], d["M"])
    d["GL"] = _product_error(x["G"], d["G"], x["L"], d["L"])
    d["LN"] = _product_error(x["L"], d["L"], x["N"], d["N"])
    d["MM"] = _product_error(x["M"], d["M"], x["M"], d["M"])
    terms_A, terms_B = ("EN", "2FM", "GL"), ("LN", "MM")
    d["A"] = sum(d[t] for t in terms_A) + gamma(3, u) * sum(x[t] + d[t] for t in terms_A)
    d["B"] = sum(d[t] for t in terms_B) + gamma(2, u) * sum(x[t] + d[t] for t in terms_B)
    dH = 0.5 * _quotient_error(x["A"], d["A"], x["D"], d["D"], u, q)
    dK = _quotient_error(x["B"], d["B"], x["D"], d["D"], u, q)
    return dH, dK, d


def curvature_bound(g, e32, e64, M, H, K):
    """Bounds on |GPU H - twin H| and |GPU K - twin K| per texel: the GPU's and the twin's bounds added."""
    x = _twin_forms(g)
    _, _, d64 = curvature_errors(x, e64, M, U64, 2, 1)
    x = {k: a + d64.get(k, 0.0) for k, a in x.items()}  # |exact| <= |twin| + the twin's error
    out = []
    for value, (b32, b64) in zip((H, K), zip(curvature_errors(x, e32, M, U32, 4, 5)[:2],
                                              curvature_errors(x, e64, M, U64, 2, 1)[:2])):
        b = b32 + b64
        m = b.shape[0]
        for (r, c), nb in zip(cut_vertices(m), cut_neighbours(m)):  # mean of 4: error / 4 + gamma_2 sum / 4
            bn, vn = b[nb[:, 0], nb[:, 1]], np.abs(value[nb[:, 0], nb[:, 1]])
            b[r, c] = 0.25 * bn.sum() + (gamma(2, U32) + gamma(2, U64)) * 0.25 * (vn + bn).sum()
        out.append(b)
    return out


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
        # at the cut vertices: the level-0 float64 normal rounded to float32, the same bits at every level
        assert np.array_equal(gpu.n[cv[:, 0], cv[:, 1]], cut_normals(pad(G)).astype(np.float32))
        regular = np.ones(ang.shape, bool)
        regular[cv[:, 0], cv[:, 1]] = False
        rows.append((k, dg / U32, ep / U32, dp / U32, float(ang[regular].max()), float(np.median(bound[regular])),
                     float((ang / bound)[regular].max()), float(ang[~regular].max()), float(bound[~regular].max())))
    print(f"\n{name}: level, max|dg|/u, position bound/u, max|dp|/u; normals: max angle, median bound, "
          "max angle/bound; at cut vertices: max angle, max bound")
    for r in rows:
        print("  %d  %5.2f  %6.2f  %5.2f   %.2e  %.2e  %.3f   %.2e  %.2e" % r)


CURVATURE_LEVELS = 4


@pytest.mark.parametrize("name", sorted(IMAGES))
def test_gpu_curvature_equals_the_twin_within_derived_bounds(name):
    G = IMAGES[name]
    M = float(np.abs(G).max())
    e32 = control_bounds(CURVATURE_LEVELS, M, U32, upload=1)
    e64 = control_bounds(CURVATURE_LEVELS, M, U64, upload=0)
    g = pad(G)
    rows = []
    for k in range(CURVATURE_LEVELS + 1):
        if k:
            g = average(split(g))
        H, K = curvature(g)
        sub = subdivide_gpu(G, k, curvature=True)
        Hg, Kg = curvature_gpu(sub.g)
        assert np.array_equal(sub.curvature, np.stack([Hg, Kg], axis=-1))  # in the chain or on its own
        bH, bK = curvature_bound(g, e32[k], e64[k], M, H, K)
        cv = cut_vertices(H.shape[0])
        cut = np.zeros(H.shape, bool)
        cut[cv[:, 0], cv[:, 1]] = True
        row = [k]
        for got, want, bound in ((Hg, H, bH), (Kg, K, bK)):
            err = np.abs(got.astype(np.float64) - want)
            assert np.isfinite(got).all()
            assert (err <= bound).all(), (k, float(np.nanmax(err - bound)))
            finite = np.isfinite(bound)
            row += [float(np.median(np.abs(want))), float(err.max()), float(np.median(err)), float(np.median(bound)),
                    float((err / bound)[finite].max()), float((err / bound)[cut].max()), 1.0 - finite.mean()]
        rows.append(tuple(row))
    print(f"\n{name}: level; for H then K: median|value|, max|error|, median|error|, median bound, "
          "max error/bound, max error/bound at the cut vertices, share of texels without a finite bound")
    for r in rows:
        print("  %d   %.2f %.1e %.1e %.1e %.3f %.4f %.0e    %.2f %.1e %.1e %.1e %.3f %.4f %.0e" % r)


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
