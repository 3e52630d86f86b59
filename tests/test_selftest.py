"""The self-test runs and writes its JSON; the evaluation rows stay within their derived bounds on every case; each
first_root row reports the fraction of compared cases within its derived bound, and every case beyond it meets a
separately derived expectation (float32 spacing at the root, the bracket width after N steps, or the GPU point is a
root at float32 precision; splinevis.selftest._test_roots)."""

import json

import numpy as np
import pytest

from splinevis.selftest import DERIV_BOUND, EVAL_BOUND, RESTRICT_BOUND, ROOT_BOUND, gamma_eps, run_selftest


def test_bounds_are_the_derived_formulas():
    u = 2.0**-24
    assert gamma_eps(12) == pytest.approx(12 * u / (1 - 12 * u) / (2 * u))
    assert EVAL_BOUND(4) == pytest.approx(6.0, rel=1e-5)
    assert DERIV_BOUND(1) == pytest.approx(1.0, rel=1e-5)  # one subtraction
    assert RESTRICT_BOUND() == pytest.approx(6.0, rel=1e-5)
    assert ROOT_BOUND(4) == pytest.approx(2 * 12 + 6, rel=1e-4)


@pytest.mark.gl
def test_selftest_full_size(tmp_path):
    res = run_selftest(tmp_path, cases=100_000, seed=0, progress=False, programs=False)  # programs: test_program_hard_cases
    saved = json.loads((tmp_path / "selftest.json").read_text())
    assert saved["functions"].keys() == res["functions"].keys()
    names = {f"bernstein_eval_n{n}" for n in range(1, 5)} | {f"bernstein_deriv_n{n}" for n in range(1, 5)}
    names |= {f"first_root_n{n}" for n in range(2, 5)} | {"restrict_quartic_tri"}
    names |= {f"first_root_bracketed_n{n}" for n in range(2, 5)}
    assert set(res["functions"]) == names
    for name, r in res["functions"].items():
        assert r["pass"], name
        assert np.isfinite(r["median_err_eps"])
        if name.startswith("first_root"):
            # the compared cases: both found a root, the twin's root well-conditioned
            assert r["total_cases"] == 100_000 and r["cases"] > 30_000
            assert r["within_bound"] + r["exceeding"] == r["cases"]
            assert r["within_fraction"] == pytest.approx(r["within_bound"] / r["cases"])
            assert r["max_err_within_eps"] <= r["bound_eps"], name
            assert r["max_err_eps"] >= r["max_err_within_eps"]
            # every case beyond the bound meets one of the separately derived expectations (selftest._test_roots)
            b = r["beyond_bound"]
            assert b["unexplained"] == 0, (name, b)
            assert b["float32_spacing"] + b["bracket_width"] + b["gpu_point_is_float32_root"] == b["count"] == r["exceeding"]
            assert b["max_err_over_spacing_bound"] <= 1.0
            assert r["ill_conditioned"]["unexplained"] == 0, (name, r["ill_conditioned"])
            assert r["unexplained_total"] == 0
            if name.startswith("first_root_bracketed"):
                assert b["max_abs_diff_bracket_width"] <= b["bracket_bound"]
                # existence disagreements of the bracketed method: only at the residual tolerance
                for side in ("glsl_only", "twin_only"):
                    assert r[side]["count"] == r[side]["near_tolerance"], (name, side, r[side])
                for who in ("glsl", "float64_twin"):
                    v = r["vs_reference"][who]
                    assert v["missed"] == 0 and v["wrong_root"] == 0, (name, who, v)
                assert r["glsl_bit_identical_to_float32_emulation"] == 100_000
            else:
                # the 4-start Newton accepts only float32 roots: every GPU root passes the exact residual bound
                assert r["glsl_roots_that_are_float32_roots"] == r["glsl_roots"] > 30_000
                assert b["bracket_width"] == 0  # no bracket: that expectation is the bracketed method's only
        else:
            assert r["cases"] == 100_000
            assert r["max_err_eps"] <= r["bound_eps"], name
            assert r["exceeding"] == 0, name
    assert res["pass"]  # its time is the benchmarks' business, not a test's (it failed on a loaded machine)


def test_selftest_rejects_tiny_case_counts(tmp_path):
    with pytest.raises(ValueError, match=r"cases must be an integer >= 1000; got 10"):
        run_selftest(tmp_path, cases=10)
