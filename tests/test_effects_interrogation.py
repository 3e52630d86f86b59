"""Surface-interrogation effects (reflection lines about any axis, highlight lines, draft angle, curvature
kinds) per pixel against the same formula on the float64 twin's hits (points and normals).

A ray-cast sphere isosurface is the test object: its twin gives every pixel's exact hit, and the effects'
GLSL runs unchanged for every family. Pixels whose twin value lies within a small margin of a colour
boundary may fall either way (float32 normals, sub-pixel sampling) and are left out; the margin is stated
with each test. The stripe tests draw the plain step (``antialias=False``): they test where the stripes are;
tests/test_stripes_antialias.py tests their filter.
"""

from __future__ import annotations

import numpy as np
import pytest

import splinevis
from splinevis.analysis.zebra import zebra_reference
from splinevis.gl.camera import pixel_rays
from splinevis.programs import program_for
from _sphere_scene import CAMERA, WINDOW, render, sphere

pytestmark = pytest.mark.gl

# float32 normals of the sphere spline are good to ~1e-4 rad against its float64 twin; a pixel's ray and the
# twin's ray through the pixel centre agree; the spline itself is only an approximation of the sphere, but both
# sides see the same spline. Margins below are a few times that.
ANGLE_MARGIN = 3e-3
_sphere, _render = sphere, render


def _twin(model, matrix):
    o, d = pixel_rays(matrix, *WINDOW)
    hits = program_for(model).raycast(model, o, d, 0.0)
    return hits, d / np.linalg.norm(d, axis=-1, keepdims=True)


def _stripe(x):
    """Bright (True) where fract(x) >= 0.5, and the distance of x to the nearest band edge."""
    f = x - np.floor(x)
    return f >= 0.5, np.minimum(np.abs(f - 0.5), np.minimum(f, 1 - f))


@pytest.fixture(scope="module")
def sphere():
    return _sphere()


@pytest.mark.parametrize("axis", [(1.0, 0.0, 0.0), (0.3, -0.5, 0.8)])
def test_reflection_lines_about_any_axis_match_the_twin(sphere, axis):
    stripes = 6
    img, matrix = _render(sphere, reflection_lines=stripes, reflection_axis=axis, antialias=False)
    bright, hit, dist = zebra_reference(sphere, matrix, WINDOW, stripes, axis)
    # the stripe phase moves by (2 stripes / pi) * |dr| with |dr| <= 2 |dn|: margin in phase units
    ok = hit & (dist > 4 * stripes / np.pi * ANGLE_MARGIN)
    assert ok.sum() > 2000 and 0.3 < bright[ok].mean() < 0.7  # both colours, a good part of the picture
    got_bright = img[..., 0] > 0.5
    assert (got_bright[ok] == bright[ok]).mean() >= 0.998


def test_reflection_axis_changes_the_picture(sphere):
    a, _ = _render(sphere, reflection_lines=6)
    b, _ = _render(sphere, reflection_lines=6, reflection_axis=(0.0, 0.0, 1.0))
    assert (np.abs(a - b).max(axis=-1) > 0.5).mean() > 0.05


def test_highlight_lines_match_the_twin(sphere):
    spacing, height = 0.35, 1.5  # the actor's offset (-1, -1, -1) is no whole number of spacings
    img, matrix = _render(sphere, highlight_lines=spacing, highlight_height=height, antialias=False)
    hits, _ = _twin(sphere, matrix)
    p, n = hits.points, hits.normals / np.linalg.norm(hits.normals, axis=-1, keepdims=True)
    m, across = np.array([0.0, 0.0, 1.0]), np.cross([0.0, 0.0, 1.0], [1.0, 0.0, 0.0])  # W = (0, 1, 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (height - p @ m) / (n @ m)
        w = np.einsum("...i,i->...", p + s[..., None] * n, across) / spacing
        # w = (p + s n).W / spacing with s = (h - p.m) / (n.m): a normal error |dn| moves it by at most
        # |s| |dn| (1 + |n.W| / |n.m|) / spacing
        margin = np.abs(s) * ANGLE_MARGIN * (1 + np.abs(n @ across) / np.abs(n @ m)) / spacing
    bright, dist = _stripe(w)
    ok = hits.hit & (np.abs(n @ m) > 0.1) & (dist > margin)
    assert ok.sum() > 1000 and 0.2 < bright[ok].mean() < 0.8
    assert ((img[..., 0] > 0.5)[ok] == bright[ok]).mean() >= 0.998


def test_highlight_lines_do_not_depend_on_the_eye(sphere):
    # the band of a surface point is a function of the point alone: the +z pole seen from two eyes is in the
    # same band (w = 0 there: on a band edge, so look just beside it, at the twin's hits of two views)
    a, ma = _render(sphere, highlight_lines=0.5, highlight_height=1.5, antialias=False)
    hits_a, _ = _twin(sphere, ma)
    other_eye = [(3.0, 0.2, 2.2), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    assert other_eye != CAMERA
    b, mb = _render(sphere, camera=other_eye, highlight_lines=0.5, highlight_height=1.5, antialias=False)
    hits_b, _ = _twin(sphere, mb)
    # pixels of the two views that see (nearly) the same surface point carry the same colour
    pa, pb = hits_a.points[hits_a.hit], hits_b.points[hits_b.hit]
    ca, cb = a[..., 0][hits_a.hit] > 0.5, b[..., 0][hits_b.hit] > 0.5
    from scipy.spatial import cKDTree

    dist, idx = cKDTree(pb).query(pa)
    # the band coordinate of view a's points (twin): pairs within a pixel footprint of each other, away from
    # band edges by more than that footprint moves w
    p, n = pa, hits_a.normals[hits_a.hit] / np.linalg.norm(hits_a.normals[hits_a.hit], axis=-1, keepdims=True)
    w = (p + ((1.5 - p[:, 2]) / n[:, 2])[:, None] * n)[:, 1] / 0.5
    _, edge = _stripe(w)
    close = (dist < 5e-3) & (np.abs(n[:, 2]) > 0.3) & (edge > 0.1)
    assert close.sum() > 200
    assert (ca[close] == cb[idx[close]]).mean() > 0.995


def test_draft_angle_classes_match_the_twin(sphere):
    pull, minimum = np.array([0.0, 0.0, 1.0]), 5.0
    img, matrix = _render(sphere, output="draft", pull_direction=tuple(pull), draft_angle=minimum)
    hits, _ = _twin(sphere, matrix)
    n = hits.normals / np.linalg.norm(hits.normals, axis=-1, keepdims=True)
    alpha = np.degrees(np.arcsin(np.clip(n @ pull, -1, 1)))  # the sphere's outward normal: its own orientation
    ok = hits.hit & (np.abs(np.abs(alpha) - minimum) > np.degrees(2 * ANGLE_MARGIN))
    want = np.where(alpha >= minimum, 1, np.where(alpha <= -minimum, 0, 2))  # green, red, yellow
    r, g = img[..., 0], img[..., 1]
    got = np.where((g > 0.25) & (r < 0.2), 1, np.where((r > 0.25) & (g < 0.2), 0, np.where((r > 0.6) & (g > 0.6), 2, -1)))
    assert {0, 1, 2} <= set(np.unique(want[ok]).tolist())
    assert (got[ok] == want[ok]).mean() >= 0.998


@pytest.mark.parametrize("kind", ["mean", "gaussian", "k1", "k2", "max"])
def test_curvature_kinds_of_a_sphere(sphere, kind):
    # a sphere of radius 0.7: k1 = k2 = H = +-1/0.7, K = 1/0.49 (sign of H and k by the normal's orientation,
    # the same for every pixel); at curvature_scale = 2 |value| the colour is half way to full
    want = {"mean": 1 / 0.7, "gaussian": 1 / 0.49, "k1": 1 / 0.7, "k2": 1 / 0.7, "max": 1 / 0.7}[kind]
    img, matrix = _render(sphere, output="curvature", curvature=kind, curvature_scale=2 * want)
    hits, _ = _twin(sphere, matrix)
    inner = hits.hit & (img.sum(-1) > 0)
    assert inner.sum() > 2000
    # half way from white to red (positive) or blue (negative): red channel 1.0 or ~0.62; the spline's
    # curvature is within a few percent of the sphere's
    white_to = np.array([0.71, 0.02, 0.15]) if kind == "gaussian" else None
    col = np.median(img[inner], axis=0)
    if white_to is not None:
        assert np.allclose(col, 0.5 * (1 + white_to), atol=0.04)
    else:
        red, blue = 0.5 * (1 + np.array([0.71, 0.02, 0.15])), 0.5 * (1 + np.array([0.23, 0.30, 0.75]))
        assert min(np.abs(col - red).max(), np.abs(col - blue).max()) < 0.04


def test_interrogation_style_errors():
    with pytest.raises(ValueError, match="highlight_axis .* must lie in the plane"):
        splinevis.Style(highlight_lines=0.1, highlight_axis=(0, 0, 1))
    with pytest.raises(ValueError, match="Style.curvature"):
        splinevis.Style(output="curvature", curvature="gauss")
    with pytest.raises(ValueError, match="draft_angle must be degrees"):
        splinevis.Style(output="draft", draft_angle=95)
    with pytest.raises(ValueError, match="non-zero direction"):
        splinevis.Style(reflection_lines=4, reflection_axis=(0, 0, 0))
    # only what is declared is compiled in
    assert splinevis.Style(highlight_lines=0.2).include_files() == ["lib/effects/lights.glsl",
                                                                   "lib/effects/highlight_lines.glsl",
                                                                   "lib/effects/footprint.glsl"]
    assert splinevis.Style(output="draft").include_files() == ["lib/effects/draft.glsl"]
