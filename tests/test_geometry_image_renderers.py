"""The geometry image's renderers (splinevis.geometry_image.renderers): the proven position and normal bounds
of the level-L mesh hold against the float64 limit surface (GeometryImage.evaluate / normals: the B-spline of
the padded image, itself checked against scipy in tests/test_geometry_image_model.py) on synthetic closed
shapes, and the choice by accuracy takes the coarsest level meeting the request.

The mesh is the float64 twin's (subdivision.subdivide): its limit points and normals carry rounding of a few
u_64 of the image's size, far below the bounds' rounding terms (those are the GPU's float32 ones), so the
comparison needs no tolerance: measured <= bound exactly as derived."""

from functools import lru_cache

import numpy as np
import pytest

import splinevis
from datasets_synthetic.closed_meshes import bent_blob, star_blob, stretched_blob
from splinevis.choice import choose
from splinevis.geometry_image.model import GeometryImage
from splinevis.geometry_image.program import model_from
from splinevis.geometry_image.renderers import normal_error_deg, position_bounds
from splinevis.geometry_image.subdivision import subdivide
from splinevis.gl.screen_error import View

SHAPES = {"star_blob": star_blob, "stretched_blob": stretched_blob, "bent_blob": bent_blob}


@lru_cache(maxsize=None)
def _image(name, n=17) -> GeometryImage:
    return model_from(SHAPES[name](level=3), n)


def _samples(gi, L, count, rng):
    """Random points of the level-L mesh: (parameters (K, 2), cell indices (K,), vertex indices (K, 3) into the
    (M, M) grid, barycentric weights (K, 3)), half of them in the cells at the cut vertices."""
    N = gi.n - 1
    m = 1 << L
    M = N * m + 1
    a = rng.integers(0, N * m, count)  # sub-square column (s)
    b = rng.integers(0, N * m, count)  # sub-square row (t)
    cuts = np.array([[c, r] for r, c in ((0, N // 2), (N, N // 2), (N // 2, 0), (N // 2, N))])  # (s, t)
    near = rng.integers(0, 4, count // 2)
    off = rng.integers(-m, m, (count // 2, 2))
    a[:count // 2] = np.clip(cuts[near, 0] * m + off[:, 0], 0, N * m - 1)
    b[:count // 2] = np.clip(cuts[near, 1] * m + off[:, 1], 0, N * m - 1)
    lam = rng.dirichlet((1.0, 1.0, 1.0), count)
    v00 = b * M + a
    upper = rng.random(count) < 0.5  # grid_faces: (00, 01, 11) and (00, 11, 10), 01 = next column
    v = np.where(upper[:, None], np.stack([v00, v00 + M + 1, v00 + M], 1), np.stack([v00, v00 + 1, v00 + M + 1], 1))
    st_grid = np.stack([v % M, v // M], axis=-1) / m  # (K, 3, 2) vertex parameters
    st = np.einsum("kj,kjd->kd", lam, st_grid)
    cell = np.minimum(b // m, N - 1) * N + np.minimum(a // m, N - 1)
    return st, cell, v, lam, np.stack([np.minimum(a // m, N - 1), np.minimum(b // m, N - 1)], 1)


@pytest.mark.parametrize("name", sorted(SHAPES))
@pytest.mark.parametrize("L", [0, 1, 2, 3])
def test_position_bound_holds_inside_triangles(name, L):
    gi = _image(name)
    sub = subdivide(gi.control, L)
    p = sub.p.reshape(-1, 3)
    st, cell, v, lam, cells = _samples(gi, L, 20_000, np.random.default_rng(L))
    mesh = np.einsum("kj,kjd->kd", lam, p[v])
    exact = gi.evaluate(st, cells=cells)  # the triangle's own cell (one polynomial piece)
    dist = np.linalg.norm(mesh - exact, axis=1)
    bound = position_bounds(gi, L)[cell]
    assert (dist <= bound).all(), float((dist / bound).max())
    assert dist.max() > 0.0
    # not a tolerance of the property above: a check that the bound stays useful (measured 1.3-2.8 here; the
    # cell-wide second-derivative bounds against the largest chord error sampled)
    assert bound.max() / dist.max() < 10.0


def _shading_angles(gi, L, count, seed):
    sub = subdivide(gi.control, L)
    n = sub.n.reshape(-1, 3)
    st, cell, v, lam, cells = _samples(gi, L, count, np.random.default_rng(seed))
    shade = np.einsum("kj,kjd->kd", lam, n[v])
    shade /= np.linalg.norm(shade, axis=1, keepdims=True)
    exact = gi.normals(st)
    cos = np.clip(np.einsum("kd,kd->k", shade, exact), -1.0, 1.0)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(shade, exact), axis=1), cos))


# levels where the bound is finite for these images (stretched_blob has no cone at level 0, bent_blob's cells
# fold until level 3: the bound is inf there, honestly)
NORMAL_CASES = [("star_blob", 0), ("star_blob", 2), ("star_blob", 4), ("stretched_blob", 1), ("stretched_blob", 3),
                ("bent_blob", 3), ("bent_blob", 4)]


@pytest.mark.parametrize("name,L", NORMAL_CASES)
def test_normal_bound_holds_inside_triangles(name, L):
    gi = _image(name)
    bound, proven = normal_error_deg(gi, None, L, {})
    assert proven and np.isfinite(bound)
    measured = _shading_angles(gi, L, 20_000, 7 + L)
    assert measured.max() <= bound, (measured.max(), bound)
    assert measured.max() > 0.0


def _view(distance=4.0):
    return View((0.0, -distance, 0.5 * distance), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240)


def test_choice_takes_coarser_levels_for_looser_requests():
    gi = _image("star_blob")
    levels = [choose(gi, _view(), e).level for e in (4.0, 1.0, 0.25, 0.06)]
    assert levels == sorted(levels) and levels[0] < levels[-1], levels
    c = choose(gi, _view(), 0.25)
    assert c.renderer == "subdivision" and c.meets and c.chosen.proven and c.error_px <= 0.25
    coarser = [o for o in c.options if o.level < c.level]
    assert all(o.error_px > 0.25 for o in coarser)
    far = choose(gi, _view(40.0), 0.25)  # ten times farther: fewer pixels per unit, a coarser level
    assert far.level < c.level


def test_choice_meets_a_normal_request():
    gi = _image("star_blob")
    c = choose(gi, _view(), None, max_normal_error_deg=15.0)
    assert c.meets and c.chosen.normal_deg <= 15.0 and c.chosen.normal_proven
    assert "deg (proven)" in c.message
    loose = choose(gi, _view(), 4.0)
    both = choose(gi, _view(), 4.0, max_normal_error_deg=15.0)
    assert both.level > loose.level  # the normals ask for more than the positions here


def test_plotter_draws_the_chosen_level(tmp_path):
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    actor = pl.add_geometry_image(star_blob(level=3), n=17, max_error_px=1.0, reflection_lines=8)
    c = actor.choice
    assert c.renderer == "subdivision" and c.meets and c.error_px <= 1.0
    assert actor.GetMapper().GetInput().GetNumberOfPoints() == (16 * 2 ** c.level + 1) ** 2
    img = pl.screenshot(str(tmp_path / "geometry_image_choice.png"))
    assert img.std() > 10
    pl.close()
    with pytest.raises(ValueError, match="displacement map belongs to one level"):
        splinevis.Plotter(off_screen=True).add_geometry_image(_image("star_blob"), max_error_px=1.0,
                                                              displacement=np.zeros((17, 17)))
