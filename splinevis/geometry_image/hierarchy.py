"""A one-to-one start for the spherical parametrization of meshes a one-shot Tutte embedding cannot handle
(scans with legs, ears and fingers), coarse to fine as Praun and Hoppe build theirs [PraunHoppe2003, sec. 3]:

1. **Simplify** by half-edge collapses ``v -> u`` (``v`` removed, its triangles given to ``u``; the two
   triangles on the edge vanish), in rounds: each round collapses, shortest edge first, a set of vertices whose
   closed neighbourhoods are pairwise disjoint, so the collapses of a round do not interact and each keeps the
   mesh a closed genus-0 manifold when it passes the link condition (``u`` and ``v`` share exactly the two
   neighbours opposite their edge, each of degree 4 or more). Rounds go on down to a tetrahedron, or until no
   collapse is allowed.
2. **Embed the base**: a tetrahedron's four vertices at a regular tetrahedron's, two of them swapped if the
   triangles come out clockwise (every triangle of a tetrahedron on those points is then outward); any other
   base by the Tutte start of :mod:`.sphere`.
3. **Re-insert** the rounds in reverse. A removed ``v`` goes near ``u``, inside the corner its two lost
   triangles span there: at ``unit(X_u + s d)`` for a direction ``d`` into that corner, ``s`` halved until all
   of ``v``'s triangles are outward (``det[a, b, c] > 0``). For small ``s`` they are: ``v``'s other triangles
   tend to ``u``'s old ones, which were outward, and the two new ones open inside the corner. Each inserted
   vertex then moves to the analytic centre of the region where all its triangles are outward (its ring's
   kernel, an intersection of hemispheres), so no triangle is left a hair from flat, then descends the stretch
   of its own star alone (:func:`_settle_inserted`, Praun and Hoppe's per-vertex optimization); and the stretch of
   the whole level is relaxed (:func:`.relax._relax`, which never flips a triangle): a few steps after every
   round while it is small, then whenever it has grown by a quarter, and towards convergence whenever it has
   grown by half (:data:`FULL_GROWTH`). Most of the stretch is so settled on the coarse levels, where a leg is a
   few triangles and a step is cheap: with only the short relaxations the four-legged scan ended at L2 stretch
   5.8 (largest per triangle 75), with them at 2.8. Every level is so one-to-one by construction; the final
   check of :mod:`.sphere` confirms it. Should a vertex find no place (a level relaxed into triangles thinner
   than rounding allows), the levels are rebuilt with the short relaxations only.

Why coarse to fine: a Tutte (harmonic) embedding shrinks a protrusion exponentially along its length: the feet
of a four-legged scan came out with ``|det| ~ 1e-17``, below double precision, so flipped. Here every vertex is
placed among neighbours already spread out by the relaxation of the coarser levels.

Why our own code: no kept library records the collapses of a simplification (pymeshlab decimates without
them) or embeds on the sphere; this is numpy and scipy.sparse.
"""

from __future__ import annotations

import time

import numpy as np

from .._reproducible import solve_small

from .relax import DET_BOUND, _det, _relax, _unit
from .tutte import _start_vertices, _tutte_sphere

__all__ = ["simplify", "hierarchical_sphere", "RELAX_ALWAYS", "GROWTH"]

#: Levels up to this many vertices are relaxed after every round (cheap, and where a squeezed triangle would
#: leave the next vertex no room); larger ones when the vertex count has grown by :data:`GROWTH`.
RELAX_ALWAYS = 2000
GROWTH = 1.25

#: A level is relaxed towards convergence (up to :data:`FULL_STEPS` steps, until the energy falls by less than
#: ``FULL_TOL`` a step) whenever the vertex count has grown by this factor since the last such relaxation.
FULL_GROWTH = 1.5
FULL_STEPS = 100
FULL_TOL = 1e-4
FULL_WORK = 250_000

#: Default weight of the inverse map's stretch in the relaxations of the coarse levels (``inverse`` of
#: :func:`hierarchical_sphere` and :class:`.stretch.StretchEnergy`: with it the energy is the symmetric Dirichlet
#: energy of Smith and Schaefer [SmithSchaefer2015] of the map normalized to the sphere's area). What it is for:
#: the L2 stretch of the map from the sphere to the mesh never penalizes a direction in which the sphere
#: oversamples the mesh, so the coarse levels settle into bands squeezed across and drawn out along (a square of
#: the sphere 9 times longer one way than the other over half of beast.obj, about 23 where its geometry image folds
#: and turns inside out: strips along the limbs and down the belly, the same on armadillo.obj); the fine levels'
#: relaxation is local and does not undo a band the coarse levels made. The inverse term grows where the sphere
#: oversamples and keeps the coarse levels nearer conformal; the finest level still descends the L2 stretch alone.
#: Why 0 by default: measured (n = 257; the guarded fit at fairness 0.1, folds at level 4 / inside out / Hausdorff;
#: then what the build kept) it helps the four-legged scan and hurts the bust:
#: beast.obj 0: 0.34 % / 2.5 % / 0.72 % (anisotropy median 9.1); 0.5: 0.17 % / 1.7 % / 0.59 % (5.9); 1: 0.039 % /
#: 0.94 % / 0.75 % (7.5), kept 0.038 % / 0.71 % / 0.91 %; 2: 0.16 % / 1.2 % / 0.70 % (6.1); 5: 0.22 % / 1.3 % /
#: 0.81 % (4.5): the fold share scatters by a factor of 4 between neighbouring weights. armadillo.obj kept: 0:
#: 0.118 % / 0.34 % / 0.93 %; 0.5: 0.10 % / 0.25 % / 0.99 %; 1: 0.118 % / 0.47 % / 0.91 %. nefertiti.obj kept: 0:
#: 0.0023 % / 0.061 % / 0.42 %; 1: 0.0022 % / 0.15 % / 0.63 % (L2 stretch 1.21 -> 1.28, anisotropy median 1.41 ->
#: 1.56): past the check's inside-out threshold. ``parametrization_options={"level_inverse": 1.0}`` of
#: :func:`.build.geometry_image_from_mesh` turns it on; its ``n="auto"`` turns it on by itself, with an image twice
#: as fine, where the image of the plain map still folds (:data:`.auto.ESCALATE_INVERSE`).
LEVEL_INVERSE = 0.0

#: Steps of :func:`_settle_inserted` after each round's insertion.
SETTLE = 10


def _adjacency(F, n):
    from scipy.sparse import coo_matrix

    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = coo_matrix((np.ones(i.size, dtype=np.int64), (i, j)), shape=(n, n)).tocsr()
    return ((A + A.T) > 0).astype(np.int64).tocsr()


def _candidate_edges(P, F, A, deg):
    """Directed edges ``v -> u`` that pass the link condition, with their length: ``(v, u, length)``."""
    # each directed half-edge (a -> b) of a triangle (a, b, c) has c opposite; the edge's two triangles give its
    # two opposite vertices
    a = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    b = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    c = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    n = A.shape[0]
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    key, a, b, c = key[order], a[order], b[order], c[order]
    # closed manifold: every edge key appears exactly twice, consecutively
    first, second = slice(0, None, 2), slice(1, None, 2)
    x, y = c[first], c[second]
    lo, hi = np.minimum(a[first], b[first]), np.maximum(a[first], b[first])
    common = np.asarray((A[lo].multiply(A[hi])).sum(axis=1)).ravel()  # shared neighbours of the edge's ends
    ok = (common == 2) & (deg[x] > 3) & (deg[y] > 3)
    v = np.concatenate([lo[ok], hi[ok]])
    u = np.concatenate([hi[ok], lo[ok]])
    return v, u, np.linalg.norm(P[v] - P[u], axis=1)


def _incidence(F, n):
    """Sparse (V, F): vertex -> its triangles."""
    from scipy.sparse import coo_matrix

    rows = F.ravel()
    cols = np.repeat(np.arange(len(F)), 3)
    return coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n, len(F))).tocsr()


def _keeps_shape(P, F, incident, v, u):
    """For each collapse of ``v[i]`` into ``u[i]``, whether it leaves each of ``v``'s other triangles a proper
    triangle turned less than 90 degrees (``incident``: :func:`_incidence` of ``F``): the coarse levels stay
    surfaces the stretch can be measured on (a triangle of zero area has no stretch, and its cotangent weights are
    infinite). A triangle's new area must exceed ``1e-6`` of the largest of ``v``'s triangles."""
    start, count = incident.indptr[v], np.diff(incident.indptr)[v]
    which = np.repeat(np.arange(v.size), count)
    tri = incident.indices[np.repeat(start - np.cumsum(count) + count, count) + np.arange(count.sum())]
    star = F[tri]
    vv, uu = v[which][:, None], u[which][:, None]
    keep = ~(star == uu).any(axis=1)
    moved = np.where(star == vv, uu, star)
    before = np.cross(P[star[:, 1]] - P[star[:, 0]], P[star[:, 2]] - P[star[:, 0]])
    after = np.cross(P[moved[:, 1]] - P[moved[:, 0]], P[moved[:, 2]] - P[moved[:, 0]])
    size = np.linalg.norm(before, axis=1)
    largest = np.zeros(v.size)
    np.maximum.at(largest, which, np.where(keep, size, 0.0))
    good = (np.einsum("ij,ij->i", before, after) > 0) & (np.linalg.norm(after, axis=1) > 1e-6 * largest[which])
    return np.bincount(which, weights=keep & ~good, minlength=v.size) == 0


def _greedy_disjoint(v, indptr, indices, n, budget):
    """Indices ``i`` of the candidate collapses ``v[i]`` taken in order whose closed neighbourhoods (the vertex
    and its ring in the adjacency ``indptr``, ``indices``, as Python lists) are disjoint from those taken before;
    at most ``budget``. Plain Python lists: a candidate costs a few list look-ups, where numpy's per-call overhead
    on rings of six made this loop half of the simplification's time on the 100k-triangle scans."""
    blocked = bytearray(n)
    chosen = []
    for i, vi in enumerate(v):
        if blocked[vi]:
            continue
        ring = indices[indptr[vi]: indptr[vi + 1]]
        for r in ring:
            if blocked[r]:
                break
        else:
            chosen.append(i)
            blocked[vi] = 1
            for r in ring:
                blocked[r] = 1
            if len(chosen) == budget:
                break
    return chosen


def simplify(P, F, *, base: int = 4) -> tuple:
    """Rounds of independent half-edge collapses of the closed genus-0 mesh ``(P, F)`` (module docstring) down to
    ``base`` vertices or until none is allowed. Returns ``(base_faces, rounds)``: each round
    ``(removed, target, faces_before)``, coarsest last.

    >>> from datasets_synthetic.closed_meshes import sphere_mesh
    >>> m = sphere_mesh(level=2)
    >>> F0, rounds = simplify(m.points, m.faces.reshape(-1, 4)[:, 1:])
    >>> len(np.unique(F0)), len(F0)  # a tetrahedron
    (4, 4)
    """
    P = np.asarray(P, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    n = len(P)
    rounds = []
    while True:
        alive = np.unique(F)
        if alive.size <= base:
            break
        A = _adjacency(F, n)
        deg = np.diff(A.indptr)
        v, u, length = _candidate_edges(P, F, A, deg)
        if v.size == 0:
            break
        order = np.lexsort((u, length))  # shortest first (ties by index: the same on every machine)
        v, u = v[order], u[order]
        incident = _incidence(F, n)
        budget = alive.size - base
        indptr, indices = A.indptr.tolist(), A.indices.tolist()
        while True:  # greedy over the candidates; those chosen that would spoil a triangle are struck, and again
            chosen = np.asarray(_greedy_disjoint(v.tolist(), indptr, indices, n, budget), dtype=np.int64)
            spoils = chosen[~_keeps_shape(P, F, incident, v[chosen], u[chosen])]
            if not spoils.size:
                break
            keep = np.ones(v.size, dtype=bool)
            keep[spoils] = False
            v, u = v[keep], u[keep]
        if not chosen.size:
            break
        removed, target = v[chosen], u[chosen]
        rounds.append((removed, target, F))
        to = np.arange(n)
        to[removed] = target
        G = to[F]
        F = G[(G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 2] != G[:, 0])]
    return F, rounds


def _tetrahedron(F, n):
    """``(n, 3)``: unit vectors of a regular tetrahedron for the four vertices of ``F``, every triangle outward
    (the other rows zero)."""
    ids = np.unique(F)
    X = np.zeros((n, 3))
    X[ids] = _unit(np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]]))
    if (_det(X, F) < 0).all():
        X[ids[[0, 1]]] = X[ids[[1, 0]]]
    return X


def _stars(F, removed):
    """The triangles of ``F`` around the removed vertices, each turned to start there, ``(v, a, b)`` in the same
    orientation, and for each the index of its vertex in ``removed`` (no triangle has two: their neighbourhoods
    are disjoint)."""
    T = F[np.isin(F, removed).any(axis=1)]
    k = np.argmax(np.isin(T, removed), axis=1)
    r = np.arange(len(T))
    T = np.stack([T[r, k], T[r, (k + 1) % 3], T[r, (k + 2) % 3]], axis=1)
    slot = np.full(int(F.max()) + 1, -1)
    slot[removed] = np.arange(removed.size)
    return T, slot[T[:, 0]]


def _insert(X, removed, target, T, owner):
    """Place each removed vertex near its target with all its triangles (``T``, ``owner``: :func:`_stars`)
    outward (module docstring); returns the vertices it could not place (empty when all are placed)."""
    u = target[owner]
    # the two triangles on the collapsed edge: (v, u, x) and (v, y, u); the corner at u spans x..y
    x = np.zeros(removed.size, dtype=np.int64)
    y = np.zeros(removed.size, dtype=np.int64)
    first = T[:, 1] == u
    x[owner[first]] = T[first, 2]
    second = T[:, 2] == u
    y[owner[second]] = T[second, 1]
    Xu = X[target]
    ring_sum = np.zeros((removed.size, 3))
    np.add.at(ring_sum, owner, X[T[:, 1]])
    with np.errstate(invalid="ignore", divide="ignore"):  # opposite tx, ty: a direction of NaN, tried as 0 below
        tx, ty = _unit(X[x] - Xu), _unit(X[y] - Xu)
        directions = [_unit(tx + ty), -_unit(tx + ty), _unit(ring_sum) - Xu]
    placed = np.zeros(removed.size, dtype=bool)
    for d in directions:
        for s in 0.5 ** np.arange(1, 52):
            todo = ~placed
            if not todo.any():
                return removed[:0]
            X[removed[todo]] = _unit(Xu[todo] + s * np.nan_to_num(d[todo]))
            bad = np.zeros(removed.size, dtype=bool)
            bad[owner[~(_det(X, T) > DET_BOUND)]] = True
            placed |= todo & ~bad
    return removed[~placed]


def _center_inserted(X, removed, T, owner, iterations: int = 60):
    """Move each inserted vertex to the analytic centre of its ring's kernel on the sphere: the maximum of
    ``sum log det[x, a, b]`` over its triangles ``(x, a, b)`` (the region where all of them are outward is the
    intersection of the hemispheres ``x . (a x b) > 0``). Damped Newton steps in the tangent plane, each halved
    until every triangle stays outward and the sum grows; a vertex placed a hair from its target moves out to
    where its triangles are as far from flat as its ring allows (``T``, ``owner``: :func:`_stars`)."""
    C = np.cross(X[T[:, 1]], X[T[:, 2]])  # det[x, a, b] = x . (a x b)
    m = removed.size

    def barrier(x):
        d = np.einsum("ij,ij->i", C, x[owner])
        phi = np.zeros(m)
        bad = np.zeros(m, dtype=bool)
        bad[owner[~(d > DET_BOUND)]] = True
        np.add.at(phi, owner, np.log(np.where(d > 0, d, 1.0)))
        return np.where(bad, -np.inf, phi), d

    x = X[removed].copy()
    phi, d = barrier(x)
    active = np.ones(m, dtype=bool)
    for _ in range(iterations):
        g = np.zeros((m, 3))
        np.add.at(g, owner, C / d[:, None])
        H = np.zeros((m, 3, 3))
        np.add.at(H, owner, np.einsum("fi,fj->fij", C, C) / (d * d)[:, None, None])
        # tangent basis at x
        e1 = np.cross(x, np.where(np.abs(x[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
        e1 = _unit(e1)
        e2 = np.cross(x, e1)
        E = np.stack([e1, e2], axis=2)  # (m, 3, 2)
        gt = np.einsum("mik,mi->mk", E, g)
        Ht = np.einsum("mik,mij,mjl->mkl", E, H, E) + 1e-300 * np.eye(2)
        newton = solve_small(Ht, gt)
        step = np.einsum("mik,mk->mi", E, newton)
        # the Newton decrement squared, g . H^-1 g: the barrier's rise still to come is about half of it; below
        # 1e-3 a vertex is at its centre for our purpose (the relaxation moves it on anyway)
        moving = active & (np.einsum("mk,mk->m", gt, newton) > 1e-3)
        if not moving.any():
            break
        lam = np.ones(m)
        for _ in range(40):
            y = np.where(moving[:, None], _unit(x + lam[:, None] * step), x)
            phi_new, d_new = barrier(y)
            worse = moving & ~(phi_new > phi)
            if not worse.any():
                break
            lam[worse] *= 0.5
            moving &= lam > 1e-12
        better = moving & (phi_new > phi)
        x[better] = y[better]
        phi = np.where(better, phi_new, phi)
        d = np.einsum("ij,ij->i", C, x[owner])
        active &= better  # no step raised it: done
        if not active.any():
            break
    X[removed] = x


def _settle_inserted(X, P, removed, T, owner, iterations: int = 20):
    """Lower the stretch of each inserted vertex's star by moving that vertex alone, as Praun and Hoppe optimize
    each vertex they insert [PraunHoppe2003, sec. 3]: the stars are disjoint (:func:`_stars`), so the energy is a
    sum of one term per vertex and every vertex descends its own. Steps along the negative tangent gradient, one
    length per vertex, doubled after a step that lowers its term with every triangle outward, halved (and the
    vertex left where it was) otherwise; the start is a tenth of the vertex's mean distance to its ring."""
    from .stretch import StretchEnergy

    S = StretchEnergy(P, T)
    m = removed.size

    def terms(Y):
        J2, flat, sph = S._terms(Y)[:3]
        det = _det(Y, T)
        e = np.bincount(owner, weights=0.5 * S.area * J2 * flat / sph, minlength=m)
        bad = np.bincount(owner, weights=~(det > DET_BOUND), minlength=m) > 0
        return np.where(bad, np.inf, e)

    x = X[removed]
    e = terms(X)
    reach = np.bincount(owner, weights=np.linalg.norm(X[T[:, 1]] - x[owner], axis=1), minlength=m)
    reach /= np.bincount(owner, minlength=m)
    lam = None
    for _ in range(iterations):
        g = S.gradient(X)[1][removed]
        g -= np.einsum("ij,ij->i", g, x)[:, None] * x
        norm = np.linalg.norm(g, axis=1)
        if lam is None:
            lam = 0.1 * reach / np.maximum(norm, 1e-300)
        X[removed] = _unit(x - lam[:, None] * g)
        e_new = terms(X)
        better = e_new < e
        x[better] = X[removed[better]]
        X[removed] = x
        e = np.where(better, e_new, e)
        lam = np.where(better, 2.0 * lam, 0.5 * lam)


def _refine(P, X, rounds, nbase, relax_steps, progress, full, inverse=LEVEL_INVERSE):
    """Steps 3 of the module docstring on the base embedding ``X``: re-insert the rounds, settle the inserted
    vertices and relax the levels (``full``: :func:`_settle_inserted` and the long relaxations of
    :data:`FULL_GROWTH`; else only the short ones; ``inverse``: :data:`LEVEL_INVERSE`)."""
    from .stretch import StretchEnergy

    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(rounds), desc="coarse to fine", unit="level")
    relaxed_at = converged_at = nbase
    for removed, target, faces in reversed(rounds):
        T, owner = _stars(faces, removed)
        lost = _insert(X, removed, target, T, owner)
        if lost.size:
            raise RuntimeError(f"coarse to fine: {lost.size} vertices (e.g. {int(lost[0])}) found no place with "
                               "all their triangles outward.")
        _center_inserted(X, removed, T, owner)
        if full and SETTLE:
            _settle_inserted(X, P, removed, T, owner, SETTLE)
        ids = np.unique(faces)
        if ids.size >= len(P):
            pass
        elif full and ids.size >= FULL_GROWTH * converged_at:
            local = np.searchsorted(ids, faces)
            steps = min(FULL_STEPS, max(relax_steps, FULL_WORK // ids.size))
            Y, _ = _relax(X[ids], StretchEnergy(P[ids], local, inverse=inverse), steps, False,
                           FULL_TOL)
            X[ids] = Y
            relaxed_at = converged_at = ids.size
        elif ids.size <= RELAX_ALWAYS or ids.size >= GROWTH * relaxed_at:
            local = np.searchsorted(ids, faces)
            Y, _ = _relax(X[ids], StretchEnergy(P[ids], local, inverse=inverse), relax_steps, False,
                           1e-3)
            X[ids] = Y
            relaxed_at = ids.size
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    return X


def hierarchical_sphere(P, F, *, relax_steps: int = 10, progress: bool = False,
                        inverse: float = LEVEL_INVERSE) -> tuple:
    """One-to-one unit vectors ``X`` (V, 3) for the closed genus-0 mesh ``(P, F)`` built coarse to fine (module
    docstring), and a dict of ``levels``, ``base_vertices`` and ``seconds``. The finest level is not relaxed
    here: :func:`.sphere.spherical_parametrization` relaxes the whole mesh next. ``inverse`` weighs the inverse
    map's stretch in the coarse levels' relaxations (:data:`LEVEL_INVERSE`).

    >>> from datasets_synthetic.closed_meshes import stretched_blob
    >>> m = stretched_blob(level=2)
    >>> F = m.faces.reshape(-1, 4)[:, 1:]
    >>> X, info = hierarchical_sphere(m.points, F)
    >>> int((_det(X, F) <= DET_BOUND).sum()), info["base_vertices"]
    (0, 4)
    """
    t0 = time.perf_counter()
    P = np.asarray(P, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    base, rounds = simplify(P, F)
    nbase = np.unique(base).size
    if nbase == 4:
        X = _tetrahedron(base, len(P))
    else:  # no collapse allowed before a tetrahedron: the Tutte start of the base mesh
        ids = np.unique(base)
        local = np.searchsorted(ids, base)
        v = next(_start_vertices(local, np.ones(ids.size)), None)
        if v is None:
            raise RuntimeError(f"the simplified mesh ({ids.size} vertices) has no vertex to cut it open at.")
        X = np.zeros((len(P), 3))
        X[ids] = _tutte_sphere(P[ids], local, np.ones(ids.size), v)
    try:
        X = _refine(P, X.copy(), rounds, nbase, relax_steps, progress, True, inverse)
    except RuntimeError:  # a vertex found no place: the light schedule (no settling, no long relaxations)
        X = _refine(P, X, rounds, nbase, relax_steps, progress, False, inverse)
    return X, {"levels": len(rounds), "base_vertices": nbase, "seconds": time.perf_counter() - t0}
