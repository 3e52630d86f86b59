"""Prefiltered volume splines built tile by tile (outofcore.volume.padded_volume_dask, write_volume_store with
prefilter= and padding=) equal the in-memory VolumeSpline's, bit for bit; the global interpolation is refused."""

from __future__ import annotations

import numpy as np
import pytest

from splinevis.outofcore import write_volume_store
from splinevis.outofcore.volume import padded_volume_dask
from splinevis.volume.model import VolumeSpline


@pytest.mark.parametrize("scheme,padding", [("quadratic", "quadratic"), ("cubic", "cubic")])
def test_prefiltered_store_equals_the_in_memory_spline(tmp_path, scheme, padding):
    v = np.random.default_rng(3).random((9, 8, 10))
    model = VolumeSpline(v, scheme, prefilter="local", padding=padding, order="zyx")
    # chunks of every size, the prefilter's halo crossing sample chunks
    P = padded_volume_dask(v, chunks=(3, 5, 4), scheme=scheme, prefilter="local", padding=padding).compute()
    assert np.array_equal(P, model.padded)
    store = write_volume_store(tmp_path / "v.zarr", v, scheme, chunks=4, progress=False, prefilter="local",
                               padding=padding)
    assert np.array_equal(store.padded[...], model.padded)
    assert (store.prefilter, store.padding) == ("local", padding) and "prefilter='local'" in repr(store)
    for L in range(store.depth + 1):
        a, b = store.level(L)
        assert np.array_equal(a, model.octree.levels[L][0]) and np.array_equal(b, model.octree.levels[L][1])
    w = store.window(1, 3, 0, 2, 1, 3)  # cubes 4..8 (z), 0..7 (y), 4..9 (x)
    cubes = np.array([[0, 0, 0], [5, 7, 4], [3, 2, 1]])
    assert np.array_equal(w.cube_coefficients(cubes), model.cube_coefficients(cubes + [4, 0, 4]))
    # the prefilter is what the store holds: not the plain scheme's data
    assert not np.array_equal(store.padded[...], VolumeSpline(v, scheme, order="zyx").padded)


def test_global_interpolation_is_refused_tile_by_tile(tmp_path):
    v = np.zeros((8, 8, 8))
    with pytest.raises(ValueError, match="not built tile by tile.*prefilter='local'.*in memory"):
        write_volume_store(tmp_path / "v.zarr", v, "cubic", chunks=4, progress=False, prefilter="interpolate",
                           padding="cubic")
    with pytest.raises(ValueError, match="prefilter must be one of"):
        padded_volume_dask(v, prefilter="smooth")
