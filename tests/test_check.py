"""``splinevis check``: each judge fails on a case made to be wrong and passes on a right one (terrain and volume
judges, the shared picture measures, the report and the command's exit status; the NURBS and mesh judges have
their own test files)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from splinevis.check.judge import FamilyJudge, Finding, picture_findings, silhouette_measures, worst_level
from splinevis.check.run import judge_file


def _levels(findings):
    return [f.level for f in findings]


# ---- shared picture measures ---------------------------------------------------------------------------------

def _disc(shape=(120, 160), r=40, centre=(60, 80)):
    y, x = np.mgrid[0:shape[0], 0:shape[1]]
    return (y - centre[0]) ** 2 + (x - centre[1]) ** 2 <= r * r


def test_the_same_silhouette_passes():
    b = _disc()
    m = silhouette_measures(b, b)
    assert (m["iou"], m["leaks"], m["pinholes"]) == (1.0, 0, 0)
    assert picture_findings("default", m) == []


def test_a_silhouette_in_a_wrong_frame_fails():
    b = _disc()
    s = _disc(centre=(60, 110))  # the same disc drawn 30 px off: a wrong frame
    m = silhouette_measures(s, b)
    assert m["iou"] < 0.9
    assert "FAIL" in _levels(picture_findings("default", m))


def test_a_hole_fails_and_a_crack_pattern_fails():
    b = _disc()
    hole = b & ~_disc(r=8)  # a hole of ~200 px in a disc of ~5000
    m = silhouette_measures(hole, b)
    assert m["leaks"] == int((b & ~hole).sum()) and m["leak_fraction"] > 0.01
    assert "FAIL" in _levels(picture_findings("default", m))
    cracked = b.copy()
    cracked[42:80:6, 62:100:6] = False  # isolated pixels well inside: a pattern of pinholes
    m = silhouette_measures(cracked, b)
    assert m["pinholes"] == m["leaks"] == 49
    assert "FAIL" in _levels(picture_findings("default", m))


def test_worst_level_orders_pass_warn_fail():
    assert worst_level([]) == "PASS"
    assert worst_level([Finding("WARN", "a"), Finding("FAIL", "b"), Finding("PASS", "c")]) == "FAIL"
    with pytest.raises(ValueError, match="level 'BAD'"):
        Finding("BAD", "x")


# ---- terrain: the reader against the file ----------------------------------------------------------------------

def _write_asc(path, z, cell=10.0, nodata=None):
    ny, nx = z.shape
    head = f"ncols {nx}\nnrows {ny}\nxllcorner 1000\nyllcorner 2000\ncellsize {cell}\n"
    if nodata is not None:
        head += f"NODATA_value {nodata}\n"
    rows = z[::-1]  # ESRI grids are written north row first
    path.write_text(head + "\n".join(" ".join(f"{v:g}" for v in r) for r in rows) + "\n")


@pytest.fixture()
def hill(tmp_path):
    y, x = np.mgrid[0:24, 0:32]
    z = np.round(100 + 30 * np.sin(x / 5.0) * np.cos(y / 7.0) + 0.7 * y, 1)
    p = tmp_path / "hill.asc"
    _write_asc(p, z)
    return p, z


def test_terrain_reader_matches_the_file_exactly(hill):
    from splinevis.io import read_heights
    from splinevis.terrain.judge import JUDGE, reader_against_file

    p, z = hill
    grid = read_heights(p)
    r = reader_against_file(p, grid)
    assert r["on_lattice"] and r["samples"] == z.size and r["max_difference"] == 0.0 and r["reader_excess"] == 0.0
    findings = []
    JUDGE.accuracy(p, grid, JUDGE.build(grid, {}, findings), None, {}, findings)
    assert _levels(findings) == ["PASS"]


def test_terrain_dem_shifted_by_one_row_fails(hill):
    from splinevis.io import HeightGrid, read_heights
    from splinevis.terrain.judge import JUDGE

    p, z = hill
    grid = read_heights(p)
    shifted = HeightGrid(np.roll(grid.heights, 1, axis=0), grid.spacing, grid.origin, source=grid.source)
    findings = []
    acc = JUDGE.accuracy(p, shifted, JUDGE.build(shifted, {}, findings), None, {}, findings)
    assert acc["reader"]["max_difference"] > 0
    assert worst_level(findings) == "FAIL"
    assert "the reader disagrees with the file" in findings[-1].reason


def test_terrain_nodata_is_filled_with_a_warning(tmp_path):
    from splinevis.io import read_heights
    from splinevis.terrain.judge import JUDGE

    y, x = np.mgrid[0:20, 0:20]
    z = (50.0 + x + y).astype(float)
    z[:5, :5] = -9999
    p = tmp_path / "holes.asc"
    _write_asc(p, z, nodata=-9999)
    findings = []
    grid = JUDGE.read(p, {}, findings)
    JUDGE.accuracy(p, grid, JUDGE.build(grid, {}, findings), None, {}, findings)
    assert any(f.level == "WARN" and "6.2 % of the grid is nodata" in f.reason for f in findings)
    assert grid.heights.shape == (20, 20) and read_heights(p, fill="nearest").heights[0, 0] == grid.heights[0, 0]


def test_terrain_file_judged_end_to_end(hill, tmp_path):
    p, _ = hill
    r = judge_file(p, "terrain", tmp_path / "out")
    assert r["verdict"] == "PASS", r["findings"]
    assert r["views"]["default"]["iou"] > 0.97 and r["views"]["close-up"]["iou"] > 0.97
    assert r["views"]["close-up"]["spline_pixels"] > r["views"]["default"]["spline_pixels"]  # really closer
    assert (tmp_path / "out" / r["thumbnail"]).stat().st_size > 1000


def test_a_spline_with_a_hole_is_judged_fail_end_to_end(hill, tmp_path):
    """The terrain judge, except that the picture is the baseline with a patch of cells cut out."""
    from splinevis.terrain.judge import JUDGE

    p, _ = hill

    def add_with_hole(plotter, model, options):
        mesh = JUDGE.baseline(JUDGE.read(p, {}, []), model, {}, [])
        c = np.asarray(mesh.cell_centers().points)
        mid = c.mean(axis=0)
        keep = np.hypot(c[:, 0] - mid[0], c[:, 1] - mid[1]) > 40.0
        return plotter.add_mesh(mesh.extract_cells(np.nonzero(keep)[0]))

    holed = FamilyJudge("terrain", "warp_by_scalar mesh", JUDGE.read, JUDGE.build, JUDGE.baseline, JUDGE.accuracy,
                        add_with_hole)
    r = judge_file(p, holed, tmp_path / "out")
    assert r["verdict"] == "FAIL"
    assert any("background pixels inside the silhouette" in f["reason"] and f["level"] == "FAIL" for f in r["findings"])


# ---- volume: value at samples and the frame ------------------------------------------------------------------

@pytest.fixture()
def ball(tmp_path):
    import pyvista as pv

    z, y, x = np.mgrid[0:20, 0:22, 0:24].astype(float)
    values = 100.0 - np.sqrt((x - 11.5) ** 2 + (y - 10.5) ** 2 + (z - 9.5) ** 2) * 8
    img = pv.ImageData(dimensions=(24, 22, 20), spacing=(0.5, 0.5, 0.75), origin=(10.0, -3.0, 2.0))
    img.point_data["density"] = values.ravel()
    p = tmp_path / "ball.vti"
    img.save(p)
    return p, values


def test_volume_reader_in_the_right_frame_passes_and_a_wrong_frame_fails(ball):
    from splinevis.io import VolumeGrid
    from splinevis.volume.judge import JUDGE

    p, values = ball
    findings = []
    grid = JUDGE.read(p, {}, findings)
    model = JUDGE.build(grid, {"isovalue": 40.0}, findings)
    acc = JUDGE.accuracy(p, grid, model, JUDGE.baseline(grid, model, {}, findings), {}, findings)
    assert _levels(findings) == ["PASS"] and acc["reader_checked_against"] == "VTK"
    # the quadratic quasi-interpolant reproduces linear functions: at interior samples of a cone-like field the
    # error is the second-order term, far below the value range
    assert acc["max_value_error_range"] < 0.05
    wrong = VolumeGrid(grid.values, spacing=grid.spacing, origin=np.asarray(grid.origin) + [0.5, 0, 0])
    findings = []
    JUDGE.accuracy(p, wrong, JUDGE.build(wrong, {"isovalue": 40.0}, findings), None, {}, findings)
    assert worst_level(findings) == "FAIL" and "sample positions differ" in findings[-1].reason


def test_volume_isovalue_from_the_histogram(ball):
    from splinevis.volume.judge import JUDGE, choose_isovalue

    p, values = ball
    iso, how = choose_isovalue(values)
    assert values.min() < iso < values.max() and "Otsu" in how
    findings = []
    model = JUDGE.build(JUDGE.read(p, {}, findings), {}, findings)
    assert model.isovalue == iso and f"isovalue {iso:.6g}" in findings[0].reason


def test_volume_file_judged_end_to_end(ball, tmp_path):
    p, _ = ball
    r = judge_file(p, "volume", tmp_path / "out", options={"isovalue": 40.0})
    assert r["verdict"] == "PASS", r["findings"]
    assert r["views"]["default"]["iou"] > 0.97


# ---- the command -------------------------------------------------------------------------------------------

def test_check_command_writes_the_report_and_exits_1_on_an_unlisted_fail(hill, tmp_path):
    from splinevis.cli import main

    p, _ = hill
    bad = tmp_path / "broken.asc"
    bad.write_text("ncols 4\nnrows 3\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3 4\n5 6\n")  # cut short
    out = tmp_path / "report"
    assert main(["check", str(p), str(bad), "--out", str(out), "--quiet"]) == 1
    report = json.loads((out / "report.json").read_text())
    verdicts = {r["name"]: r["verdict"] for r in report["files"]}
    assert verdicts == {"hill.asc": "PASS", "broken.asc": "FAIL"}
    assert "| terrain | 2 | 1 | 0 | 1 |" in (out / "report.md").read_text()
    assert (out / "contact_sheet.png").stat().st_size > 1000
    known = tmp_path / "known.json"
    known.write_text(json.dumps({"broken.asc": "cut short"}))
    assert main(["check", str(p), str(bad), "--out", str(out), "--quiet", "--known", str(known)]) == 0


def test_the_real_file_known_list_is_file_names_with_measured_reasons():
    """tests/realdata_known.json (read by ``make check`` and CI): a flat object, bare file names (what the
    report's "name" holds), each with a reason in words; no machine's absolute path."""
    import re
    from pathlib import Path

    known = json.loads((Path(__file__).parent / "realdata_known.json").read_text())
    assert isinstance(known, dict)
    for name, reason in known.items():
        assert "/" not in name and name == name.strip(), name
        assert isinstance(reason, str) and len(reason) > 20, name
        assert not re.search(r"(?<![\w.])/[A-Za-z_]+/", reason), f"{name}: an absolute path in {reason!r}"
