"""The Newell teapot data set (datasets_synthetic.teapot): the .bpt file it writes reads back exactly, its
normals face out, its poles sit where the data collapse control rows, and its seams are the ones the
construction implies (every ring of four patches closes around the axis with mirror-symmetric quarter arcs:
G2; profile joins have collinear control points but unequal curvature: G1; nothing is G0). No GL needed."""

import collections

import numpy as np
import pytest

from datasets_synthetic.teapot import TEAPOT_GROUPS, newell_teapot, write_bpt
from splinevis.io import read_nurbs
from splinevis.nurbs.continuity import find_seams


#: Rounding of a bicubic evaluation of points of size <= 3.525: 16 products summed, a few ulps each.
EVAL_ULPS = 16 * np.finfo(float).eps * 3.525


def _group(name):
    return name.rsplit(" ", 1)[0]


def test_bpt_file_reads_back_to_the_same_control_points(tmp_path):
    path = write_bpt(tmp_path / "teapot.bpt")
    text = path.read_text().split("\n")
    assert text[0] == "32" and text[1] == "3 3" and len(text[2].split()) == 3
    m = read_nurbs(path)
    ref = newell_teapot(outward=False)
    assert len(m) == 32
    for a, b in zip(m.surfaces, ref.surfaces):
        assert a.degree == (3, 3)
        np.testing.assert_array_equal(a.control_points, b.control_points)  # decimal text, repr round trip


def test_outward_model_is_the_bpt_model_with_u_and_v_swapped():
    a, b = newell_teapot(), newell_teapot(outward=False)
    t = np.linspace(0.0, 1.0, 7)
    U, V = (x.ravel() for x in np.meshgrid(t, t))
    for sa, sb in zip(a.surfaces, b.surfaces):
        # the same 16 points summed with the same weights in another order: equal to a few ulps of |P|max
        np.testing.assert_allclose(sa.evaluate(U, V), sb.evaluate(V, U), rtol=0, atol=EVAL_ULPS)


def test_normals_point_out_of_the_pot():
    m = newell_teapot()
    t = np.linspace(0.1, 0.9, 5)
    U, V = (x.ravel() for x in np.meshgrid(t, t))
    for s, name in zip(m.surfaces, m.names):
        P, N = s.evaluate(U, V), s.normal(U, V)
        group = _group(name)
        if group in ("upper body", "lower body"):
            away = P * [1.0, 1.0, 0.0]  # from the axis
        elif group == "lid":
            away = np.tile([0.0, 0.0, 1.0], (len(U), 1))
        elif group == "bottom":
            away = np.tile([0.0, 0.0, -1.0], (len(U), 1))
        else:  # rim (a lip curled over: its inner half faces the axis), knob (its neck turns inwards), handle
            continue  # and spout (tubes): no single "away" direction; the knob's pole is checked below
        assert np.all(np.einsum("ij,ij->i", N, away) > 0), name


@pytest.mark.parametrize("group, pole, up", [("lid knob", (0.0, 0.0, 3.15), 1.0), ("bottom", (0.0, 0.0, 0.0), -1.0)])
def test_poles_collapse_a_control_row_and_have_the_axis_as_normal(group, pole, up):
    m = newell_teapot()
    patches = [s for s, n in zip(m.surfaces, m.names) if _group(n) == group]
    assert len(patches) == 4
    for s in patches:
        P = s.control_points
        rows = [P[0], P[-1], P[:, 0], P[:, -1]]
        collapsed = [r for r in rows if np.ptp(r, axis=0).max() == 0.0]
        assert len(collapsed) == 1 and np.array_equal(collapsed[0][0], pole)
        # the limit normal at the pole (S_u x S_v vanishes there) is the axis, pointing out of the pot
        uv = np.linspace(0.0, 1.0, 5)
        for u, v in ((np.zeros(5), uv), (np.ones(5), uv), (uv, np.zeros(5)), (uv, np.ones(5))):
            at_pole = np.all(np.abs(s.evaluate(u, v) - pole) == 0.0, axis=1)
            if at_pole.all():
                np.testing.assert_allclose(s.normal(u, v), np.tile([0.0, 0.0, up], (5, 1)), atol=1e-12)
                c = s.curvature(u, v)
                assert np.isnan(c["H"]).all()  # no 0/0 quotient at the degenerate row


def test_seams_follow_the_construction():
    m = newell_teapot()
    seams = find_seams(m.surfaces)
    levels = collections.Counter()
    for seam in seams:
        ga, gb = sorted((_group(m.names[seam.a]), _group(m.names[seam.b])))
        around = ga == gb and ga not in ("handle", "spout")
        levels[("around" if around else "profile", seam.level)] += 1
        assert seam.level != "G0"
        assert np.max(seam.gap) <= EVAL_ULPS  # shared boundary control points are equal in the data
    rings = [g for g, a, b in TEAPOT_GROUPS if g not in ("handle", "spout")]
    assert levels[("around", "G2")] == 4 * len(rings)
    # profile joins: rim|upper, upper|lower, lower|bottom, knob|lid (4 each); the handle's and the spout's
    # two mirror pairs meet G2 across the mirror plane y = 0 (2 edges per pair) and G1 along the tube (2)
    assert levels[("profile", "G1")] == 4 * 4 + 2 + 2
    assert levels[("profile", "G2")] == 4 + 4
    assert sum(levels.values()) == len(seams)
