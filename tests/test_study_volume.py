"""The volume study's pieces on tiny sizes (the full study runs in minutes; these in seconds).

Scene: the torus distance field (ring R = 0.6, tube r = 0.25, level 0) sampled on 24^3 points (h = 2/23),
a 160x120 window, one configuration per method. Tolerances are derived where possible, and say so.
"""

import json
import math

import numpy as np
import pytest

from datasets_synthetic.volumes import torus_distance
from splinevis.studies import volume as V
from splinevis.studies import volume_accuracy as A
from splinevis.studies.report import clean

WINDOW = (160, 120)


@pytest.fixture(scope="module")
def ref():
    f = torus_distance()
    return V.exact_reference(f, f.sample(24), WINDOW)


def test_unproject_inverts_window_depth(ref):
    from splinevis.gl.camera import window_depth

    pts = ref.points.copy()
    depth = np.where(ref.covered, window_depth(ref.matrix, pts), 1.0)
    back = V.unproject(ref.matrix, depth)
    assert np.isnan(back[~ref.covered]).all()
    assert np.abs(back[ref.covered] - pts[ref.covered]).max() < 1e-9


def test_two_sided_lighting_normals_are_recovered():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(2000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    intensity = np.abs(n @ A._LIGHTS.T)
    got = V.normals_from_two_sided(intensity)
    assert A._angles(got, n).max() < 1e-4  # exact inputs (arccos near 1 resolves ~1e-6 degrees): the sign pattern is recovered up to the global sign
    q = np.round(intensity * 255) / 255  # 8-bit: the components are off by <= 1/510, about 0.1 degree
    assert np.median(A._angles(V.normals_from_two_sided(q), n)) < 0.3


@pytest.mark.gl
def test_methods_on_the_torus(ref):
    from splinevis.volume.model import VolumeSpline

    r, h = ref.field.r, ref.h
    mc = V.measure_mesh(ref, method="flying_edges", upsample=1, repeats=1)
    sp = V.measure_spline(ref, VolumeSpline(ref.grid, "quadratic"), repeats=1)
    vtk = V.measure_vtk(ref, sample_distance=h / 4, repeats=1)
    for row in (mc, sp, vtk):
        assert row["frame_median_ms"] > 0
        assert row["pixels_exact"] == ref.covered.sum() > 3000
        # coverage differs only along the silhouette: a few percent of the covered pixels at most
        assert row["coverage_mismatch_rel"] < 0.05
        assert row["normal_pixels"] > 0.9 * row["pixels_exact"]
    # marching cubes: every shown point lies on a triangle whose vertices are on the linear edge interpolant
    # of the distance field; a triangle spans at most a cube face diagonal sqrt(2) h, whose sagitta on a tube
    # of radius r - h (the tightest curvature near the surface) is (sqrt(2) h)^2 / (8 (r - h)) = h^2 / (4 (r - h))
    sagitta = h * h / (4 * (r - h)) / h
    assert mc["position_err_median_h"] < sagitta
    assert mc["position_err_p95_h"] < 2 * sagitta
    # the splines are smooth second-order quasi-interpolants: their bias is O(h^2 |D^2 f|) with
    # |D^2 f| <= 1 / (r - h) near the surface; the twin's roots are exact to float64 here
    assert sp["position_err_p95_h"] < sagitta
    assert sp["gpu_twin_coverage_disagree"] <= 0.001 * sp["pixels_shown"]
    # smooth spline normals beat the interpolated vertex normals of a mesh on the same samples
    assert sp["normal_err_median_deg"] < mc["normal_err_median_deg"]
    assert sp["normal_err_median_deg"] < 2.0
    # VTK's volume: no depth, normals read back from 8-bit renders: above the read-out floor, below a few degrees
    assert vtk["position_err_median_h"] is None
    assert vtk["quantisation_floor_median_deg"] < vtk["normal_err_median_deg"] < 5.0
    json.dumps(clean([mc, sp, vtk]), allow_nan=False)


def test_approximation_and_memory_rows():
    rows = V.approximation_rows(sizes=(8, 12), schemes=("trilinear", "quadratic"), n_points=300, progress=False)
    assert {r["field"] for r in rows} == {"marschner_lobb", "blob"}
    assert len(rows) == 2 * 2 * 2
    blob_q = [r for r in rows if r["field"] == "blob" and r["scheme"] == "quadratic"]
    assert blob_q[0]["order_value_max"] is None and blob_q[1]["value_max"] < blob_q[0]["value_max"]
    mem = V.memory_rows(sizes=(16,), schemes=("quadratic",), progress=False)
    (m,) = mem
    for key in ("geometry_MB", "data_texture_MB", "determining_set_MB", "all_coefficients_MB", "octree_MB"):
        assert m[key] > 0
    # 1 float per padded sample vs 20 per relevant cube vs 24 * 10 per relevant cube
    assert m["data_texture_MB"] == pytest.approx(18 ** 3 * 4 / 2**20)
    assert m["all_coefficients_MB"] == pytest.approx(m["relevant_cubes"] * 240 * 4 / 2**20)
    assert 0 < m["relevant_cubes"] <= m["octree_candidates"] <= 16 ** 3
    assert m["preprocessing_s"] > 0 and m["second_isovalue_s"] > 0


def test_report_is_nan_free_json_and_markdown():
    result = {"quick": True, "cubic": {"available": False, "note": "cubic scheme NOT available (test)"}, "seconds": 1.0,
              "approximation": [{"field": "blob", "scheme": "quadratic", "n": 8, "h": 0.25, "value_max": 0.1,
                                 "order_value_max": None, "gradient_max": float("nan"), "order_gradient_max": None,
                                 "gradient_rms": 0.1}],
              "accuracy_setup": {"field": "torus", "grid": "8^3", "h": 0.25, "window": [160, 120], "pixels_exact": 10,
                                 "pixel_footprint_h": 0.1},
              "accuracy_vs_time": [{"method": "VTK volume", "config": "h/4", "elements": None, "frame_median_ms": 1.0,
                                    "coverage_mismatch": 0, "position_err_median_h": None,
                                    "normal_err_median_deg": math.inf}],
              "memory": [], "paper_table_1": V.PAPER_TABLE_1}
    cleaned = clean(result)
    text = json.dumps(cleaned, allow_nan=False)
    assert "NaN" not in text and "Infinity" not in text
    md = V._markdown(cleaned)
    assert "cubic scheme NOT available" in md and "### paper" in md


def test_cli_runs_the_volume_study_runner_with_its_options(monkeypatch, tmp_path, capsys):
    # `splinevis study volume --out DIR --quick` must call run_volume_study(DIR, quick=True, ...) and list what it
    # wrote; a stand-in runner records the call (the real study takes minutes and is run by the sessions)
    from splinevis.cli import main
    from splinevis.studies import volume as study_module

    calls = []

    def runner(out_dir, *, quick=False, progress=True):
        calls.append((str(out_dir), quick, progress))
        (tmp_path / "volume.md").write_text("# stand-in")
        (tmp_path / "volume.json").write_text("{}")
        return {"quick": quick}

    monkeypatch.setattr(study_module, "run_volume_study", runner)
    assert main(["study", "volume", "--out", str(tmp_path), "--quick", "--quiet"]) == 0
    assert calls == [(str(tmp_path), True, False)]
    out = capsys.readouterr().out
    assert str(tmp_path / "volume.md") in out and str(tmp_path / "volume.json") in out


def test_cubic_status_says_what_it_found(monkeypatch):
    # the cubic scheme is implemented: here it must be found
    assert V.cubic_status() == (True, "cubic scheme available")
    # and when it cannot be built, the note says so and why
    import splinevis.volume.model as model

    class Broken:
        def __init__(self, *args, **kwargs):
            raise NotImplementedError("no cubic here")

    monkeypatch.setattr(model, "VolumeSpline", Broken)
    ok, note = V.cubic_status()
    assert ok is False and note.startswith("cubic scheme NOT available (NotImplementedError: no cubic here)")


@pytest.mark.gl
def test_volume_file_example_draws_reflection_lines(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    from PIL import Image

    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "vol.png"
    res = subprocess.run([sys.executable, str(root / "examples/volume_isosurface.py"), str(out), "--scheme", "quadratic"],
                         check=True, capture_output=True, text=True, cwd=root)
    assert "blob.vti: 40x40x40 samples" in res.stdout
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    shown = ~np.all(img > 250, axis=-1)
    assert 0.1 < shown.mean() < 0.9
    dark = np.all(img < 60, axis=-1)
    assert 0.2 < dark.sum() / shown.sum() < 0.8  # stripes, not a black or an unstriped surface
