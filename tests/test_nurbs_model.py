"""Reference values for the float64 NURBS model (``splinevis.nurbs``) and its operations.

References: splipy (an independent B-spline library), ``scipy.interpolate.NdBSpline`` (tensor-product
B-splines; rational surfaces through their homogeneous components and the quotient rule
[PieglTiller1997, eq. (4.20)]), and surfaces whose geometry is known in closed form (sphere, torus,
cylinder, saddle [DoCarmo1976, sec. 3-3]).

Tolerances
----------
Evaluating ``A^(k,l) = sum_a sum_b N_a^(k)(u) N_b^(l)(v) Pw_ab`` in floating point commits an error of at
most ``gamma_m * sum |N_a^(k)| |N_b^(l)| |Pw_ab|`` with ``m`` a small multiple of ``p + q`` (the basis
recurrences and the double sum) [Higham2002, sec. 3.4]. We call ``C^(k,l) = sum |N^(k)| |N^(l)| |Pw|`` the
condition (for ``k = l = 0`` and a polynomial surface it is at most ``max |P|``, the model size). The
rational derivative ``S^(k,l) = (A^(k,l) - sum binom w^(i,j) S^(k-i,l-j)) / w`` propagates those errors as
``E^(k,l) = (C^(k,l) + sum binom |w^(i,j)| E^(k-i,l-j) + ...) / w``; both implementations commit errors of
that size, so the difference must stay below ``c * eps * E`` with ``c`` of order ``(p+q)^2 < 200``. We
test against ``1e-12 * E`` (``1e-12 / eps ~ 4500``): a real bug (a wrong knot, basis function or
quotient-rule term) shows up as an ``O(1) * E`` error.
"""

from math import comb

import numpy as np
import pytest
import splipy  # the test extra (`pip install .[test]`)
from scipy.interpolate import NdBSpline

from splinevis.nurbs import NurbsSurface
from splinevis.nurbs.basis import basis_funs, check_knots, ders_basis_funs, find_span
from splinevis.nurbs.exact import cylinder, saddle, sphere, torus
from splinevis.nurbs.operations import bezier_patches, elevate_degree, insert_knot, refine_knots


REL = 1e-12  # relative to the propagated error scale E (see the module docstring)
EPS = np.finfo(float).eps


# ----------------------------------------------------------------------------------------------------
# random surfaces
def random_knots(rng, p, n, clamped, max_mult=None):
    """A knot vector of degree p for n control points: interior knots with random multiplicities up to
    ``max_mult`` (default p, a C0 crease), clamped (ends p + 1 times) or unclamped (distinct end knots)."""
    max_mult = p if max_mult is None else max_mult
    inner_count = n - p - 1  # knots strictly inside the domain
    mults = []
    while sum(mults) < inner_count:
        mults.append(int(rng.integers(1, max_mult + 1)))
    if mults:
        mults[-1] -= sum(mults) - inner_count
    ends = 1 if clamped else p + 1  # distinct knots at either end (unclamped: u_0 < ... < u_p)
    vals = np.sort(rng.uniform(0.0, 1.0, len(mults) + 2 * ends))
    vals = vals[0] + np.cumsum(np.concatenate([[0.0], np.diff(vals) + 0.05]))  # knots >= 0.05 apart
    inner = np.repeat(vals[ends:ends + len(mults)], mults)
    if clamped:
        U = np.concatenate([[vals[0]] * (p + 1), inner, [vals[-1]] * (p + 1)])
    else:
        U = np.concatenate([vals[:ends], inner, vals[-ends:]])
    return check_knots(U, p, n)


def random_surface(rng, p, q, clamped=True, rational=False, max_mult=None):
    nu = p + 1 + int(rng.integers(0, 5))
    nv = q + 1 + int(rng.integers(0, 5))
    U = random_knots(rng, p, nu, clamped, max_mult)
    V = random_knots(rng, q, nv, clamped, max_mult)
    P = rng.uniform(-1.0, 1.0, (nu, nv, 3)) * np.array([3.0, 2.0, 1.0])
    W = rng.uniform(0.3, 3.0, (nu, nv)) if rational else None
    return NurbsSurface((p, q), (U, V), P, W, name="random")


def random_params(rng, s, m=40, gap=1e-8):
    """Parameters in the domain, at least ``gap`` away from every knot (derivatives at a crease are
    one-sided and libraries may pick different sides; splipy snaps parameters within 1e-10 to knots)."""
    (u0, u1), (v0, v1) = s.domain
    out = []
    for (a, b), K in (((u0, u1), s.knots[0]), ((v0, v1), s.knots[1])):
        t = rng.uniform(a, b, 4 * m)
        t = t[np.min(np.abs(t[:, None] - K[None, :]), axis=1) > gap][:m]
        out.append(t)
    return out[0], out[1]


def error_scale(s, u, v, order):
    """``E^(k,l)`` per point: the propagated condition of the (rational) derivatives (module docstring)."""
    (p, q), (U, V) = s.degree, s.knots
    Pw = np.abs(s.homogeneous())
    su, sv = find_span(p, U, u), find_span(q, V, v)
    Nu = np.abs(ders_basis_funs(su, u, p, order, U))
    Nv = np.abs(ders_basis_funs(sv, v, q, order, V))
    iu = su[:, None] - p + np.arange(p + 1)
    iv = sv[:, None] - q + np.arange(q + 1)
    net = Pw[iu[:, :, None], iv[:, None, :]]
    C = np.einsum("mka,mlb,mabc->mklc", Nu, Nv, net)  # conditions of the homogeneous components
    Cp, Cw = np.linalg.norm(C[..., :3], axis=-1), C[..., 3]
    w = np.abs(s._homogeneous_derivatives(u, v, order)[..., 3])
    S = np.linalg.norm(s.derivatives(u, v, order), axis=-1)
    # first-order propagation through S^(k,l) = (A^(k,l) - sum C(k,i) C(l,j) w^(i,j) S^(k-i,l-j)) / w:
    # an error eps C_w in w^(i,j) costs eps C_w |S^(k-i,l-j)|, an error E in S^(k-i,l-j) costs |w^(i,j)| E
    E = np.zeros_like(Cp)
    for k in range(order + 1):
        for l in range(order - k + 1):
            acc = Cp[:, k, l] + Cw[:, 0, 0] * S[:, k, l]
            for i in range(k + 1):
                for j in range(l + 1):
                    if i or j:
                        acc += comb(k, i) * comb(l, j) * (w[:, i, j] * E[:, k - i, l - j] + Cw[:, i, j] * S[:, k - i, l - j])
            E[:, k, l] = acc / w[:, 0, 0]
    return E


#: the largest error / E seen per check (printed by ``python tests/test_nurbs_model.py``)
MEASURED = {}


def assert_close(got, ref, scale, what):
    err = np.linalg.norm(got - ref, axis=-1)
    worst = float(np.max(err / scale))
    key = what.split(" p=")[0]
    MEASURED[key] = max(MEASURED.get(key, 0.0), worst)
    assert worst <= REL, f"{what}: error {worst:.3g} x the error scale E (limit {REL})"
    return worst


# ----------------------------------------------------------------------------------------------------
# (a) splipy
def to_splipy(s):
    (p, q), (U, V) = s.degree, s.knots
    b1, b2 = splipy.BSplineBasis(p + 1, U), splipy.BSplineBasis(q + 1, V)
    if s.weights is None:
        return splipy.Surface(b1, b2, s.control_points.copy(), raw=True)
    return splipy.Surface(b1, b2, s.homogeneous().copy(), rational=True, raw=True)


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("rational", [False, True])
def test_against_splipy(seed, rational):
    rng = np.random.default_rng(100 + seed)
    p, q = (int(d) for d in rng.integers(1, 8, 2))
    s = random_surface(rng, p, q, clamped=bool(seed % 2), rational=rational)
    ref = to_splipy(s)
    u, v = random_params(rng, s)
    order = 1 if rational else 2  # splipy's rational derivatives stop at first order (scipy covers order 2)
    D = s.derivatives(u, v, order)
    E = error_scale(s, u, v, order)
    assert_close(D[:, 0, 0], ref.evaluate(u, v, tensor=False), E[:, 0, 0], f"splipy rational={rational} S^(0,0)")
    assert np.abs(D[:, 0, 0] - ref.evaluate(u, v, tensor=False)).max() <= 1e-12 * np.abs(s.control_points).max()
    for k in range(order + 1):
        for l in range(order - k + 1):
            if k + l:
                r = ref.derivative(u, v, d=(k, l), tensor=False)
                assert_close(D[:, k, l], r, E[:, k, l], f"splipy rational={rational} S^({k},{l}) p={p} q={q}")


def test_splipy_normals_of_a_rational_surface():
    rng = np.random.default_rng(7)
    s = random_surface(rng, 3, 2, rational=True)
    u, v = random_params(rng, s)
    n_ref = to_splipy(s).normal(u, v, tensor=False)
    # unit normals: the error of S_u x S_v relative to |S_u| |S_v|, amplified by 1 / sin(angle(S_u, S_v))
    D = s.derivatives(u, v, 1)
    E = error_scale(s, u, v, 1)
    sin = np.linalg.norm(np.cross(D[:, 1, 0], D[:, 0, 1]), axis=-1) / (
        np.linalg.norm(D[:, 1, 0], axis=-1) * np.linalg.norm(D[:, 0, 1], axis=-1))
    cond = (E[:, 1, 0] / np.linalg.norm(D[:, 1, 0], axis=-1) + E[:, 0, 1] / np.linalg.norm(D[:, 0, 1], axis=-1)) / sin
    assert_close(s.normal(u, v), n_ref, cond, "splipy rational normal")


# ----------------------------------------------------------------------------------------------------
# (b) scipy NdBSpline
def scipy_derivatives(s, u, v, order):
    """Rational derivatives from NdBSpline derivatives of the homogeneous components and the quotient
    rule ``S^(k,l) = (A^(k,l) - sum_{(i,j) != 0} C(k,i) C(l,j) w^(i,j) S^(k-i,l-j)) / w``."""
    (p, q), (U, V) = s.degree, s.knots
    spl = NdBSpline((U, V), s.homogeneous(), (p, q))
    x = np.column_stack([u, v])
    Aw = {(k, l): spl(x, nu=(k, l)) for k in range(order + 1) for l in range(order + 1 - k)}
    S = {}
    for k in range(order + 1):
        for l in range(order + 1 - k):
            val = Aw[k, l][:, :3].copy()
            for i in range(k + 1):
                for j in range(l + 1):
                    if i or j:
                        val -= comb(k, i) * comb(l, j) * Aw[i, j][:, 3:] * S[k - i, l - j]
            S[k, l] = val / Aw[0, 0][:, 3:]
    return S


@pytest.mark.parametrize("seed", range(40))
def test_against_scipy_ndbspline(seed):
    """Random degrees 1..7 per direction, clamped and unclamped knots, interior knots up to multiplicity
    p (C0 creases), polynomial and rational, derivatives up to order 2."""
    rng = np.random.default_rng(seed)
    p, q = (int(d) for d in rng.integers(1, 8, 2))
    clamped, rational = bool(seed % 2), bool((seed // 2) % 2)
    s = random_surface(rng, p, q, clamped=clamped, rational=rational)
    u, v = random_params(rng, s, gap=1e-12)
    D = s.derivatives(u, v, 2)
    E = error_scale(s, u, v, 2)
    if not rational:  # the control points are the coefficients
        spl = NdBSpline(s.knots, s.control_points, s.degree)
        x = np.column_stack([u, v])
        for k, l in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            assert_close(D[:, k, l], spl(x, nu=(k, l)), E[:, k, l], f"scipy coefficients S^({k},{l}) p={p} q={q}")
    ref = scipy_derivatives(s, u, v, 2)
    assert np.abs(D[:, 0, 0] - ref[0, 0]).max() <= 1e-12 * np.abs(s.control_points).max()  # and the model size
    for (k, l), r in ref.items():
        assert_close(D[:, k, l], r, E[:, k, l], f"scipy homogeneous rational={rational} S^({k},{l}) p={p} q={q}")


@pytest.mark.parametrize("seed", range(8))
def test_points_at_knots_and_domain_ends(seed):
    """Exactly at knots (creases included) and at the domain corners the surface is continuous: both
    libraries must agree there, whichever side they evaluate from."""
    rng = np.random.default_rng(50 + seed)
    p, q = (int(d) for d in rng.integers(1, 8, 2))
    s = random_surface(rng, p, q, clamped=bool(seed % 2), rational=True)
    (u0, u1), (v0, v1) = s.domain
    ku = np.unique(s.knots[0][(s.knots[0] >= u0) & (s.knots[0] <= u1)])
    kv = np.unique(s.knots[1][(s.knots[1] >= v0) & (s.knots[1] <= v1)])
    uu, vv = (a.ravel() for a in np.meshgrid(ku, kv, indexing="ij"))
    E = error_scale(s, uu, vv, 0)
    assert_close(s.evaluate(uu, vv), scipy_derivatives(s, uu, vv, 0)[0, 0], E[:, 0, 0], "scipy points at knots")


# ----------------------------------------------------------------------------------------------------
# (c) exact surfaces
def gauss_area(s, n):
    """Area by n x n Gauss-Legendre points per knot rectangle (the integrand |S_u x S_v| is smooth
    inside each rectangle, not across a double knot)."""
    x, w = np.polynomial.legendre.leggauss(n)
    total = 0.0
    bu, bv = np.unique(s.knots[0]), np.unique(s.knots[1])
    for a, b in zip(bu[:-1], bu[1:]):
        for c, d in zip(bv[:-1], bv[1:]):
            uu = 0.5 * (a + b) + 0.5 * (b - a) * x
            vv = 0.5 * (c + d) + 0.5 * (d - c) * x
            U, V = np.meshgrid(uu, vv, indexing="ij")
            D = s.derivatives(U.ravel(), V.ravel(), 1)
            J = np.linalg.norm(np.cross(D[:, 1, 0], D[:, 0, 1]), axis=-1).reshape(n, n)
            total += 0.25 * (b - a) * (d - c) * np.einsum("i,j,ij->", w, w, J)
    return total


@pytest.mark.parametrize("surface,exact", [(sphere(1.7), 4 * np.pi * 1.7**2),
                                           (torus(2.0, 0.5), 4 * np.pi**2 * 2.0 * 0.5),
                                           (cylinder(1.5, 2.0), 2 * np.pi * 1.5 * 2.0)])
def test_area_by_gauss_legendre(surface, exact):
    """The integrand is the square root of a rational function: no rule integrates it exactly, so check
    convergence: the 24- and 32-point rules agree to 1e-14 (the rounding of the sum; the 12-point rule
    is already there), so the quadrature error of the 32-point rule is far below the 1e-12 tested
    against the closed form."""
    a24, a32 = gauss_area(surface, 24), gauss_area(surface, 32)
    assert abs(a32 - a24) <= 1e-14 * exact
    assert abs(a32 - exact) <= 1e-12 * exact


def test_sphere_curvature_normals_and_poles():
    r, c = 1.7, np.array([0.3, -0.2, 0.5])
    s = sphere(r, c)
    rng = np.random.default_rng(3)
    u = rng.uniform(0, 1, 400)
    v = np.concatenate([rng.uniform(0, 1, 380), 10.0 ** -rng.uniform(2, 6, 10), 1 - 10.0 ** -rng.uniform(2, 6, 10)])
    X = s.evaluate(u, v)
    assert np.abs(np.linalg.norm(X - c, axis=1) - r).max() <= 8 * EPS * r
    n = s.normal(u, v)
    outward = (X - c) / r
    # the normal's error: eps * cond(S_u) / |S_u| with |S_u| ~ r sin(theta); sin(theta) = rho / r
    sin = np.linalg.norm((X - c)[:, :2], axis=1) / r
    assert np.max(np.linalg.norm(n - outward, axis=1) * sin) <= 1e-13
    # K and H divide by EG - F^2 ~ sin^2: the relative error grows like eps / sin^2 (first and second
    # fundamental forms both lose a factor 1 / sin of relative accuracy near the poles)
    cv = s.curvature(u, v)
    assert np.max(np.abs(cv["K"] * r * r - 1) * sin**2) <= 1e-12
    assert np.max(np.abs(cv["H"] * r + 1) * sin**2) <= 1e-12  # outward normal: H = -1/r
    # k1 = H + sqrt(H^2 - K) with H^2 - K = 0 exactly: the two bounds above give |H^2 - K| r^2 <= 3e-12 / sin^2,
    # so the square root costs half the digits: |k1 r + 1| <= (1e-12 + sqrt(3e-12)) / sin
    assert np.max(np.abs(cv["k1"] * r + 1) * sin) <= 1e-12 + np.sqrt(3e-12)
    # the poles themselves: S_u = 0 there; the limit normal is -z at the south pole, +z at the north pole
    up = s.normal(np.linspace(0, 1, 9), np.ones(9))
    down = s.normal(np.linspace(0, 1, 9), np.zeros(9))
    assert np.abs(up - [0, 0, 1]).max() <= 1e-14 and np.abs(down - [0, 0, -1]).max() <= 1e-14


def test_torus_curvature():
    R, r = 2.0, 0.5
    s = torus(R, r)
    rng = np.random.default_rng(4)
    u, v = rng.uniform(0, 1, 500), rng.uniform(0, 1, 500)
    X = s.evaluate(u, v)
    cphi = (np.linalg.norm(X[:, :2], axis=1) - R) / r
    cv = s.curvature(u, v)
    K = cphi / (r * (R + r * cphi))
    # K ranges over [-1/(r (R - r)), 1/(r (R + r))]; the absolute error is eps * (1/r^2) * small condition
    assert np.abs(cv["K"] - K).max() <= 1e-12 / r**2
    H = (R + 2 * r * cphi) / (2 * r * (R + r * cphi))
    assert np.abs(np.abs(cv["H"]) - H).max() <= 1e-12 / r
    assert np.abs((np.linalg.norm(X[:, :2], axis=1) - R) ** 2 + X[:, 2] ** 2 - r * r).max() <= 16 * EPS * (R + r) ** 2


def test_cylinder_curvature():
    r = 1.5
    s = cylinder(r, 2.0)
    rng = np.random.default_rng(5)
    u, v = rng.uniform(0, 1, 300), rng.uniform(0, 1, 300)
    cv = s.curvature(u, v)
    assert np.abs(cv["K"]).max() <= 1e-12 / r**2
    assert np.abs(np.abs(cv["H"]) - 1 / (2 * r)).max() <= 1e-12 / r
    assert np.abs(cv["k2"] if cv["H"][0] > 0 else cv["k1"]).max() <= 1e-12 / r  # one principal curvature 0


def test_saddle_curvature():
    a = 1.3
    s = saddle(a)
    rng = np.random.default_rng(6)
    u, v = rng.uniform(0, 1, 300), rng.uniform(0, 1, 300)
    x, y = a * (2 * u - 1), a * (2 * v - 1)
    X = s.evaluate(u, v)
    assert np.abs(X - np.column_stack([x, y, x * x - y * y])).max() <= 8 * EPS * a * a
    cv = s.curvature(u, v)
    g = 1 + 4 * x * x + 4 * y * y
    assert np.abs(cv["K"] + 4 / g**2).max() <= 1e-12 * 4
    # the normal S_u x S_v ~ (-2x, 2y, 1) points up: H = 4 (y^2 - x^2) / g^(3/2)
    assert np.abs(cv["H"] - 4 * (y * y - x * x) / g**1.5).max() <= 1e-12 * 2


# ----------------------------------------------------------------------------------------------------
# (d) the book's examples and error messages
def test_book_examples_2_3_and_2_4():
    U = np.array([0, 0, 0, 1, 2, 3, 4, 4, 5, 5, 5.0])
    assert find_span(2, U, [2.5]).tolist() == [4]
    assert basis_funs([4], [2.5], 2, U).tolist() == [[0.125, 0.75, 0.125]]
    d = ders_basis_funs([4], [2.5], 2, 2, U)[0]
    assert d.tolist() == [[0.125, 0.75, 0.125], [-0.5, 0.0, 0.5], [1.0, -2.0, 1.0]]
    # the same against splipy's basis (all 8 functions; the non-zero ones are N_2, N_3, N_4)
    ref = splipy.BSplineBasis(3, U)
    for k in range(3):
        assert np.abs(ref.evaluate([2.5], d=k)[0, 2:5] - d[k]).max() <= 4 * EPS


@pytest.mark.parametrize("kwargs,message", [
    (dict(weights=[[1, 1], [1, 0]]), r"weights\[1, 1\] = 0\.0 .*fix the model"),
    (dict(weights=[[1, -2], [1, 1]]), r"weights\[0, 1\] = -2\.0"),
    (dict(weights=[[1, 1, 1], [1, 1, 1]]), r"weights must have shape \(2, 2\)"),
    (dict(knots=([0, 0, 1, 0.5], [0, 0, 1, 1])), r"knots\[0\] \(u\) must be non-decreasing; knots\[0\] \(u\)\[3\] = 0\.5"),
    (dict(knots=([0, 0, 1, 1, 1], [0, 0, 1, 1])), r"must have 4 entries \(n \+ p \+ 2\), got 5"),
    (dict(control_points=np.zeros((2, 2, 2))), r"control_points must have shape \(nu, nv, 3\)"),
    (dict(degree=(26, 1)), r"degree must be an integer in 1\.\.25, got 26"),
])
def test_error_messages(kwargs, message):
    args = dict(degree=(1, 1), knots=([0, 0, 1, 1], [0, 0, 1, 1]), control_points=np.zeros((2, 2, 3)))
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        NurbsSurface(**args)


def test_parameter_outside_the_domain():
    s = torus()
    with pytest.raises(ValueError, match=r"parameter 1\.5 is outside the knot domain \[0\.0, 1\.0\]; clamp or rescale"):
        s.evaluate([0.5], [1.5])
    with pytest.raises(ValueError, match=r"parameter nan is outside"):
        s.evaluate([np.nan], [0.5])
    with pytest.raises(ValueError, match="same number of parameters"):
        s.evaluate([0.1, 0.2], [0.5])


# ----------------------------------------------------------------------------------------------------
# (e) operations
def assert_same_geometry(a, b, rng, label, order=2, m=60):
    """``b`` represents ``a``: points and derivatives agree at random parameters (not at knots, where
    creases make derivatives one-sided)."""
    assert a.domain == b.domain
    u, v = random_params(rng, a, m)
    u2, v2 = random_params(rng, b, m)
    u, v = np.concatenate([u, u2]), np.concatenate([v, v2])
    Da, Db = a.derivatives(u, v, order), b.derivatives(u, v, order)
    # both sides commit rounding errors of the size of their own error scale; the operations themselves
    # are convex combinations (insertion, blossoms) adding a few eps * C each
    E = np.maximum(error_scale(a, u, v, order), error_scale(b, u, v, order))
    worst = 0.0
    for k in range(order + 1):
        for l in range(order + 1 - k):
            worst = max(worst, assert_close(Db[:, k, l], Da[:, k, l], E[:, k, l], f"{label} S^({k},{l})"))
    return worst


@pytest.mark.parametrize("seed", range(16))
def test_insert_and_refine_keep_the_surface(seed):
    rng = np.random.default_rng(200 + seed)
    p, q = (int(d) for d in rng.integers(1, 8, 2))
    s = random_surface(rng, p, q, clamped=bool(seed % 2), rational=bool((seed // 2) % 2))
    (u0, u1), (v0, v1) = s.domain
    a = insert_knot(s, "u", float(rng.uniform(u0, u1)), int(rng.integers(1, p + 1)))
    assert a.shape[0] > s.shape[0] and a.shape[1] == s.shape[1]
    assert_same_geometry(s, a, rng, "insert_knot")
    knots = rng.uniform(v0, v1, 3)
    b = refine_knots(s, 1, np.concatenate([knots, knots[:1]]) if q > 1 else knots)
    assert b.shape[1] == s.shape[1] + (4 if q > 1 else 3)
    assert_same_geometry(s, b, rng, "refine_knots")
    # inserting at an existing interior knot up to the degree, and at the domain's ends
    inner = [x for x in np.unique(s.knots[0]) if u0 < x < u1]
    if inner:
        x = inner[0]
        left = p - int(np.count_nonzero(s.knots[0] == x))
        c = insert_knot(s, "u", x, left)
        assert int(np.count_nonzero(c.knots[0] == x)) == p
        assert_same_geometry(s, c, rng, "insert_knot to multiplicity p")
        with pytest.raises(ValueError, match=r"insert it at most 0 more time"):
            insert_knot(c, "u", x)


def test_insert_knot_errors_and_splipy_agreement():
    s = torus()
    with pytest.raises(ValueError, match=r"knot 0\.5 has multiplicity 2 .* insert it at most 0 more time"):
        insert_knot(s, "u", 0.5)
    with pytest.raises(ValueError, match=r"knot 1\.2 is outside the knots\[1\] \(v\) domain \[0\.0, 1\.0\]"):
        insert_knot(s, "v", 1.2)
    with pytest.raises(ValueError, match=r"direction must be 'u' \(0\) or 'v' \(1\), got 'w'"):
        insert_knot(s, "w", 0.5)
    assert insert_knot(s, "u", 0.3, 0).shape == s.shape  # zero insertions: an unchanged copy
    # the same control points as splipy's knot insertion (a representation is unique for its knots)
    ins = insert_knot(insert_knot(s, "u", 0.1), "v", 0.6)
    ref = to_splipy(s)
    ref.insert_knot(0.1, 0)
    ref.insert_knot(0.6, 1)
    assert np.abs(ins.homogeneous() - ref.controlpoints).max() <= 8 * EPS * 2.5


@pytest.mark.parametrize("seed", range(16))
def test_elevate_degree_keeps_the_surface(seed):
    rng = np.random.default_rng(300 + seed)
    p, q = (int(d) for d in rng.integers(1, 6, 2))
    s = random_surface(rng, p, q, clamped=bool(seed % 2), rational=bool((seed // 2) % 2))
    times = int(rng.integers(1, 8 - p))
    e = elevate_degree(s, "u", times)
    assert e.degree == (p + times, q)
    # continuity kept: every interior knot's multiplicity grows by exactly `times`
    (u0, u1), _ = s.domain
    for x in np.unique(s.knots[0]):
        if u0 < x < u1:
            assert np.count_nonzero(e.knots[0] == x) == np.count_nonzero(s.knots[0] == x) + times
    assert_same_geometry(s, e, rng, "elevate_degree u")
    assert_same_geometry(s, elevate_degree(s, "v", 1), rng, "elevate_degree v")


def test_elevate_degree_matches_splipy_and_limits():
    s = random_surface(np.random.default_rng(9), 3, 2, clamped=True, rational=True)
    e = elevate_degree(elevate_degree(s, "u", 1), "v", 2)
    ref = to_splipy(s)
    ref.raise_order(1, 2)
    assert np.array_equal(e.knots[0], ref.knots(0, with_multiplicities=True))
    scale = np.abs(s.homogeneous()).max()
    assert np.abs(e.homogeneous() - ref.controlpoints).max() <= 1e-13 * scale
    with pytest.raises(ValueError, match=r"cannot elevate degree 3 by 23: the degree must stay in 1\.\.25"):
        elevate_degree(s, "u", 23)
    assert elevate_degree(s, "u", 0) is s


def test_bezier_patches_of_the_torus():
    s = torus()
    patches = bezier_patches(s)
    assert len(patches) == 16
    rng = np.random.default_rng(10)
    for patch, ((u0, u1), (v0, v1)) in patches:
        assert patch.degree == (2, 2) and patch.shape == (3, 3) and patch.rational
        assert patch.domain == ((u0, u1), (v0, v1))
        u, v = rng.uniform(u0, u1, 30), rng.uniform(v0, v1, 30)
        E = error_scale(s, u, v, 2)
        Da, Db = s.derivatives(u, v, 2), patch.derivatives(u, v, 2)
        for k, l in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            assert_close(Db[:, k, l], Da[:, k, l], E[:, k, l], f"torus patch S^({k},{l})")
    rects = [r for _, r in patches]
    assert sum((b - a) * (d - c) for (a, b), (c, d) in rects) == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("seed", range(12))
def test_bezier_patches_of_random_surfaces(seed):
    rng = np.random.default_rng(400 + seed)
    p, q = (int(d) for d in rng.integers(1, 8, 2))
    s = random_surface(rng, p, q, clamped=bool(seed % 2), rational=bool((seed // 2) % 2))
    patches = bezier_patches(s)
    (u0, u1), (v0, v1) = s.domain
    spans_u = np.unique(s.knots[0][(s.knots[0] >= u0) & (s.knots[0] <= u1)])
    spans_v = np.unique(s.knots[1][(s.knots[1] >= v0) & (s.knots[1] <= v1)])
    assert len(patches) == (spans_u.size - 1) * (spans_v.size - 1)
    for patch, ((a, b), (c, d)) in patches:
        assert patch.shape == (p + 1, q + 1)
        u, v = rng.uniform(a, b, 12), rng.uniform(c, d, 12)
        E = error_scale(s, u, v, 2)
        Da, Db = s.derivatives(u, v, 2), patch.derivatives(u, v, 2)
        for k, l in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            assert_close(Db[:, k, l], Da[:, k, l], E[:, k, l], f"bezier_patches S^({k},{l})")


if __name__ == "__main__":  # the measured errors (x E) of every check, for the record
    import sys

    code = pytest.main([__file__, "-q", "-p", "no:cacheprovider"])
    run = [m for n, m in sys.modules.items() if n.endswith("test_nurbs_model") and n != "__main__"]
    for key, value in sorted(run[0].MEASURED.items()):
        print(f"{key:36s} {value:.3g}")
    sys.exit(code)
