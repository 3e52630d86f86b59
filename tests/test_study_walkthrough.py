"""The walkthrough study's comparisons (splinevis.studies.walkthrough_compare) and its report: section (b)'s
OpenCASCADE meshes matched to the levels like the uniform ones, section (e)'s simplified levels held to
delta_l + eps_l, the markdown's sections and the JSON's fields. One run of the study with ``quick=True`` on
smaller models than its quick settings (the same code path; a few tens of seconds). No timing asserts."""

import json

import numpy as np
import pytest

from splinevis.studies import walkthrough as W
from splinevis.studies import walkthrough_compare as C
from splinevis.studies.nurbs_occ import occ_available

TINY = {"main": ("teapot", 4), "main_delta": 0.1, "small": ("teapot", 1), "deltas": (0.1, 0.3),
        "hull": ("hull", 60), "hull_delta": 0.02, "frames": 8, "pixel_errors": (1.0, 4.0),
        "simplify": ("hull_noportholes", 300), "simplify_delta": 0.01, "simplify_samples": 12, "repeats": 1,
        "occ_step": 4.0, "cad_copies": 1, "cad_delta": 0.02}
SMALL_WINDOW = (320, 240)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("walkthrough")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(W, "_settings", lambda quick: dict(TINY))
        for module in (W, C):  # a smaller window: the same code path, a sixth of the pixels to render
            mp.setattr(module, "WINDOW", SMALL_WINDOW)
        result = W.run_walkthrough_study(out, quick=True, progress=False)
    return out, result


def test_json_and_markdown_have_the_new_sections(run):
    out, result = run
    data = json.loads((out / "walkthrough.json").read_text())
    assert data == result
    assert data["window"] == list(SMALL_WINDOW)
    b, e = data["lod_vs_meshes"], data["simplification"]
    assert set(b) >= {"delta", "levels", "uniform", "occ", "occ_available", "matches"}
    assert len(b["levels"]) == len(b["matches"]) == 4
    assert set(b["matches"][0]) >= {"uniform", "uniform_deviation", "uniform_ratio", "occ", "occ_deviation",
                                    "occ_triangles", "occ_frame_ms", "occ_ratio"}
    assert set(e) >= {"source", "levels", "flights", "share", "build_plain_s", "build_simplified_s"}
    assert [r["level"] for r in e["levels"]] == [0, 1, 2, 3]
    # (f): the three configurations; only the last draws exact close-ups, and it does on the close approach
    f = data["finer"]["rows"]
    assert [r["configuration"] for r in f] == ["static levels", "+ dynamic tessellation", "+ exact close-ups"]
    assert f[0]["refined"] == 0 and f[0]["closeup_frames"] == 0 and f[1]["closeup_frames"] == 0
    assert f[2]["closeup_frames"] > 0
    # (g): the plate through STEP is a closed solid at level 0 and at mixed levels
    g = data["cad"]
    assert g["available"] and g["faces"] == 32 and g["open_edges_level0"] == 0 and g["open_edges_mixed_max"] == 0
    md = (out / "walkthrough.md").read_text()
    assert "## (f) Finer than level 0" in md and "## (g) A trimmed CAD assembly through STEP" in md
    assert [(f["lod"].split()[0], f["pixel_error"]) for f in e["flights"]] == [
        ("plain", 1.0), ("simplified", 1.0), ("plain", 4.0), ("simplified", 4.0)]
    assert "0 portholes" in e["source"]
    md = (out / "walkthrough.md").read_text()
    for heading in ("## (b) LOD against uniform tessellation and OpenCASCADE at equal measured deviation",
                    "## (e) Simplified levels: bounded by delta_l + eps_l", "| OpenCASCADE / LOD triangles |",
                    "| triangles simplified |", "| Simplifier measured (max) |"):
        assert heading in md
    assert "carries no normals" not in md and "smooth shading" in md
    for png in ("walkthrough_meshes.png", "walkthrough_views.png", "walkthrough_triangles.png",
                "walkthrough_frames.png"):
        assert f"]({png})" in md and (out / png).stat().st_size > 0
    assert md.count("| plain (bounds ") == md.count("| simplified (bounds ") == 2


def test_each_match_is_the_coarsest_mesh_at_most_as_far_from_the_surface(run):
    b = run[1]["lod_vs_meshes"]
    assert b["occ_available"] == occ_available()
    if b["occ_available"]:  # OCP is part of the test environment (the extra "cad"); else the next test's case
        assert [r["deflection"] for r in b["occ"]] == pytest.approx(C.occ_deflections(
            [r["bound"] for r in b["levels"]], 4.0))
    for prefix, rows in (("uniform", b["uniform"]), ("occ", b["occ"] if b["occ_available"] else [])):
        for level, m in zip(b["levels"], b["matches"]):
            ok = [r for r in rows if r["deviation"] <= level["deviation"]]
            if not ok:
                assert m[f"{prefix}_triangles"] is None and m[prefix].startswith("none of")
                continue
            assert m[f"{prefix}_deviation"] <= m["lod_deviation"] == level["deviation"]
            assert m[f"{prefix}_triangles"] == min(r["triangles"] for r in ok)
            assert m[f"{prefix}_ratio"] == pytest.approx(m[f"{prefix}_triangles"] / level["triangles"], rel=1e-12)
    matched = [m for m in b["matches"] if m["occ_triangles"] is not None]
    assert len(matched) >= (2 if b["occ_available"] else 0)  # the coarse levels are within reach of BRepMesh


def test_without_opencascade_the_table_says_so(run, monkeypatch, tmp_path):
    from splinevis.nurbs.exact import torus
    from splinevis.nurbs.lod.levels import build_lod

    monkeypatch.setattr(C, "occ_available", lambda: False)
    lod = build_lod(torus(), 0.05, levels=2, progress=False)
    b = C.lod_vs_meshes(lod, torus(), per_spans=(1, 2, 4), deflections=(0.05,))
    assert b["occ_available"] is False and len(b["occ"]) == 1 and "not importable" in b["occ"][0]["mesh"]
    assert all(m["occ"] == "OpenCASCADE (OCP) not importable" and m["occ_triangles"] is None for m in b["matches"])
    result = json.loads(json.dumps(run[1]))  # the run's result, section (b) replaced
    result["lod_vs_meshes"] = {"delta": 0.05, **b}
    md = W.write_markdown(tmp_path, result).read_text()
    assert "| OpenCASCADE: not available (OCP not importable; pip install splinevis[cad]) |" in md
    assert md.count("| OpenCASCADE (OCP) not importable |") == 2


def test_simplified_levels_have_fewer_triangles_within_their_bound(run):
    e = run[1]["simplification"]
    rows = e["levels"]
    assert rows[0]["eps"] == 0.0 and rows[0]["triangles_simplified"] == rows[0]["triangles_plain"]
    for r in rows[1:]:
        assert r["eps"] == pytest.approx(e["share"] * r["delta"], rel=1e-12)
        assert r["bound"] == pytest.approx(r["delta"] + r["eps"], rel=1e-12)
        assert r["triangles_simplified"] <= r["triangles_plain"]
        # the Simplifier keeps a result only when its measured distance is within the bound (no tolerance)
        assert 0.0 < r["simplifier_measured"] <= r["bound"]
        # the study's own measure: the plain level is within its proven delta_l, the simplified within the bound
        assert r["deviation_plain"] <= r["delta"] and r["deviation_simplified"] <= r["bound"]
    assert sum(r["triangles_simplified"] for r in rows[1:]) < sum(r["triangles_plain"] for r in rows[1:])
    assert rows[-1]["supers_reduced"] > 0 and rows[-1]["ratio"] < 1.0


def test_simplification_levels_refuses_different_builds():
    from splinevis.nurbs.exact import torus
    from splinevis.nurbs.lod.levels import build_lod

    a = build_lod(torus(), 0.05, levels=2, progress=False)
    b = build_lod(torus(), 0.05, levels=3, progress=False)
    with pytest.raises(ValueError, match="one delta and one number of levels"):
        C.simplification_levels(a, b, torus())


def test_occ_deflections_cover_the_levels():
    d = C.occ_deflections([0.01, 0.04, 0.16, 0.64])
    # 0.64 / 0.005 = 128 = sqrt(2)**14: the last is the coarsest tolerance, up to the rounding of the powers
    assert len(d) == 15 and d[0] == 0.005 and d[-1] == pytest.approx(0.64, rel=1e-14)
    assert np.allclose(np.diff(np.log(d)), np.log(np.sqrt(2.0)))
