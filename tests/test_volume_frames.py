"""Volumes on rotated orthogonal lattices (Gaussian cube files, NRRD/MHA/VTI direction matrices) are drawn
in their true frame through the actor's transform: known answers against the same field on an
axis-aligned lattice, and against the float64 twin on world rays."""

from __future__ import annotations

import numpy as np
import pytest

import splinevis
from splinevis.analysis.agreement import depth_agreement
from splinevis.io import VolumeGrid, read_volume
from splinevis.volume.isosurface import Isosurface
from splinevis.volume.model import VolumeSpline

N = 14
SPACING = (2.0 / (N - 1),) * 3
ORIGIN = (-1.0, -1.0, -1.0)
CAMERA = [(3.0, 2.0, 2.5), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
CLIP = (1.0, 8.0)
WINDOW = (96, 72)


def _rotation():
    a, b, c = 0.5, -0.8, 1.2
    rz = lambda t: np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1.0]])  # noqa: E731
    rx = lambda t: np.array([[1.0, 0, 0], [0, np.cos(t), -np.sin(t)], [0, np.sin(t), np.cos(t)]])  # noqa: E731
    return rz(a) @ rx(b) @ rz(c)


def _field():
    """An off-centre ellipsoid field: no symmetry hides a wrong rotation or a swapped axis."""
    z, y, x = np.meshgrid(*(ORIGIN[a] + np.arange(N) * SPACING[a] for a in (2, 1, 0)), indexing="ij")
    return np.sqrt(((x - 0.15) / 0.9) ** 2 + ((y + 0.1) / 0.6) ** 2 + ((z - 0.05) / 0.75) ** 2)


def _render(grid, camera):
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    pl.add_isosurface(grid, 0.8, lights=0, color=(1.0, 0.0, 0.0))
    pl.camera_position = camera
    pl.camera.clipping_range = CLIP
    pl.screenshot()
    depth = pl.depth_buffer()
    pl.close()
    return depth


def test_rotated_lattice_matches_the_axis_aligned_one_seen_by_the_rotated_camera():
    R, shift = _rotation(), np.array([0.3, -0.2, 0.5])
    values = _field()
    plain = VolumeGrid(values, spacing=SPACING, origin=ORIGIN)
    moved_origin = tuple(np.asarray(ORIGIN) + shift)
    rotated = VolumeGrid(values, spacing=SPACING, origin=moved_origin, direction=R)

    def move(p):  # a world point of the plain scene to the rotated scene: origin' + R (p - origin)
        return tuple(np.asarray(moved_origin) + R @ (np.asarray(p, dtype=float) - ORIGIN))

    (eye, focal, up) = CAMERA
    depth_plain = _render(plain, CAMERA)
    depth_rotated = _render(rotated, [move(eye), move(focal), tuple(R @ np.asarray(up, dtype=float))])
    hit_plain, hit_rot = depth_plain < 1.0, depth_rotated < 1.0
    assert hit_plain.sum() > 0.1 * hit_plain.size  # the surface fills a good part of the picture
    assert (hit_plain != hit_rot).sum() <= 0.01 * hit_plain.size  # coverage: at most a few silhouette pixels
    both = hit_plain & hit_rot
    assert np.abs(depth_plain - depth_rotated)[both].max() < 2e-4
    # drawn WITHOUT the rotation (the lattice frame as world) the picture differs: the test can fail
    unrotated = VolumeGrid(values, spacing=SPACING, origin=moved_origin)
    depth_wrong = _render(unrotated, [move(eye), move(focal), tuple(R @ np.asarray(up, dtype=float))])
    assert ((depth_wrong < 1.0) != hit_plain).sum() > 0.02 * hit_plain.size


def _render_normals(grid, camera):
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    pl.add_isosurface(grid, 0.8, output="normals")
    pl.camera_position = camera
    pl.camera.clipping_range = CLIP
    img = pl.screenshot().astype(np.float64) / 255.0
    depth = pl.depth_buffer()
    pl.close()
    return img, depth < 1.0


def test_normal_colours_of_a_rotated_lattice_are_world_normals():
    # the same world geometry drawn from a plain and a rotated lattice: the encoded normals are world
    # normals, so the rotated scene's colour is the plain one's normal turned by R
    R, shift = _rotation(), np.array([0.3, -0.2, 0.5])
    values = _field()
    moved_origin = tuple(np.asarray(ORIGIN) + shift)

    def move(p):
        return tuple(np.asarray(moved_origin) + R @ (np.asarray(p, dtype=float) - ORIGIN))

    eye, focal, up = CAMERA
    moved_camera = [move(eye), move(focal), tuple(R @ np.asarray(up, dtype=float))]
    plain, hit_plain = _render_normals(VolumeGrid(values, spacing=SPACING, origin=ORIGIN), CAMERA)
    rot, hit_rot = _render_normals(VolumeGrid(values, spacing=SPACING, origin=moved_origin, direction=R), moved_camera)
    both = hit_plain & hit_rot
    assert both.sum() > 0.1 * both.size
    n_plain = 2 * plain[both][:, :3] - 1
    want = 0.5 * (n_plain @ R.T + 1)  # colour of R n
    err = np.abs(rot[both][:, :3] - want)
    # 8-bit colours: each channel of the plain normal carries 1/255 of rounding, R mixes three of them
    # (|row of R|_1 <= sqrt(3)), plus the rotated picture's own 0.5/255; pixels next to a silhouette or a
    # depth step may see another sample (allowed for 1 %)
    tol = (np.sqrt(3) + 0.5) / 255
    assert np.quantile(err.max(axis=1), 0.99) <= tol
    # the lattice-frame colours (no rotation) are far off: the test can fail
    assert np.abs(rot[both][:, :3] - plain[both][:, :3]).max(axis=1).mean() > 10 * tol


def test_rotated_lattice_agrees_with_the_float64_twin_on_world_rays():
    surface = Isosurface(VolumeSpline(VolumeGrid(_field(), spacing=SPACING, origin=(0.2, -0.4, 0.1),
                                                 direction=_rotation())), 0.8)
    r = depth_agreement(surface, CAMERA, WINDOW)
    assert r["both"] > 0.1 * r["pixels"]
    assert r["hit_disagree"] <= 0.005 * r["pixels"] and r["leaks"] == 0
    assert np.all(r["depth_error"] <= r["depth_bound"])


def test_cube_file_is_drawn_in_its_frame(tmp_path):
    from datasets_synthetic.volume_files import write_cube

    R = _rotation()
    grid = VolumeGrid(_field(), spacing=SPACING, origin=ORIGIN, direction=R)
    read = read_volume(write_cube(grid, tmp_path / "density.cube"))
    assert np.allclose(read.direction, R)
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    actor = pl.add_isosurface(read, 0.8)
    assert actor.rotation is not None and np.allclose(actor.rotation, R)
    assert actor.culler is not None and actor.culler.rotation is not None  # culled in its lattice frame
    pl.close()


def test_a_sheared_lattice_is_refused_with_a_clear_error():
    shear = np.array([[1.0, 0.3, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"not orthonormal \(a shear or non-orthogonal axes.*Resample onto an "
                                         r"orthogonal lattice"):
        VolumeGrid(_field(), spacing=SPACING, direction=shear)


# --- culling in the lattice frame -------------------------------------------------------------------------

SHIFT = np.array([0.3, -0.2, 0.5])
MOVED = np.asarray(ORIGIN) + SHIFT


def _rotated_grid():
    return VolumeGrid(_field(), spacing=SPACING, origin=tuple(MOVED), direction=_rotation())


def _world(lattice_point):
    """World point of a lattice-frame point of the rotated grid: pivot + R (p - pivot)."""
    return tuple(MOVED + _rotation() @ (np.asarray(lattice_point, dtype=float) - MOVED))


def _lattice_camera(eye, focal, up):
    """A camera given in the lattice frame of the rotated grid (lattice origin = the plain scene's origin)."""
    return [_world(np.asarray(eye) + SHIFT), _world(np.asarray(focal) + SHIFT), tuple(_rotation() @ np.asarray(up))]


def _render_culled(camera, culling, view_angle=30.0):
    pl = splinevis.Plotter(off_screen=True, window_size=WINDOW)
    actor = pl.add_isosurface(_rotated_grid(), 0.8, lights=0, color=(1.0, 0.0, 0.0), culling=culling,
                              program_options={"block_size": 4})  # 4^3 blocks of 4^3 cubes: room to cull
    pl.camera_position = camera
    pl.camera.view_angle = view_angle
    pl.camera.clipping_range = CLIP
    image = np.asarray(pl.screenshot()).copy()
    depth = pl.depth_buffer()
    culler = getattr(actor, "culler", None)
    counts = None if culler is None else (culler.visible_units, len(culler.units), actor.poly.GetNumberOfPolys())
    pl.close()
    return image, depth, counts


def _same_picture(a, b):
    (img_a, depth_a, _), (img_b, depth_b, _) = a, b
    hit_a, hit_b = depth_a < 1.0, depth_b < 1.0
    assert hit_a.sum() > 0.02 * hit_a.size  # something is drawn
    # culling only drops whole proxy boxes outside the frustum: the same fragments are drawn (the tolerance
    # of the rotated-vs-plain comparison above, which is far looser than needed here)
    assert (hit_a != hit_b).sum() <= 0.01 * hit_a.size
    assert np.abs(depth_a - depth_b)[hit_a & hit_b].max() < 2e-4
    assert np.abs(img_a.astype(int) - img_b.astype(int)).max() <= 1


def test_a_rotated_lattice_is_culled_in_its_frame_without_changing_the_picture():
    whole = _lattice_camera(*CAMERA)
    on, off = _render_culled(whole, True), _render_culled(whole, False)
    assert off[2] is None and on[2] is not None
    visible, units, _ = on[2]
    assert units > 8 and visible == units  # everything in view
    _same_picture(on, off)
    assert np.array_equal(on[1], off[1])  # in fact pixel-identical

    # close to the +x +y side, looking at one corner region with a narrow lens: the far blocks are culled
    corner = _lattice_camera((0.55, 0.45, 2.6), (0.55, 0.45, 0.0), (0.0, 1.0, 0.0))
    on, off = _render_culled(corner, True, 20.0), _render_culled(corner, False, 20.0)
    visible, units, polys = on[2]
    assert 0 < visible < units and polys == 12 * visible
    _same_picture(on, off)
    assert np.array_equal(on[1], off[1])

    # looking away from the volume: nothing drawn
    away = _lattice_camera((0.0, 0.0, 3.0), (0.0, 0.0, 6.0), (0.0, 1.0, 0.0))
    image, depth, (visible, units, polys) = _render_culled(away, True)
    assert visible == 0 and polys == 0 and units > 0 and (depth == 1.0).all()


def test_the_culler_maps_frustum_planes_into_the_lattice_frame():
    # against brute force in the WORLD: a block is culled exactly when its 8 rotated corners all lie outside
    # one plane (the culler's positive-vertex test in the lattice frame is that test, the motion being rigid)
    from splinevis.hierarchy import FrustumCuller

    R = _rotation()
    units = np.argwhere(np.ones((4, 4, 4), bool)) * 4
    half = -0.5 * np.asarray(SPACING)
    culler = FrustumCuller(units, spacing=SPACING, origin=half, level=2, offset=MOVED, rotation=R)
    corners = np.array(np.meshgrid((0, 1), (0, 1), (0, 1), indexing="ij")).reshape(3, -1).T  # (8, 3)
    boxes = half + (units[:, None, :] + 4 * corners[None]) * np.asarray(SPACING)  # (64, 8, 3) lattice frame
    world = MOVED + boxes @ R.T
    rng = np.random.default_rng(3)
    culled = 0
    for _ in range(30):
        n = rng.normal(size=(6, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        planes = np.column_stack([n, rng.uniform(-0.5, 1.0, 6) - n @ MOVED])  # planes near the volume
        outside = ((world @ n.T + planes[:, 3]) < 0).all(axis=1).any(axis=1)  # (64,)
        assert culler.visible(culler.model_planes(planes)).tolist() == (~outside).tolist()
        culled += int(outside.sum())
    assert 0 < culled < 30 * 64  # both answers occur
    # without the rotation the same planes give another answer: the test can fail
    plain = FrustumCuller(units, spacing=SPACING, origin=half, level=2, offset=MOVED)
    assert any(plain.visible(plain.model_planes(p)).tolist() != culler.visible(culler.model_planes(p)).tolist()
               for p in [np.column_stack([n, rng.uniform(-0.5, 1.0, 6) - n @ MOVED])
                         for n in rng.normal(size=(30, 6, 3))])


# --- float64 twin: world-frame results --------------------------------------------------------------------

def _rays(n=400, seed=7):
    """Rays from a sphere of radius 4 around the plain lattice's centre towards points near it."""
    rng = np.random.default_rng(seed)
    o = rng.normal(size=(n, 3))
    o = 4.0 * o / np.linalg.norm(o, axis=1, keepdims=True)
    d = rng.uniform(-0.4, 0.4, size=(n, 3)) - o
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def test_twin_hits_of_a_rotated_lattice_are_world_points_and_normals():
    from splinevis.volume.program import raycast_world

    R = _rotation()
    plain = Isosurface(VolumeSpline(VolumeGrid(_field(), spacing=SPACING, origin=ORIGIN)), 0.8)
    rotated = Isosurface(VolumeSpline(_rotated_grid()), 0.8)
    o, d = _rays()
    hp = raycast_world(plain, o, d)
    hr = raycast_world(rotated, MOVED + (o - ORIGIN) @ R.T, d @ R.T)  # the same rays, moved with the lattice
    assert hp.hit.sum() > 0.5 * len(o)
    assert np.array_equal(hp.hit, hr.hit)
    h = hp.hit
    # float64 round-off scale: the rays differ by the rounding of the rigid motion (~ a few eps x |coordinates|
    # ~ 1e-15 x 5); the root in t moves by that over |grad . d| / |grad| (>~ 1e-2 for all but grazing rays),
    # so 1e-9 x extent leaves a wide margin; normals (|grad| ~ 1 .. 2) the same relative to their size
    extent = float(np.linalg.norm(np.array(_field().shape) * SPACING)) + 4.0
    assert np.abs(hr.t[h] - hp.t[h]).max() < 1e-9 * extent
    assert np.abs(hr.points[h] - (MOVED + (hp.points[h] - ORIGIN) @ R.T)).max() < 1e-9 * extent
    scale = np.linalg.norm(hp.normals[h], axis=1).max()
    assert np.abs(hr.normals[h] - hp.normals[h] @ R.T).max() < 1e-9 * scale
    # the tests can fail: the lattice-frame answers (the old behaviour) are far off
    assert np.abs(hr.normals[h] - hp.normals[h]).max() > 0.1 * scale
    # a world hit point lies on the world-frame isosurface: its lattice point has the isovalue, and the world
    # normal is the world gradient (the lattice gradient rotated)
    spline = rotated.spline
    lattice = MOVED + (hr.points[h] - MOVED) @ R
    value, grad = spline.evaluate(lattice, gradient=True)
    assert np.abs(value - 0.8).max() < 1e-10
    assert np.abs(grad @ R.T - hr.normals[h]).max() < 1e-9 * scale
    # and the hit is where the world ray is at t
    oh, dh = (MOVED + (o - ORIGIN) @ R.T)[h], (d @ R.T)[h]
    assert np.allclose(hr.points[h], oh + hr.t[h][:, None] * dh, rtol=0, atol=1e-12)
