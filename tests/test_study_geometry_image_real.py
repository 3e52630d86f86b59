"""Section (g) of the geometry-image study (real meshes) run on a tiny synthetic closed mesh passed as the data
folder (a few seconds): the tables' values are consistent with what they claim, the triangle counts are matched
as the module says, the figure is written and every panel shows a surface; a missing data folder skips the
section without failing. No timing asserts."""

import numpy as np
import pytest
from PIL import Image

from datasets_synthetic.closed_meshes import star_blob
from splinevis.studies.geometry_image_real import matched_steps, real_mesh_markdown, real_mesh_section

N, LEVEL = 17, 1  # a 17 x 17 image drawn at level 1: 2 (16 * 2)^2 = 2,048 triangles


@pytest.fixture(scope="module")
def section(tmp_path_factory):
    data = tmp_path_factory.mktemp("meshes")
    star_blob(level=2).save(data / "blob.ply")  # 320 triangles
    out = tmp_path_factory.mktemp("out")
    return out, real_mesh_section(out, data_dir=data, names=("blob", "absent"), n=N, level=LEVEL, size=(160, 160),
                                  progress=False)


def test_build_row(section):
    _, s = section
    assert s["available"] and s["missing"] == ["absent"]
    (b,) = s["build"]
    assert (b["mesh"], b["triangles_in"], b["n"], b["flipped"]) == ("blob", 320, N, 0)
    assert 0.0 <= b["rms"] <= b["hausdorff"]  # an RMS never exceeds the largest value it averages
    assert b["limit_triangles"] == 2 * ((N - 1) * 4) ** 2 and 0 <= b["folded_limit"] <= b["limit_triangles"]
    assert b["total_s"] > 0 and b["fit_s"] > 0
    # built in a process of its own: its peak holds at least the imported libraries (numpy, scipy, pyvista: tens of
    # MB); NaN would mean not measured
    assert 30.0 < b["memory_mb"] and b["memory_mb"] == b["memory_mb"]
    assert 0.0 <= b["folds_level4"] <= 1.0 and 0.0 <= b["reversed"] <= 1.0
    assert 1.0 <= b["anisotropy_median"] <= b["anisotropy_p95"]  # sigma_1 / sigma_2, at least 1 by its definition


def test_equal_triangle_rows(section):
    _, s = section
    rows = {r["method"]: r for r in s["equal_triangles"]}
    assert set(rows) == {"geometry image", "Loop (MeshLab)", "Catmull-Clark (MeshLab)"}
    gi = rows["geometry image"]
    assert gi["triangles"] == 2 * ((N - 1) << LEVEL) ** 2
    steps = matched_steps(320, gi["triangles"])
    for key, method in (("loop", "Loop (MeshLab)"), ("catmull_clark", "Catmull-Clark (MeshLab)")):
        # the subdivision ran the steps chosen for it: its triangle count is the one matched_steps predicts
        assert rows[method]["triangles"] == steps[key][1]
    # Loop's counts are 4x apart, so the nearest in ratio is within a factor 2; Catmull-Clark's too once the image
    # has 3 or more triangles per input triangle (its first step makes 6): here 2,048 / 320 = 6.4
    assert 0.5 <= rows["Loop (MeshLab)"]["ratio"] <= 2.0 and 0.5 <= rows["Catmull-Clark (MeshLab)"]["ratio"] <= 2.0
    for r in rows.values():
        assert r["hausdorff"] == max(r["to_input_max"], r["from_input_max"])
        # a weighted mean is at most the largest value; the drawn mesh's vertices are among the samples
        assert 0.0 <= r["mean"] <= r["to_input_max"] <= r["hausdorff"]
        assert 0.0 <= r["normal_rms_deg"] <= r["normal_max_deg"] <= 180.0
        assert r["normal_p99_deg"] <= r["normal_max_deg"]
        assert 0 <= r["folded"] <= r["triangles"] and r["edge_max"] > 0
    # one step of Loop or Catmull-Clark makes every point a convex combination of input vertices within one
    # triangle fan of an input vertex v (Loop: v's ring or an edge's two triangles; Catmull-Clark: face centroids,
    # edge points, vertex points), so it lies within the longest input edge of v, a point of the input
    blob = star_blob(level=2)
    V, F = np.asarray(blob.points), blob.faces.reshape(-1, 4)[:, 1:]
    longest = np.linalg.norm(V[F] - V[np.roll(F, 1, axis=1)], axis=2).max() / np.linalg.norm(np.ptp(V, axis=0))
    assert steps["loop"][0] == steps["catmull_clark"][0] == 1
    for method in ("Loop (MeshLab)", "Catmull-Clark (MeshLab)"):
        assert rows[method]["to_input_max"] <= longest


def test_figure_every_panel_drawn(section):
    out, s = section
    assert s["figures"] == ["geometry-image_real_blob.png"]
    img = np.asarray(Image.open(out / s["figures"][0]).convert("L"), dtype=float)
    h, w = img.shape
    body = img[int(0.25 * h):]  # below the titles
    for k in range(4):  # input, Loop, Catmull-Clark, geometry image side by side, then where it folds
        panel = body[:, k * w // 5:(k + 1) * w // 5]
        # a blank panel is white; a drawn blob with reflection lines covers a good part of it with dark stripes
        assert (panel < 200).mean() > 0.05, k
    where = body[:, 4 * w // 5:]  # the input in light grey (and the defects in colour, none on this blob)
    assert (where < 245).mean() > 0.05


def test_markdown_and_missing_data(section, tmp_path):
    _, s = section
    md = real_mesh_markdown(s)
    assert "## (g) Real meshes" in md and "| blob | geometry image |" in md
    assert "![geometry-image_real_blob.png](geometry-image_real_blob.png)" in md and "not found: absent" in md
    skipped = real_mesh_section(tmp_path, data_dir=tmp_path / "nothing", progress=False)
    assert not skipped["available"] and not skipped["build"] and not list(tmp_path.glob("*.png"))
    assert "Skipped: the data folder" in real_mesh_markdown(skipped)
