"""The tiled subdivision (splinevis.geometry_image.tiles): every tile's limit points and normals are the whole
level's, bit for bit, and the tiled fold count equals the whole level's, on crumpled images of several sizes
(image sizes whose cell count the tile size does not divide included) with folds at the cut vertices too."""

import numpy as np
import pytest

from splinevis.geometry_image.build import fold_counts
from splinevis.geometry_image.image import apply_cut_constraint, image_uv, octahedral_to_sphere
from splinevis.geometry_image.subdivision import subdivide
from splinevis.geometry_image.tiles import fold_counts_tiled, limit_tiles


def _crumpled(n, amplitude, seed):
    G = octahedral_to_sphere(image_uv(n))
    return apply_cut_constraint(G + amplitude * np.random.default_rng(seed).normal(size=G.shape))


@pytest.mark.parametrize("n, level, cells", [(17, 3, 4), (19, 2, 4), (33, 2, 7), (9, 4, 64)])
def test_tiles_are_the_whole_level_bit_for_bit(n, level, cells):
    G = _crumpled(n, 0.1, n)
    whole = subdivide(G, level)
    covered = np.zeros(whole.p.shape[:2], dtype=int)
    for r, c, p, nrm in limit_tiles(G, level, cells):
        k = len(p)
        assert p.shape == nrm.shape == (k, k, 3)
        assert np.array_equal(p, whole.p[r:r + k, c:c + k])
        inner = np.ones((k, k), dtype=bool)  # the cut vertices' normals are the level-0 ones in the whole level
        for vr, vc in zip(*np.nonzero(np.all(whole.n[r:r + k, c:c + k] != nrm, axis=-1))):
            inner[vr, vc] = False
        assert np.array_equal(nrm[inner], whole.n[r:r + k, c:c + k][inner])
        assert (~inner).sum() <= 4
        covered[r:r + k - 1, c:c + k - 1] += 1  # the cells (two triangles each) of this tile
    assert (covered[:-1, :-1] == 1).all()  # every cell in exactly one tile


@pytest.mark.parametrize("n, level, amplitude, cells, workers", [(17, 3, 0.2, 4, 1), (17, 3, 0.2, 5, 2),
                                                                 (19, 3, 0.15, 4, 2), (33, 2, 0.08, 8, 1)])
def test_tiled_fold_count_equals_the_whole_levels(n, level, amplitude, cells, workers):
    G = _crumpled(n, amplitude, 7)
    s = subdivide(G, level)
    expected = fold_counts(s.p, s.n)
    assert expected[0] > 0  # the crumpled image does fold (not a trivial equality)
    assert fold_counts_tiled(G, level, cells, workers) == expected


@pytest.mark.parametrize("step", [2, 4])
def test_tiled_fold_count_of_a_subsampled_level_equals_the_whole_grids(step):
    G = _crumpled(17, 0.2, 3)
    s = subdivide(G, 3)
    expected = fold_counts(s.p[::step, ::step], s.n[::step, ::step])
    assert expected[0] > 0
    assert fold_counts_tiled(G, 3, 4, step=step) == expected
    with pytest.raises(ValueError, match="power of two"):
        fold_counts_tiled(G, 3, 4, step=3)
