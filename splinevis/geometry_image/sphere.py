"""Spherical parametrization of a closed genus-0 triangle mesh: the first step of a smooth geometry image
[Losasso2003, sec. 3], which parametrizes the mesh on the unit sphere as Praun and Hoppe do [PraunHoppe2003] before mapping the sphere to the octahedral image.

The map sends each mesh vertex to a unit vector, each mesh triangle to the spherical triangle on those vectors.
It is built in three stages, each of which keeps it one-to-one:

1. **A bijective start: Tutte embedding and stereographic projection.** The star of one vertex ``v`` is cut
   out (the vertex of largest area whose ring has no chord, :func:`_start_vertices`; the next such vertex if the
   start fails the check below); the rest is a disk, embedded in the plane with its border (the ring of ``v``)
   on a circle and every inner vertex the weighted mean of its neighbours, with Floater's mean-value weights
   [Floater2003]. The weights are positive and the border strictly convex, so
   the embedding is one-to-one [Tutte1963; Floater2003b] and close to conformal. The inverse stereographic projection puts
   the disk on the sphere and ``v`` at the north pole; lines go to circles, so the images of the disk's
   triangles (circular-arc triangles) and of the star tile the sphere once, and the flat triangles on the same
   vertices do too unless a triangle is large against the arcs' bulge, which the check below would catch.
   A harmonic embedding shrinks protrusions exponentially along their length: on a four-legged scan the feet
   came out flat below double precision for every cut, and on the armadillo so squeezed (stretch 1993) that the
   relaxation could not recover. There the coarse-to-fine start of :mod:`.hierarchy` replaces stages 1 and 2.
2. **Möbius centering** (:mod:`.mobius`): a conformal start crowds most of the surface into a small part of the
   sphere; the Möbius transformation that puts the area-weighted centroid of the vertex images at the origin
   spreads it out, keeping the map conformal and one-to-one.
3. **Stretch relaxation.** The L2 stretch of the map from the sphere to the mesh [Sander2001], the energy Praun and Hoppe minimize,
   measured on spherical triangle areas (:mod:`.stretch`), grows without bound as a spherical triangle
   degenerates, so descending it keeps the triangles apart. The descent is L-BFGS [Nocedal1980] on the tangent planes, the points put back on the sphere
   after each step, with :meth:`.stretch.StretchEnergy.preconditioner` as the initial inverse Hessian
   (factored every 4th step by Eigen's sparse Cholesky, whose bits, unlike SuperLU's, do not follow the machine's BLAS;
   every inner product in a fixed order, :mod:`splinevis._reproducible`). A step must lower the energy (Armijo); where it would flip a triangle it is
   halved for that triangle's vertices until none flips (:func:`_safe_step`).

   Why the L2 stretch and not a higher power of it (toward Sander et al.'s L-infinity stretch): weighting the
   largest stretches more lowers them, but not the folds of the fitted image. Measured on the nefertiti scan
   (n = 257, the folds counted as :mod:`.judge` does): ``sum area s^2`` (``s`` the squared per-triangle
   stretch, normalized) took the largest stretch from 5.49 to 3.25 and the mean from 1.208 to 1.188, and the
   folded limit triangles at fairness 0.1 from 0.054 % to 0.20 % (0.0093 % to 0.0185 % at the fairness kept).

The result is checked, not assumed, to be one-to-one: every triangle must have ``det[a, b, c] > DET_BOUND``
(outward oriented beyond rounding), and the spherical triangles' areas must sum to ``4 pi``. That sum is ``4 pi`` times the map's
degree, so it tells a one-to-one map from one wrapping the sphere twice without flipping a triangle; the
tolerance :data:`AREA_TOLERANCE` is far above rounding (``~1e-16`` per triangle) and far below the ``4 pi``
between degrees.

The stretch reported is normalized as Sander et al. do it, so that 1 is the optimum (:mod:`.stretch`).

Why our own code: no Python library ships a spherical parametrization; this one is a few sparse solves (scipy)
on libigl's mass matrix and cotangent entries, and numpy.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .mobius import center_on_sphere
from .relax import DET_BOUND, _det, _relax, _unit
from .stretch import StretchEnergy
from .tutte import _start_vertices, _tutte_sphere
from .validate import check_genus0

__all__ = ["SphericalMap", "spherical_parametrization", "locate", "surface_points", "AREA_TOLERANCE", "DET_BOUND",
           "SQUEEZED"]

#: Stretch of a Tutte start above which ``start="auto"`` builds the coarse-to-fine start instead (a squeeze the
#: relaxation does not undo: measured 24 -> 1.27 on the elephant, 1993 -> 87 on the armadillo; see
#: :func:`spherical_parametrization`).
SQUEEZED = 100.0

#: Largest accepted ``|sum of spherical triangle areas - 4 pi|`` (see the module docstring).
AREA_TOLERANCE = 1e-6



@dataclass(frozen=True)
class SphericalMap:
    """A one-to-one map of a closed genus-0 triangle mesh onto the unit sphere, made by
    :func:`spherical_parametrization`: vertex ``i`` goes to ``sphere[i]``, each triangle to the spherical
    triangle on its vertices' images.

    Attributes
    ----------
    points : (V, 3) float64
        The mesh's vertices.
    faces : (F, 3) int64
        Its triangles, outward oriented.
    sphere : (V, 3) float64
        The unit vectors the vertices go to.
    stretch : dict
        The map's L2 stretch and area distortion (:func:`spherical_parametrization`).
    flipped : int
        Triangles with ``det[a, b, c] <= DET_BOUND`` on the sphere (flipped or flat within rounding): 0.
    timings : dict
        Seconds per stage.
    start : str
        Which one-to-one start the relaxation began from: ``"tutte"`` or ``"coarse to fine"``.
    start_levels : int
        The coarse-to-fine start's levels (rounds of collapses re-inserted); 0 for a Tutte start.

    The arrays are read-only.

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> smap = spherical_parametrization(sphere_mesh(level=1), iterations=0)
    >>> smap.sphere.shape, smap.faces.dtype, smap.flipped, smap.sphere.flags.writeable
    ((42, 3), dtype('int64'), 0, False)
    """

    points: np.ndarray
    faces: np.ndarray
    sphere: np.ndarray
    stretch: dict = field(default_factory=dict)
    flipped: int = 0
    timings: dict = field(default_factory=dict)
    start: str = "tutte"
    start_levels: int = 0


def _frozen(a, dtype):
    a = np.array(a, dtype=dtype, copy=True)
    a.flags.writeable = False
    return a


def _spherical_area_sum(X, F):
    """Sum of the signed areas of the spherical triangles [VanOosterom1983]: ``tan(A / 2) = det[a, b, c] / (1 + a.b + b.c + c.a)``."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = 1.0 + np.einsum("ij,ij->i", a, b) + np.einsum("ij,ij->i", b, c) + np.einsum("ij,ij->i", c, a)
    return float(2.0 * np.arctan2(num, den).sum())


# --------------------------------------------------------------------------------------------- the pipeline
def spherical_parametrization(mesh, *, name: str = "mesh", iterations: int = 200, tol: float = 1e-4,
                              progress: bool = False, start: str = "auto",
                              level_inverse: float | None = None) -> SphericalMap:
    """Map the closed genus-0 triangle mesh ``mesh`` (a ``pyvista.PolyData`` of outward triangles) one-to-one
    onto the unit sphere with low L2 stretch (module docstring); return a :class:`SphericalMap`.

    Parameters
    ----------
    mesh : pyvista.PolyData
        Checked first by :func:`~splinevis.geometry_image.validate.check_genus0`, whose
        :class:`~splinevis.errors.MeshTopologyError` names the failed check (and ``name``).
    name : str
        The mesh's name in messages.
    iterations : int
        Most steps of the stretch relaxation (0: the centered conformal start).
    tol : float
        The relaxation stops once its last 5 steps lowered the energy by less than ``5 tol`` of it (not before
        its 10th step, while L-BFGS still learns the curvature), or when no step lowers it. ``1e-3`` is about
        twice as fast on the 100k-triangle scans but leaves local distortion the geometry image's fit turns into
        ripples: nefertiti folded on 0.18 % of its level-4 limit triangles at fairness 0.1 against 0.048 % at
        ``1e-4`` (0.046 % and 0.0086 % at fairness 3).
    progress : bool
        Show a tqdm progress bar over the relaxation's steps.
    start : {"auto", "tutte", "hierarchy"}
        The one-to-one start: the Tutte embedding with Moebius centering (``"tutte"``: stages 1 and 2), the
        coarse-to-fine construction of :mod:`.hierarchy` (``"hierarchy"``), or ``"auto"``: Tutte, replaced by
        coarse to fine where no Tutte start is one-to-one or its stretch exceeds :data:`SQUEEZED`. The Tutte
        start squeezes protrusions, and past some point the relaxation cannot undo it: the armadillo's Tutte
        start has stretch 1993 and relaxes to 87, its coarse-to-fine start 2.68 and relaxes to 2.07 (the
        elephant's Tutte start, 24, relaxes to 1.27 as well as its coarse-to-fine one).
    level_inverse : float, optional
        Weight of the inverse map's stretch in the coarse-to-fine start's relaxations (None:
        :data:`.hierarchy.LEVEL_INVERSE`, whose comment has what it was measured to do): 1 kept the coarse levels
        of the four-legged scan nearer conformal, its geometry image folding on 0.038 % instead of 0.34 % of the
        limit triangles, and made the bust's worse.

    ``stretch`` holds the L2 stretch of the map from the sphere to the mesh, normalized so that 1 is the optimum
    (module docstring): ``"l2"`` over the mesh (at least 1); ``"l2_max"`` and ``"l2_p95"`` over its triangles,
    ``sqrt(|J_t|^2 / 2)`` normalized alike (below 1: a triangle with more than its share of the sphere);
    ``"area_ratio_max"`` and ``"area_ratio_p95"`` of ``max(r, 1/r)``, ``r`` a triangle's share of the mesh's area
    over its share of the sphere's; ``"anisotropy_median"`` and ``"anisotropy_p95"``, area-weighted over the mesh,
    of ``sigma_1 / sigma_2`` (:meth:`.stretch.StretchEnergy.anisotropy`: 1 where the map is conformal; the L2
    stretch does not see it, as it never penalizes a direction the sphere oversamples); ``"l2_start"``, ``"l2"`` before the relaxation; ``"steps"``, its steps.
    ``timings`` has the seconds of ``"validate"``, ``"tutte"``,
    ``"mobius"``, ``"hierarchy"``, ``"relax"``, ``"check"`` and ``"total"``. A map that fails the final
    one-to-one check raises ``RuntimeError`` (each stage keeps the map one-to-one; the check guards against
    lost precision).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import stretched_blob
    >>> smap = spherical_parametrization(stretched_blob(level=2), name="blob")
    >>> smap.flipped, bool(np.allclose(np.linalg.norm(smap.sphere, axis=1), 1.0))
    (0, True)
    >>> bool(1.0 <= smap.stretch["l2"] < smap.stretch["l2_start"])
    True
    """
    import igl

    t0 = time.perf_counter()
    timings = {}
    check_genus0(mesh, name)
    P = np.asarray(mesh.points, dtype=np.float64)
    F = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 4)[:, 1:]  # all triangles: checked
    timings["validate"] = time.perf_counter() - t0

    if level_inverse is not None and not (np.isfinite(level_inverse) and level_inverse >= 0):
        raise ValueError(f"level_inverse must be a finite weight >= 0 or None, got {level_inverse!r}.")
    if start not in ("auto", "tutte", "hierarchy"):
        raise ValueError(f"start must be 'auto', 'tutte' or 'hierarchy', got {start!r}.")
    mass = igl.massmatrix(P, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    timings["tutte"] = timings["mobius"] = timings["hierarchy"] = 0.0
    failure = f"{name}: no vertex has a chordless ring to cut the mesh open at."
    X, method, levels = None, "tutte", 0
    S = StretchEnergy(P, F)
    for v in (_start_vertices(F, mass) if start != "hierarchy" else ()):  # the next one if not one-to-one
        t = time.perf_counter()
        Y = _tutte_sphere(P, F, mass, v)
        timings["tutte"] += time.perf_counter() - t
        t = time.perf_counter()
        Y = center_on_sphere(Y, mass)
        timings["mobius"] += time.perf_counter() - t
        try:
            _check_one_to_one(Y, F, name, f"the Tutte start cut at vertex {v}")
            X = Y
            break
        except RuntimeError as err:
            failure = str(err)
    l2_start = S.report(X)["l2"] if X is not None else None
    squeezed = l2_start is not None and start == "auto" and l2_start > SQUEEZED
    if X is None and start == "tutte":
        raise RuntimeError(failure + " (start='auto' or 'hierarchy' builds the coarse-to-fine start)")
    if X is None or squeezed:
        from .hierarchy import hierarchical_sphere

        t = time.perf_counter()
        try:
            Y, info = hierarchical_sphere(P, F, progress=bool(progress), **(
                {} if level_inverse is None else {"inverse": float(level_inverse)}))
            _check_one_to_one(Y, F, name, "the coarse-to-fine start")
            X, method, levels = Y, "coarse to fine", int(info["levels"])
            l2_start = S.report(X)["l2"]
        except RuntimeError as err:
            if X is None:
                raise RuntimeError(f"{failure}; and {err}") from err
        timings["hierarchy"] = time.perf_counter() - t

    t = time.perf_counter()
    X, steps = _relax(X, S, int(iterations), bool(progress), float(tol))
    timings["relax"] = time.perf_counter() - t

    t = time.perf_counter()
    _check_one_to_one(X, F, name, "the relaxed map")
    stretch = {**S.report(X), "l2_start": l2_start, "steps": steps}
    timings["check"] = time.perf_counter() - t
    timings["total"] = time.perf_counter() - t0
    return SphericalMap(points=_frozen(P, np.float64), faces=_frozen(F, np.int64), sphere=_frozen(X, np.float64),
                        stretch=stretch, flipped=int((~(_det(X, F) > DET_BOUND)).sum()), timings=timings,
                        start=method, start_levels=levels)


def _check_one_to_one(X, F, name, what):
    flipped = int((~(_det(X, F) > DET_BOUND)).sum())
    area = _spherical_area_sum(X, F)
    if flipped or abs(area - 4 * np.pi) > AREA_TOLERANCE:
        raise RuntimeError(f"{name}: {what} is not one-to-one: {flipped} flipped triangles, spherical area "
                           f"{area:.12g} against 4 pi = {4 * np.pi:.12g}.")


# -------------------------------------------------------------------------------------------- point location
def locate(sphere_map, directions, *, k: int = 8, tol: float = 1e-12):
    """The spherical triangle of ``sphere_map`` containing each direction, and the barycentric coordinates of
    the direction's ray's crossing with that flat triangle.

    Parameters
    ----------
    sphere_map : SphericalMap
    directions : array_like, (N, 3) or (3,)
        Any nonzero lengths.
    k : int
        Candidates first tried per direction: the triangles with the ``k`` nearest centroids; the directions
        none contains are tried again with ``4 k``, ``16 k``, ... up to all triangles.
    tol : float
        A barycentric coordinate down to ``-tol`` counts as inside (directions on edges and vertices).

    Returns
    -------
    face : (N,) int64
    bary : (N, 3) float64
        Sum 1, each at least ``-tol``: ``bary @ sphere[faces[face]]`` is along the direction and
        ``bary @ points[faces[face]]`` the mesh point (:func:`surface_points`).

    A direction ``q`` is in triangle ``abc`` (``det[a, b, c] > 0``) when ``q = alpha a + beta b + gamma c``
    with ``alpha, beta, gamma >= 0``; ``alpha = det[q, b, c] / det[a, b, c]`` and alike, so the barycentrics are
    ``(det[q, b, c], det[a, q, c], det[a, b, q])`` over their sum, which must be positive (else ``q`` is on the
    far side). Of the candidates the one with the largest smallest coordinate wins. A direction no triangle
    contains (the map is not one-to-one) raises ``ValueError``.

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> smap = spherical_parametrization(sphere_mesh(level=1), iterations=0)
    >>> face, bary = locate(smap, [[0.0, 0.0, 1.0], [1.0, 1.0, 1.0]])
    >>> face.shape, bool(np.allclose(bary.sum(axis=1), 1.0) and (bary >= -1e-12).all())
    ((2,), True)
    """
    from scipy.spatial import cKDTree

    q = np.atleast_2d(np.asarray(directions, dtype=np.float64))
    length = np.linalg.norm(q, axis=1) if q.ndim == 2 and q.shape[1] == 3 else None
    if length is None or not (np.isfinite(length).all() and (length > 0).all()):
        raise ValueError(f"directions must be finite nonzero 3-vectors, shape (N, 3); got shape {q.shape}.")
    q = q / length[:, None]
    X, F = sphere_map.sphere, sphere_map.faces
    tree = cKDTree(_unit(X[F].sum(axis=1)))
    face = np.full(len(q), -1, dtype=np.int64)
    bary = np.zeros((len(q), 3))
    for start in range(0, len(q), 1 << 15):  # bounded memory: (chunk, k, 3) arrays
        chunk = slice(start, start + (1 << 15))
        face[chunk], bary[chunk] = _locate_in(X, F, tree, q[chunk], int(k), float(tol))
    return face, bary


def _locate_in(X, F, tree, q, k, tol):
    face = np.full(len(q), -1, dtype=np.int64)
    bary = np.zeros((len(q), 3))
    todo = np.arange(len(q))
    kk = min(k, len(F))
    while todo.size:
        cand = tree.query(q[todo], k=kk)[1].reshape(len(todo), kk)
        a, b, c = (X[F[cand, i]] for i in range(3))
        Q = np.broadcast_to(q[todo][:, None, :], a.shape)
        w = np.stack([np.einsum("nki,nki->nk", Q, np.cross(b, c)), np.einsum("nki,nki->nk", a, np.cross(Q, c)),
                      np.einsum("nki,nki->nk", a, np.cross(b, Q))], axis=2)
        total = w.sum(axis=2, keepdims=True)
        w = np.where(total > 0, w / np.where(total > 0, total, 1.0), -np.inf)
        best = np.argmax(w.min(axis=2), axis=1)
        rows = np.arange(len(todo))
        found = w[rows, best].min(axis=1) >= -tol
        face[todo[found]] = cand[rows, best][found]
        bary[todo[found]] = w[rows, best][found]
        todo = todo[~found]
        if todo.size and kk == len(F):
            raise ValueError(f"{todo.size} directions, like {q[todo[0]].tolist()}, are in no spherical triangle "
                             "(is the map one-to-one?).")
        kk = min(4 * kk, len(F))
    return face, bary


def surface_points(sphere_map, directions) -> np.ndarray:
    """The mesh points the spherical map sends to ``directions`` (``(N, 3)``, any nonzero lengths):
    ``bary @ points[faces[face]]`` with :func:`locate`'s triangles and barycentrics (the inverse map, linear on
    each triangle along the rays).

    Examples
    --------
    >>> from datasets_synthetic.closed_meshes import ellipsoid_mesh
    >>> smap = spherical_parametrization(ellipsoid_mesh(level=1), iterations=0)
    >>> bool(np.allclose(surface_points(smap, smap.sphere), smap.points, atol=1e-12))
    True
    """
    face, bary = locate(sphere_map, directions)
    return np.einsum("ni,nij->nj", bary, sphere_map.points[sphere_map.faces[face]])
