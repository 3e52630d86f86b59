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
    assert not hasattr(actor, "culler") or actor.culler is None  # no axis-aligned culling of a rotated lattice
    pl.close()


def test_a_sheared_lattice_is_refused_with_a_clear_error():
    shear = np.array([[1.0, 0.3, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"not orthonormal \(a shear or non-orthogonal axes.*Resample onto an "
                                         r"orthogonal lattice"):
        VolumeGrid(_field(), spacing=SPACING, direction=shear)
