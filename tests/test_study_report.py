"""The studies' shared report helpers (splinevis.studies.report) and the list of studies: exact strings
for the formats and tables, NaN-free JSON, the "paper" labels, and the ``study`` command's choices.
No GL needed."""

import contextlib
import doctest
import io
import json
import math

import numpy as np
import pytest

from splinevis.studies import STUDIES, get, notes
from splinevis.studies import report as R


def test_docstring_examples_run():
    import splinevis.studies

    for mod in (R, splinevis.studies):
        result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
        assert result.attempted > 0 and result.failed == 0, mod.__name__


@pytest.mark.parametrize("value, kind, text", [
    (None, "e", "-"), (None, "s", "-"), (0.000123456, "e", "1.23e-04"), (12345.0, "e", "1.23e+04"),
    (3.14159, "f1", "3.1"), (3.14159, "f2", "3.14"), (2.005, "f2", "2.00"), (1234567.8, "int", "1,234,567"),
    (np.int64(42), "int", "42"), (True, "s", "True"), ("blocks, data", "s", "blocks, data"), (0.5, "x", "0.5"),
    (float("nan"), "e", "nan"), (math.inf, "f1", "inf"),
])
def test_fmt(value, kind, text):
    assert R.fmt(value, kind) == text


def test_md_table_exact():
    rows = [{"method": "MC skimage", "ms": 12.345, "px": 1234, "err": 0.00051},
            {"method": "quadratic spline", "ms": 3.0, "px": None}]
    cols = [("method", "method", "s"), ("frame median ms", "ms", "f1"), ("coverage px", "px", "int"), ("err °", "err", "e")]
    assert R.md_table(rows, cols) == (
        "| method | frame median ms | coverage px | err ° |\n"
        "|---|---|---|---|\n"
        "| MC skimage | 12.3 | 1,234 | 5.10e-04 |\n"
        "| quadratic spline | 3.0 | - | - |\n")
    assert R.md_table([], cols[:2]) == "| method | frame median ms |\n|---|---|\n"
    assert R.md_table(rows[:1], cols[:1], lambda v, k: f"<{v}>") == "| method |\n|---|\n| <MC skimage> |\n"


def test_paper_labels():
    assert R.PAPER == "paper"
    assert R.paper_columns([("rms", "paper_rms_rel", "e")]) == [("paper rms", "paper_rms_rel", "e")]
    text = R.paper_table("[Kalbe2008, Table 1]", [{"dataset": "neghip", "voxels": "64^3", "QSS_s": 0.2}],
                         [("dataset", "dataset", "s"), ("voxels", "voxels", "s"), ("QSS s", "QSS_s", "f1")])
    assert text == ("### paper ([Kalbe2008, Table 1])\n\n"
                    "| paper dataset | voxels | QSS s |\n"
                    "|---|---|---|\n"
                    "| neghip | 64^3 | 0.2 |\n")


def test_the_studies_keep_paper_numbers_in_paper_columns():
    from splinevis.studies.terrain import PAPER_TABLE_I
    from splinevis.studies.volume_memory import PAPER_COLUMNS, PAPER_TABLE_1, memory_markdown

    md = "\n".join(memory_markdown([]))
    assert "### paper (" in md and "| paper dataset |" in md
    measured, paper = md.split("### paper (")
    assert "| paper" not in measured  # the measured table has no paper column
    assert [line.split(" | ")[0] for line in paper.splitlines() if line.startswith("| ")] == (
        ["| paper dataset"] + [f"| {r['dataset']}" for r in PAPER_TABLE_1])
    assert {k for _, k, _ in PAPER_COLUMNS} == set(PAPER_TABLE_1[0])
    assert ("C1", 144) in PAPER_TABLE_I


def test_clean_and_write_json(tmp_path):
    obj = {"a": (np.float64(1.5), np.float32(float("nan")), -math.inf), 3: {"n": np.int32(7), "ok": np.bool_(False)},
           "s": "x", "none": None}
    assert R.clean(obj) == {"a": [1.5, None, None], "3": {"n": 7, "ok": False}, "s": "x", "none": None}
    path = R.write_json(tmp_path / "r.json", obj)
    assert path == tmp_path / "r.json"
    text = path.read_text()
    assert json.loads(text) == R.clean(obj)
    assert text == json.dumps(R.clean(obj), indent=2) and not text.endswith("\n")
    assert "NaN" not in text and "Infinity" not in text


def test_log_line():
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        R.log("terrain", "accuracy table")
    assert err.getvalue() == "[terrain study] accuracy table\n"


def test_progress_bar_is_silent_when_disabled(capsys):
    assert list(R.progress_bar(range(3), "jobs", enabled=False)) == [0, 1, 2]
    assert capsys.readouterr().err == ""


def test_timed_rows():
    class Scene:
        frames = 0

        def render_now(self):
            Scene.frames += 1

    row = R.timed(Scene(), 4)
    assert list(row) == ["frame_min_ms", "frame_median_ms", "repeats"] and row["repeats"] == 4
    assert 0 <= row["frame_min_ms"] <= row["frame_median_ms"]
    assert Scene.frames == 2 + 4  # two warm-up frames
    assert list(R.timed(Scene(), 1, with_repeats=False)) == ["frame_min_ms", "frame_median_ms"]


def test_error_summary():
    assert R.error_summary([4.0, 0.0, 2.0], "normal", "deg") == {
        "normal_err_median_deg": 2.0, "normal_err_p95_deg": pytest.approx(3.8), "normal_err_max_deg": 4.0}
    assert R.error_summary(np.zeros(0), "position", "h") == {
        "position_err_median_h": None, "position_err_p95_h": None, "position_err_max_h": None}
    assert list(R.error_summary([1.0], "normal", "deg", stats=("median", "p95"))) == [
        "normal_err_median_deg", "normal_err_p95_deg"]


def test_save_figure(tmp_path):
    plt = R.pyplot()
    fig, ax = plt.subplots(figsize=(2, 1))
    ax.plot([0, 1], [0, 1])
    assert R.save_figure(fig, tmp_path / "f.png", dpi=30) == tmp_path / "f.png"
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not plt.fignum_exists(fig.number)


def test_no_study_imports_another_studys_privates():
    import ast
    from pathlib import Path

    import splinevis.studies

    folder = Path(splinevis.studies.__file__).parent
    for path in folder.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                private = [a.name for a in node.names if a.name.startswith("_")]
                assert not private, f"{path.name} imports {private} from .{node.module}"


def test_the_list_of_studies_drives_the_cli(capsys):
    from splinevis.cli import main

    assert list(STUDIES) == ["terrain", "volume", "nurbs", "walkthrough", "geometry-image", "antialiasing"]
    assert get("terrain").runner == "splinevis.studies.terrain:run_terrain_study"
    for study in STUDIES.values():
        module, _, function = study.runner.partition(":")
        assert callable(getattr(__import__(module, fromlist=[function]), function))
        assert study.json_file("out").name == f"{study.name}.json"
    with pytest.raises(ValueError, match="study 'x' is not known; choose one of 'terrain', 'volume', 'nurbs', 'walkthrough', 'geometry-image', 'antialiasing'."):
        get("x")
    with pytest.raises(SystemExit) as exc:
        main(["study", "--help"])
    assert exc.value.code == 0
    assert "{terrain,volume,nurbs,walkthrough,geometry-image,antialiasing}" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exc:
        main(["study", "sphere", "--out", "x"])
    assert exc.value.code == 2


def test_notes_list_what_is_not_available():
    note = "cubic scheme NOT available (test); the study ran the quadratic only"
    assert notes({"quick": True, "cubic": {"available": False, "note": note}, "rows": [{"available": False}]}) == [note]
    assert notes({"cubic": {"available": True, "note": "cubic scheme available"}, "memory": []}) == []


def test_cli_study_prints_files_json_and_notes(tmp_path, monkeypatch, capsys):
    """The listing the ``study`` command prints: markdown files, figures, then the JSON; then the notes."""
    from splinevis import cli
    from splinevis.studies import Study

    def fake(out_dir, *, quick=False, progress=True):
        for name in ("b.md", "a.md", "z.png"):
            (tmp_path / name).write_text("")
        return {"quick": quick, "cubic": {"available": False, "note": "cubic scheme NOT available (test)"}}

    monkeypatch.setitem(STUDIES, "volume", Study("volume", "x:y", "test"))
    monkeypatch.setattr(Study, "run", lambda self, out, **kw: fake(out, **kw))
    assert cli.main(["study", "volume", "--out", str(tmp_path), "--quick", "--quiet"]) == 0
    assert capsys.readouterr().out.splitlines() == [
        str(tmp_path / "a.md"), str(tmp_path / "b.md"), str(tmp_path / "z.png"), str(tmp_path / "volume.json"),
        "note: cubic scheme NOT available (test)"]
