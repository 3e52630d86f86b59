"""Least-squares fitting of a smooth geometry image to a parametrized surface, with fairness
[Losasso2003, sec. 4, "Fitting"].

The surface is sampled on a grid ``oversample`` times finer than the control image (through the octahedral map and
a spherical parametrization, or any map from unit directions to points), and the control points minimize

    E(g) = |B g - X|^2 / K  +  lambda |F g|^2 / L

``B`` the bicubic B-spline design matrix of the padded image at the ``K`` sample parameters (scipy's
``NdBSpline.design_matrix``), ``X`` the samples, ``F`` the fairness operator (each control point minus the centroid
of its four neighbours in the closed mesh, ``L`` rows) and ``lambda`` the fairness weight. The unknowns are the
*free* control points: one per class of samples the X-cut identifies, the four cut vertices eliminated as the
centroids of their neighbours [Losasso2003, eq. 2], so every fitted image is ``C^1`` at the cut vertices by
construction. The normal equations are solved by conjugate gradients (Jacobi-preconditioned,
[HestenesStiefel1952]), the three coordinates at once, with inner products in a fixed order
(:func:`splinevis._reproducible.conjugate_gradients`: the same image on every machine).

**Why one fairness weight for all control points.** Both terms are averages over the image, so where the
control points are ``h`` apart in 3-D the fairness term is ``lambda (h^2 / 4)^2 |Lap g|^2`` per unit of
surface area against the data term (the umbrella ``F g`` is ``h^2 / 4`` times the surface Laplacian of a
smooth ``g``): the fit smooths at the scale ``lambda^(1/4) h / 2``, finer where the map expands the mesh and
coarser where it compresses it. Weighting row ``i`` of ``F`` by ``w = (l / h)^4`` (``l`` the input's edge
length there) would smooth at the scale of the input's edges everywhere instead, meant against a spline that
rings beside the facets' creases where it resolves them (``h < l``). Measured (257 x 257, ``lambda = 0.1``,
folds counted as :mod:`.judge` does): the real meshes' folds sit where the map *compresses* (armadillo:
``l / h`` median 0.40 at the folded cells, 0.78 overall), where ``w < 1`` smooths less: 87,846 -> 81,416 folded
limit triangles on the armadillo, 5,839 -> 10,978 on nefertiti, and CG took 4 to 30 times the iterations;
``w = max(1, h / l)^4`` (more fairness where compressed) cut the armadillo's to 12,336 but moved the surface
1.6 % of the diagonal from the mesh. Coarse faceted inputs drawn fine (an icosahedron of 20 triangles, the
star blob of 80, at n = 17 to 65) do not ring with ``w = 1`` (no folded limit triangle at level 4). So the
weight is uniform, and ripples where the map compresses are met by the image's size and ``lambda`` (:mod:`.build`).

Why our own code: the design matrix and CG come from scipy; the elimination of the X-cut's identified samples and
cut vertices (the linear map from free variables to the padded image) is specific to the construction.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .._reproducible import conjugate_gradients
from .image import cut_neighbours, cut_vertices, image_uv, octahedral_to_sphere, pad
from .model import GeometryImage

__all__ = ["FitResult", "free_variables", "fit_geometry_image"]


def _representatives(n: int) -> np.ndarray:
    """Flat index of one representative per class of identified samples, for every sample."""
    N = n - 1
    rep = np.arange(n * n).reshape(n, n)
    for _ in range(3):  # border halves, then the corners through two borders
        rep[0] = np.minimum(rep[0], rep[0, ::-1])
        rep[N] = np.minimum(rep[N], rep[N, ::-1])
        rep[:, 0] = np.minimum(rep[:, 0], rep[::-1, 0])
        rep[:, N] = np.minimum(rep[:, N], rep[::-1, N])
        corners = (np.array([0, 0, N, N]), np.array([0, N, 0, N]))
        rep[corners] = rep[corners].min()
    return rep.ravel()


def free_variables(n: int):
    """The linear map from free control points to the image: ``(S, free)`` where ``S`` is a sparse
    ``(n * n, m)`` matrix with ``image.ravel() = S @ x`` for the ``m`` free points ``x`` and ``free`` their flat
    sample indices (one representative per class of samples the X-cut identifies; the four cut vertices are
    rows of ``S`` averaging their neighbours).

    >>> S, free = free_variables(5)
    >>> S.shape, len(free)  # 25 samples; 16 border samples make 9 classes (4 of them cut vertices)
    ((25, 14), 14)
    >>> np.asarray(S.sum(axis=1)).ravel().tolist() == [1.0] * 25  # every sample an affine combination
    True
    """
    from scipy.sparse import coo_matrix

    N = int(n) - 1
    rep = _representatives(n)
    cuts = cut_vertices(n)
    cut_flat = cuts[:, 0] * n + cuts[:, 1]
    is_cut = np.isin(rep, cut_flat)
    free = np.unique(rep[~is_cut])
    column = np.full(n * n, -1)
    column[free] = np.arange(free.size)
    rows, cols, vals = [], [], []
    plain = np.flatnonzero(~is_cut)
    rows.append(plain)
    cols.append(column[rep[plain]])
    vals.append(np.ones(plain.size))
    for flat_cut, nb in zip(cut_flat, cut_neighbours(n)):
        members = np.flatnonzero(rep == rep[flat_cut])
        nb_cols = column[rep[nb[:, 0] * n + nb[:, 1]]]
        if (nb_cols < 0).any():
            raise ValueError(f"a {N + 1} x {N + 1} image is too small: a cut vertex's neighbour is a cut vertex.")
        rows.append(np.repeat(members, 4))
        cols.append(np.tile(nb_cols, members.size))
        vals.append(np.full(4 * members.size, 0.25))
    S = coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                   shape=(n * n, free.size)).tocsr()
    S.sum_duplicates()
    return S, free


@dataclass(frozen=True, eq=False)
class FitResult:
    """A fitted geometry image and how well it fits its samples.

    Attributes
    ----------
    image : GeometryImage
    fairness : float
        The weight ``lambda``.
    rms, max : float
        Residual ``|P(s_k, t_k) - X_k|`` at the samples, RMS and largest, in units of the samples' bounding-box
        diagonal (not the distance to a mesh: :mod:`.measure`).
    roughness : float
        ``|F g|^2 / L``, the fairness term, in squared diagonal units.
    iterations : tuple of int
        CG iterations per coordinate.
    seconds : dict
        ``{"sample", "assemble", "solve"}``.
    values : (M, M, 3) array
        The fitted surface at the samples' parameters (``P(s_k, t_k)``).

    Examples
    --------
    >>> r = fit_geometry_image(lambda d: d, 9)
    >>> r.image.n, r.rms < 0.01
    (9, True)
    """

    image: GeometryImage
    fairness: float
    rms: float
    max: float
    roughness: float
    iterations: tuple
    seconds: dict = field(default_factory=dict)
    values: np.ndarray = field(default=None, repr=False)


def fit_geometry_image(surface_at, n: int, *, fairness: float = 1e-3, oversample: int = 4, samples=None,
                       rtol: float = 1e-10) -> FitResult:
    """Fit an ``n x n`` geometry image to the surface ``surface_at`` (module docstring).

    Parameters
    ----------
    surface_at : callable
        Unit directions ``(K, 3)`` -> surface points ``(K, 3)``: the inverse of a spherical parametrization
        (:func:`splinevis.geometry_image.sphere.surface_points`), or an exact map for synthetic shapes.
    n : int
        Samples per side, odd (``2^k + 1`` for levels of detail down to the octahedron).
    fairness : float
        ``lambda`` >= 0: 0 fits the samples as closely as the space allows (ripples where the parametrization
        is uneven), larger values trade distance for smoothness of the control net.
    oversample : int
        Samples per control point and direction (the sample grid has ``oversample (n - 1) + 1`` per side).
    samples : (M, M, 3) array_like, optional
        Samples on that grid already computed (then ``surface_at`` is not called).
    rtol : float
        Relative residual at which CG stops.

    Raises
    ------
    ValueError
        ``fairness`` negative, ``oversample`` < 1, samples not finite (which one), or CG not converging.

    Examples
    --------
    >>> r = fit_geometry_image(lambda d: d * [2.0, 1.0, 1.0], 17, fairness=0.0)  # an ellipsoid
    >>> bool(r.rms < 0.01), r.iterations[0] > 0
    (True, True)
    """
    from scipy.interpolate import NdBSpline

    if not fairness >= 0.0:
        raise ValueError(f"fairness must be >= 0, got {fairness!r}.")
    if int(oversample) < 1:
        raise ValueError(f"oversample must be >= 1, got {oversample!r}.")
    N = int(n) - 1
    seconds = {}
    t0 = time.perf_counter()
    M = int(oversample) * N + 1
    if samples is None:
        X = np.asarray(surface_at(octahedral_to_sphere(image_uv(M)).reshape(-1, 3)), dtype=np.float64)
    else:
        X = np.asarray(samples, dtype=np.float64)
        if X.shape[:2] != (M, M):
            raise ValueError(f"samples must be a ({M}, {M}, 3) grid for n={n}, oversample={oversample}; got {X.shape}.")
    X = X.reshape(-1, 3)
    bad = ~np.isfinite(X).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"surface sample {k} (row {k // M}, column {k % M} of the {M} x {M} grid) is not finite.")
    seconds["sample"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    S, free = free_variables(N + 1)
    Spad = S[pad(np.arange((N + 1) ** 2).reshape(N + 1, N + 1), 1).ravel()]  # padded image = Spad @ x
    knots = np.arange(-3.0, N + 4.0)
    w = np.linspace(0.0, N, M)
    tt, ss = np.meshgrid(w, w, indexing="ij")  # first B-spline dimension along rows (t), second along columns
    B = NdBSpline.design_matrix(np.column_stack([tt.ravel(), ss.ravel()]), (knots, knots), 3)
    A = (B @ Spad).tocsr()
    centre = pad(np.arange((N + 1) ** 2).reshape(N + 1, N + 1), 1)
    r, c = np.divmod(free, N + 1)
    r, c = r + 1, c + 1
    nb = [centre[r - 1, c], centre[r + 1, c], centre[r, c - 1], centre[r, c + 1]]
    F = S[free] - 0.25 * (S[nb[0]] + S[nb[1]] + S[nb[2]] + S[nb[3]])
    K, L = A.shape[0], F.shape[0]
    normal = (A.T @ A) / K + (fairness / L) * (F.T @ F)
    rhs = (A.T @ X) / K
    seconds["assemble"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    x0 = X.reshape(M, M, 3)[::oversample, ::oversample].reshape(-1, 3)[free]
    x, iterations = conjugate_gradients(normal, rhs, x0, diagonal=normal.diagonal(), rtol=rtol,
                                        maxiter=20 * normal.shape[0])
    for axis, count in enumerate(iterations):
        if count < 0:
            raise ValueError(f"conjugate gradients did not converge for coordinate {'xyz'[axis]} in "
                             f"{20 * normal.shape[0]} iterations; the samples may be degenerate (all on a plane "
                             "or a line).")
    iterations = tuple(iterations)
    seconds["solve"] = time.perf_counter() - t0

    G = (S @ x).reshape(N + 1, N + 1, 3)
    diag = float(np.linalg.norm(X.max(axis=0) - X.min(axis=0))) or 1.0
    values = A @ x
    res = np.linalg.norm(values - X, axis=1) / diag
    rough = float((np.linalg.norm(F @ x, axis=1) ** 2).mean()) / diag ** 2
    image = GeometryImage(G)
    return FitResult(image, float(fairness), float(np.sqrt((res ** 2).mean())), float(res.max()), rough,
                     iterations, seconds, values.reshape(M, M, 3))
