"""Rounding-error bounds of the float32 Bernstein-Bezier algorithms the shaders run, derived operation by
operation [Higham2002, sec. 3.4]: what every GLSL-vs-float64 comparison (the self-test, the root-method
study, the tests) measures its errors against. Plain numbers, no GL.
"""

from __future__ import annotations

from . import roots as _roots

__all__ = ["U32", "EPS32", "gamma_eps", "EVAL_BOUND", "DERIV_BOUND", "RESTRICT_BOUND", "ROOT_BOUND"]

U32 = 2.0**-24
EPS32 = 2.0**-23


def gamma_eps(m: int) -> float:
    """``gamma_m = m u / (1 - m u)`` [Higham2002, sec. 3.4] in units of eps32 = 2u.

    >>> gamma_eps(12)  # m u / eps32 = m / 2, enlarged by 1 / (1 - m u)
    6.000004291537493
    """
    return m * U32 / (1.0 - m * U32) / EPS32


def EVAL_BOUND(n: int) -> float:
    """de Casteljau of degree n: each of the n levels computes s*a + t*b with s = fl(1 - t): at most 3
    roundings per term per level (1 - t, the product, the sum), so
    ``|fl(f) - f| <= gamma_{3n} sum_k |c_k| B_k(t)`` [Farin2002, ch. 3; MainarPena1999]. An FMA only
    removes roundings. Error unit: eps32 * sum_k |c_k| B_k(t).

    >>> EVAL_BOUND(4) == gamma_eps(12)
    True
    """
    return gamma_eps(3 * n)


def DERIV_BOUND(n: int) -> float:
    """f' = n (b1 - b0) after n - 1 levels: b0, b1 carry gamma_{3(n-1)}, the difference and the product
    by n one rounding each, so ``|err| <= gamma_{3n-1} n sum_k (|c_k| + |c_{k+1}|) B^{n-1}_k(t)``. Error
    unit: eps32 * n sum_k (|c_k| + |c_{k+1}|) B^{n-1}_k(t).

    >>> DERIV_BOUND(4)  # gamma_11
    5.500003606083373
    """
    return gamma_eps(3 * n - 1)


def RESTRICT_BOUND() -> float:
    """Quartic triangle blossom: 4 levels of l.x*a + l.y*b + l.z*c (a product and at most two sums per
    term: 3 roundings per level), so ``|err_k| <= gamma_{12} blossom(|b|; |l0|^{4-k}, |l1|^k)``. Error
    unit: eps32 * that blossom.

    >>> RESTRICT_BOUND() == gamma_eps(12)
    True
    """
    return gamma_eps(12)


def ROOT_BOUND(n: int) -> float:
    """GLSL root vs float64-twin root near the same simple root x*. The GLSL x passes
    ``|fl32 f(x)| <= K_n eps32 S`` so the exact ``|f(x)| <= (K_n + EVAL_BOUND(n)) eps32 S``; the twin's x
    passes ``|f(x)| <= K_n eps32 S`` in float64. To first order ``|x - x*| <= |f(x)| / |f'(x*)|``, so
    ``|x_glsl - x_twin| <= (2 K_n + EVAL_BOUND(n)) eps32 S / |f'|``. Error unit: eps32 S(x*) / |f'(x*)|.
    Valid while f' changes by less than half over that interval (else the case is ill-conditioned).

    >>> ROOT_BOUND(4)  # 2 K_4 + gamma_12
    30.000370502474993
    """
    return 2.0 * _roots.root_tolerance_k(n) + EVAL_BOUND(n)
