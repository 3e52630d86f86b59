"""Drawing from a volume store: a window of bricks is the whole volume's spline over its cubes (bit for bit), a
decimated level is the spline of every 2^L-th sample, a camera view reads only the bricks that hold the
isovalue in view and draws the picture of the in-memory isosurface, and the level drawn fits the budget and
the texture. The GPU tests need GL (llvmpipe)."""

import numpy as np
import pytest

from datasets_synthetic.large_grids import large_volume
from splinevis.outofcore import write_volume_store
from splinevis.outofcore import render_volume as rv
from splinevis.volume.isosurface import Isosurface
from splinevis.volume.model import VolumeSpline

N, TILE, ISO = 40, 16, 0.5  # bricks of 16, 16, 8 cubes per axis: the last one partial
CAMERA = [(16.0, -2.0, 28.0), (13.0, 4.0, 11.0), (0.0, 1.0, 0.0)]  # from above, over the corner x, y high


@pytest.fixture(scope="module")
def samples():
    return large_volume(N, chunks=N).compute()


@pytest.fixture(scope="module")
def store(samples, tmp_path_factory):
    return write_volume_store(tmp_path_factory.mktemp("v") / "s.zarr", samples, "quadratic", chunks=TILE,
                              spacing=(0.5, 0.5, 0.5), origin=(-3.0, 1.0, 2.0), progress=False)


@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_window_is_the_in_memory_spline_of_its_cubes(samples, store, tmp_path, scheme):
    s = store if scheme == "quadratic" else write_volume_store(tmp_path / "c.zarr", samples, "cubic", chunks=TILE,
                                                               spacing=(0.5, 0.5, 0.5), origin=(-3.0, 1.0, 2.0),
                                                               progress=False)
    full = VolumeSpline(samples, scheme, order="zyx", spacing=(0.5, 0.5, 0.5), origin=(-3.0, 1.0, 2.0))
    rng = np.random.default_rng(0)
    # inside (neighbouring samples as the layer), at the lower and the upper border (the store's padding)
    for k0, k1, j0, j1, i0, i1 in [(1, 2, 1, 2, 1, 2), (0, 2, 0, 1, 1, 3), (1, 3, 2, 3, 0, 3)]:
        w = s.window(k0, k1, j0, j1, i0, i1)
        a = (k0 * TILE, min(k1 * TILE, N))
        b = (j0 * TILE, min(j1 * TILE, N))
        c = (i0 * TILE, min(i1 * TILE, N))
        assert w.shape == (a[1] - a[0], b[1] - b[0], c[1] - c[0])
        # the same float64 numbers as the in-memory padding (the store's is computed by the same formula)
        assert np.array_equal(w.padded, full.padded[a[0]:a[1] + 2, b[0]:b[1] + 2, c[0]:c[1] + 2])
        cubes = rng.integers(0, np.array(w.shape[::-1]), size=(200, 3))
        got = w.cube_coefficients(cubes)
        want = full.cube_coefficients(cubes + np.array([c[0], b[0], a[0]]))
        assert np.array_equal(got, want)  # same data, same products: bit for bit
        lo = np.array(w.bounds[::2]) + 1e-9
        hi = np.array(w.bounds[1::2]) - 1e-9
        pts = lo + rng.random((300, 3)) * (hi - lo)
        # the points' index coordinates are (p - origin) / spacing with the window's origin: they differ by
        # roundings of numbers up to N (a few ulps of N each), which move the value by the gradient times that
        val, grad = full.evaluate(pts, gradient=True)
        tol = 8 * np.finfo(float).eps * (N * np.abs(grad * 0.5).sum(axis=1) + np.abs(val))
        assert (np.abs(w.evaluate(pts) - val) <= tol).all()
    with pytest.raises(ValueError, match="must be non-empty and inside the store's 3x3x3 tiles"):
        s.window(0, 4, 0, 1, 0, 1)


def test_decimated_level_is_the_spline_of_every_2_to_the_L_th_sample(samples, store):
    for L in (1, 2):
        st = 1 << L
        ref = VolumeSpline(samples[::st, ::st, ::st], "quadratic", order="zyx")  # padding: linear extrapolation
        n = ref.shape[0]
        for q in [(slice(0, n),) * 3, (slice(2, n - 1), slice(0, 4), slice(1, n))]:
            P = rv._level_padded(store, L, q)
            want = ref.padded[q[0].start:q[0].stop + 2, q[1].start:q[1].stop + 2, q[2].start:q[2].stop + 2]
            assert np.array_equal(P, want)


def test_bricks_in_view_hold_the_isovalue(samples, store):
    full = VolumeSpline(samples, "quadratic", order="zyx")
    lo, hi = full.cube_ranges()
    t = TILE
    b = rv.view_bricks(store, ISO, "all")
    straddle = {(k, j, i) for k in range(3) for j in range(3) for i in range(3)
                if lo[k * t:(k + 1) * t, j * t:(j + 1) * t, i * t:(i + 1) * t].min() <= ISO
                <= hi[k * t:(k + 1) * t, j * t:(j + 1) * t, i * t:(i + 1) * t].max()}
    assert {tuple(x) for x in b.tolist()} == straddle and 0 < len(straddle) < 27
    # every relevant cube of the whole volume lies in one of them
    rel = full.relevant(ISO).cubes[:, ::-1] // t
    assert {tuple(x) for x in rel.tolist()} <= straddle
    # a box: its bricks holding the isovalue are read, and the cubes drawn are the whole volume's relevant cubes
    # of those bricks with the same tetrahedra (the float32 cube test subtracts the mid-range of the data, the
    # window's here and the volume's there: both are supersets of the exact answer, equal on these data)
    b = rv.view_bricks(store, ISO, (8.0, 20.0, 0.0, 9.0, 0.0, 30.0))
    v = rv.load_volume_view(store, ISO, b)
    assert v.level == 0 and v.read == len(b) == 7
    off = np.array([q.start for q in v.cubes])[::-1]
    got = dict(zip(map(tuple, (v.isosurface.relevant.cubes + off).tolist()), v.isosurface.relevant.masks.tolist()))
    inb = {tuple(x) for x in b.tolist()}
    r = full.relevant(ISO)
    want = {tuple(c): m for c, m in zip(r.cubes.tolist(), r.masks.tolist()) if (c[2] // t, c[1] // t, c[0] // t) in inb}
    assert len(want) > 1000 and got == want
    with pytest.raises(ValueError, match="no brick of the volume store"):
        rv.load_volume_view(store, 2.0, rv.view_bricks(store, 2.0, "all"))


def _shot(pl):
    im = pl.screenshot().astype(int)
    pl.close()
    return im


@pytest.mark.gl
def test_camera_view_reads_its_bricks_and_draws_the_in_memory_isosurface(samples, store, monkeypatch):
    import splinevis

    reads = []
    real = rv._read_brick
    monkeypatch.setattr(rv, "_read_brick", lambda s, k, j, i: reads.append((k, j, i)) or real(s, k, j, i))
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    pl.camera_position = CAMERA
    actor = pl.add_isosurface_store(store, ISO, lights=1)
    view = actor.store_view
    expect = {tuple(b) for b in rv.view_bricks(store, ISO, renderer=pl.renderer).tolist()}
    got = _shot(pl)
    everything = {tuple(b) for b in rv.view_bricks(store, ISO, "all").tolist()}
    # only the bricks that hold the isovalue in view were read, each once: a proper part of those holding it
    assert view.level == 0 and sorted(reads) == sorted(expect) and len(reads) == view.read
    assert 0 < len(reads) < len(everything)
    # the whole in-memory isosurface from the same camera
    full = VolumeSpline(samples, "quadratic", order="zyx", spacing=(0.5, 0.5, 0.5), origin=(-3.0, 1.0, 2.0))
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    pl.add_spline(Isosurface(full, ISO), lights=1)
    pl.camera_position = CAMERA
    pl.reset_camera_clipping_range()
    want = _shot(pl)
    hit = want.sum(-1) < 750
    assert hit.mean() > 0.2  # the surface covers a good part of the picture
    # same float64 data; the float32 texture holds data minus the mid-range of the data drawn (the window's,
    # not the whole volume's), so roots move by float32 roundings (~1e-7 of the cube): a shade changes by a
    # unit in rare pixels, a silhouette pixel may flip
    diff = np.abs(got - want).max(-1)
    assert (diff == 0).mean() > 0.999 and (diff > 8).mean() < 0.001


@pytest.mark.gl
def test_level_fits_the_budget_and_the_texture(samples, store, monkeypatch):
    import splinevis
    from splinevis.gl import proxies

    every = rv.view_bricks(store, ISO, "all")
    v0 = rv.load_volume_view(store, ISO, every)
    n0 = int(np.prod(v0.shape))
    assert v0.level == 0 and [(q.start, q.stop) for q in v0.cubes] == [(0, 32), (0, 40), (0, 40)]
    v = rv.load_volume_view(store, ISO, every, max_cubes=n0 - 1)  # one cube too many: level 1
    assert v.level == 1 and v.read == 0 and v.isosurface.spline.spacing.tolist() == [1.0, 1.0, 1.0]
    # a texture of one row of 1024 RGBA texels holds 4096 floats: level 1's 19 x 22 x 22 padded samples do
    # not fit, level 2's 11 x 12 x 12 do
    monkeypatch.setattr(proxies, "MAX_TEXTURE_ROWS", 1)
    monkeypatch.setattr(proxies, "TEXTURE_WIDTH", 1024)
    v = rv.load_volume_view(store, ISO, every)
    assert v.level == 2 and v.read == 0 and v.shape == (9, 10, 10)
    monkeypatch.undo()
    # its cubes cover those of level 0 (along y and x up to the last sample of the level, 36 of 0..39)
    b0, b = v0.isosurface.spline.bounds, v.isosurface.spline.bounds
    assert b[0] <= b0[0] and b[2] <= b0[2] and b[4] <= b0[4] and b[5] >= b0[5]
    assert (b[1], b[3]) == (-3.0 + 9.5 * 2.0, 1.0 + 9.5 * 2.0)  # sample 36 and half a cube of 2: the level's end
    assert v.isosurface.spline.origin.tolist() == [-3.0, 1.0, 2.0]  # sample 0 is the store's
    # it is the spline of every 4th sample over those cubes
    ref = VolumeSpline(samples[::4, ::4, ::4], "quadratic", order="zyx")
    assert np.array_equal(v.isosurface.spline.padded, ref.padded[:11, :12, :12])
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    actor = pl.add_isosurface_store(store, ISO, "all", level=2, lights=1)
    assert actor.store_view.shape == (9, 10, 10)
    im = _shot(pl)
    assert (im.sum(-1) < 750).mean() > 0.05  # drawn
    with pytest.raises(ValueError, match=r"level must be in 0\.\.4"):  # 40, 20, 10, 5, 3 samples
        rv.load_volume_view(store, ISO, every, level=5)


def test_a_thin_last_brick_is_drawn_with_its_neighbours_cubes(tmp_path):
    # 34 cubes in bricks of 16: the last brick has 2 cubes, fewer than the stencil's 3
    z, y, x = np.mgrid[0:34, 0:34, 0:34].astype(float)
    f = np.sin(x / 3) + y / 10 + z / 20
    s = write_volume_store(tmp_path / "s.zarr", f, chunks=16, progress=False)
    full = VolumeSpline(f, order="zyx")
    iso = float(full.evaluate([[32.5, 32.5, 32.5]])[0])  # a surface through the last brick
    v = rv.load_volume_view(s, iso, np.array([[2, 2, 2]]))
    assert v.level == 0 and v.read == 1 and v.cubes == (slice(31, 34),) * 3  # one cube of brick 1 per axis
    assert np.array_equal(v.isosurface.spline.padded[2:, 2:, 2:], full.padded[33:, 33:, 33:])  # the read part
    r = full.relevant(iso)
    want = {tuple(c) for c in r.cubes.tolist() if min(c) >= 32}
    assert want and {tuple(c) for c in (v.isosurface.relevant.cubes + 31).tolist()} == want
