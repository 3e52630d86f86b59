"""Out-of-core construction: chunked terrains and volumes equal the in-memory ones, the stores' pyramids equal
MinMaxPyramid's, windows evaluate like the whole model, tiles_in_view covers a view, a dask.distributed
cluster gives the same store, and bad input fails clearly."""

import dask.array as da
import numpy as np
import pytest
import zarr

from splinevis.hierarchy.pyramid import MinMaxPyramid
from splinevis.outofcore import (
    open_terrain_store,
    open_volume_store,
    terrain_coefficients_dask,
    terrain_halo,
    tiles_in_view,
    volume_coefficients_dask,
    volume_cube_ranges_dask,
    write_terrain_store,
    write_volume_store,
)
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.schemes import STENCIL_SCHEMES, terrain_coefficients
from splinevis.volume.model import VolumeSpline
from splinevis.volume.schemes import spline_coefficients

RTOL = 1e-15  # of the largest coefficient: the BLAS product rounds a few rows by a unit in the last place


def _dem(shape, seed=0):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:shape[0], 0:shape[1]] / 10.0
    return 100 * np.sin(x) * np.cos(1.3 * y) + 20 * rng.random(shape) + 1000.0


def _close(a, b):
    scale = np.abs(b).max()
    return float(np.abs(a - b).max()) <= RTOL * scale


@pytest.mark.parametrize("scheme", STENCIL_SCHEMES)  # C2-interp is refused out of core (tests/test_terrain_interpolating.py)
def test_terrain_chunks_equal_in_memory(scheme):
    z = _dem((65, 53) if scheme == "C0" else (67, 53))
    z = z - z.mean()  # what TerrainSpline hands the scheme
    ref = terrain_coefficients(z, scheme)[0]
    tiles = [16, (5, 7)] if scheme == "C0" else [16, (11, 13), (7, 20)]  # dividing the cells and not
    tiles = [t for t in tiles if min(np.atleast_1d(t)) >= terrain_halo(scheme)["min_tile"]]
    for t in tiles:
        got = terrain_coefficients_dask(z, scheme, chunks=t).compute()
        assert got.shape == ref.shape
        if scheme == "linear":  # one GEMM row per cell pair: no rounding differences at all
            assert (got == ref).all()
        assert _close(got, ref), (scheme, t, np.abs(got - ref).max())
        assert (got == ref).mean() > 0.97  # all but a few rows of the matrix products bit for bit


def test_terrain_from_zarr_and_rechunked_dask(tmp_path):
    z = _dem((40, 37)) - 1000.0
    arr = zarr.open_array(str(tmp_path / "h.zarr"), mode="w", shape=z.shape, chunks=(9, 11), dtype="f8")
    arr[...] = z
    ref = terrain_coefficients(z, "C1")[0]
    assert _close(terrain_coefficients_dask(arr, "C1", chunks=12).compute(), ref)
    assert _close(terrain_coefficients_dask(str(tmp_path / "h.zarr"), "C1", chunks=12).compute(), ref)
    assert _close(terrain_coefficients_dask(da.from_array(z, chunks=(3, 17)), "C1", chunks=12).compute(), ref)


def test_terrain_store_pyramid_and_windows(tmp_path):
    z = _dem((67, 53))
    store = write_terrain_store(tmp_path / "t.zarr", z, "C1", chunks=16, spacing=(30.0, 20.0),
                                origin=(5e5, 4e6), progress=False)
    model = TerrainSpline.from_heights(z, "C1", spacing=(30.0, 20.0), origin=(5e5, 4e6))
    assert store.z_ref == pytest.approx(model.z_ref, rel=1e-15, abs=0)
    assert store.data_range == model.data_range and store.extent == model.extent
    coef = store.coefficients[...]
    assert _close(coef, model.coefficients)
    # the store's pyramid is, level for level, MinMaxPyramid of its coefficients (bit for bit) ...
    mine = MinMaxPyramid(coef.reshape(*coef.shape[:2], 30).min(-1), coef.reshape(*coef.shape[:2], 30).max(-1))
    assert store.depth == mine.depth == model.hierarchy.depth
    for L in range(store.depth + 1):
        lo, hi = store.level(L)
        assert (lo == mine.levels[L][0]).all() and (hi == mine.levels[L][1]).all()
        assert _close(lo, model.hierarchy.levels[L][0]) and _close(hi, model.hierarchy.levels[L][1])
    # ... its level log2(tile) holds the tiles' bounds, and the pyramid from there up is the top of the model's
    t = store.tile_bounds()
    lo4, hi4 = store.level(4)
    assert (t[..., 0] == lo4).all() and (t[..., 1] == hi4).all()
    top = store.pyramid(4)
    for L in range(top.depth + 1):
        assert (top.levels[L][0] == mine.levels[L + 4][0]).all()
    # a window of tiles evaluates like the whole model inside it
    w = store.window(1, 3, 1, 4)
    assert w.origin == (5e5 + 16 * 30.0, 4e6 + 16 * 20.0) and w.shape == (32, 36)
    x0, x1, y0, y1 = w.extent
    rng = np.random.default_rng(1)
    x = rng.uniform(x0, x1, 200)
    y = rng.uniform(y0, y1, 200)
    assert np.abs(w.evaluate(x, y) - model.evaluate(x, y)).max() <= 1e-12 * np.abs(z).max()
    assert (w.coefficients == coef[16:48, 16:52]).all()


def test_tiles_in_view_cover_the_box_and_nothing_outside(tmp_path):
    z = _dem((67, 53), seed=3)
    store = write_terrain_store(tmp_path / "t.zarr", z, "C2", chunks=8, progress=False)
    coef = store.coefficients[...].reshape(66, 52, 30) + store.z_ref
    clo, chi = coef.min(-1), coef.max(-1)
    tb = store.tile_bounds() + store.z_ref
    rng = np.random.default_rng(2)
    jj, ii = np.mgrid[0:66, 0:52]
    for _ in range(25):
        bx = np.sort(rng.uniform(-5, 57, 2))
        by = np.sort(rng.uniform(-5, 71, 2))
        bz = np.sort(rng.uniform(z.min() - 20, z.max() + 20, 2))
        box = (bx[0], bx[1], by[0], by[1], bz[0], bz[1])
        got = {tuple(t) for t in tiles_in_view(store, box).tolist()}
        touched = ((ii <= bx[1]) & (ii + 1 >= bx[0]) & (jj <= by[1]) & (jj + 1 >= by[0])
                   & (clo <= bz[1]) & (chi >= bz[0]))
        need = {(int(j) // 8, int(i) // 8) for j, i in np.argwhere(touched)}
        assert need <= got
        for ty, tx in got:  # no tile entirely outside the box
            assert tx * 8 <= bx[1] and min(tx * 8 + 8, 52) >= bx[0] and ty * 8 <= by[1] and min(ty * 8 + 8, 66) >= by[0]
            assert tb[ty, tx, 0] <= bz[1] and tb[ty, tx, 1] >= bz[0]
    # planes: the half space x + y >= 60 keeps exactly the tiles with a corner there
    got = {tuple(t) for t in tiles_in_view(store, planes=[(1.0, 1.0, 0.0, -60.0)]).tolist()}
    want = {(ty, tx) for ty in range(9) for tx in range(7) if min(tx * 8 + 8, 52) + min(ty * 8 + 8, 66) >= 60}
    assert got == want


def test_store_on_a_distributed_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    z = _dem((40, 45))
    ref = write_terrain_store(tmp_path / "local.zarr", z, "C2-cubic", chunks=10, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster):
            s = write_terrain_store(tmp_path / "dist.zarr", z, "C2-cubic", chunks=10, progress=False)
            v = write_volume_store(tmp_path / "v.zarr", _dem((6, 7))[:6, :7, None] * np.ones(8), "quadratic", chunks=4,
                                   progress=False)
    assert s.z_ref == pytest.approx(ref.z_ref, rel=1e-15, abs=0)
    model = TerrainSpline.from_heights(z, "C2-cubic")
    assert _close(s.coefficients[...], model.coefficients)
    for L in range(s.depth + 1):
        assert _close(s.level(L)[0], model.hierarchy.levels[L][0])
    vm = VolumeSpline(_dem((6, 7))[:6, :7, None] * np.ones(8), "quadratic", order="zyx")
    assert (v.padded[...] == vm.padded).all() and (v.level(0)[1] == vm.cube_ranges()[1]).all()


@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_volume_chunks_equal_in_memory(tmp_path, scheme):
    v = np.random.default_rng(7).random((20, 20, 20))
    ref = spline_coefficients(v, scheme)
    assert (volume_coefficients_dask(v, scheme, chunks=8).compute() == ref).all()  # even x tiles: bit for bit
    assert _close(volume_coefficients_dask(v, scheme, chunks=(5, 6, 7)).compute(), ref)
    model = VolumeSpline(v, scheme, order="zyx")
    lo, hi = model.cube_ranges()
    r = volume_cube_ranges_dask(v, scheme, chunks=(6, 7, 9)).compute()
    assert (r[..., 0] == lo).all() and (r[..., 1] == hi).all()
    store = write_volume_store(tmp_path / "v.zarr", v, scheme, chunks=8, coefficients=True, progress=False)
    assert (store.padded[...] == model.padded).all()
    assert store.depth == model.octree.depth
    for L in range(store.depth + 1):
        a, b = store.level(L)
        assert (a == model.octree.levels[L][0]).all() and (b == model.octree.levels[L][1]).all()
    assert (store._g["coefficients"][...] == ref).all()
    cubes = np.array([[0, 0, 0], [19, 3, 7], [5, 19, 19], [10, 10, 10]])
    assert _close(store.cube_coefficients(cubes), model.cube_coefficients(cubes))


def test_clear_errors(tmp_path):
    z = _dem((30, 30))
    with pytest.raises(ValueError, match=r"chunks of 3 cells along y \(rows\) are smaller than the halo of scheme C1.*at "
                                         r"least 5 cells"):
        terrain_coefficients_dask(z, "C1", chunks=3)
    with pytest.raises(ValueError, match="smaller than the halo of the 27-point volume stencil"):
        volume_coefficients_dask(np.zeros((6, 6, 6)), "cubic", chunks=1)
    with pytest.raises(ValueError, match="sizes 4k \\+ 1.*not supported out of core"):
        terrain_coefficients_dask(z, "C0", chunks=4)
    with pytest.raises(FileNotFoundError, match="no terrain store at"):
        open_terrain_store(tmp_path / "missing.zarr")
    with pytest.raises(FileNotFoundError, match="no volume store at"):
        open_volume_store(tmp_path / "missing.zarr")
    write_terrain_store(tmp_path / "c2.zarr", z, "C2", chunks=8, progress=False)
    with pytest.raises(ValueError, match="written with scheme 'C2', not 'C1'"):
        open_terrain_store(tmp_path / "c2.zarr", scheme="C1")
    with pytest.raises(ValueError, match="not a volume store"):
        open_volume_store(tmp_path / "c2.zarr")
    bad = z.copy()
    bad[20, 3] = np.nan
    with pytest.raises(ValueError, match="must be finite"):
        terrain_coefficients_dask(bad, "C1", chunks=8).compute()


def test_geotiff_is_read_by_windows_like_read_heights(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import Affine

    from splinevis.io import read_heights
    from splinevis.outofcore.halo import as_dask_array

    z = _dem((23, 31)).astype(np.float32)
    path = tmp_path / "dem.tif"
    with rasterio.open(path, "w", driver="GTiff", height=23, width=31, count=1, dtype="float32", crs="EPSG:32633",
                       transform=Affine(30.0, 0.0, 5e5, 0.0, -30.0, 4.1e6)) as dst:
        dst.write(z, 1)  # row 0 = north
    lazy = as_dask_array(path, chunks=(7, 9))
    assert lazy.chunks[0] == (7, 7, 7, 2)
    assert (lazy.compute() == np.asarray(read_heights(path).heights)).all()
    assert _close(terrain_coefficients_dask(path, "C1", chunks=8).compute(),
                  terrain_coefficients(np.asarray(read_heights(path).heights, dtype=np.float64), "C1")[0])


def test_store_with_oblong_tiles(tmp_path):
    z = _dem((30, 47))
    s = write_terrain_store(tmp_path / "t.zarr", z, "C2", chunks=(8, 16), progress=False)
    model = TerrainSpline.from_heights(z, "C2")
    assert s.tiles == (4, 3) and s.coefficients.chunks == (8, 16, 2, 15)
    for L in range(s.depth + 1):
        assert _close(s.level(L)[1], model.hierarchy.levels[L][1])
    assert _close(s.window(3, 4, 2, 3).coefficients, model.coefficients[24:29, 32:46])
