"""First roots of ray-restricted cubics: the GPU root finders measured against the robust reference.

The volume ray caster (``glsl/programs/isosurface.glsl``) restricts a cubic trivariate spline to the
ray's segment in a tetrahedron, subtracts the isovalue and needs the first root in [0, 1] of the
resulting cubic BB polynomial [Kalbe2008, sec. 5.3]. The ray caster offers a stable closed form
(``sv_first_root_cubic``) and the Newton iteration from three secure starts of [Kalbe2008, sec. 5.3]
(``sv_first_root_newton3``); this module compares them -- and the library's bracketed Newton and the
four-start Newton of [Reis2008, sec. V] --
through their float32 twins on realistic inputs (:func:`sample_ray_cubics`), with
:func:`splinevis.bb.roots.roots_reference` as the judge (:func:`compare_root_methods`).

Example
-------
>>> from splinevis.volume.root_methods import compare_root_methods, sample_ray_cubics
>>> table = compare_root_methods(sample_ray_cubics(2000, seed=1), iterations=(5,))
>>> table["analytic cubic"]["missed"]
0
"""

from __future__ import annotations

import numpy as np

from ..bb import roots as _roots
from ..bb.simplex import restrict_to_segment
from .partition import NUM_TETS, barycentric_matrices

__all__ = ["sample_ray_cubics", "compare_root_methods", "first_root_tolerance", "format_table", "CATEGORIES"]

#: Outcome categories of :func:`compare_root_methods` (every cubic falls in exactly one).
CATEGORIES = ("correct", "later", "earlier", "inaccurate", "missed", "spurious", "no_root_agreed")

_EPS32 = 2.0**-23


def _fields():
    # datasets_synthetic is a top-level package of the repository (synthetic test data)
    from datasets_synthetic.volumes import marschner_lobb, sphere_distance

    return [marschner_lobb(), sphere_distance()]


def sample_ray_cubics(n: int, seed: int = 0, *, samples: int = 24, return_source: bool = False):
    """Cubic BB polynomials ``p - isovalue`` along random ray segments through relevant tetrahedra.

    Two synthetic volumes (Marschner-Lobb and a sphere distance field, ``samples`` per axis, from
    ``datasets_synthetic.volumes``) are approximated by the cubic C1 spline on the type-6 partition
    (:class:`splinevis.volume.model.VolumeSpline` with ``"cubic"``). Half of the rays go through each.
    For every ray: a random relevant tetrahedron of the field's isovalue (uniform over all relevant
    (cube, tetrahedron) pairs of :meth:`~splinevis.volume.model.VolumeSpline.relevant`), a uniform random
    point inside it and a uniform random direction; the line is clipped to the tetrahedron by its
    barycentric coordinates (``lam_i >= 0``, entry to exit, as the ray caster clips), the tetrahedron's
    cubic is restricted to that segment by blossoming (:func:`splinevis.bb.simplex.restrict_to_segment`)
    and the isovalue subtracted.

    Parameters
    ----------
    n : int
        Number of cubics.
    seed : int
        Seed of ``numpy.random.default_rng``.
    samples : int
        Grid samples per axis of the synthetic volumes.
    return_source : bool
        Also return an ``(n,)`` int array: 0 Marschner-Lobb, 1 sphere distance.

    Returns
    -------
    (n, 4) float64 ndarray (and the source indices)

    Examples
    --------
    >>> cubics, source = sample_ray_cubics(6, seed=0, return_source=True)
    >>> cubics.shape, np.bincount(source).tolist()  # half from each volume
    ((6, 4), [3, 3])
    """
    from .model import VolumeSpline

    n = int(n)
    if n < 0:
        raise ValueError(f"n must be >= 0, got {n!r}.")
    rng = np.random.default_rng(seed)
    bmats = barycentric_matrices()  # lam = B_t @ (x, y, z, 1), local cube coordinates
    fields = _fields()
    counts = [n // 2 + n % 2, n // 2]
    out, src = [], []
    bits = np.int64(1) << np.arange(NUM_TETS, dtype=np.int64)
    for f_idx, (field, m) in enumerate(zip(fields, counts)):
        if m == 0:
            continue
        spline = VolumeSpline(field.sample(samples), "cubic")
        rel = spline.relevant(field.isovalue)
        has = (rel.masks[:, None] & bits[None, :]) != 0          # (cubes, 24)
        cube_idx, tet_idx = np.nonzero(has)
        pick = rng.integers(0, len(cube_idx), size=m)
        cubes_used, inv = np.unique(cube_idx[pick], return_inverse=True)
        coef = spline.cube_coefficients(rel.cubes[cubes_used])[inv.ravel(), tet_idx[pick]]  # (m, 20)
        B = bmats[tet_idx[pick]]                                   # (m, 4, 4)
        lam_p = rng.dirichlet(np.ones(4), size=m)                  # uniform point in the tetrahedron
        d = rng.normal(size=(m, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        dl = np.einsum("mij,mj->mi", B[:, :, :3], d)               # d lam / ds along the ray
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -lam_p / dl                                        # where lam_i reaches 0
        s_in = np.max(np.where(dl > 0, s, -np.inf), axis=1)        # entry: last face crossed inwards
        s_out = np.min(np.where(dl < 0, s, np.inf), axis=1)        # exit: first face crossed outwards
        lam0 = np.clip(lam_p + s_in[:, None] * dl, 0.0, None)
        lam1 = np.clip(lam_p + s_out[:, None] * dl, 0.0, None)
        lam0 /= lam0.sum(1, keepdims=True)
        lam1 /= lam1.sum(1, keepdims=True)
        cub = restrict_to_segment(coef, lam0, lam1, d=3) - field.isovalue
        out.append(cub)
        src.append(np.full(m, f_idx))
    cubics = np.concatenate(out) if out else np.zeros((0, 4))
    source = np.concatenate(src) if src else np.zeros(0, np.int64)
    perm = rng.permutation(len(cubics))
    cubics, source = cubics[perm], source[perm]
    return (cubics, source) if return_source else cubics


def _jet(c, t):
    """float64 f, S = sum |c_k| B_k, f', f'' of cubics c (M, 4) at t (M,) (NaN t -> NaN)."""
    t = np.where(np.isfinite(t), t, 0.5)
    s = 1.0 - t
    B = np.stack([s**3, 3 * s * s * t, 3 * s * t * t, t**3], axis=-1)
    f = np.sum(c * B, -1)
    S = np.sum(np.abs(c) * B, -1)
    d = 3.0 * np.diff(c, axis=-1)
    fp = d[:, 0] * s * s + 2 * d[:, 1] * s * t + d[:, 2] * t * t
    dd = 2.0 * np.diff(d, axis=-1)
    fpp = dd[:, 0] * s + dd[:, 1] * t
    return f, S, fp, fpp


def first_root_tolerance(c, r):
    """Derived tolerance ``delta(r)`` for a float32 root finder at a reference root ``r`` of cubics ``c``.

    A float32 method returns an ``x`` whose exact residual is at most the value-level uncertainty
    ``eps_f = (2 K_3 + EVAL_BOUND(3)) eps32 S(r)`` (the residual test's ``K_3 eps32 S`` on both sides
    plus the float32 de Casteljau error ``gamma_9 S``; :func:`splinevis.selftest.ROOT_BOUND`). With the
    local model ``|f(r + dx)| >= |f'| |dx| - |f''| dx^2 / 2`` this confines ``x`` to
    ``|dx| <= 2 eps_f / (|f'| + sqrt(f'^2 + 2 |f''| eps_f))`` -- the linear bound ``eps_f / |f'|`` for a
    simple root, ``sqrt(2 eps_f / |f''|)`` for a double (tangent) root -- and the float32 argument itself
    is only resolved to half an ulp, ``<= eps32 |r| / 2``; ``delta = that + eps32 |r|``.

    Examples
    --------
    A simple root of ``(t - 1/4)(t - 3/4)`` and the double root of ``(t - 1/2)^2``, in units of eps32:

    >>> c = np.array([[3 / 16, -7 / 48, -7 / 48, 3 / 16], [1 / 4, -1 / 12, -1 / 12, 1 / 4]])
    >>> (first_root_tolerance(c, np.array([0.25, 0.5])) / 2.0 ** -23).round(1)
    array([   7.6, 4857.8])
    """
    from ..bb.float32_bounds import EVAL_BOUND

    c = np.asarray(c, dtype=np.float64)
    r = np.asarray(r, dtype=np.float64)
    _, S, fp, fpp = _jet(c, r)
    eps_f = (2.0 * _roots.root_tolerance_k(3) + EVAL_BOUND(3)) * _EPS32 * S
    with np.errstate(all="ignore"):
        lin = 2.0 * eps_f / (np.abs(fp) + np.sqrt(fp * fp + 2.0 * np.abs(fpp) * eps_f))
        lin = np.where(np.isfinite(lin), lin, 0.0)
    return lin + _EPS32 * np.abs(r)


def _classify(c, x, ref):
    r1 = ref[:, 0]
    has, found = np.isfinite(r1), np.isfinite(x)
    tol = first_root_tolerance(c, r1)
    with np.errstate(invalid="ignore"):
        correct = has & found & (np.abs(x - r1) <= tol)
        dist = np.abs(np.where(np.isfinite(ref), ref, np.inf) - x[:, None])
        nearest = np.argmin(np.where(np.isnan(dist), np.inf, dist), axis=1)
        rest = has & found & ~correct
        # a returned x passing the exact-arithmetic residual test (K_3 + EVAL_BOUND(3) = 9 + 4.5 units, plus
        # the argument rounding eps32 |x f'|) is a near root: a complex pair within float32 rounding of the
        # real axis, indistinguishable from a touching root in float32
        fx, Sx, fpx, _ = _jet(c, x)
        near = np.abs(fx) <= ((_roots.root_tolerance_k(3) + 4.5) * _EPS32 * Sx + _EPS32 * np.abs(x * fpx))
        earlier = rest & (x < r1 - tol) & near
        later = rest & ~earlier & (nearest > 0)
    spurious = ~has & found
    return {
        "correct": correct,
        "later": later,
        "earlier": earlier,
        "inaccurate": rest & ~earlier & ~later,
        "missed": has & ~found,
        "spurious": spurious,
        "no_root_agreed": ~has & ~found,
        "spurious_near_root": spurious & near,
    }


def compare_root_methods(cubics, iterations=(3, 5, 8), *, ref=None, masks: bool = False) -> dict:
    """Outcome counts of the float32 root finders on cubics, judged by the float64 reference.

    Methods (float32 twins of ``glsl/lib/core/roots.glsl``; the coefficients are first rounded to float32, as
    the GPU sees them, and the reference solves that same float32 polynomial in float64):

    * ``"analytic cubic"`` -- :func:`splinevis.bb.roots.first_root_cubic` (closed form + 1 polish step);
    * ``"newton3 paper I=N"`` -- :func:`splinevis.bb.roots.newton_three_starts` ([Kalbe2008, sec. 5.3]);
    * ``"bracketed I=N"`` -- :func:`splinevis.bb.roots.first_root_bracketed` (the library default);
    * ``"newton4 I=N"`` -- :func:`splinevis.bb.roots.newton_secure` (the four starts of [Reis2008, sec. V]);

    for every ``N`` in ``iterations``.

    Categories (:data:`CATEGORIES`, each cubic in exactly one): ``correct`` -- within
    :func:`first_root_tolerance` of the reference's first root; ``later`` -- a root was returned whose
    nearest reference root is a later one; ``earlier`` -- returned before the first root by more than the
    tolerance at a near root (passing the exact-arithmetic residual test: a near miss before the first root);
    ``inaccurate`` -- otherwise outside the tolerance, nearest to the first root; ``missed`` -- none
    returned though the reference has one; ``spurious`` -- returned though the reference has none
    (``spurious_near_root``, also given, counts those passing the exact-arithmetic residual test: near
    misses indistinguishable from a touching root in float32); ``no_root_agreed``.

    Parameters
    ----------
    cubics : (n, 4) array_like
    iterations : iterable of int
        Iteration counts of the iterative methods (1..8).
    ref : (n, 3) ndarray, optional
        Precomputed ``roots_reference`` of the float32-rounded cubics.
    masks : bool
        Return boolean masks instead of counts.

    Returns
    -------
    dict
        ``{method: {category: count}}`` plus ``"_n"`` and ``"_with_root"`` (cubics whose reference has a root).

    Examples
    --------
    >>> table = compare_root_methods([[3 / 16, -7 / 48, -7 / 48, 3 / 16], [1.0, 2.0, 2.0, 1.0]], iterations=(5,))
    >>> table["_n"], table["_with_root"], table["analytic cubic"]["correct"], table["analytic cubic"]["no_root_agreed"]
    (2, 1, 1, 1)
    """
    c = np.asarray(cubics, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 4:
        raise ValueError(f"cubics must have shape (n, 4), got {c.shape}.")
    c32 = c.astype(np.float32)
    c64 = c32.astype(np.float64)
    if ref is None:
        ref = _roots.roots_reference(c64)
    f32 = np.float32
    runs = {"analytic cubic": lambda: _roots.first_root_cubic(c32, dtype=f32)}
    for it in iterations:
        it = int(it)
        runs[f"newton3 paper I={it}"] = lambda it=it: _roots.newton_three_starts(c32, it, dtype=f32)
        runs[f"bracketed I={it}"] = lambda it=it: _roots.first_root_bracketed(c32, it, dtype=f32)
        runs[f"newton4 I={it}"] = lambda it=it: _roots.newton_secure(c32, it, dtype=f32)
    table = {"_n": int(len(c)), "_with_root": int(np.isfinite(ref[:, 0]).sum())}
    for name, run in runs.items():
        x = np.asarray(run(), dtype=np.float64)
        cl = _classify(c64, x, ref)
        table[name] = cl if masks else {k: int(v.sum()) for k, v in cl.items()}
    return table


def format_table(table: dict) -> str:
    """The counts of :func:`compare_root_methods` as a fixed-width text table.

    Examples
    --------
    >>> table = compare_root_methods([[3 / 16, -7 / 48, -7 / 48, 3 / 16], [1.0, 2.0, 2.0, 1.0]], iterations=(5,))
    >>> print(format_table(table).splitlines()[2])
    analytic cubic             1          0          0          0          0          0          1          0
    """
    cols = list(CATEGORIES) + ["spurious_near_root"]
    names = [k for k in table if not k.startswith("_")]
    w = max(len(k) for k in names)
    lines = [f"{'method':<{w}} " + " ".join(f"{h:>10}" for h in [c[:10] for c in cols]),
             f"(n = {table['_n']}, with a first root in [0, 1]: {table['_with_root']})"]
    for k in names:
        lines.append(f"{k:<{w}} " + " ".join(f"{table[k][col]:>10d}" for col in cols))
    return "\n".join(lines)
