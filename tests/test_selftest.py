"""The self-test runs, writes its JSON and every GLSL function stays within its derived bound."""

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
        assert r["max_err_eps"] <= r["bound_eps"], name
        assert r["pass"], name
        assert np.isfinite(r["median_err_eps"])
        if name.startswith("first_root"):
            assert r["total_cases"] == 100_000 and r["unexplained_total"] == 0
            assert r["cases"] > 30_000  # well-conditioned cases where both found the same root
            if name.startswith("first_root_bracketed"):
                for who in ("glsl", "float64_twin"):
                    v = r["vs_reference"][who]
                    assert v["missed"] == 0 and v["wrong_root"] == 0, (name, who, v)
                assert r["glsl_bit_identical_to_float32_emulation"] == 100_000
        else:
            assert r["cases"] == 100_000
    assert res["pass"] and res["seconds"] < 60


def test_selftest_rejects_tiny_case_counts(tmp_path):
    with pytest.raises(ValueError, match=r"cases must be an integer >= 1000; got 10"):
        run_selftest(tmp_path, cases=10)
