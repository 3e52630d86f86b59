"""Tensor-product Bezier patches: the GLSL function (glsl/lib/tensor/bezier_patch.glsl) against its float64
twin (splinevis.bb.tensor) within derived float32 bounds, and the twin against exact values."""

import numpy as np
import pytest

from splinevis.bb.tensor import BEZIER_PATCH_BOUND, bezier_patch_eval
from splinevis.gl.harness import run_glsl

U32 = 2.0 ** -24


def test_twin_reproduces_polynomials_exactly():
    # degree elevation of f(u, v) = u^2 v: coefficients i(i-1)/(m(m-1)) * j/n for degree (3, 2)
    m, n = 3, 2
    i, j = np.meshgrid(np.arange(m + 1), np.arange(n + 1), indexing="ij")
    c = i * (i - 1) / (m * (m - 1)) * j / n
    u, v = np.array([0.0, 0.3, 1.0]), np.array([0.7, 0.5, 1.0])
    f, fu, fv = bezier_patch_eval(np.broadcast_to(c, (3,) + c.shape), u, v)
    assert np.allclose(f, u ** 2 * v, atol=1e-15) and np.allclose(fu, 2 * u * v, atol=1e-15)
    assert np.allclose(fv, u ** 2, atol=1e-15)


def test_twin_rejects_bad_shapes():
    with pytest.raises(ValueError, match=r"\(\.\.\., m \+ 1, n \+ 1\) with m, n <= 4"):
        bezier_patch_eval(np.zeros((6, 2)), 0.5, 0.5)


@pytest.mark.gl
@pytest.mark.parametrize("m, n", [(3, 3), (2, 3), (3, 1), (1, 1)])
def test_glsl_matches_twin_within_derived_bound(m, n):
    rng = np.random.default_rng(m * 10 + n)
    k = 20000
    c = np.zeros((k, 4, 4), np.float32)
    scale = 10.0 ** rng.uniform(-4, 4, size=(k, 1, 1))
    c[:, : m + 1, : n + 1] = (rng.normal(size=(k, m + 1, n + 1)) * scale).astype(np.float32)
    uv = rng.random((k, 2)).astype(np.float32)
    uv[:50] = [0.0, 1.0]  # corners
    rows = np.concatenate([c.reshape(k, 16), uv], axis=1)
    body = (f"float c[16]; for (int q = 0; q < 16; ++q) c[q] = sv_in[q];"
            f"float f; float fu; float fv; sv_bezier_patch_eval(c, {m}, {n}, vec2(sv_in[16], sv_in[17]), f, fu, fv);"
            "sv_out[0] = f; sv_out[1] = fu; sv_out[2] = fv;")
    out = run_glsl('#include "lib/tensor/bezier_patch.glsl"\n', body, rows, 3).astype(np.float64)
    cc = c[:, : m + 1, : n + 1].astype(np.float64)
    u, v = uv[:, 0].astype(np.float64), uv[:, 1].astype(np.float64)
    f, fu, fv = bezier_patch_eval(cc, u, v)
    # value: gamma_{3(m+n)} times the patch of |c|
    scale_f = bezier_patch_eval(np.abs(cc), u, v)[0]
    assert np.all(np.abs(out[:, 0] - f) <= BEZIER_PATCH_BOUND(m, n) * U32 * scale_f + 1e-45)
    # derivative in u: rows' m (b1 - b0) carry 3m - 1 roundings on m sum (|c_k| + |c_k+1|) B^{m-1}_k(u), then
    # n levels in v (3 roundings each): gamma_{3(m+n)} times the degree (m-1, n) patch of m (|c_k| + |c_k+1|)
    if m:
        du_abs = m * (np.abs(cc[:, 1:, :]) + np.abs(cc[:, :-1, :]))
        scale_u = bezier_patch_eval(du_abs, u, v)[0]
        assert np.all(np.abs(out[:, 1] - fu) <= BEZIER_PATCH_BOUND(m, n) * U32 * scale_u + 1e-45)
    dv_abs = n * (np.abs(cc[:, :, 1:]) + np.abs(cc[:, :, :-1]))
    scale_v = bezier_patch_eval(dv_abs, u, v)[0]
    assert np.all(np.abs(out[:, 2] - fv) <= BEZIER_PATCH_BOUND(m, n) * U32 * scale_v + 1e-45)
