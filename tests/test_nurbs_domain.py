"""Parameters never leave the knot domain (issue: real CAD files crashed ``add_nurbs`` with "parameter
15.000000000000004 is outside the knot domain [..., 15.000000000000002]").

``lo + t (hi - lo)`` rounds past ``hi`` when ``lo`` and ``hi`` differ in magnitude (the STEP file's
``[-54.0036550378855, -1.2874806216379383e-32]`` gives ``0.0`` at ``t = 1``) or by one rounding step on symmetric
domains (the Rhino file's ``[-2.123162437099668, 2.1231624370996682]``). Every path from a domain to parameters
goes through :func:`splinevis.nurbs.basis.at_fraction` (or ``into_domain`` for computed parameters); these
tests drive the paths that raised (the ray caster's proxy and certified bound, closed-edge detection,
curvature samples, tessellation, seams, pull-back) on such domains, and random ones.
"""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from splinevis.nurbs.basis import at_fraction, find_span, into_domain
from splinevis.nurbs.model import NurbsModel
from splinevis.nurbs.surface import NurbsSurface

# the domains of the real files that crashed (STEP, IGES, Rhino v1), and the examples
REAL_DOMAINS = [(-54.0036550378855, -1.2874806216379383e-32), (-6.589091811, 1.421085e-14),
                (-2.123162437099668, 2.1231624370996682), (-7.3, 15.000000000000002), (1e-9, 1e9)]


def _knots(lo, hi, p, inner, end_multiplicity):
    """A knot vector of degree p on [lo, hi]: ends repeated ``end_multiplicity`` times (p + 1: clamped), the
    inner knots at fractions ``inner`` (formed with at_fraction, so the vector is non-decreasing)."""
    pad = p + 1 - end_multiplicity  # unclamped: knots outside the domain, spaced like the first span
    k = np.sort(at_fraction(lo, hi, np.asarray(inner, dtype=np.float64)))
    step = (hi - lo) / (len(inner) + 1)
    left = lo - step * np.arange(pad, 0, -1)
    right = hi + step * np.arange(1, pad + 1)
    return np.concatenate([left, [lo] * end_multiplicity, k, [hi] * end_multiplicity, right])


def _surface(du, dv, p=3, q=2, inner=(0.25, 0.5), end_multiplicity=None, rational=True):
    U = _knots(*du, p, inner, end_multiplicity or p + 1)
    V = _knots(*dv, q, inner, end_multiplicity or q + 1)
    nu, nv = len(U) - p - 1, len(V) - q - 1
    rng = np.random.default_rng(7)
    g = np.stack(np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="ij"), axis=-1)
    P = np.concatenate([g, 0.2 * rng.standard_normal((nu, nv, 1))], axis=-1)
    W = 0.5 + rng.random((nu, nv)) if rational else None
    return NurbsSurface((p, q), (U, V), P, W, name="patch")


def test_the_plain_formula_leaves_the_domain_and_at_fraction_does_not():
    lo, hi = REAL_DOMAINS[0]
    assert lo + 1.0 * (hi - lo) > hi  # the rounding the files hit
    with pytest.raises(ValueError, match="outside the knot domain"):
        find_span(3, np.r_[[lo] * 4, [hi] * 4], [lo + 1.0 * (hi - lo)])
    assert at_fraction(lo, hi, [0.0, 1.0]).tolist() == [lo, hi]


@pytest.mark.parametrize("domain", REAL_DOMAINS, ids=lambda d: f"[{d[0]!r}, {d[1]!r}]")
def test_every_path_from_a_domain_to_parameters_stays_inside(domain):
    """Failed before the helper with "parameter ... is outside the knot domain" (the Rhino and STEP domains)."""
    from splinevis.nurbs import continuity, shell, tessellate
    from splinevis.nurbs.pullback import _Inverter

    s = _surface(domain, domain)
    model = NurbsModel([s], source="domain test")
    c = model.curvature_samples(9)
    assert np.isfinite(c["K"]).all() and c["K"].size == 81
    us, vs = tessellate.span_grid(s, 4)
    assert us[0] == domain[0] and us[-1] == domain[1] and (np.diff(us) >= 0).all()
    assert vs[0] == domain[0] and vs[-1] == domain[1] and (np.diff(vs) >= 0).all()
    bound = shell.certified_deviation(s, us, vs)
    assert np.isfinite(bound).all() and (bound >= 0).all()
    assert shell._closed(s, 0) in (True, False) and shell._closed(s, 1) in (True, False)
    proxy = shell.tessellate(model, subdivisions=2)
    assert proxy is not None
    assert continuity.find_seams([s]) is not None
    foot = _Inverter(s)
    inside = foot.wrap(np.array([[domain[1] + 1e-300, domain[0]], [domain[0], domain[1]]]))
    assert (inside >= domain[0]).all() and (inside <= domain[1]).all()


@settings(max_examples=60, deadline=None)
@given(lo=st.floats(-1e9, 1e9, allow_nan=False, allow_infinity=False),
       width=st.floats(1e-9, 2e9, allow_nan=False, allow_infinity=False),
       t=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=20))
def test_at_fraction_is_inside_monotone_and_exact_at_the_ends(lo, width, t):
    hi = lo + width
    if not hi > lo:
        return
    t = np.sort(np.r_[0.0, t, 1.0])
    u = at_fraction(lo, hi, t)
    assert u[0] == lo and u[-1] == hi
    assert (u >= lo).all() and (u <= hi).all()
    assert (np.diff(u) >= 0).all()  # rounding may merge neighbours, never reorder them
    # within one rounding of the exact affine value (|lo| + |t (hi - lo)| ulps of the operands)
    exact = lo + t * (hi - lo)
    assert np.all(np.abs(u - exact) <= 4 * np.finfo(float).eps * (abs(lo) + np.abs(t) * (hi - lo)))


@settings(max_examples=25, deadline=None)
@given(domain=st.sampled_from(REAL_DOMAINS) | st.tuples(st.floats(-1e9, 1e9), st.floats(1e-9, 1e9)).map(
           lambda a: (a[0], a[0] + a[1])),
       p=st.integers(1, 4), end_multiplicity=st.integers(1, 5))
@example(domain=(268435456.0, 268435456.0000001), p=1, end_multiplicity=2)  # a random draw that failed once
def test_random_knot_vectors_with_repeated_or_open_ends(domain, p, end_multiplicity):
    """Clamped (end knots repeated p + 1 times) and unclamped vectors: the domain is [U_p, U_{n+1}] either way,
    and every sampled parameter evaluates."""
    lo, hi = domain
    if not hi > lo or not np.isfinite(hi):
        return
    m = min(end_multiplicity, p + 1)
    U = _knots(lo, hi, p, (0.25, 0.5), m)
    if np.unique(U, return_counts=True)[1].max() > p + 1:
        # a domain a few ulps wide (e.g. 1e-7 at 2.7e8): the inner knots round onto its ends, a multiplicity
        # no knot vector may have; the reader's constructor must say so, not evaluate garbage
        with pytest.raises(ValueError, match="multiplicity"):
            _surface((lo, hi), (lo, hi), p=p, q=p, end_multiplicity=m, rational=False)
        return
    s = _surface((lo, hi), (lo, hi), p=p, q=p, end_multiplicity=m, rational=False)
    (u0, u1), (v0, v1) = s.domain
    from splinevis.nurbs import tessellate

    us, vs = tessellate.span_grid(s, 3)
    assert us[0] >= u0 and us[-1] <= u1 and vs[0] >= v0 and vs[-1] <= v1
    U, V = np.meshgrid(us, vs)
    assert np.isfinite(s.evaluate(U.ravel(), V.ravel())).all()
    c = NurbsModel([s]).curvature_samples(5)
    assert c["K"].size == 25


def test_into_domain_clamps_rounding_and_refuses_nan():
    assert into_domain([15.000000000000004], -7.3, 15.000000000000002).tolist() == [15.000000000000002]
    with pytest.raises(ValueError, match="NaN"):
        into_domain([np.nan], 0.0, 1.0)
