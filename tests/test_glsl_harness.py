"""The moderngl harness and the GLSL library against the float64 twins."""

import numpy as np
import pytest

from splinevis.bb import de_casteljau, first_root_bracketed, newton_secure, restrict_to_segment
from splinevis.errors import ShaderCompileError
from splinevis.gl.harness import run_glsl

pytestmark = pytest.mark.gl
EPS32 = 2.0**-23


def test_inputs_round_trip_exactly():
    rng = np.random.default_rng(0)
    x = (rng.normal(size=(1000, 6)) * 10.0 ** rng.uniform(-30, 30, size=(1000, 6))).astype(np.float32)
    out = run_glsl("// nothing\n", "for (int q = 0; q < 6; ++q) sv_out[q] = sv_in[q];", x, 6)
    assert out.dtype == np.float32 and out.shape == (1000, 6)
    assert np.array_equal(out, x)  # bit-exact: texelFetch on RGBA32F and an RGBA32F framebuffer


def test_bernstein_exact_values_at_half():
    # f(1/2) with c = (1, 0, 0, 0, 0) is 1/16; derivative of t^4 at 1/2 is 4/8; all exact in float32
    rows = np.array([[1, 0, 0, 0, 0, 0.5], [0, 0, 0, 0, 1, 0.5], [1, 2, 3, 4, 5, 1.0], [1, 2, 3, 4, 5, 0.0]], np.float32)
    body = ("float c[5] = float[5](sv_in[0], sv_in[1], sv_in[2], sv_in[3], sv_in[4]);"
            "sv_out[0] = sv_bernstein_eval(c, 4, sv_in[5]); sv_out[1] = sv_bernstein_deriv(c, 4, sv_in[5]);")
    out = run_glsl('#include "lib/core/bernstein.glsl"\n', body, rows, 2)
    assert out[:, 0].tolist() == [1 / 16, 1 / 16, 5.0, 1.0]
    assert out[:, 1].tolist() == [-0.5, 0.5, 4.0, 4.0]


def test_first_root_matches_float32_emulation_and_twin():
    rng = np.random.default_rng(1)
    c = (rng.normal(size=(20000, 5)) * 10.0 ** rng.uniform(-3, 3, size=(20000, 1))).astype(np.float32)
    body = "sv_out[0] = sv_first_root_newton4(float[5](sv_in[0], sv_in[1], sv_in[2], sv_in[3], sv_in[4]), 4, 6);"
    g = run_glsl('#include "lib/core/roots.glsl"\n', body, c, 1)[:, 0]
    g = np.where(g == -1.0, np.nan, g)
    em = newton_secure(c, 6, dtype=np.float32)
    # same operations in IEEE float32: llvmpipe reproduces the emulation except for rare FMA/trajectory cases
    same = (np.isnan(g) & np.isnan(em)) | (g == em)
    assert same.mean() > 0.999
    tw = newton_secure(c.astype(np.float64), 6)
    both = np.isfinite(g) & np.isfinite(tw)
    assert (np.isfinite(g) == np.isfinite(tw)).mean() > 0.97
    assert np.median(np.abs(g[both] - tw[both])) < 1e-6


def _hard_root_cases(rng, m, n):
    from splinevis.selftest import _root_inputs

    if n >= 2:
        c32, _ = _root_inputs(rng, m, n)
    else:  # lines: random coefficients over 12 decades
        c32 = (rng.normal(size=(m, 2)) * 10.0 ** rng.uniform(-6, 6, size=(m, 2))).astype(np.float32)
    special = np.zeros((8, n + 1), np.float32)
    special[1, :] = 1.0                                     # constant, no root
    special[2, 0] = -1.0; special[2, n] = 1.0               # sign change, flat middle
    special[3, n] = 0.0; special[3, 0] = -1.0               # root exactly at 1
    special[4, 0] = 0.0; special[4, 1:] = 2.0               # root exactly at 0
    special[5, ::2] = 1e-30; special[5, 1::2] = -1e-30      # tiny alternating
    special[6, ::2] = 1e37; special[6, 1::2] = -1e37        # huge alternating (n * differences stay finite)
    special[7, 0] = np.inf                                  # non-finite: no root
    return np.concatenate([c32, special])


@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("iterations", [1, 6, 8, 16])
def test_first_root_bracketed_equals_float32_twin_on_hard_cases(n, iterations):
    c = _hard_root_cases(np.random.default_rng(10 + n), 20_000, n)
    args = ", ".join(f"sv_in[{k}]" if k <= n else "0.0" for k in range(5))
    for name in ("sv_first_root_bracketed", "sv_first_root"):   # sv_first_root dispatches to it by default
        g = run_glsl('#include "lib/core/roots.glsl"\n', f"sv_out[0] = {name}(float[5]({args}), {n}, {iterations});", c, 1)[:, 0]
        g = np.where(g == -1.0, np.nan, g)
        em = first_root_bracketed(c, iterations, dtype=np.float32)
        # llvmpipe is bit-identical to the float32 twin (same operations in the same order, no FMA contraction)
        assert np.array_equal(g, em, equal_nan=True), (name, int((~((g == em) | (np.isnan(g) & np.isnan(em)))).sum()))


def test_sv_first_root_paper_flag_selects_newton4():
    c = np.random.default_rng(5).normal(size=(5000, 5)).astype(np.float32)
    body = "sv_out[0] = sv_first_root(float[5](sv_in[0], sv_in[1], sv_in[2], sv_in[3], sv_in[4]), 4, 6);"
    g = run_glsl('#include "lib/core/roots.glsl"\n', body, c, 1, defines={"SV_ROOTS_PAPER": True})[:, 0]
    ref = run_glsl('#include "lib/core/roots.glsl"\n', body.replace("sv_first_root(", "sv_first_root_newton4("), c, 1)[:, 0]
    assert np.array_equal(g, ref)


def test_restrict_quartic_tri_matches_twin():
    rng = np.random.default_rng(2)
    m = 5000
    b = rng.normal(size=(m, 15)).astype(np.float32)
    l0 = rng.dirichlet(np.ones(3), size=m).astype(np.float32)
    l1 = rng.dirichlet(np.ones(3), size=m).astype(np.float32)
    body = ("float b[15]; for (int q = 0; q < 15; ++q) b[q] = sv_in[q];"
            "float c[5]; sv_restrict_quartic_tri(b, vec3(sv_in[15], sv_in[16], sv_in[17]), vec3(sv_in[18], sv_in[19], sv_in[20]), c);"
            "for (int k = 0; k < 5; ++k) sv_out[k] = c[k];")
    out = run_glsl('#include "lib/simplex/blossom.glsl"\n', body, np.concatenate([b, l0, l1], 1), 5)
    ref = restrict_to_segment(b.astype(float), l0.astype(float), l1.astype(float), d=2)
    scale = restrict_to_segment(np.abs(b.astype(float)), l0.astype(float), l1.astype(float), d=2)
    # derived bound gamma_12 (4 levels x 3 roundings) in units of the |b| blossom
    assert np.all(np.abs(out - ref) <= 6.0 * (1 + 1e-5) * EPS32 * scale)
    # coefficient 0 is the value at l0, coefficient 4 the value at l1
    np.testing.assert_allclose(out[:, 0], de_casteljau(b.astype(float), l0.astype(float), d=2), atol=1e-5)


def test_compiles_under_version_150_in_one_program():
    src = '#include "lib/core/roots.glsl"\n#include "lib/simplex/blossom.glsl"\n#include "lib/core/bernstein.glsl"\n'
    out = run_glsl(src, "sv_out[0] = sv_bernstein_eval(float[5](1.0, 1.0, 1.0, 1.0, 1.0), 4, sv_in[0]);",
                   np.array([[0.3]], np.float32), 1)
    assert out[0, 0] == pytest.approx(1.0, abs=4 * EPS32)


def test_broken_glsl_file_reports_origin(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "broken.glsl").write_text(
        "// a broken helper\nfloat sv_ok(float x) { return x; }\nfloat sv_bad(float x) { return x +* 2.0; }\n"
    )
    with pytest.raises(ShaderCompileError, match=r"lib/broken\.glsl:3") as info:
        run_glsl('#include "lib/broken.glsl"\n', "sv_out[0] = sv_bad(sv_in[0]);", np.zeros((4, 1), np.float32), 1,
                 root=tmp_path)
    err = info.value
    assert "return x +* 2.0;" in str(err)
    assert err.stage == "fragment"
    assert any(where == "lib/broken.glsl:3" for _, _, where in err.locations)


def test_bad_arguments():
    with pytest.raises(ValueError, match=r"outputs must be an integer in 1\.\.16; got 17"):
        run_glsl("//\n", "", np.zeros((2, 1), np.float32), 17)
    with pytest.raises(ValueError, match=r"inputs must have shape \(M, k\)"):
        run_glsl("//\n", "", np.zeros((0, 3), np.float32), 1)


def test_large_batch_is_fast():
    import time

    x = np.random.default_rng(3).random((100_000, 6)).astype(np.float32)
    body = "float c[5] = float[5](sv_in[0], sv_in[1], sv_in[2], sv_in[3], sv_in[4]); sv_out[0] = sv_bernstein_eval(c, 4, sv_in[5]);"
    run_glsl('#include "lib/core/bernstein.glsl"\n', body, x[:10], 1)  # compile once
    t0 = time.perf_counter()
    out = run_glsl('#include "lib/core/bernstein.glsl"\n', body, x, 1)
    assert time.perf_counter() - t0 < 2.0
    ref = de_casteljau(x[:, :5].astype(float), np.stack([1 - x[:, 5].astype(float), x[:, 5]], -1), d=1)
    S = de_casteljau(np.abs(x[:, :5].astype(float)), np.stack([1 - x[:, 5].astype(float), x[:, 5]], -1), d=1)
    assert np.all(np.abs(out[:, 0] - ref) <= 6.0 * (1 + 1e-5) * EPS32 * S)
