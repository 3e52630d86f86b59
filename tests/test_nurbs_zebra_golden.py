"""The golden case of surface interrogation: two patches joined G1 show a kink in the zebra stripes at the
seam, joined G2 they do not. Measured on the stripe edges of the rendered picture (not by eye), and on the
float64 twin's exact zebra picture as the reference for how large the kink is."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

import splinevis
from datasets_synthetic.nurbs_joins import joined_pair
from splinevis.nurbs import NurbsModel

pytestmark = pytest.mark.gl

WINDOW = (480, 360)
CAMERA = [(0.1, -1.6, 2.3), (0.0, 0.5, 0.0), (0.0, 0.0, 1.0)]
AXIS = (1.0, 0.0, 0.0)  # light lines across the seam (x = 0): the stripes cross it
STRIPES = 20
NEAR, FAR = 2.0, 40.0  # pixels from the seam's image where the stripe edges are fitted, on each side


def _render(model):
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    pl.set_background("black")
    pl.add_spline(model, lights=0, color=(1.0, 1.0, 1.0), reflection_lines=STRIPES, reflection_axis=AXIS)
    pl.camera_position = CAMERA
    pl.camera.clipping_range = (0.5, 6.0)
    img = pl.screenshot().astype(np.float64) / 255.0
    matrix = pl.camera_matrix()
    pl.close()
    return img[..., 0] > 0.5, img.sum(-1) > 0.05, matrix


def _reference(model, matrix, pixels):
    from splinevis.analysis.zebra import zebra_reference

    bright, hit, _ = zebra_reference(model, matrix, WINDOW, STRIPES, AXIS, pixels=pixels)
    return bright, hit


def _reference_pixels(frame):
    """Where the float64 twin is evaluated (it costs per ray): the band the kink fits read (|s| < FAR, with a
    margin for the edge test's neighbours) and every second pixel of every second row elsewhere."""
    s, _ = frame
    rows, cols = np.mgrid[0:WINDOW[1], 0:WINDOW[0]]
    return (np.abs(s) < FAR + 3) | ((rows % 2 == 0) & (cols % 2 == 0))


def _seam_frame(matrix):
    """(s, t) per pixel: signed pixel distance to the image of the seam x = 0, z = 0 (a straight line), and
    the position along it."""
    ends = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 1.0]]) @ matrix.T
    ndc = ends[:, :2] / ends[:, 3:4]
    px = np.column_stack([(ndc[:, 0] + 1) / 2 * WINDOW[0] - 0.5, (1 - ndc[:, 1]) / 2 * WINDOW[1] - 0.5])  # (col, row)
    t = (px[1] - px[0]) / np.linalg.norm(px[1] - px[0])
    normal = np.array([-t[1], t[0]])
    rows, cols = np.mgrid[0:WINDOW[1], 0:WINDOW[0]]
    dc, dr = cols - px[0, 0], rows - px[0, 1]
    return dc * normal[0] + dr * normal[1], dc * t[0] + dr * t[1]


def kink_angles(bright, surface, frame) -> np.ndarray:
    """For every stripe edge that crosses the seam: the angle (degrees) between the edge's tangents at the
    seam seen from either side. Each side's edge pixels (NEAR..FAR pixels from the seam) are fitted by
    t = a + b s + c s^2 (s across, t along the seam's image); the tangent at the seam has slope b."""
    s, t = frame
    edge = surface & ndimage.binary_erosion(surface, iterations=2) & (
        (bright != np.roll(bright, 1, axis=0)) | (bright != np.roll(bright, 1, axis=1)))
    labels, count = ndimage.label(edge & (np.abs(s) < FAR), structure=np.ones((3, 3)))
    out = []
    for k in range(1, count + 1):
        sk, tk = s[labels == k], t[labels == k]
        slopes = []
        for side in (sk > NEAR, sk < -NEAR):
            if side.sum() < 12 or np.ptp(sk[side]) < 0.5 * (FAR - NEAR):
                break  # the edge does not run across this side of the seam
            slopes.append(np.polyfit(sk[side], tk[side], 2)[1])
        if len(slopes) == 2:
            out.append(abs(np.degrees(np.arctan(slopes[0]) - np.arctan(slopes[1]))))
    return np.array(out)


@pytest.fixture(scope="module")
def measured():
    result = {}
    for join in ("G1", "G2"):
        model = NurbsModel(list(joined_pair(join)))
        bright, surface, matrix = _render(model)
        frame = _seam_frame(matrix)
        pixels = _reference_pixels(frame)
        ref_bright, ref_hit = _reference(model, matrix, pixels)
        result[join] = (kink_angles(bright, surface, frame), kink_angles(ref_bright, ref_hit, frame), bright, ref_bright,
                        surface, pixels)
    return result


def test_zebra_stripes_kink_at_a_g1_seam_and_not_at_a_g2_seam(measured):
    g1, g1_ref = measured["G1"][0], measured["G1"][1]
    g2, g2_ref = measured["G2"][0], measured["G2"][1]
    assert len(g1) >= 2 and len(g2) >= 2  # stripe edges cross the seam in both pictures
    # the tangent of an edge fitted over ~38 pixels of whole-pixel positions is good to about 1 degree per side:
    # a smooth (G2) crossing reads below ~2.5 degrees, the G1 seam's kink (the twin says how large) far above
    assert np.median(g2_ref) < 2.5 and np.median(g2) < 2.5
    assert np.median(g1_ref) > 8.0 and np.median(g1) > 8.0
    assert abs(np.median(g1) - np.median(g1_ref)) < 2.0  # the GPU's kink is the exact one


def test_zebra_pictures_match_the_twin_away_from_stripe_edges(measured):
    for join in ("G1", "G2"):
        _, _, bright, ref_bright, surface, pixels = measured[join]
        inner = ndimage.binary_erosion(surface, iterations=2)
        # pixels with a differing neighbour in the reference sit on a stripe edge: either colour is right there
        # (outside the band the twin has every second pixel, so "neighbour" is any evaluated pixel within two;
        # only pixels the twin evaluated are compared)
        edge = np.zeros_like(pixels)
        for dy in range(-2, 3):
            for dx in range(-2, 3):
                other, seen = np.roll(ref_bright, (dy, dx), (0, 1)), np.roll(pixels, (dy, dx), (0, 1))
                edge |= seen & (other != ref_bright)
        ok = inner & ~edge & pixels
        assert ok.sum() > 10000
        assert (bright[ok] == ref_bright[ok]).mean() > 0.999


def test_stripes_for_view_is_the_largest_count_within_the_pixel_budget():
    """stripes_for_view: n pairs of stripes at the measured phase rate q (phase per pixel at the quantile) span
    1 / (n q) pixels; the count is the largest n with 1 / (n q) >= pixels_per_pair, and twice the pixels across
    the same view halve q (so the count doubles, to within the floor)."""
    from splinevis.analysis.zebra import stripes_for_view
    from splinevis.analytic import QuarticTrianglePatch

    patch = QuarticTrianglePatch.demo()
    a = stripes_for_view(patch, np.eye(4), (80, 60), (1, 0, 0), pixels_per_pair=5.0, quantile=0.8, step=1)
    n, q = a["stripes"], a["rate_quantile"]
    assert n * q * 5.0 <= 1.0 < (n + 1) * q * 5.0
    b = stripes_for_view(patch, np.eye(4), (160, 120), (1, 0, 0), pixels_per_pair=5.0, quantile=0.8, step=1)
    assert abs(b["rate_quantile"] / q - 0.5) < 0.05  # the same surface sampled at twice the pixels
    assert 2 * n - 1 <= b["stripes"] <= 2 * n + 2
    with pytest.raises(ValueError, match="Nyquist"):
        stripes_for_view(patch, np.eye(4), (80, 60), (1, 0, 0), pixels_per_pair=2.0)
