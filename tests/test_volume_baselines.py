"""Baselines of the volume isosurfaces (splinevis.volume.baselines): marching cubes meshes and VTK's GPU isosurface ray caster.

Error bounds used below, for the signed distance field f(p) = |p - c| - R of a sphere sampled on spacing h:

* Marching cubes vertex. A vertex lies on a grid edge a -> a + h e at the zero of the linear interpolant
  L of g(s) = f(a + s e). Interpolation error: |g(s) - L(s)| = s (h - s) / 2 |g''(xi)| <= h^2 / 8 max|g''|,
  and g'' = (1 - (e.u)^2) / r <= 1 / r with r >= R - h on an edge that crosses the sphere. Because f is a
  distance field, the distance of the vertex to the sphere is exactly |f(vertex)| = |g(s*)| = |g - L|(s*):
      dist <= h^2 / (8 (R - h))                                   (C = 1/8)
  If the samples carry an error delta (upsampled data), L moves by at most delta: dist <= h^2/(8(R-h)) + delta.
* Trilinear interpolant (the GPU texture): error <= sum_i h^2/8 max|f_ii| <= 3 h^2 / (8 (R - sqrt(3) h)); f is
  convex so the interpolant is >= f and its zero set lies inside the sphere (silhouettes only shrink).
* VTK's isosurface blend mode shades the first ray sample past the iso value, without refining. With a parallel
  projection looking down -z every ray enters the volume's box at its front face z = z1 and samples
  z1 - k s; a ray at distance d from the axis hits iff some sample lies inside, i.e. d < sqrt(R^2 - z*^2)
  with z* the sample closest to the centre plane. So the silhouette radius is predicted exactly from the
  sample distance s (and worst case shrinks by about s^2 / (8 R)).
"""

import numpy as np
import pytest

from splinevis.io.volumes import VolumeGrid
from splinevis.volume.baselines import METHODS, marching_cubes_mesh, upsample_grid

R = 0.6


def sphere_grid(n=32, *, spacing=None, origin=(0.0, 0.0, 0.0), center=(0.0, 0.0, 0.0), sign=1.0):
    """Signed distance of a sphere of radius R (negative inside), on [-1, 1]^3 shifted by ``origin``."""
    spacing = np.full(3, 2.0 / (n - 1)) if spacing is None else np.asarray(spacing, float)
    shape = (np.round(2.0 / spacing).astype(int) + 1)[::-1]  # (nz, ny, nx)
    o = np.asarray(origin, float) - 1.0
    z, y, x = (np.arange(m) * s for m, s in zip(shape, spacing[::-1]))
    Z, Y, X = np.meshgrid(z, y, x, indexing="ij")
    c = np.asarray(center, float) + 1.0  # centre relative to the first sample
    vals = np.sqrt((X - c[0]) ** 2 + (Y - c[1]) ** 2 + (Z - c[2]) ** 2) - R
    return VolumeGrid(sign * vals, spacing=tuple(spacing), origin=tuple(o))


def _faces(mesh):
    return mesh.faces.reshape(-1, 4)[:, 1:]


def _check_sphere_mesh(mesh, center, h, delta=0.0, sign=1.0):
    p = mesh.points - np.asarray(center)
    r = np.linalg.norm(p, axis=1)
    err = np.abs(r - R).max()
    bound = h ** 2 / (8 * (R - h)) + delta
    assert err <= bound * (1 + 1e-6) + 1e-9, (err, bound)
    n = mesh.point_data["Normals"]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
    # toward increasing values: outward for sign=+1, inward for sign=-1; gradient normals within ~3 degrees
    assert (sign * np.einsum("ij,ij->i", n, p / r[:, None])).min() > 0.995
    f = _faces(mesh)
    a, b, c = (p[f[:, i]] for i in range(3))
    fn = np.cross(b - a, c - a)
    area2 = np.linalg.norm(fn, axis=1)
    ok = area2 > 1e-12 * h * h
    facing = sign * np.einsum("ij,ij->i", fn, a + b + c)[ok]
    assert (facing > 0).all(), "triangle winding not consistent with the normals"
    assert mesh.n_open_edges == 0
    return err


@pytest.mark.parametrize("method", METHODS)
def test_marching_cubes_vertices_on_sphere_and_upsampling_helps(method):
    g = sphere_grid(24, center=(0.013, -0.021, 0.007))
    h = g.spacing[0]
    center = (0.013, -0.021, 0.007)
    errs = []
    for u in (1, 2):
        mesh = marching_cubes_mesh(g, 0.0, method=method, upsample=u)
        assert mesh.is_all_triangles and mesh.n_cells == mesh.field_data["n_triangles"][0] > 100
        assert mesh.field_data["method"][0] == method and mesh.field_data["upsample"][0] == u
        assert mesh.field_data["build_seconds"][0] >= 0 and mesh.points.dtype == np.float64
        delta = 0.0
        if u > 1:  # error of the resampled data at the fine samples next to the surface
            fine = upsample_grid(g, u)
            exact = sphere_grid(spacing=fine.spacing, center=center).values
            band = np.abs(exact) < 2 * fine.spacing[0]
            delta = np.abs(fine.values - exact)[band].max()
        errs.append(_check_sphere_mesh(mesh, center, h / u, delta))
    assert errs[1] < 0.5 * errs[0], errs


@pytest.mark.parametrize("method", METHODS)
def test_orientation_follows_increasing_values(method):
    g = sphere_grid(16, sign=-1.0)  # positive inside: increasing values point inward
    mesh = marching_cubes_mesh(g, 0.0, method=method)
    _check_sphere_mesh(mesh, (0, 0, 0), g.spacing[0], sign=-1.0)
    flipped = marching_cubes_mesh(g, 0.0, method=method, orientation="decreasing")
    _check_sphere_mesh(flipped, (0, 0, 0), g.spacing[0], sign=1.0)


@pytest.mark.parametrize("method", METHODS)
def test_anisotropic_spacing_and_large_origin(method):
    origin = (1e5, -1e5, 2e5)
    spacing = (2 / 20, 2 / 28, 2 / 36)
    center = (0.05, -0.02, 0.03)
    g = sphere_grid(spacing=spacing, origin=origin, center=center)
    assert g.shape == (37, 29, 21)
    mesh = marching_cubes_mesh(g, 0.0, method=method)
    # the edge bound with the longest edge; world positions at 1e5 keep full float64 accuracy
    _check_sphere_mesh(mesh, np.add(origin, center), max(spacing))
    b = mesh.bounds
    assert abs((b[0] + b[1]) / 2 - (origin[0] + center[0])) < 0.01
    assert abs((b[4] + b[5]) / 2 - (origin[2] + center[2])) < 0.01


def test_upsample_grid_keeps_bounds_and_samples():
    z, y, x = np.meshgrid(np.arange(5), np.arange(6), np.arange(7), indexing="ij")
    g = VolumeGrid(1.0 * x + 2.0 * y + 3.0 * z, spacing=(0.5, 0.25, 2.0), origin=(10.0, 20.0, 30.0))
    for u in (2, 3, 4):
        for order in (1, 3):
            f = upsample_grid(g, u, order=order)
            assert f.shape == tuple((np.array(g.shape) - 1) * u + 1)
            assert np.allclose(f.bounds, g.bounds, rtol=0, atol=1e-12) and f.origin == g.origin
            assert np.allclose(f.values[::u, ::u, ::u], g.values, atol=1e-12)  # endpoints map onto endpoints
            if order == 1:  # trilinear reproduces the linear field exactly at o / u
                k, j, i = np.meshgrid(*(np.arange(m) / u for m in f.shape), indexing="ij")
                assert np.allclose(f.values, i + 2 * j + 3 * k, atol=1e-12)
    assert upsample_grid(g, 1) is g
    with pytest.raises(ValueError, match="1..4"):
        upsample_grid(g, 5)


@pytest.mark.parametrize("method", METHODS)
def test_empty_and_flat(method):
    g = sphere_grid(12)
    for iso in (5.0, -5.0):
        mesh = marching_cubes_mesh(g, iso, method=method)
        assert mesh.n_points == 0 and mesh.n_cells == 0
        assert "outside the data range" in mesh.field_data["note"][0]
        assert mesh.field_data["n_triangles"][0] == 0
    flat = VolumeGrid(np.full((6, 7, 8), 2.5))
    for u in (1, 2):
        mesh = marching_cubes_mesh(flat, 2.5, method=method, upsample=u)  # whatever the library does: no crash
        assert mesh.n_cells == mesh.field_data["n_triangles"][0]
        if mesh.n_cells:
            assert mesh.is_all_triangles
    step = np.zeros((6, 7, 8))
    step[:, :, 4:] = 1.0  # iso value equal to a plateau: a plane at the plateau's edge
    mesh = marching_cubes_mesh(VolumeGrid(step), 1.0, method=method)
    assert mesh.n_cells == 0 or np.ptp(mesh.points[:, 0]) < 1e-9


def test_bad_arguments():
    g = sphere_grid(8)
    with pytest.raises(ValueError, match="not known"):
        marching_cubes_mesh(g, 0.0, method="cubes")
    with pytest.raises(TypeError, match="VolumeGrid"):
        marching_cubes_mesh(g.values, 0.0)


# ----------------------------------------------------------------------------------------------------------------
# VTK GPU ray casting, isosurface blend mode (needs GL; llvmpipe is enough)

W, H = 200, 150
SCALE = 1.0  # parallel scale: half the view height in world units
PX = (H / 2) / SCALE  # pixels per world unit


def _plotter(center, z_eye=5.0):
    import splinevis

    pl = splinevis.Plotter(off_screen=True, window_size=(W, H))
    pl.set_background("black")
    c = np.asarray(center, float)
    pl.camera.position = tuple(c + (0.0, 0.0, z_eye))
    pl.camera.focal_point = tuple(c)
    pl.camera.up = (0.0, 1.0, 0.0)
    pl.enable_parallel_projection()
    pl.camera.parallel_scale = SCALE
    pl.camera.clipping_range = (z_eye - 2, z_eye + 2)
    return pl


ORANGE = (1.0, 0.5, 0.2)


def _volume_mask(image):
    # unshaded volume colour (255, 128, 51) exactly
    return (image[..., 0] == 255) & (np.abs(image[..., 1].astype(int) - 128) <= 1) & (np.abs(image[..., 2].astype(int) - 51) <= 1)


def _predicted_radius(sample_distance, z_front=1.0):
    if sample_distance is None:
        zstar = 0.0  # VTK's automatic distance (half the spacing) is far below a pixel here
    else:
        k = np.round(z_front / sample_distance)
        zstar = np.min(np.abs(z_front - np.arange(k - 1, k + 2) * sample_distance))
    return np.sqrt(R ** 2 - zstar ** 2) * PX


@pytest.mark.gl
@pytest.mark.parametrize("origin", [(0.0, 0.0, 0.0), (1e5, -1e5, 2e5)])
@pytest.mark.parametrize("sample_distance", [None, 0.1, 0.3, 0.4, 2 / 7, 0.5])
def test_vtk_isosurface_silhouette(sample_distance, origin, tmp_path):
    from splinevis.volume.baselines import add_vtk_isosurface

    g = sphere_grid(32, origin=origin)
    h = g.spacing[0]
    pl = _plotter(origin)
    vol = add_vtk_isosurface(pl, g, 0.0, sample_distance=sample_distance, shade=False, color=ORANGE)
    pl.render_now()
    image = pl.screenshot()
    pl.close()
    mapper = vol.GetMapper()
    assert mapper.GetBlendMode() == mapper.ISOSURFACE_BLEND
    assert np.allclose(vol.GetBounds(), g.bounds)
    mask = _volume_mask(image)
    assert mask.sum() > 1000, "blank image"
    ys, xs = np.nonzero(mask)
    assert abs(xs.mean() - (W - 1) / 2) < 0.3 and abs(ys.mean() - (H - 1) / 2) < 0.3
    radius = np.sqrt(mask.sum() / np.pi)
    tri = 3 * h ** 2 / (8 * (R - np.sqrt(3) * h)) * PX  # the trilinear zero set lies inside by at most this
    predicted = _predicted_radius(sample_distance)
    assert predicted - tri - 0.35 <= radius <= predicted + 0.35, (radius, predicted, tri)


@pytest.mark.gl
def test_vtk_isosurface_shaded_and_composited_with_meshes():
    """Opaque meshes in front hide the volume; the volume covers meshes behind it (rays stop at the opaque
    depth buffer). The volume writes no depth: the depth buffer shows the back plane through the sphere."""
    import pyvista as pv

    from splinevis.volume.baselines import add_vtk_isosurface

    g = sphere_grid(32)
    pl = _plotter((0, 0, 0))
    add_vtk_isosurface(pl, g, 0.0, shade=False, color=ORANGE)
    # front plane at z = +0.9 covering x < 0 ; back plane at z = -0.9 covering everything
    pl.add_mesh(pv.Plane(center=(-1.0, 0, 0.9), direction=(0, 0, 1), i_size=2.0, j_size=3.0), color="blue",
                lighting=False)
    pl.add_mesh(pv.Plane(center=(0, 0, -0.9), direction=(0, 0, 1), i_size=4.0, j_size=3.0), color="lime",
                lighting=False)
    pl.render_now()
    image = pl.screenshot()
    depth = pl.depth_buffer()
    pl.close()
    yy, xx = np.mgrid[0:H, 0:W]
    rr = np.hypot(xx - (W - 1) / 2, yy - (H - 1) / 2)
    left, right = xx < (W - 1) / 2 - 1, xx > (W - 1) / 2 + 1
    inside, outside = rr < R * PX - 1.5, rr > R * PX + 1.5
    blue = (image[..., 2] > 200) & (image[..., 0] < 50) & (image[..., 1] < 50)
    green = (image[..., 1] > 200) & (image[..., 0] < 50) & (image[..., 2] < 50)
    vol = _volume_mask(image)
    assert blue[left].mean() > 0.99  # front plane hides the left half of the sphere
    assert vol[right & inside].mean() > 0.99  # the sphere covers the back plane
    assert green[right & outside].mean() > 0.99
    # depth: front plane at z=0.9, back plane at z=-0.9 everywhere else (clipping range 3..7 -> linear in z)
    z_front, z_back = (5 - 0.9 - 3) / 4, (5 + 0.9 - 3) / 4
    assert np.allclose(depth[left], z_front, atol=2e-3)
    assert np.allclose(depth[right & inside], z_back, atol=2e-3)


@pytest.mark.gl
def test_shaded_volume_and_marching_cubes_mesh_in_one_plotter():
    """Both baselines side by side, shaded: the mesh (vertex normals) and the ray-cast volume have the same
    silhouette radius within a pixel, and shading varies across the sphere (lit, not flat)."""
    from splinevis.volume.baselines import add_vtk_isosurface

    left = sphere_grid(24, origin=(-0.8, 0.0, 0.0))
    right = sphere_grid(24, origin=(0.8, 0.0, 0.0))
    pl = _plotter((0, 0, 0))
    pl.camera.parallel_scale = 1.2
    add_vtk_isosurface(pl, left, 0.0, color=ORANGE)
    mesh = marching_cubes_mesh(right, 0.0, method="flying_edges")
    pl.add_mesh(mesh, color=ORANGE, smooth_shading=True)
    pl.render_now()
    image = pl.screenshot()
    pl.close()
    fg = image.max(axis=2) > 10
    px = (H / 2) / 1.2
    cx = [(W - 1) / 2 - 0.8 * px, (W - 1) / 2 + 0.8 * px]
    xx = np.arange(W)
    radii = []
    for c in cx:
        half = fg & (np.abs(xx - c) < 0.8 * px)[None, :]
        radii.append(np.sqrt(half.sum() / np.pi))
        lum = image[half].astype(float).mean(axis=1)
        assert lum.std() > 10, "flat shading"
    assert abs(radii[0] - R * px) < 1.0 and abs(radii[1] - R * px) < 1.0, radii
