"""Stripes filtered over the pixel (glsl/lib/effects/footprint.glsl): the GLSL average against its float64 twin
(splinevis.analysis.footprint) within the derived float32 bound, and a reflection-line pattern finer than a pixel
rendering to its mean grey (a moire without the filter)."""

from __future__ import annotations

import numpy as np
import pytest

from splinevis.analysis.footprint import MAX_WIDTH, MIN_WIDTH, float32_bound, mean_deviation_bound, stripe_bright
from splinevis.analysis.zebra import reflection_phase
from splinevis.gl.camera import pixel_rays
from splinevis.gl.harness import run_glsl
from splinevis.programs import program_for
from _sphere_scene import WINDOW, render, sphere

pytestmark = pytest.mark.gl


def _glsl_bright(x, w, antialias=True):
    rows = np.column_stack([x, w]).astype(np.float32)
    out = run_glsl('#include "lib/effects/footprint.glsl"\n', "sv_out[0] = sv_stripe_bright(sv_in[0], sv_in[1]);",
                   rows, 1, defines={"SV_ANTIALIAS": True} if antialias else None)
    return out[:, 0].astype(np.float64), rows.astype(np.float64)


def test_filtered_stripe_matches_the_float64_twin():
    rng = np.random.default_rng(7)
    m = 20000
    x = rng.uniform(-64, 64, m)
    w = 10.0 ** rng.uniform(-4, 4, m)
    x[:8] = [0.0, 0.5, 0.25, -0.5, 1.0, 0.75, 3.5, -2.25]      # edges and stripe middles
    w[:8] = [MIN_WIDTH, 1.0, 0.5, 2.0, 0.0, MAX_WIDTH, np.inf, 0.5]
    g, rows = _glsl_bright(x, w)
    xs, ws = rows[:, 0], rows[:, 1]
    twin = stripe_bright(xs, ws)
    filtered = (ws >= MIN_WIDTH) & (ws < MAX_WIDTH)
    # the derived bound of the float32 operations (splinevis.analysis.footprint.float32_bound)
    assert np.all(np.abs(g - twin)[filtered] <= float32_bound(ws[filtered]))
    assert np.array_equal(g[~filtered], twin[~filtered])  # the step (exact) and the mean (exact)
    assert g[1] == 0.5 and g[5] == 0.5 and g[6] == 0.5     # astride an edge; beyond MAX_WIDTH; not finite
    # without SV_ANTIALIAS the plain step whatever the footprint
    g0, _ = _glsl_bright(x, w, antialias=False)
    assert np.array_equal(g0, stripe_bright(xs, ws, antialias=False))


def test_box_average_is_within_a_quarter_over_w_of_the_mean():
    # m + r periods (0 <= r < 1) hold m/2 bright plus between max(0, r - 1/2) and min(r, 1/2): the average's
    # largest deviation from 1/2 is min(r, 1 - r) / (2 w) exactly, at most 1/(4 w) (r = 1/2)
    x = np.linspace(-3, 3, 60001)
    for w in (1.5, 2.0, 2.5, 4.0, 7.25):
        dev = np.abs(stripe_bright(x, w) - 0.5)
        r = w - np.floor(w)
        exact = min(r, 1 - r) / (2 * w)
        assert dev.max() <= mean_deviation_bound(w) + 1e-12
        assert abs(dev.max() - exact) <= 1e-4 / w + 1e-12  # the grid's step (1e-4) moves a box end by that


FINE = 400  # reflection-line pairs over a half turn: most of the sphere's pixels hold several


def _render(model, antialias):
    img, matrix = render(model, reflection_lines=FINE, antialias=antialias)
    return img[..., 0], matrix


def _twin_footprint(model, matrix):
    """The stripe coordinate's footprint per pixel from the float64 twin: |x(right) - x| + |x(below) - x| at
    pixel centres (the phase unwrapped), and whether the pixel and both neighbours hit the surface."""
    o, d = pixel_rays(matrix, *WINDOW)
    hits = program_for(model).raycast(model, o.reshape(-1, 3), d.reshape(-1, 3), 0.0)
    x = np.full(d.shape[:2], np.nan)
    x.ravel()[hits.hit] = reflection_phase(d.reshape(-1, 3)[hits.hit], hits.normals[hits.hit], (1, 0, 0)) * FINE
    dx = np.mod(x[:-1, 1:] - x[:-1, :-1] + FINE, 2 * FINE) - FINE
    dy = np.mod(x[1:, :-1] - x[:-1, :-1] + FINE, 2 * FINE) - FINE
    w = np.abs(dx) + np.abs(dy)
    return w, np.isfinite(w)


def test_stripes_finer_than_a_pixel_render_to_their_mean():
    model = sphere()
    filtered, matrix = _render(model, True)
    plain, _ = _render(model, False)
    w, ok = _twin_footprint(model, matrix)
    # pixels whose footprint holds at least 4 stripe pairs: their average lies within 1/(4 w) <= 1/16 of the
    # mean. The shader's footprint is the same difference taken in the pixel's 2 x 2 quad, up to a pixel away:
    # we allow it to be half the twin's (1/8), plus 8-bit rounding of the picture. A pixel whose two quad
    # partners both lie outside the proxy primitive drawn (a corner of a block of cubes) has no neighbour
    # that hit and keeps its point sample (lib/effects/footprint.glsl): 2.4 % of these pixels in this view.
    fine = ok & (w >= 4.0)
    assert fine.sum() > 0.5 * ok.sum()  # most of the sphere: the case is not empty
    mean = 0.15 + 0.85 * 0.5
    tol = 0.85 * mean_deviation_bound(2.0) + 1.0 / 255
    dev_filtered = np.abs(filtered[:-1, :-1][fine] - mean)
    dev_plain = np.abs(plain[:-1, :-1][fine] - mean)
    assert (dev_filtered <= tol).mean() >= 0.95
    # one sample per pixel: every pixel is dark or bright, 0.425 from the mean -- a moire, and the check fails
    assert np.quantile(dev_plain, 0.5) > tol


def test_toksvig_factor_from_the_quad_derivatives_matches_the_twin():
    # Normals turning about y by k per pixel along x (the same turn for both rows of each 2 x 2 quad, so coarse
    # and fine derivatives agree): |dn/dX| = 2 sin(k / 2) exactly, dn/dY = 0.
    from splinevis.analysis.footprint import toksvig_factor

    side, s = 64, 40.0
    px, py = np.meshgrid(np.arange(side), np.arange(side))
    k = 0.03 * (1 + py // 2)  # 0.03 .. 0.96 rad a pixel
    n = np.stack([np.sin(0.3 + k * px), np.zeros_like(k, dtype=float), np.cos(0.3 + k * px)], axis=-1)
    rows = n.reshape(-1, 3).astype(np.float32)
    out = run_glsl('uniform float sv_ambient;\nuniform float sv_diffuse;\n#include "lib/effects/lights.glsl"\n',
                   "sv_out[0] = sv_toksvig_factor(vec3(sv_in[0], sv_in[1], sv_in[2]), 40.0);", rows, 1,
                   defines={"SV_NUM_LIGHTS": 1, "SV_SPECULAR": True, "SV_ANTIALIAS": True})[:, 0].astype(np.float64)
    step = (2 * np.sin(k / 2)).ravel()
    twin = toksvig_factor(np.stack([step, 0 * step, 0 * step], -1), np.zeros((step.size, 3)), s)
    # float32: each normal's components round by u, so |dn| by <= 4u and the variance by <= |dn| 8u / 12; ft's
    # slope in the variance is at most s / 2 (its denominator is >= 1 for s >= 1); plus ~16 roundings of ft
    u = 2.0**-24
    assert np.all(np.abs(out - twin) <= s / 2 * step * 8 * u / 12 + 16 * u * (1 + s))
    assert twin.min() < 0.5 < twin.max()  # the range spans a barely and a strongly widened highlight
