"""The stored scheme weights (splinevis/terrain/_c1_weights.py, splinevis/volume/_scheme_weights.py, written by
tools/gen_scheme_weights.py) are the derivations' results to the bit (the C1 terrain weights solved in exact
rational arithmetic, splinevis/_exact.py), the generated files are current, and building splines reads them
without any linear algebra.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from splinevis.terrain import c1_scheme
from splinevis.terrain._c1_weights import C1_FLOATS
from splinevis.volume import _scheme_weights, cubic, schemes
from splinevis.volume.stencil import _stored_weights

ROOT = Path(__file__).resolve().parents[1]


def _generator():
    spec = importlib.util.spec_from_file_location("gen_scheme_weights", ROOT / "tools" / "gen_scheme_weights.py")
    gen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gen)
    return gen


@pytest.fixture(scope="module")
def derived():
    """The weights re-derived by the linear algebra of the schemes (the proof of the stored tables)."""
    return _generator().derived_tables()


def _bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def _c1_forward_bound():
    """Forward error bound of the float64 least-norm solve of the C1 system, ``sqrt(N) u kappa max|W|``: the
    first-order perturbation bound of a consistent least-squares problem (residual 0), ``|dx| / |x| <= p u
    kappa`` with kappa = s_max / s_rank of the system, and p = sqrt(N) (N unknowns) for the backward error of
    an SVD-based solver. The last bits of the float64 solution depend on the BLAS kernels (an AVX-512 machine
    differs from an AVX2 one by ~8 units in the last place), so it is compared with the exact one within this."""
    A, _, _ = c1_scheme.c1_system()
    rank = c1_scheme._c1_solution()[1]["rank"]
    s = np.linalg.svd(A, compute_uv=False)
    stored = np.array(C1_FLOATS, dtype=np.float64)
    return np.sqrt(A.shape[1]) * np.finfo(float).eps / 2 * (s[0] / s[rank - 1]) * np.abs(stored).max()


def test_stored_c1_terrain_weights_are_the_exact_derivation(derived):
    stored = np.array(C1_FLOATS, dtype=np.float64)
    assert stored.shape == (len(c1_scheme.C1_STENCIL), 30)
    # the stored floats are the correctly rounded exact least-norm weights, to the bit
    exact = _generator().exact_c1()
    assert np.array_equal(_bits(stored), _bits([[float(q) for q in row] for row in exact]))
    assert np.array_equal(_bits(stored), _bits(derived["C1"]))
    # the exact weights satisfy the C1 and cubic-reproduction rows exactly (the system's entries are the
    # fractions of denominator <= 12 that its float64 entries round)
    A, rhs, _ = c1_scheme.c1_system()
    x = [q for row in exact for q in row]
    for r in np.random.default_rng(0).choice(A.shape[0], 40, replace=False):
        row = [Fraction(float(v)).limit_denominator(12) for v in A[r]]
        assert sum(a * b for a, b in zip(row, x) if a) == Fraction(float(rhs[r])).limit_denominator(12)
    # the float64 solve agrees within its forward error bound
    assert np.abs(stored - c1_scheme._c1_solution()[0]).max() <= _c1_forward_bound()
    # the scheme's window holds exactly these rows at the stencil's offsets, zeros elsewhere
    st = c1_scheme._c1()
    offs = [(st.x0 + b, st.y0 + a) for a in range(st.kh) for b in range(st.kw)]
    rows = [offs.index(o) for o in c1_scheme.C1_STENCIL]
    assert np.array_equal(_bits(st.W[rows]), _bits(stored))
    assert not np.delete(st.W, rows, axis=0).any()


@pytest.mark.parametrize("scheme", ["quadratic", "cubic"])
def test_stored_volume_weights_are_exact_fractions_equal_to_the_derivation(derived, scheme):
    W = derived[scheme.upper()]
    stored = _stored_weights(scheme)
    assert np.array_equal(_bits(stored), _bits(W))  # also no sign-of-zero difference
    assert not stored.flags.writeable
    shape, den = _scheme_weights.TABLES[scheme]
    assert stored.shape == shape and den == {"quadratic": 16, "cubic": 192}[scheme]
    # every derived float64 weight is the float64 value (correctly rounded) of an exact fraction n / den
    num = np.round(W * den).astype(np.int64)
    assert all(float(Fraction(int(n), den)) == float(w) for n, w in zip(num.ravel(), W.ravel()))
    assert _generator().common_denominator(W) == den
    # the interface reads them: point weights mapped to the tetrahedra
    tmap = (schemes._domain() if scheme == "quadratic" else cubic._domain())[1]
    assert np.array_equal(_bits(schemes.tet_weights(scheme)), _bits(stored[tmap]))


def test_generated_weight_modules_are_current(derived):
    for rel, text in _generator().generate(derived).items():
        assert (ROOT / rel).read_text() == text, f"run python tools/gen_scheme_weights.py ({rel} is stale)"


_NO_SOLVE = r"""
import numpy as np
import splinevis.terrain.c1_scheme as c1
import splinevis.volume.cubic as vc
import splinevis.volume.schemes as vs
from splinevis.terrain.schemes import terrain_coefficients
from splinevis.volume.model import VolumeSpline

def boom(*args, **kwargs):
    raise AssertionError("a scheme derivation / solver ran while building a spline")

for mod, names in [(np.linalg, ["lstsq", "solve", "svd", "matrix_rank", "pinv"]),
                   (c1, ["_c1_solution", "c1_system"]), (vs, ["_weights"]), (vc, ["_weights"])]:
    for name in names:
        setattr(mod, name, boom)
rng = np.random.default_rng(0)
coef, info = terrain_coefficients(rng.random((9, 9)), "C1")
v = rng.random((5, 5, 5))
for scheme in ("quadratic", "cubic"):
    s = VolumeSpline(v, scheme)
    s.cube_coefficients(np.array([[1, 2, 3]]))
    vs.spline_coefficients(v, scheme)
vc.cubic_c1_spline(v)
print("ok", coef.shape, s.weights.shape)
"""


def test_building_splines_runs_no_derivation():
    run = subprocess.run([sys.executable, "-c", _NO_SOLVE], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "ok (8, 8, 2, 15) (24, 20, 27)"
