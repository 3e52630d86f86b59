"""The geometry-image program (kind 'passes'): the GPU passes against the float64 twin on the declared hard cases,
continuous level of detail without pops, negative levels down to the octahedron, displacement mapping, and what
users see (pictures that show the surface, the same picture at UTM-sized coordinates, clear errors)."""

import numpy as np
import pytest

import splinevis
from datasets_synthetic.closed_meshes import star_blob, torus_mesh
from splinevis.errors import MeshTopologyError
from splinevis.geometry_image.build import geometry_image_from_mesh
from splinevis.geometry_image.program import PROGRAM, displacement_map, min_level, surface_arrays
from splinevis.geometry_image.subdivision import geomorph, subsample
from _subdivision_bounds import C_LIMIT, U32, control_bounds, gamma

def position_bound(levels, M, fractional):
    """Float32 bound on |GPU limit point - exact| for an image with max|G - centre| = M (the passes run relative
    to the centre): the control points' bound after ``levels`` steps (upload, splits and averages,
    tests/_subdivision_bounds.py), then the limit mask adds gamma_10 (M + e) and a geomorph pass (a linear
    subdivision and a blend, 4 roundings) gamma_4 (M + e); adding the centre back in float64 is exact to 2^-53 of
    the coordinates, counted by the caller. The twin's own float64 error is below 1e-12 M at these levels."""
    e = control_bounds(levels, M, U32, upload=1)[-1]
    e += gamma(C_LIMIT, U32) * (M + e)
    if fractional:
        e += gamma(4, U32) * (M + e)
    return np.sqrt(3.0) * e + 1e-12 * M  # componentwise -> Euclidean


@pytest.mark.gl
@pytest.mark.parametrize("case", PROGRAM.hard_cases(), ids=lambda c: c.name)
def test_hard_cases_gpu_equals_twin_and_shows_the_surface(case):
    image = case.model()
    level = case.program_options["level"]
    gpu = surface_arrays(image, level, backend="gpu")
    twin = surface_arrays(image, level, backend="numpy")
    G = image.control.reshape(-1, 3)
    centre = 0.5 * (G.min(axis=0) + G.max(axis=0))
    M = float(np.abs(G - centre).max())
    k = int(np.floor(level))
    bound = position_bound(max(k + (level != k), 0), M, level != k) + 4 * 2.0 ** -53 * np.abs(centre).max()
    err = np.linalg.norm(gpu[0] - twin[0], axis=-1).max()
    assert err <= bound, (err, bound)
    cos = np.einsum("...i,...i->...", gpu[1], twin[1])
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 0.1  # normals: see the subdivision GPU test's bounds
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    pl.add_spline(image, reflection_lines=8, program_options=case.program_options)
    pl.camera_position = case.camera_for(image)
    pl.reset_camera_clipping_range()
    shown = (pl.depth_buffer() < 1).mean()
    img = pl.screenshot().astype(float)
    pl.close()
    assert shown > 0.05 and img[..., 0].std() > 20  # the surface is there, and striped


@pytest.mark.gl
def test_utm_coordinates_draw_the_same_picture_as_at_the_origin():
    """The mesh is drawn relative to its centre: shifted by UTM-sized coordinates with the camera shifted alike,
    the picture is the same but for pixels on stripe edges (float32 depth and rasterization at 1e-7 relative)."""
    image = PROGRAM.hard_cases()[0].model()
    far = np.array([4.0e5, 5.2e6, 300.0])
    shots = []
    for offset in (np.zeros(3), far):
        shifted = splinevis.geometry_image.GeometryImage(image.control + offset)
        pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
        pl.add_geometry_image(shifted, level=2, reflection_lines=8)
        pl.camera_position = [tuple(offset + (3.0, -4.0, 2.5)), tuple(offset), (0, 0, 1)]
        pl.reset_camera_clipping_range()
        shots.append(pl.screenshot().astype(int))
        pl.close()
    differ = (np.abs(shots[0] - shots[1]).max(axis=-1) > 40).mean()
    assert differ < 0.01, differ


def test_continuous_level_blends_without_pops():
    """level = k + alpha is (1 - alpha) L_lin[p^k] + alpha p^{k+1}: at alpha -> 0 the linearly subdivided p^k
    (same picture as level k), at alpha = 1 exactly level k + 1, and linear in between (no jumps)."""
    image, _ = geometry_image_from_mesh(star_blob(level=3), n=17, measure=False)
    p1 = surface_arrays(image, 2, backend="numpy")[0]
    p0 = subsample(p1, 1)
    for alpha in (0.25, 0.5, 0.75):
        p = surface_arrays(image, 1 + alpha, backend="numpy")[0]
        np.testing.assert_allclose(p, geomorph(p0, p1, alpha), atol=1e-13)
    near0 = surface_arrays(image, 1 + 1e-9, backend="numpy")[0]
    np.testing.assert_allclose(near0[::2, ::2], surface_arrays(image, 1, backend="numpy")[0], atol=1e-8)
    steps = [surface_arrays(image, 1 + a, backend="numpy")[0] for a in np.linspace(0.0 + 1e-9, 1.0 - 1e-9, 9)]
    jumps = [np.abs(b - a).max() for a, b in zip(steps, steps[1:])]
    assert max(jumps) < 1.01 * min(jumps) + 1e-12  # equal steps: linear in alpha


def test_negative_levels_end_in_the_octahedron():
    image, _ = geometry_image_from_mesh(star_blob(level=3), n=33, measure=False)
    assert min_level(33) == -4
    p, n, _ = surface_arrays(image, -4, backend="numpy")
    assert p.shape == (3, 3, 3)
    corners = p[[0, 0, 2, 2], [0, 2, 0, 2]]
    np.testing.assert_allclose(corners, corners[[0, 0, 0, 0]], atol=1e-12)  # the four corners are one vertex
    distinct = np.unique(np.round(p.reshape(-1, 3), 9), axis=0)
    assert len(distinct) == 6  # the octahedron's six vertices
    np.testing.assert_allclose(p, subsample(surface_arrays(image, 0, backend="numpy")[0], 4), atol=0)
    with pytest.raises(ValueError, match=r"level must be in \[-4, 8\]"):
        surface_arrays(image, -4.5)


def test_displacement_moves_the_surface_onto_the_mesh():
    """A displacement map of the residual along the normals (first-order exact) takes the distance of the limit
    points to the mesh from the fit's error down to the second-order remainder: asserted at least 4x smaller
    (max and RMS)."""
    import igl

    mesh = star_blob(level=4)
    image, _ = geometry_image_from_mesh(mesh, n=17, measure=False)
    V, F = np.asarray(mesh.points, dtype=np.float64), mesh.faces.reshape(-1, 4)[:, 1:].astype(np.int64)

    def distances(points):
        return np.sqrt(igl.point_mesh_squared_distance(np.ascontiguousarray(points.reshape(-1, 3)), V, F)[0])

    before = distances(surface_arrays(image, 2, backend="numpy")[0])
    d = displacement_map(image, mesh, 2)
    after = distances(surface_arrays(image, 2, displacement=d, backend="numpy")[0])
    assert after.max() < 0.25 * before.max() and np.sqrt((after ** 2).mean()) < 0.25 * np.sqrt((before ** 2).mean())
    with pytest.raises(ValueError, match=r"output grid's shape \(65, 65\)"):
        surface_arrays(image, 2, displacement=d[:-1, :-1])


@pytest.mark.gl
def test_displacement_on_the_gpu_equals_the_twin():
    mesh = star_blob(level=3)
    image, _ = geometry_image_from_mesh(mesh, n=17, measure=False)
    d = displacement_map(image, mesh, 1)
    gpu = surface_arrays(image, 1, displacement=d, backend="gpu")[0]
    twin = surface_arrays(image, 1, displacement=d, backend="numpy")[0]
    M = float(np.abs(image.control).max())
    assert np.abs(gpu - twin).max() < position_bound(1, 2 * M, False) + 4 * U32 * (M + np.abs(d).max())


def test_bad_meshes_get_clear_errors():
    pl = splinevis.Plotter(off_screen=True, window_size=(40, 30))
    try:
        with pytest.raises(MeshTopologyError, match="genus 0: mesh has genus 1"):
            pl.add_geometry_image(torus_mesh(n=8), n=9)
    finally:
        pl.close()


@pytest.mark.gl
def test_curvature_and_isophotes_on_the_smooth_surface():
    """The program computes curvature only when the scene shows it, with the NURBS program's sign (H < 0 on an
    outward convex surface: blue in the diverging map), and isophotes draw bands on the exact normals."""
    image, _ = geometry_image_from_mesh(star_blob(level=3), n=17, measure=False)
    built = PROGRAM.make(image, splinevis.Style(lights=1), level=1)
    assert "curvature" not in built.point_data
    curved = PROGRAM.make(image, splinevis.Style(output="curvature", curvature_scale=2.0), level=1)
    H, K = np.asarray(curved.point_data["curvature"]).T
    assert np.median(H) < 0 and np.median(K) > 0
    shots = {}
    for name, style in (("curvature", dict(output="curvature", curvature_scale=2.0)), ("isophotes", dict(isophotes=6))):
        pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
        pl.add_geometry_image(image, level=1, **style)
        pl.camera_position = [(3.0, -4.0, 2.5), (0, 0, 0), (0, 0, 1)]
        shown = pl.depth_buffer() < 1
        shots[name] = (pl.screenshot().astype(int), shown)
        pl.close()
    img, shown = shots["curvature"]
    assert (img[shown][:, 2] > img[shown][:, 0]).mean() > 0.9  # blue: negative mean curvature
    img, shown = shots["isophotes"]
    assert img[shown].std() > 30  # bands, not a flat shade
