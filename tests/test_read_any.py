"""splinevis.read: any family by content, and the top-level names."""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

import splinevis


def test_read_picks_the_reader_by_content(tmp_path):
    img = pv.ImageData(dimensions=(5, 6, 7), spacing=(0.5, 0.5, 0.5))
    img.point_data["f"] = np.arange(img.n_points, dtype=np.float64)
    img.save(tmp_path / "cube.vti")
    vol = splinevis.read(tmp_path / "cube.vti")
    assert isinstance(vol, splinevis.VolumeGrid) and vol.values.shape == (7, 6, 5)
    # an OBJ exported as a triangle soup (every triangle its own vertices) comes back welded, with a warning
    sphere = pv.Sphere(theta_resolution=8, phi_resolution=8).triangulate()
    faces = sphere.faces.reshape(-1, 4)[:, 1:]
    soup = pv.PolyData(sphere.points[faces.ravel()], np.hstack([np.full((len(faces), 1), 3),
                                                                np.arange(faces.size).reshape(-1, 3)]))
    soup.save(tmp_path / "soup.obj")
    with pytest.warns(UserWarning, match="welded"):
        mesh = splinevis.read(tmp_path / "soup.obj")
    assert mesh.n_points == sphere.n_points and mesh.n_cells == sphere.n_cells


def test_read_refuses_what_it_does_not_know(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(ValueError, match="not a file splinevis reads"):
        splinevis.read(tmp_path / "notes.txt")
    with pytest.raises(FileNotFoundError, match="no such file"):
        splinevis.read(tmp_path / "missing.vti")
    with pytest.raises(ValueError, match="family 'cad' is not known"):
        splinevis.read(tmp_path / "notes.txt", family="cad")


def test_top_level_names_resolve():
    for name in splinevis.__all__:
        assert getattr(splinevis, name) is not None, name
    assert "read_volume" in dir(splinevis)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        splinevis.nothing  # noqa: B018
