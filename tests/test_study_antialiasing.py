"""The antialiasing study on one small scene: its files, and the ordering it exists to show."""

from __future__ import annotations

import json

import pytest

from splinevis.studies.antialiasing import RENDERERS, run_antialiasing_study

pytestmark = pytest.mark.gl


def test_filtered_stripes_are_closer_to_the_reference_at_the_same_cost(tmp_path):
    result = run_antialiasing_study(tmp_path, quick=True, progress=False, window=(96, 72), repeats=1,
                                    scenes=("geometry image",))
    rows = {r["renderer"]: r for r in result["rows"]}
    assert list(rows) == [r[0] for r in RENDERERS]
    plain, filtered = rows["exact, plain step"], rows["exact, filtered"]
    ss4 = rows["exact, filtered, SSAA 4x4"]
    # the filter removes the aliasing of the plain step; 16 samples a pixel come closest of all. The
    # reference is the plain step's 16-sample mean, so a single sample's error is mostly aliasing.
    assert filtered["mean"] < 0.6 * plain["mean"]
    assert ss4["mean"] < filtered["mean"]
    assert filtered["closest_single_sample"] and not plain["closest_single_sample"]
    assert all(r["pixels"] > 500 for r in rows.values())
    written = json.loads((tmp_path / "antialiasing.json").read_text())
    assert len(written["rows"]) == len(RENDERERS)
    assert (tmp_path / "antialiasing.png").stat().st_size > 10_000
    assert "exact, filtered" in (tmp_path / "antialiasing.md").read_text()


def test_unknown_scene_is_named(tmp_path):
    with pytest.raises(ValueError, match=r"scenes \['teapot'\] are not known"):
        run_antialiasing_study(tmp_path, scenes=("teapot",))
