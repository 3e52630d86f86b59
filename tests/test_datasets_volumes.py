"""datasets_synthetic.volumes: exact gradients, exact ray hits, sampling layout, quantisation, noise."""

import doctest

import numpy as np
import pytest

import datasets_synthetic.volumes as volumes_module
from datasets_synthetic.volumes import (
    blob,
    constant,
    marschner_lobb,
    plateau,
    sphere_distance,
    thin_sheet,
    torus_distance,
)

EPS = np.finfo(np.float64).eps

# (field, bound on |third derivatives| over the box): the central-difference error of a derivative is at most
# h^2 / 6 * M3 (truncation) + eps * max|f| / h (rounding of the two values) + eps * |p| * max|f'| / h
# (p +- h is rounded, so the step actually taken differs from 2h).
FIELDS = [
    # Marschner-Lobb: the radial term oscillates at up to 2 pi f_M * pi / 2 ~ 59.2 rad per unit, amplitude
    # alpha / (2 (1 + alpha)) = 0.1: M3 <= 0.1 * 59.2^3 * (a few, chain rule) < 1e5
    (marschner_lobb(), 1e5),
    (sphere_distance(0.7, (0.1, -0.05, 0.02)), 1e3),  # ~ 3 / |p - c|^2 away from the centre (excluded < 0.1)
    (torus_distance(0.6, 0.25), 1e4),  # ~ 3 / dist^2 away from the core circle and the axis (excluded < 0.1)
    (blob(), 4 * 15 / 0.3 ** 3),  # Gaussians: |f'''| <= w * ~15 / sigma^3 each
    (thin_sheet(), 20 / (2 / 63 / 2.3548) ** 3),  # sigma ~ 0.0135: |f'''| <= ~2 / sigma^3 (scale up for safety)
    (plateau(), 0.0),  # piecewise quadratic in |p|: exact derivative of x^2 pieces, points near the kinks excluded
    (constant(3.0), 0.0),
]


def test_docstring_examples_run():
    result = doctest.testmod(volumes_module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def _away_from_singularities(field, p):
    if field.name == "sphere_distance":
        return np.linalg.norm(p - field.center, axis=1) > 0.1
    if field.name == "torus_distance":
        rho = np.hypot(p[:, 0], p[:, 1])
        return (np.hypot(rho - field.R, p[:, 2]) > 0.1) & (rho > 0.1)
    if field.name == "plateau":
        u = np.abs(np.linalg.norm(p, axis=1) - 0.5)
        return (np.abs(u - 0.15) > 1e-3) & (np.linalg.norm(p, axis=1) > 0.1)
    if field.name == "thin_sheet":
        return np.ones(len(p), bool)
    return np.ones(len(p), bool)


@pytest.mark.parametrize("field, m3", FIELDS, ids=[f.name for f, _ in FIELDS])
def test_gradient_matches_central_differences_within_the_error_bound(field, m3):
    rng = np.random.default_rng(3)
    b = np.asarray(field.bounds).reshape(3, 2)
    p = b[:, 0] + rng.random((400, 3)) * (b[:, 1] - b[:, 0])
    if field.name == "thin_sheet":  # put half of the points inside the thin ridge, where the gradient is large
        s = p @ field.plane_normal - field.offset
        p[:200] -= (s[:200] - rng.normal(0, field.sigma, 200))[:, None] * field.plane_normal
    p = p[_away_from_singularities(field, p)]
    h = 1e-5
    fmax = np.abs(field.value(p)).max() + 1.0
    g = field.gradient(p)
    tol = h * h / 6 * m3 + 4 * EPS * fmax / h + 4 * EPS * np.abs(p).max() * np.abs(g).max() / h
    assert g.shape == p.shape
    for a in range(3):
        e = np.zeros(3)
        e[a] = h
        num = (field.value(p + e) - field.value(p - e)) / (2 * h)
        assert np.abs(num - g[:, a]).max() <= tol, (field.name, a, np.abs(num - g[:, a]).max(), tol)


def test_marschner_lobb_formula_and_gradient_on_the_axis():
    f = marschner_lobb()
    x, y, z = 0.3, -0.4, 0.2
    r = 0.5
    expect = (1 - np.sin(np.pi * z / 2) + 0.25 * (1 + np.cos(2 * np.pi * 6 * np.cos(np.pi * r / 2)))) / 2.5
    assert f.value([x, y, z]) == pytest.approx(expect, rel=1e-15)
    assert f.isovalue == 0.5 and f.bounds == (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)
    g = f.gradient([[0.0, 0.0, 0.3]])
    assert np.isfinite(g).all() and abs(g[0, 0]) < 1e-12 and abs(g[0, 1]) < 1e-12


@pytest.mark.parametrize("field", [sphere_distance(0.7, (0.1, -0.05, 0.02)), torus_distance(0.6, 0.25), thin_sheet()],
                         ids=["sphere", "torus", "sheet"])
def test_ray_hit_lands_on_the_isosurface_and_is_the_first_crossing(field):
    rng = np.random.default_rng(7)
    n = 2000
    o = rng.normal(size=(n, 3))
    o = 3.0 * o / np.linalg.norm(o, axis=1, keepdims=True)  # cameras on a sphere of radius 3
    target = rng.uniform(-0.8, 0.8, size=(n, 3))
    d = (target - o) * rng.uniform(0.5, 2.0, size=(n, 1))  # non-unit directions
    t = field.ray_hit(o, d)
    hit = np.isfinite(t)
    assert 0.2 * n < hit.sum() < n
    p = o[hit] + t[hit, None] * d[hit]
    # the value at the hit is the level to rounding: |p| ~ 1, so a few ulps of 1
    assert np.abs(field.value(p) - field.isovalue).max() <= 64 * EPS * (1 + (field.name == "thin_sheet") * 16)
    # first crossing inside the box (crossings outside it are clipped away): the field does not cross the
    # level on a fine march through the box before t
    for k in np.flatnonzero(hit)[:200]:
        s = np.linspace(0, t[k], 400)[:-1]
        pts = o[k] + s[:, None] * d[k]
        pts = pts[np.all(np.abs(pts) <= 1.0, axis=1)]
        if not len(pts):
            continue
        v = field.value(pts) - field.isovalue
        assert np.all(np.sign(v) == np.sign(v[0])), (field.name, k)
    # misses really miss: the sign never changes along a fine march through the box
    for k in np.flatnonzero(~hit)[:100]:
        s = np.linspace(0, 2.0 * 3.0 / np.linalg.norm(d[k]) * 2, 4000)
        pts = o[k] + s[:, None] * d[k]
        pts = pts[np.all(np.abs(pts) <= 1.0, axis=1)]
        if len(pts):
            v = field.value(pts) - field.isovalue
            assert np.all(v > 0) or np.all(v < 0), (field.name, k)


def test_sphere_ray_hit_exact_cases_and_closest_point():
    f = sphere_distance(0.5)
    t = f.ray_hit([[-3.0, 0, 0], [0, 0, 0], [-3.0, 2.0, 0], [3.0, 0, 0]],
                  [[2.0, 0, 0], [0, 0, 1], [1, 0, 0], [1, 0, 0]])
    assert t[0] == 1.25 and t[1] == 0.5 and np.isnan(t[2]) and np.isnan(t[3])
    p = np.array([[0.3, 0.4, 1.2], [0.0, 0.0, 0.0]])
    c = f.closest_point(p)
    assert np.allclose(np.linalg.norm(c, axis=1), 0.5, rtol=0, atol=1e-15)
    assert np.allclose(c[0], p[0] / np.linalg.norm(p[0]) * 0.5, atol=1e-16)
    assert np.allclose(f.normal(p[:1]), p[:1] / np.linalg.norm(p[0]), atol=1e-15)


def test_torus_known_hits_normals_and_closest_point():
    f = torus_distance(0.6, 0.25)
    # along the x axis from -3: outer wall at x = -0.85
    t = f.ray_hit([[-3.0, 0.0, 0.0], [0.0, 0.0, 3.0], [-3.0, 0.0, 0.5]], [[1.0, 0, 0], [0, 0, -1], [1.0, 0, 0]])
    assert t[0] == pytest.approx(3.0 - 0.85, abs=1e-14) and np.isnan(t[1]) and np.isnan(t[2])
    n = f.normal([[-0.85, 0.0, 0.0], [0.6, 0.0, 0.25]])
    assert np.allclose(n, [[-1.0, 0, 0], [0, 0, 1.0]], atol=1e-15)
    rng = np.random.default_rng(0)
    p = rng.uniform(-1, 1, (200, 3))
    c = f.closest_point(p)
    assert np.abs(f.value(c)).max() < 1e-15
    assert np.allclose(np.linalg.norm(p - c, axis=1), np.abs(f.value(p)), atol=1e-14)  # exact distance


def test_sample_layout_spacing_and_world_points():
    f = blob()
    g = f.sample((5, 4, 3))
    assert g.shape == (3, 4, 5) and g.spacing == (0.5, 2 / 3, 1.0) and g.origin == (-1.0, -1.0, -1.0)
    assert g.source == "synthetic:blob" and g.scalars == "blob" and g.dtype == "float64"
    for k, j, i in [(0, 0, 0), (2, 3, 4), (1, 2, 3)]:
        assert g.values[k, j, i] == f.value(g.to_world([i, j, k]))
    with pytest.raises(ValueError, match="at least 2 samples per axis"):
        f.sample(1)


def test_sample_quantised_records_scale_and_keeps_the_level_meaningful():
    f = sphere_distance()
    g = f.sample(17, dtype="uint8")
    slope, intercept = g.rescale
    codes = (g.values - intercept) / slope
    assert g.dtype == "uint8" and np.allclose(codes, np.rint(codes), atol=1e-9)
    assert np.rint(codes).min() == 0 and np.rint(codes).max() == 255
    exact = f.sample(17).values
    assert np.abs(g.values - exact).max() <= slope / 2 * (1 + 1e-9)
    g16 = f.sample(9, dtype="uint16", value_range=(-1.0, 1.0))
    assert g16.rescale == (2.0 / 65535, -1.0)
    with pytest.raises(ValueError, match="choose 'uint8' or 'uint16'"):
        f.sample(9, dtype="float32")


def test_sample_noise_is_seeded():
    f = marschner_lobb()
    a, b, c = f.sample(8, noise=0.01, seed=1), f.sample(8, noise=0.01, seed=1), f.sample(8, noise=0.01, seed=2)
    assert np.array_equal(a.values, b.values) and not np.array_equal(a.values, c.values)
    assert 0.005 < np.std(a.values - f.sample(8).values) < 0.02


def test_thin_sheet_is_about_one_voxel_thick_and_plateau_is_exactly_at_level():
    s = thin_sheet()
    g = s.sample(64)
    assert s.thickness == pytest.approx(g.spacing[0])
    mid = s.offset * s.plane_normal
    assert s.value(mid) == 1.0
    edge = mid + s.thickness / 2 * s.plane_normal
    assert s.value(edge) == pytest.approx(0.5, abs=1e-14)  # |grad f| ~ 44 there: a few ulps of position
    p = plateau()
    r = np.linspace(0.36, 0.64, 50)[:, None] * np.array([0.6, 0.0, 0.8])
    assert np.all(p.value(r) == 0.5) and np.all(p.gradient(r) == 0.0)
    assert p.value([0.0, 0.0, 0.0]) < 0.5 < p.value([0.9, 0.9, 0.0])
    c = constant(2.5)
    assert c.isovalue == 2.5 and np.all(c.sample(3).values == 2.5)
    with pytest.raises(NotImplementedError, match="sphere_distance, torus_distance and thin_sheet"):
        c.ray_hit([[0, 0, 0]], [[1, 0, 0]])


def test_blob_surface_is_one_component_inside_the_box():
    from scipy import ndimage

    f = blob()
    g = f.sample(48)
    inside = g.values > f.isovalue
    _, count = ndimage.label(inside)
    assert count == 1
    border = np.concatenate([g.values[[0, -1]].ravel(), g.values[:, [0, -1]].ravel(), g.values[..., [0, -1]].ravel()])
    assert border.max() < f.isovalue


def test_every_field_has_its_level_inside_the_value_range():
    for f in (marschner_lobb(), sphere_distance(), torus_distance(), blob(), thin_sheet(), plateau()):
        lo, hi = f.sample(32).value_range
        assert lo < f.isovalue < hi or f.name == "thin_sheet" and lo < f.isovalue <= hi, f.name
