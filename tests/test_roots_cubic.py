"""Cubic first roots: the stable closed form and the Newton iteration of [Kalbe2008, sec. 5.3] from three starts.

GLSL (``sv_first_root_cubic``, ``sv_first_root_newton3``) against the float32 twins on the GPU, the float64
twins against the robust reference, hard cases, and the comparison on ray-restricted spline cubics.
"""

from math import comb

import numpy as np
import pytest

from splinevis.bb.roots import (
    EPS32, eval_deriv, first_root_cubic, first_root_quadratic, first_root_reference, newton_three_starts,
    root_tolerance_k, roots_reference,
)
from splinevis.volume.root_methods import (
    CATEGORIES, compare_root_methods, first_root_tolerance, format_table, sample_ray_cubics,
)

K3 = root_tolerance_k(3)


def bb_from_roots(roots, a=1.0):
    """BB coefficients of a * prod (t - r)."""
    n = len(roots)
    p = np.poly(roots)[::-1] * a
    return np.array([sum(comb(k, j) / comb(n, j) * p[j] for j in range(k + 1)) for k in range(n + 1)]).real


def _accept_bound(c, r):
    """Where the closed form's acceptance test |f| <= K_3 eps32 S + eps32 |x f'| puts x: to first order
    |x - r| <= (K_3 eps32 S(r) + eps32 |r f'(r)|) / |f'(r)| (1% for the linearization)."""
    f, fp = eval_deriv(c, r)
    S, _ = eval_deriv(np.abs(c), r)
    return (K3 * EPS32 * S / np.abs(fp) + EPS32 * np.abs(r)) * 1.01


def _dbl_bound(c, r):
    """Double root: f(r + dx) ~ f'' dx^2 / 2 <= (K_3 + EVAL) eps32 S gives |dx| <= sqrt(2 (K_3 + 4.5) eps32 S / |f''|)."""
    fpp = 6.0 * eval_deriv(np.diff(np.diff(c)), r)[0]
    S, _ = eval_deriv(np.abs(c), r)
    return np.sqrt(2.0 * (K3 + 4.5) * EPS32 * S / abs(fpp))


# ----------------------------------------------------------------------------------------------------
# float64 twin vs reference
# ----------------------------------------------------------------------------------------------------

def test_closed_form_vs_reference_random_well_conditioned_cubics():
    rng = np.random.default_rng(4)
    m = 20_000
    roots = rng.uniform(-0.5, 1.5, size=(m, 3))
    scale = 10.0 ** rng.uniform(-6, 6, size=m) * np.where(rng.random(m) < 0.5, -1, 1)
    srt = np.sort(roots, 1)
    ok = np.diff(srt, axis=1).min(1) > 0.02              # simple, separated roots
    ok &= np.all(np.abs(roots) > 1e-3, 1) & np.all(np.abs(roots - 1) > 1e-3, 1)  # none right at an end
    c = np.array([bb_from_roots(r, s) for r, s in zip(roots[ok], scale[ok])])
    ref = first_root_reference(c)
    has = np.isfinite(ref)
    assert has.sum() > 5000 and (~has).sum() > 500
    for polish in (0, 1, 2):
        x = first_root_cubic(c, polish=polish)
        assert np.array_equal(np.isfinite(x), has)       # no miss, no spurious root
        # derived from the acceptance test (the tolerance is float32's, as for newton_secure's float64 twin)
        assert np.all(np.abs(x[has] - ref[has]) <= _accept_bound(c[has], ref[has]))
    # the closed form itself is accurate in float64 (the test tolerance above is float32's)
    assert np.median(np.abs(first_root_cubic(c, polish=0)[has] - ref[has])) < 1e-14


def test_float32_twin_vs_reference_hard_random_cubics():
    from splinevis.selftest import _root_inputs

    c32, kind = _root_inputs(np.random.default_rng(11), 30_000, 3)
    cl = compare_root_methods(c32, iterations=(), masks=True)["analytic cubic"]
    # never missed, never a later root. "correct" = within the derived first_root_tolerance (value-level
    # uncertainty (2 K_3 + gamma_9) eps32 S carried through f' and f'', plus the float32 argument rounding
    # eps32 |r|: the plain ROOT_BOUND of the selftest is below one ulp for steep roots, where even the
    # correctly rounded root fails it). "earlier"/"spurious" are near roots only (kinds 3/4: complex pairs
    # within float32 rounding of the real axis; they pass the exact-arithmetic residual test).
    assert cl["missed"].sum() == 0 and cl["later"].sum() == 0
    assert np.all(cl["spurious"] == cl["spurious_near_root"])
    assert cl["inaccurate"].sum() <= 2                    # measured: 0-2 roots at ~1e-13 off by ~1e-18
    assert cl["correct"].sum() > 0.7 * len(c32)


# ----------------------------------------------------------------------------------------------------
# hard cases (float64 and float32 twins)
# ----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_hard_cases(dtype):
    def fr(c):
        return float(first_root_cubic(np.asarray(c, np.float64).astype(dtype), dtype=dtype))

    tol = 1e-12 if dtype is np.float64 else 1e-6
    # tangent (double root) before a simple one, and after it
    c = bb_from_roots([0.4, 0.4, 0.8])
    assert abs(fr(c) - 0.4) <= _dbl_bound(c, 0.4)
    c = bb_from_roots([0.3, 0.7, 0.7])
    assert fr(c) == pytest.approx(0.3, abs=tol)
    c = bb_from_roots([0.6, 0.6, 2.0])                     # double root only (pair touching the axis)
    assert abs(fr(c) - 0.6) <= _dbl_bound(c, 0.6)
    # a pair just off the axis that float32 cannot tell from a touching root: accepted only within rounding
    c = bb_from_roots([0.5 + 1e-5j, 0.5 - 1e-5j, 3.0])
    x = fr(c)
    assert np.isnan(x) or abs(x - 0.5) <= _dbl_bound(c, 0.5)
    assert np.isnan(fr(bb_from_roots([0.5 + 0.1j, 0.5 - 0.1j, 3.0])))
    # triple root: f = (t - 1/4)^3, residual-level accuracy (t - 1/4)^3 ~ eps S -> |dx| ~ cbrt(eps)
    assert fr(bb_from_roots([0.25, 0.25, 0.25])) == pytest.approx(0.25, abs=2e-3)
    # roots exactly at 0 and 1
    assert fr(bb_from_roots([0.0, 0.5, 0.7])) == 0.0
    assert fr([0.0, 1.0, 2.0, 3.0]) == 0.0
    assert fr(bb_from_roots([1.0, 1.5, 2.0])) == 1.0
    assert fr([-3.0, -2.0, -1.0, 0.0]) == 1.0
    assert fr(np.zeros(4)) == 0.0                          # zero polynomial
    assert np.isnan(fr([1.0, 2.0, 1.0, 3.0]))              # positive: no root
    assert np.isnan(fr([1.0, np.inf, 2.0, 0.5])) and np.isnan(fr([np.nan, 1.0, 1.0, 1.0]))
    # power-form leading coefficient exactly 0 (a quadratic written as a cubic) and ~0: the homogeneous
    # form has a root at t = infinity there, no special case; agrees with the quadratic closed form
    q = bb_from_roots([0.35, 0.9])
    c = np.array([q[0], (q[0] + 2 * q[1]) / 3, (2 * q[1] + q[2]) / 3, q[2]])   # degree elevation
    assert fr(c) == pytest.approx(0.35, abs=tol)
    assert fr(c) == pytest.approx(float(first_root_quadratic(q, dtype=dtype)), abs=tol)
    for lead in (1e-7, -1e-7, 1e-3):
        c = bb_from_roots([0.35, 0.9, 1.0 / lead], lead)  # third root far out: a3 = lead
        assert fr(c) == pytest.approx(0.35, abs=tol * 10)
    # huge and tiny scales (exact power-of-two scaling keeps disc ~ c^4 in range)
    for s in (1e-30, 1e30, -1e30, 1e-35, 1e35):
        c = bb_from_roots([0.2, 0.55, 0.9], s)
        assert fr(c) == pytest.approx(0.2, abs=tol * 10)
    # coefficients spanning 1e8 in magnitude: (t - 1e-8 r) near 0, and a steep root near 1
    c = np.array([-1e-8, 1.0, 1.0, 1.0])
    x = fr(c)
    ref = first_root_reference(c)
    assert abs(x - ref) <= _accept_bound(c, ref)
    c = np.array([1.0, 1.0, 1e-8, -1e-8])
    ref = first_root_reference(c)
    assert abs(fr(c) - ref) <= _accept_bound(c, ref) + 1e-12


def test_newton3_is_paper_method_and_measured_weaknesses():
    # starts 0, inflection point, 1: a simple first root is found with I = 5
    # (accepted by the residual test |f| <= K_3 eps32 S, hence within K_3 eps32 S / |f'| of the root)
    c = bb_from_roots([0.3, 0.6, 0.9])
    assert abs(newton_three_starts(c, 5) - 0.3) <= _accept_bound(c, 0.3)
    # inflection point outside (0, 1): the middle start is 1/2
    c = bb_from_roots([0.2, 2.0, 3.0])
    assert abs(newton_three_starts(c, 5) - 0.2) <= _accept_bound(c, 0.2)
    # the tangent (double) root the closed form finds is missed by Newton (linear convergence)
    c = bb_from_roots([0.4, 0.4, 1.5])
    assert np.isnan(newton_three_starts(c, 5))
    assert abs(first_root_cubic(c) - 0.4) <= _dbl_bound(c, 0.4)
    assert newton_three_starts(np.zeros(4), 3) == 0.0
    with pytest.raises(ValueError, match=r"iterations must be an integer in 1\.\.8"):
        newton_three_starts(c, 0)
    with pytest.raises(ValueError, match="4 coefficients"):
        first_root_cubic(np.zeros(3))
    with pytest.raises(ValueError, match=r"polish must be an integer in 0\.\.4"):
        first_root_cubic(c, polish=5)


# ----------------------------------------------------------------------------------------------------
# realistic inputs and the method comparison
# ----------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def ray_cubics():
    return sample_ray_cubics(12_000, seed=3, return_source=True)


def test_sample_ray_cubics_are_restrictions_with_roots(ray_cubics):
    c, src = ray_cubics
    assert c.shape == (12_000, 4) and set(np.unique(src)) == {0, 1}
    ref = first_root_reference(c)
    frac = np.isfinite(ref).mean()
    assert 0.05 < frac < 0.6                               # realistic: most segments miss the surface
    # the sphere distance is ~linear along a ray: its restrictions are nearly linear (small 2nd differences)
    d2 = np.abs(np.diff(c[src == 1], 2, axis=1)).max(1)
    assert np.median(d2) < 0.05 * np.median(np.abs(c[src == 1]).max(1))


def test_compare_root_methods_table(ray_cubics):
    c, _ = ray_cubics
    table = compare_root_methods(c, iterations=(3, 5))
    print("\n" + format_table(table))
    for name, row in table.items():
        if name.startswith("_"):
            continue
        assert sum(row[k] for k in CATEGORIES) == table["_n"]
    a = table["analytic cubic"]
    assert a["missed"] == 0 and a["later"] == 0 and a["spurious"] == a["spurious_near_root"]
    assert a["correct"] >= table["_with_root"] - 2
    assert table["bracketed I=5"]["missed"] == 0
    # measured, not assumed: the 3-start Newton of [Kalbe2008, sec. 5.3] with I = 5 misses some first roots on these inputs
    assert table["newton3 paper I=5"]["correct"] <= a["correct"]
    masks = compare_root_methods(c[:100], iterations=(5,), masks=True)
    assert masks["analytic cubic"]["correct"].dtype == bool


# ----------------------------------------------------------------------------------------------------
# GLSL on the GPU vs the float32 twins
# ----------------------------------------------------------------------------------------------------

def _gl_inputs(ray_cubics):
    from splinevis.selftest import _root_inputs

    c32, _ = _root_inputs(np.random.default_rng(21), 20_000, 3)
    special = np.array([
        bb_from_roots([0.4, 0.4, 0.8]), bb_from_roots([0.25] * 3), [0, 1, 2, 3], [-3, -2, -1, 0], np.zeros(4),
        bb_from_roots([0.2, 0.55, 0.9], 1e30), bb_from_roots([0.2, 0.55, 0.9], 1e-30),
        [-1e-8, 1.0, 1.0, 1.0], [1.0, 1.0, 1e-8, -1e-8], bb_from_roots([0.35, 0.9, 1e7], 1e-7),
        [1.0, np.inf, 2.0, 0.5],
    ])
    return np.concatenate([c32, ray_cubics[0][:10_000].astype(np.float32), special.astype(np.float32)])


@pytest.mark.gl
def test_glsl_cubic_and_newton3_vs_float32_twins(ray_cubics):
    from splinevis.gl.harness import run_glsl
    from splinevis.selftest import classify_first_roots

    c = _gl_inputs(ray_cubics)
    body = ("float c[5] = float[5](sv_in[0], sv_in[1], sv_in[2], sv_in[3], 0.0);"
            "sv_out[0] = sv_first_root_cubic(c); sv_out[1] = sv_first_root_newton3(c, 5);"
            "sv_out[2] = sv_first_root_newton3(c, 3);")
    g = run_glsl('#include "lib/core/roots.glsl"\n', body, c, 3)
    g = np.where(g == -1.0, np.nan, g)
    # Newton from three starts: only + - * / and comparisons -> bit-identical to the float32 twin
    # (the twin rejects non-finite input, like newton_secure's: the last row is left out)
    assert np.array_equal(g[:-1, 1], newton_three_starts(c[:-1], 5, dtype=np.float32), equal_nan=True)
    assert np.array_equal(g[:-1, 2], newton_three_starts(c[:-1], 3, dtype=np.float32), equal_nan=True)
    # closed form: atan, cos, sin, pow, log2, exp2 are not correctly rounded on the GPU (GLSL allows
    # several ulps), so the candidates differ by a few ulps times the conditioning; after the Newton polish
    # and the residual test both are float32 roots: same existence, and at a well-conditioned first root
    # r both lie within the derived first_root_tolerance(r) of it, hence within 2 tolerances of each other
    tw = first_root_cubic(c, dtype=np.float32)
    gc = g[:, 0]
    exist_diff = np.isfinite(gc) != np.isfinite(tw)
    assert exist_diff.sum() <= 2e-4 * len(c)              # measured: 0 (borderline residual tests only)
    same = (gc == tw) | (np.isnan(gc) & np.isnan(tw))
    assert same.mean() > 0.85                              # measured ~0.91 bit-identical
    c64 = c.astype(np.float64)
    ok = np.all(np.isfinite(c64), 1)
    ref = roots_reference(c64[ok])
    well = classify_first_roots(c64[ok], tw[ok], 3, 0.0, ref)["well"]
    r = ref[:, 0]
    tol = first_root_tolerance(c64[ok], r)
    both = well & np.isfinite(gc[ok]) & np.isfinite(tw[ok]) & (np.abs(tw[ok] - r) <= tol)
    assert both.sum() > 12_000                             # measured 14454
    assert np.all(np.abs(gc[ok][both] - tw[ok][both]) <= 2 * tol[both])
    # the special rows: zero polynomial / root at 0 -> 0, root at 1 -> 1, non-finite -> none
    sp = gc[-11:]
    assert sp[2] == 0.0 and sp[3] == 1.0 and sp[4] == 0.0 and np.isnan(sp[10])
    assert sp[5] == pytest.approx(0.2, abs=1e-6) and sp[6] == pytest.approx(0.2, abs=1e-6)
