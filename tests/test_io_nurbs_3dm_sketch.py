"""Rhino files: the curves, points and point clouds beside the surfaces are drawn (sampled curves as line
segments, points as vertices); text dots and other annotations are counted, not drawn, and nothing is skipped
with a warning. Known values: a circle of radius R sampled at 64 points per span of its NURBS form lies on
the circle to rounding, and its chords stay within R (1 - cos(pi / n)) of it; the point is where it was put."""

import warnings

import numpy as np
import pytest

R = 2.5


@pytest.fixture
def sketch_file(tmp_path):
    import rhino3dm

    P = rhino3dm.Point3d
    f = rhino3dm.File3dm()
    f.Objects.AddSphere(rhino3dm.Sphere(P(0, 0, 0), 1.0))
    f.Objects.AddCircle(rhino3dm.Circle(P(1, 2, 3), R))
    f.Objects.AddPoint(P(4, 5, 6))
    cloud = rhino3dm.PointCloud()
    for k in range(7):
        cloud.Add(P(k, -k, 0.5 * k))
    f.Objects.AddPointCloud(cloud)
    f.Objects.AddTextDot("label", P(0, 0, 2))
    path = tmp_path / "sketch.3dm"
    assert f.Write(str(path), 7)
    return path


def test_curves_points_and_clouds_are_drawn_beside_the_surfaces(sketch_file):
    from splinevis.io import read_nurbs

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing skipped with a warning
        m = read_nurbs(sketch_file)
    assert len(m) == 1 and m.skipped == {}
    by_kind = {T.shape[1]: (P, T) for _, P, T in m.companion_meshes()}
    assert len(m.companion_meshes()) == 3 and sorted(by_kind) == [1, 2]
    # the circle: every sample on it to rounding, closed, chords within the sagitta of its step
    circle = [(P, T) for _, P, T in m.companion_meshes() if T.shape[1] == 2][0]
    P, T = circle
    r = np.linalg.norm(P - [1, 2, 3], axis=1)
    assert np.abs(r - R).max() <= 1e-12 * R and np.allclose(P[:, 2], 3.0, atol=1e-12)
    assert np.abs(P[0] - P[-1]).max() <= 1e-12 * R
    mid = 0.5 * (P[T[:, 0]] + P[T[:, 1]])
    step = np.max(np.arccos(np.clip(np.einsum("ij,ij->i", P[T[:, 0]] - [1, 2, 3], P[T[:, 1]] - [1, 2, 3]) / R**2, -1, 1)))
    assert R - np.linalg.norm(mid - [1, 2, 3], axis=1).max() <= R * (1 - np.cos(step / 2)) * (1 + 1e-9)
    points = sorted((len(P), tuple(P[0])) for _, P, T in m.companion_meshes() if T.shape[1] == 1)
    assert points == [(1, (4.0, 5.0, 6.0)), (7, (0.0, 0.0, 0.0))]
    assert m.report["annotations"] == {"TextDot": 1} and "TextDot" in m.source


def test_a_bad_cell_shape_is_refused_with_the_shapes():
    from splinevis.nurbs import NurbsModel
    from splinevis.nurbs.exact import saddle

    with pytest.raises(ValueError, match=r"cells must be triangles \(m, 3\), segments \(m, 2\) or points"):
        NurbsModel([saddle()], meshes=[("quad", np.zeros((4, 3)), [[0, 1, 2, 3]])])


@pytest.mark.gl
def test_the_plotter_draws_curves_and_points_dark_beside_the_surface(sketch_file):
    import splinevis
    from splinevis.io import read_nurbs

    model = read_nurbs(sketch_file)
    segments = [len(T) for _, P, T in model.companion_meshes() if T.shape[1] == 2]
    pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
    actor = pl.add_nurbs(model)
    data = [a.mapper.dataset for a in actor.companions]
    assert sorted(d.n_verts for d in data) == [0, 1, 7] and sorted(d.n_lines for d in data) == [0, 0] + segments
    assert all(a.prop.lighting is False for a in actor.companions)
    img = pl.screenshot(return_img=True)
    pl.close()
    dark = (img[..., :3].astype(int).max(axis=-1) <= 0x30).sum()  # the unlit #202020 circle and points
    assert dark >= 50
