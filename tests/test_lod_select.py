"""View-dependent levels of detail (splinevis.nurbs.lod.select) on a fake LodModel, checked against brute
force, and the walkthrough pipeline (splinevis.nurbs.lod.pipeline) threaded and in sequence. No timing."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from _camera import look_at as _look_at
from _camera import perspective as _perspective
from splinevis.nurbs.lod.bvh import back_facing, build_bvh, frustum_planes
from splinevis.nurbs.lod.select import projection_scale, select_levels


def _ortho(half_height, aspect, near, far):
    P = np.eye(4)
    P[0, 0], P[1, 1] = 1.0 / (half_height * aspect), 1.0 / half_height
    P[2, 2], P[2, 3] = -2.0 / (far - near), -(far + near) / (far - near)
    return P


def _fake_lod(boxes, axis, half, tolerance=(0.01, 0.04, 0.16, 0.64)):
    boxes = np.asarray(boxes, dtype=np.float64)
    S, L = boxes.shape[0], len(tolerance)
    return SimpleNamespace(bvh=build_bvh(boxes), boxes=boxes,
                           supers=SimpleNamespace(axis=np.asarray(axis, float), half_angle=np.asarray(half, float)),
                           tolerance=np.asarray(tolerance, dtype=np.float64),
                           triangles=np.tile(4 ** np.arange(L)[::-1], (S, 1)), size=float(np.ptp(boxes)))


def _random_lod(S=600, seed=0):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-20, 20, (S, 3))
    hi = lo + rng.uniform(0.05, 2.0, (S, 3))
    boxes = np.stack([lo, hi], axis=2).reshape(S, 6)
    axis = rng.normal(size=(S, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    half = rng.uniform(0.0, 1.2, S)
    half[::17] = math.pi  # no cone: never back-facing
    return _fake_lod(boxes, axis, half)


def _outside(box, planes):
    """Brute force: the box's 8 corners all on the negative side of one plane."""
    corners = np.array([[x, y, z] for x in box[0:2] for y in box[2:4] for z in box[4:6]])
    return any(((corners @ p[:3] + p[3]) < 0).all() for p in planes)


CAMERAS = [((30.0, -25.0, 12.0), (0.0, 0.0, 0.0)), ((0.0, 0.0, 0.0), (5.0, 1.0, -0.5)),
           ((-3.0, 2.0, 40.0), (-2.0, 1.0, 0.0))]


@pytest.mark.parametrize("eye, focal", CAMERAS)
def test_culled_sets_equal_brute_force(eye, focal):
    lod = _random_lod()
    M = _perspective(math.radians(40.0), 4 / 3, 0.5, 200.0) @ _look_at(eye, focal)
    levels, stats = select_levels(lod, eye, M, 300)
    planes = frustum_planes(M)
    outside = np.array([_outside(b, planes) for b in lod.boxes])
    back = np.array([bool(back_facing(lod.supers.axis[i:i + 1], lod.supers.half_angle[i:i + 1],
                                      lod.boxes[i:i + 1], eye)[0]) for i in range(len(lod.boxes))])
    assert stats["culled_frustum"] == int(outside.sum())
    assert stats["culled_back"] == int((back & ~outside).sum())
    np.testing.assert_array_equal(levels < 0, outside | back)
    assert stats["visible"] == int((levels >= 0).sum()) == sum(stats["per_level"])
    # without back-patch culling only the frustum decides
    levels2, stats2 = select_levels(lod, eye, M, 300, cull_back=False)
    np.testing.assert_array_equal(levels2 < 0, outside)
    assert stats2["culled_back"] == 0
    # and without either nothing is culled but the back-facing ones when asked
    levels3, _ = select_levels(lod, eye, M, 300, cull_back=False, cull_frustum=False)
    assert (levels3 >= 0).all()


def test_back_culled_patches_are_back_facing_at_samples():
    lod = _random_lod(seed=3)
    eye = np.array([25.0, 25.0, 25.0])
    M = _perspective(math.radians(60.0), 1.0, 0.5, 200.0) @ _look_at(eye, (0.0, 0.0, 0.0))
    _, stats = select_levels(lod, eye, M, 200)
    assert stats["culled_back"] > 0
    rng = np.random.default_rng(7)
    back = back_facing(lod.supers.axis, lod.supers.half_angle, lod.boxes, eye)
    for i in np.flatnonzero(back):
        b = lod.boxes[i]
        p = rng.uniform(b[0::2], b[1::2], (200, 3))
        a, h = lod.supers.axis[i], lod.supers.half_angle[i]
        # normals within the cone: the axis tilted by up to h
        t = rng.normal(size=(200, 3))
        t -= np.outer(t @ a, a)
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        ang = rng.uniform(0.0, h, 200)
        n = np.cos(ang)[:, None] * a + np.sin(ang)[:, None] * t
        assert (np.einsum("ij,ij->i", p - eye, n) > 0).all()


def _row(distances, tolerance=(0.01, 0.04, 0.16, 0.64)):
    """Unit boxes on the -z axis of a view from the origin, at the given distances."""
    boxes = [[-0.5, 0.5, -0.5, 0.5, -d - 1.0, -d] for d in distances]
    S = len(boxes)
    return _fake_lod(boxes, np.tile([0.0, 0.0, 1.0], (S, 1)), np.full(S, math.pi), tolerance)


def test_level_is_monotone_in_distance_and_pixel_error():
    distances = np.geomspace(0.5, 5000.0, 60)
    lod = _row(distances)
    M = _perspective(math.radians(30.0), 1.0, 0.1, 1e4) @ _look_at((0, 0, 0), (0, 0, -1), (0, 1, 0))
    previous = None
    for pe in (0.25, 0.5, 1.0, 2.0, 4.0, 16.0):
        levels, stats = select_levels(lod, (0, 0, 0), M, 480, pixel_error=pe)
        assert (levels >= 0).all() and (np.diff(levels) >= 0).all()
        if previous is not None:
            assert (levels >= previous).all()
        previous = levels
        # the chosen level's projected error is within the bound, the next coarser one's is not
        k = 480 / (2 * math.tan(math.radians(15.0)))
        err = lod.tolerance[None, :] * k / distances[:, None]
        chosen = err[np.arange(distances.size), levels]
        ok = chosen <= pe * (1 + 1e-12)
        assert (ok | (levels == 0)).all()
        assert stats["needs_finer"] == int((~ok).sum())
        coarser = levels + 1 < lod.tolerance.size
        assert (err[np.flatnonzero(coarser), levels[coarser] + 1] > pe).all()
        # finer steps where level 0 is too coarse: the smallest j with tol_0 / 4**j within the bound (brute force)
        need = np.zeros(distances.size, dtype=np.int64)
        for i in np.flatnonzero(~ok):
            need[i] = next(j for j in range(1, 99) if err[i, 0] / 4.0 ** j <= pe * (1 + 1e-12))
        np.testing.assert_array_equal(stats["finer_steps"], np.minimum(need, 4))
        assert stats["finer_capped"] == int((need > 4).sum())
    levels, stats = select_levels(lod, (0, 0, 0), M, 480, pixel_error=None)
    assert (levels == 0).all() and stats["needs_finer"] == 0


def test_eye_inside_a_box_gets_the_finest_level():
    lod = _row([-0.5, 10.0])  # the first box holds the eye
    M = _perspective(math.radians(30.0), 1.0, 0.1, 1e4) @ _look_at((0, 0, 0), (0, 0, -1), (0, 1, 0))
    levels, stats = select_levels(lod, (0, 0, 0), M, 480, pixel_error=1.0, cull_back=False)
    assert levels[0] == 0 and stats["needs_finer"] >= 1
    # infinitely many finer steps: the cap, counted where it binds
    assert stats["finer_steps"][0] == 4 and stats["finer_capped"] >= 1
    _, stats = select_levels(lod, (0, 0, 0), M, 480, pixel_error=1.0, cull_back=False, max_finer=2, finer_ratio=2.0)
    assert stats["finer_steps"][0] == 2
    with pytest.raises(ValueError, match="finer_ratio must be > 1"):
        select_levels(lod, (0, 0, 0), M, 480, finer_ratio=1.0)


def test_field_of_view_from_the_matrix_and_parallel_projection():
    V = _look_at((1.0, 2.0, 3.0), (0.0, 0.0, 0.0))
    fov = math.radians(37.0)
    persp, k = projection_scale(_perspective(fov, 1.6, 0.1, 100.0) @ V, 600)
    assert persp and k == pytest.approx(600 / (2 * math.tan(fov / 2)), rel=1e-12)
    persp, k = projection_scale(_ortho(5.0, 1.6, 0.1, 100.0) @ V, 600)
    assert not persp and k == pytest.approx(60.0, rel=1e-12)
    # parallel: the level does not depend on the distance
    lod = _row(np.geomspace(1.0, 500.0, 20))
    M = _ortho(5.0, 1.0, 0.1, 1e4) @ _look_at((0, 0, 0), (0, 0, -1), (0, 1, 0))
    levels, _ = select_levels(lod, (0, 0, 0), M, 480, pixel_error=3.0, cull_back=False)
    assert len(set(levels.tolist())) == 1
    # 48 pixels per unit: 0.04 * 48 = 1.92 <= 3 < 0.16 * 48
    assert levels[0] == 1


# -------------------------------------------------------------------------------- the pipeline
def _fake_assemble(lod, levels):
    """Two triangles per drawn super-surface and level (a stand-in for levels.assemble)."""
    drawn = np.flatnonzero(levels >= 0)
    tri = np.repeat(drawn, 2 + levels[drawn])[:, None] * 4 + np.array([0, 1, 2])
    return lod.points, tri.astype(np.int64), {"triangles": int(tri.shape[0])}


def _frames(lod, path, threaded, assemble=None):
    import pyvista as pv

    from splinevis.nurbs.lod.pipeline import Walkthrough

    pl = pv.Plotter(off_screen=True, window_size=(80, 60))
    try:
        return Walkthrough(lod, pl, threaded=threaded, assemble=assemble).fly(path, progress=False)
    finally:
        pl.close()


def test_pipeline_with_a_fake_assembly():
    from splinevis.nurbs.lod.pipeline import camera_path

    lod = _random_lod(S=200)
    lod.points = np.random.default_rng(0).uniform(-20, 20, (800, 3))
    still = [[(30.0, -25.0, 12.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]] * 6
    a = _frames(lod, still, False, _fake_assemble)
    b = _frames(lod, still, True, _fake_assemble)
    assert [f["triangles"] for f in a] == [f["triangles"] for f in b]
    assert a[0]["triangles"] > 0 and all(f["mesh_age"] == 0 for f in a)
    moving = _frames(lod, camera_path((-20, 22, -20, 22, -20, 22), 8), True, _fake_assemble)
    assert len(moving) == 8 and all(f["mesh_age"] >= 0 for f in moving)


def test_pipeline_threaded_and_in_sequence_draw_the_same_mesh():
    from splinevis.nurbs.exact import torus
    from splinevis.nurbs.lod.levels import build_lod
    from splinevis.nurbs.lod.pipeline import camera_path

    lod = build_lod(torus(), 0.02, levels=3, progress=False)
    still = [[(0.5, -3.0, 2.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]] * 5
    a = _frames(lod, still, False)
    b = _frames(lod, still, True)
    assert [f["triangles"] for f in a] == [f["triangles"] for f in b]
    assert a[0]["triangles"] > 0 and a[0]["visible"] == len(lod.supers.members)  # the whole torus in view
    path = camera_path((-1.5, 1.5, -1.5, 1.5, -0.5, 0.5), 10)
    for threaded in (False, True):
        frames = _frames(lod, path, threaded)
        assert [f["frame"] for f in frames] == list(range(10))
        assert all(f["triangles"] > 0 and f["mesh_age"] >= 0 for f in frames)
