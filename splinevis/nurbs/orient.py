"""Consistent, outward orientation of a NURBS model's faces, found from the faces alone, and the continuity
(G0/G1/G2, kink angle, curvature jump) of the seams between them.

Why: a face's normal is ``S_u x S_v`` (:meth:`NurbsSurface.normal`), so its outside is an accident of how its
parameters run. STEP and Rhino faces carry an orientation flag (the readers apply it), IGES 128/144 faces do
not: one IGES part has 125 nearly tangent face pairs whose normals are opposite, and zebra stripes and
curvature signs flip from face to face. :func:`orient_faces` repairs that:

1. **Boundaries.** Each face's boundary is sampled in 3-D: the four sides of an untrimmed patch
   (counter-clockwise in ``(u, v)``) or each curve of its trim loops mapped through the surface. Loops are
   read with the even-odd rule, so their direction in the file means nothing; each trim curve is given the
   direction that keeps the face on its left in ``(u, v)`` by the inside test (:func:`.trim.inside`) at
   points just left and right of it. Mapped through the surface, "face on the left in (u, v)" is "face on
   the left seen from the normal ``S_u x S_v``" (the Jacobian keeps the orientation of ``(u, v)``).
2. **Adjacency.** A boundary sample of face A lies on face B's boundary polyline (within ``match`` times
   the model's size, tangents parallel): A and B share an edge there. The end samples of each boundary piece
   ask nothing (collinear edges touching end to end at a corner would pass), and pairs with fewer than three
   shared samples only touch at a corner. Two faces are oriented alike exactly
   when they run through their common edge in opposite directions (the induced orientations of the two
   sides of an edge of an oriented surface [DoCarmo1976, sec. 2-6]). This edge rule, not
   agreement of normals, is used: at a sharp edge the normals differ legitimately. Samples on three or more
   faces (non-manifold edges) are left out; face pairs vote with their shared length.
3. **Propagation.** Faces are joined in order of shared length (Kruskal's spanning tree with parity): each
   connected component gets a consistent orientation; pairs that contradict it (a non-orientable or
   inconsistent topology) are counted as ``conflicts``.
4. **Outward.** A component is closed when each of its boundary pieces (trim curves, sides) is shared over
   at least half its length (collapsed sides at poles and pieces shorter than the matching distance need no
   partner; a periodic face's seam is shared with itself). Its signed volume is
   ``V = 1/3 sum_faces integral (S - c) . (S_u x S_v) du dv`` (divergence theorem for the field
   ``x - c``); ``V < 0`` means the normals point inward and the whole component is flipped. Untrimmed faces
   are integrated by Gauss-Legendre rules on every knot span (exact for polynomial patches up to the rule's
   degree), trimmed faces by the midpoint rule on a grid over their loops masked by the inside test (an
   error of the order of the grid step along the trim). An open component has no outside: it keeps the
   orientation that flips the fewest faces, and the report says ``closed: False``.

Flipping a face reverses its u direction exactly (:func:`flip_u`): knots ``U -> -U`` reversed, control
points and weights reversed along u, trims ``u -> -u``. Negation is exact in floating point, so the flipped
face is exactly the same surface (``u0 + u1 - u`` would round and move interior knots relative to the ends);
evaluated points agree to rounding only, the sums running in the other order.

Seams are measured as in :mod:`.continuity` [Farin2002, ch. 14] after orientation, at up to 64 matched
samples per face pair: the gap (distance to the nearest point of the other face's boundary curve, found by
Newton steps along that curve from the polyline's foot), the kink angle between the two oriented normals
(degrees; 0 across a tangent seam, 90 across a box edge) and the jump of the normal curvature across the
seam (:func:`.continuity.normal_curvature`); the class is :func:`.continuity.classify` (``open``: a gap above
``tol_gap``). Samples where the other edge has already ended (a T-junction) are left out.

When OpenCASCADE (``OCP``, the ``cad`` extra) is installed, :func:`.occ_faces.occ_outward` orients the same faces by
sewing them and fixing the shell (``BRepBuilderAPI_Sewing``, ``ShapeFix_Shell``, ``ShapeFix_Solid``): an
independent check of this module (the tests compare both).

The samples, the inside tests and the volumes of all faces are computed together (:mod:`.batch`,
:func:`.trim.inside_many`): the same points and decisions as face by face, without numpy's cost per call on
hundreds of faces.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .basis import into_domain
from .continuity import Seam, classify, normal_curvature
from .model import NurbsModel, TrimCurve
from .surface import NurbsSurface
from .batch import CurveBatch, SurfaceBatch
from .shell_volume import _breaks, _params_many, signed_volumes
from .lazy_report import LazyReport
from .trim import inside_many, trim_pieces

__all__ = ["flip_u", "orient_faces"]


# -------------------------------------------------------------------------------------------------
def flip_u(surface: NurbsSurface, trims=None):
    """The same face with u running backwards (its normal ``S_u x S_v`` negated), and its trim loops mapped
    alike: ``S'(-u, v) == S(u, v)`` exactly, knots ``-U`` reversed, trims ``(u, v) -> (-u, v)``.

    Returns ``(surface, trims)`` (``trims`` None stays None).

    >>> from splinevis.nurbs.exact import torus
    >>> t = torus()
    >>> f, _ = flip_u(t)
    >>> f.domain[0], bool((f.evaluate([-0.3], [0.6]) == t.evaluate([0.3], [0.6])).all())
    ((-1.0, 0.0), True)
    >>> bool(np.allclose(f.normal([-0.3], [0.6]), -t.normal([0.3], [0.6]), rtol=0, atol=1e-15))
    True
    """
    U = surface.knots[0]
    # + 0.0 turns -0.0 into 0.0 and changes nothing else
    flipped = NurbsSurface(surface.degree, (-U[::-1] + 0.0, surface.knots[1]), surface.control_points[::-1],
                           None if surface.weights is None else surface.weights[::-1], name=surface.name)
    if trims is None:
        return flipped, None
    mirror = np.array([-1.0, 1.0])
    loops = [[TrimCurve(c.degree, c.knots, c.control_points * mirror + 0.0, c.weights) for c in loop] for loop in trims]
    return flipped, loops


# -------------------------------------------------------------------------------------------------
def _groups(keys):
    """``(key, indices)`` for each distinct value of the integer array ``keys`` (one sort, no per-key scans)."""
    keys = np.asarray(keys)
    if keys.size == 0:
        return []
    order = np.argsort(keys, kind="stable")
    k = keys[order]
    cut = np.flatnonzero(k[1:] != k[:-1]) + 1
    return [(int(g[0]), idx) for g, idx in zip(np.split(k, cut), np.split(order, cut))]


def _face_pieces(s: NurbsSurface, loops):
    """``[(uv_function, breaks, sign_hint, spec)]``: the pieces of the face's boundary as functions of a
    parameter; ``spec`` the trim curve, or ``(axis, value)`` of a side (``uv[:, axis] = t``, the other
    coordinate ``value``).

    Untrimmed: the four sides counter-clockwise (sign +1). Trimmed: each trim curve (sign decided later)."""
    (u0, u1), (v0, v1) = s.domain
    U, V = s.knots
    if not loops:
        bu, bv = _breaks(U, u0, u1), _breaks(V, v0, v1)
        return [
            (lambda t: np.column_stack([t, np.full_like(t, v0)]), bu, 1, (0, v0)),
            (lambda t: np.column_stack([np.full_like(t, u1), t]), bv, 1, (1, u1)),
            (lambda t: np.column_stack([t, np.full_like(t, v1)]), bu, -1, (0, v1)),  # run u1 -> u0: reversed below
            (lambda t: np.column_stack([np.full_like(t, u0), t]), bv, -1, (1, u0)),
        ]
    out = []
    for loop in loops:
        for c in loop:
            t0, t1 = c.domain
            out.append((c.evaluate, _breaks(c.knots, t0, t1), 0, c))
    return out


def _sample_boundaries(surfaces, trims, batch, curves, per_span, max_seg):
    """Boundary samples of every face, dense enough that segments are at most about ``max_seg`` long (all faces
    and pieces together: ``batch`` a :class:`.batch.SurfaceBatch` of ``surfaces``, ``curves`` a
    :class:`.batch.CurveBatch` of the trim curves in loop order)."""
    fns, breaks, hints, owner, curve_of, axis, value = [], [], [], [], [], [], []
    ncurve = 0
    for k, (s, loops) in enumerate(zip(surfaces, trims)):
        for f, b, hint, spec in _face_pieces(s, loops):
            fns.append(f)
            breaks.append(b)
            hints.append(hint)
            owner.append(k)
            if isinstance(spec, tuple):
                curve_of.append(-1)
                axis.append(spec[0])
                value.append(spec[1])
            else:
                curve_of.append(ncurve)
                ncurve += 1
                axis.append(0)
                value.append(0.0)
    hints, owner, curve_of = np.asarray(hints), np.asarray(owner), np.asarray(curve_of)
    axis, value = np.asarray(axis), np.asarray(value, dtype=np.float64)
    dom = np.array([[*s.domain[0], *s.domain[1]] for s in surfaces]).reshape(-1, 4)

    def uv_of(pc, t):  # the pieces' own points (may leave the domain by the file's tolerance)
        raw = np.empty((t.size, 2))
        c = curve_of[pc] >= 0
        raw[c] = curves.evaluate(curve_of[pc[c]], t[c])
        side, a, val = ~c, axis[pc], value[pc]
        raw[side, 0] = np.where(a[side] == 0, t[side], val[side])
        raw[side, 1] = np.where(a[side] == 0, val[side], t[side])
        return raw

    def clamp(raw, fc):
        return np.column_stack([into_domain(raw[:, 0], dom[fc, 0], dom[fc, 1]),
                                into_domain(raw[:, 1], dom[fc, 2], dom[fc, 3])])

    # pass 1: coarse samples, for the lengths
    nint = np.array([len(b) - 1 for b in breaks])
    t1, pc1 = _params_many(breaks, np.full(len(breaks), per_span))
    uv1 = clamp(uv_of(pc1, t1), owner[pc1])
    pts = batch.evaluate(owner[pc1], uv1[:, 0], uv1[:, 1])
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)[pc1[1:] == pc1[:-1]]  # within pieces
    spans = seg.reshape(-1, per_span).sum(axis=1)  # every span has per_span segments
    longest = np.maximum.reduceat(spans, np.r_[0, np.cumsum(nint)[:-1]]) if spans.size else np.zeros(0)
    # pass 2: as many samples per span as the longest chord asks
    n = np.minimum(np.maximum(per_span, np.ceil(longest / max_seg)), 256).astype(np.int64)
    tpar, piece = _params_many(breaks, n)
    # a side run backwards (counter-clockwise loop of an untrimmed patch): its samples in reverse
    start = np.r_[0, np.cumsum(nint * n + 1)]
    order = np.arange(tpar.size)
    back = np.flatnonzero(hints < 0)
    if back.size:
        rev = np.concatenate([np.arange(start[p + 1] - 1, start[p] - 1, -1) for p in back])
        order[np.concatenate([np.arange(start[p], start[p + 1]) for p in back])] = rev
    tpar = tpar[order]
    face = owner[piece]
    RAW = uv_of(piece, tpar)
    UV = clamp(RAW, face)
    X = batch.evaluate(face, UV[:, 0], UV[:, 1])
    return X, UV, RAW, face, piece, hints != 0, tpar, fns


def _trim_directions(pieces, trims, UV, face, piece, known):
    """+1 or -1 per piece: the direction that keeps the face on the left in (u, v) (even-odd inside test just
    left and right of every sample point); untrimmed sides (``known``) are +1 already."""
    npiece = int(piece.max()) + 1
    direction = np.ones(npiece)
    n = len(UV)
    interior = np.zeros(n, dtype=bool)  # samples with a neighbour on each side in the same piece
    interior[1:-1] = (piece[:-2] == piece[1:-1]) & (piece[2:] == piece[1:-1])
    trimmed = np.array([bool(loops) for loops in trims])
    sel = np.flatnonzero(interior & trimmed[face])
    if sel.size == 0:
        return direction, 0
    # at most 7 votes a piece (each is a bisection of the inside test: the points lie at the boundary)
    pos = np.arange(sel.size) - np.searchsorted(piece[sel], piece[sel])
    cnt = np.bincount(piece[sel])[piece[sel]]
    sel = sel[(pos * 7) // cnt != ((pos - 1) * 7) // cnt]
    # each face's box of boundary samples (faces' samples are contiguous, in face order)
    starts = np.r_[0, np.flatnonzero(face[1:] != face[:-1]) + 1]
    lo_f, hi_f = np.minimum.reduceat(UV, starts, axis=0), np.maximum.reduceat(UV, starts, axis=0)
    slot = np.zeros(len(trims), dtype=np.int64)
    slot[face[starts]] = np.arange(starts.size)
    ext = np.maximum(hi_f - lo_f, 1e-300)[slot[face[sel]]]
    d = (UV[sel + 1] - UV[sel - 1]) / ext  # central difference: the tangent at a point of the curve
    norm = np.linalg.norm(d, axis=1)
    ok = norm > 0
    # just left and right of the curve itself (a chord's midpoint lies off it by the sagitta)
    left = np.column_stack([-d[:, 1], d[:, 0]]) / np.where(ok, norm, 1.0)[:, None] * ext * 1e-6
    pl, pr = UV[sel] + left, UV[sel] - left
    ins = inside_many(pieces, np.concatenate([face[sel], face[sel]]), np.concatenate([pl[:, 0], pr[:, 0]]),
                      np.concatenate([pl[:, 1], pr[:, 1]]))
    vote = (ins[: sel.size].astype(int) - ins[sel.size:].astype(int)) * ok
    totals = np.bincount(piece[sel], weights=vote, minlength=npiece)
    voted = np.unique(piece[sel])
    voted = voted[~known[voted]]
    direction[voted[totals[voted] < 0]] = -1.0
    return direction, int((totals[voted] == 0).sum())


def _tangents(X, piece, direction, small):
    """Unit 3-D tangents along the traversal (central differences within a piece), zero where degenerate."""
    n = len(X)
    prev = np.arange(n) - 1
    nxt = np.arange(n) + 1
    prev[0] = 0
    nxt[-1] = n - 1
    prev = np.where(piece[prev] == piece, prev, np.arange(n))
    nxt = np.where(piece[np.minimum(nxt, n - 1)] == piece, nxt, np.arange(n))
    T = (X[nxt] - X[prev]) * direction[piece][:, None]
    length = np.linalg.norm(T, axis=1)
    seg = np.linalg.norm(X[nxt] - X[prev], axis=1) * 0.5
    with np.errstate(invalid="ignore", divide="ignore"):
        T = np.where(length[:, None] > small, T / length[:, None], 0.0)  # 0 on a collapsed boundary (a pole)
    return T, seg


# -------------------------------------------------------------------------------------------------
def _find(parent, parity, i):
    """Root of i and i's parity relative to it (path compression)."""
    path = []
    while parent[i] != i:
        path.append(i)
        i = parent[i]
    root, acc = i, 0
    for j in reversed(path):  # from next-to-root down
        acc ^= parity[j]
        parity[j] = acc
        parent[j] = root
    return root


def _match(X, T, face, piece, seg_len, tol, cos_min=0.5, k=16):
    """For each sample: the faces whose boundary polyline passes within ``tol`` with a parallel tangent.

    Returns arrays of matches ``(i, other_face, j, lam, dist, same_direction)``: ``j`` the other polyline's
    segment start (segment j -> j+1), ``lam`` the foot's fraction on it."""
    from scipy.spatial import cKDTree

    n = len(X)
    segok = np.zeros(n, dtype=bool)
    segok[:-1] = piece[:-1] == piece[1:]
    # a piece's end samples ask nothing: there collinear edges that merely touch end to end (two faces' bottom
    # edges at a shared corner) would pass for a shared edge
    interior = np.zeros(n, dtype=bool)
    interior[1:-1] = (piece[:-2] == piece[1:-1]) & (piece[2:] == piece[1:-1])
    ask = np.flatnonzero(interior & (np.linalg.norm(T, axis=1) > 0))
    tree = cKDTree(X)
    reach = tol + float(np.max(seg_len)) if n else tol
    k = min(k, n)
    dist, idx = tree.query(X[ask], k=k, distance_upper_bound=reach, workers=-1)  # same answer on any thread count
    rows, cols = np.nonzero(np.isfinite(dist))
    cand = idx[rows, cols]
    qi = ask[rows]
    keep = piece[cand] != piece[qi]  # the sample's own piece is no partner
    cand, qi = cand[keep], qi[keep]
    # candidate segments: the one starting at the sample and the one ending at it (a segment found twice is
    # harmless: the nearest per sample and face is kept below)
    js = np.concatenate([cand, cand - 1])
    qi = np.concatenate([qi, qi])
    good = (js >= 0) & segok[np.maximum(js, 0)]
    js, qi = js[good], qi[good]
    A, B, P = X[js], X[js + 1], X[qi]
    D = B - A
    dd = np.einsum("ij,ij->i", D, D)
    lam = np.clip(np.einsum("ij,ij->i", P - A, D) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    dist = np.linalg.norm(P - A - lam[:, None] * D, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cosang = np.einsum("ij,ij->i", T[qi], D) / np.sqrt(dd)
    fi, fj = face[qi], face[js]
    # the other polyline's traversal direction: D times its piece's direction is in T[js] already
    dirdot = np.einsum("ij,ij->i", T[qi], T[js] + T[js + 1])
    ok = (dist <= tol) & (np.abs(np.nan_to_num(cosang)) >= cos_min)
    ok &= (fi != fj) | (dirdot < 0)  # on the same face only a seam run the other way (a periodic face's seam)
    qi, js, lam, dist, same = qi[ok], js[ok], lam[ok], dist[ok], dirdot[ok] > 0
    other = face[js]
    # per (sample, other face) keep the nearest segment
    order = np.lexsort((dist, other, qi))
    qi, js, lam, dist, same, other = (a[order] for a in (qi, js, lam, dist, same, other))
    first = np.ones(qi.size, dtype=bool)
    first[1:] = (qi[1:] != qi[:-1]) | (other[1:] != other[:-1])
    return qi[first], other[first], js[first], lam[first], dist[first], same[first]


def orient_faces(model: NurbsModel, match: float = 1e-3, tol_gap: float = 1e-4, tol_angle_deg: float = 0.05,
                 tol_curvature: float = 1e-3, per_span: int = 8, seams: bool = True):
    """A consistently, and where closed outward, oriented copy of ``model``, and the report.

    Parameters
    ----------
    model : NurbsModel
    match : float
        Boundaries closer than ``match`` times the model's size (control-point box diagonal) are shared.
    tol_gap, tol_angle_deg, tol_curvature : float
        Seam classes as :func:`splinevis.nurbs.continuity.classify` (``tol_gap`` relative to the size).
    per_span : int
        Boundary samples per knot span at least (more where chords would exceed 1/256 of the size).
    seams : bool
        Measure the seams' continuity (second derivatives at up to 64 shared samples per face pair), on the
        first read of the report (:class:`LazyReport`; ``seconds`` is the orientation's time without it).

    Returns
    -------
    (NurbsModel, dict)
        The model with flipped faces (:func:`flip_u`) and ``report["orientation"]`` set; the report: ``flipped``
        (face indices), ``adjacent_pairs`` (face pairs sharing an edge), ``inconsistent_pairs_before`` (of
        them, those whose normals were opposite in ``model``), ``components`` (per connected component:
        ``faces``, ``closed``, ``open_length_fraction``, ``signed_volume`` or None when open), ``free_edges`` ((face, length) of
        boundary pieces no other face shares), ``conflicts`` ((face, face, shared length) contradicting the
        orientation), ``non_manifold_length``, ``ambiguous_trims`` (trim curves whose side the inside test could
        not tell), ``seams`` (a list of :class:`~.continuity.Seam` with ``side_a == side_b == "boundary"``:
        per sample gap, kink ``angle`` in degrees between the oriented normals, ``curvature_jump``),
        ``seam_levels`` (class -> count), ``size``, ``match`` (the absolute matching distance), ``seconds``.

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere
    >>> m, r = orient_faces(NurbsModel([flip_u(sphere())[0]]))
    >>> r["flipped"], r["components"][0]["closed"], round(r["components"][0]["signed_volume"], 6)
    ([0], True, 4.18879)
    """
    start = time.perf_counter()
    surfaces, trims = list(model.surfaces), list(model.trims)
    nf = len(surfaces)
    P = np.concatenate([s.control_points.reshape(-1, 3) for s in surfaces])
    size = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0))) or 1.0
    tol = match * size
    batch = SurfaceBatch(surfaces)
    curves = CurveBatch([c for loops in trims if loops for loop in loops for c in loop])
    X, UV, RAW, face, piece, known, tpar, fns = _sample_boundaries(surfaces, trims, batch, curves, per_span,
                                                                   size / 256)
    pieces = trim_pieces(trims)
    direction, ambiguous = _trim_directions(pieces, trims, RAW, face, piece, known)
    T, seg_len = _tangents(X, piece, direction, 1e-9 * size)
    qi, other, js, lam, dist, same = _match(X, T, face, piece, seg_len, tol)

    # manifold samples: one other face, or one much nearer than the rest (a narrow face's far side within
    # reach); self-seams count as covered, not as an adjacency
    order = np.lexsort((dist, qi))
    cq = qi[order]
    starts = np.r_[0, np.flatnonzero(cq[1:] != cq[:-1]) + 1]
    rank = np.empty(qi.size, dtype=int)
    rank[order] = np.arange(qi.size) - np.repeat(starts, np.diff(np.r_[starts, qi.size]))
    first, second = np.full(len(X), np.inf), np.full(len(X), np.inf)
    first[qi[rank == 0]] = dist[rank == 0]
    second[qi[rank == 1]] = dist[rank == 1]
    nearest_only = second > 10.0 * first + 1e-9 * size
    keep = ~(nearest_only[qi] & (rank > 0))
    qi, other, js, lam, dist, same = (a[keep] for a in (qi, other, js, lam, dist, same))
    cross = other != face[qi]
    nmatch = np.bincount(qi[cross], minlength=len(X))
    covered = np.bincount(qi, minlength=len(X)) > 0
    degenerate = np.linalg.norm(T, axis=1) == 0
    weight = seg_len
    manifold = cross & (nmatch[qi] == 1)
    non_manifold_length = float(weight[nmatch >= 2].sum())

    # vote per face pair: + shared length run oppositely (consistent), - run alike (one must flip)
    a, b = face[qi[manifold]], other[manifold]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * nf + hi
    vote = np.where(same[manifold], -1.0, 1.0) * weight[qi[manifold]]
    keys, inv = np.unique(key, return_inverse=True)
    total = np.bincount(inv, weights=vote)
    shared = np.bincount(inv, weights=weight[qi[manifold]])
    # fewer than 3 samples: faces touching at a corner (their edges end there), not sharing an edge
    total[np.bincount(inv) < 3] = 0.0
    order = np.argsort(-np.abs(total))
    parent, parity = list(range(nf)), [0] * nf
    conflicts = []
    for e in order:
        if total[e] == 0:
            continue
        i, j = divmod(int(keys[e]), nf)
        want = 0 if total[e] > 0 else 1
        ri, rj = _find(parent, parity, i), _find(parent, parity, j)
        if ri == rj:
            if parity[i] ^ parity[j] != want:
                conflicts.append((i, j, float(shared[e])))
            continue
        parent[rj] = ri
        parity[rj] = parity[i] ^ parity[j] ^ want
    roots = [_find(parent, parity, i) for i in range(nf)]
    flip = np.array([parity[i] if roots[i] != i else 0 for i in range(nf)], dtype=bool)

    # components: closed when (nearly) all boundary length is shared; closed ones turned outward
    # (a piece of boundary is free when less than half its length is shared: single samples at corners, where
    # the tangent turns, do not open a shell)
    uncovered = ~(covered | degenerate)
    npc = int(piece.max()) + 1
    piece_len = np.bincount(piece, weights=weight, minlength=npc)
    piece_open = np.bincount(piece, weights=weight * uncovered, minlength=npc)
    free = (piece_open > 0.5 * piece_len) & (piece_len > tol)  # a piece shorter than the reach is a vertex
    piece_face = np.zeros(npc, dtype=int)
    piece_face[piece] = face
    face_len = np.bincount(piece_face, weights=piece_len, minlength=nf)
    open_len = np.bincount(piece_face, weights=piece_len * free, minlength=nf)
    vols = None
    components = []
    roots = np.asarray(roots)
    for r in np.unique(roots):
        members = np.flatnonzero(roots == r)
        frac = float(open_len[members].sum() / max(face_len[members].sum(), 1e-300))
        closed = frac == 0.0
        entry = {"faces": members.tolist(), "closed": bool(closed), "open_length_fraction": frac,
                 "signed_volume": None}
        if closed:
            if vols is None:
                vols = signed_volumes(surfaces, trims, pieces=pieces, batch=batch, curves=curves)
            V = float(np.sum(np.where(flip[members], -1.0, 1.0) * vols[members]))
            if V < 0:
                flip[members] = ~flip[members]
                V = -V
            entry["signed_volume"] = V
        elif flip[members].sum() * 2 > members.size:  # no outside: flip the fewest faces
            flip[members] = ~flip[members]
        components.append(entry)

    new_s, new_t = [], []
    for k, (s, loops) in enumerate(zip(surfaces, trims)):
        if flip[k]:
            s, loops = flip_u(s, loops)
        new_s.append(s)
        new_t.append(loops)

    report = {"faces": nf, "flipped": np.flatnonzero(flip).tolist(), "components": components,
              "free_edges": [(int(piece_face[p]), float(piece_len[p])) for p in np.flatnonzero(free)],
              "adjacent_pairs": int((total != 0).sum()), "inconsistent_pairs_before": int((total < 0).sum()),
              "conflicts": conflicts, "non_manifold_length": non_manifold_length, "ambiguous_trims": ambiguous,
              "size": size, "match": tol}
    report["seconds"] = time.perf_counter() - start
    if seams:
        sgn = np.where(flip, -1.0, 1.0)
        args = (surfaces, sgn, X, UV, T, face, piece, tpar, fns, qi[cross], other[cross], js[cross], lam[cross],
                size, tol_gap, tol_angle_deg, tol_curvature)

        def measure():
            found = _seams(*args)
            levels = {}
            for s in found:
                levels[s.level] = levels.get(s.level, 0) + 1
            return {"seams": found, "seam_levels": levels}

        report = LazyReport(report, measure)
    old = dict(getattr(model, "report", {}) or {})
    old["orientation"] = report
    out = dataclasses.replace(model, surfaces=tuple(new_s), trims=tuple(new_t), report=old)
    return out, report


def _foot(surfaces, X, UV, face, piece, tpar, fns, P, js, lam, iterations=2):
    """Points of the other boundary nearest to ``P`` (exact points of that boundary curve): from the foot on
    the polyline segment ``js -> js + 1`` (fraction ``lam``), Newton steps along the curve's parameter with the
    segment's chord as derivative. Returns ``(points, uv)``."""
    t0, t1 = tpar[js], tpar[js + 1]
    dt = t1 - t0
    chord = (X[js + 1] - X[js]) / np.where(dt != 0, dt, 1.0)[:, None]
    cc = np.einsum("ij,ij->i", chord, chord)
    t = t0 + lam * dt
    pc, fc = piece[js], face[js]
    npiece = int(piece.max()) + 1
    tmin, tmax = np.full(npiece, np.inf), np.full(npiece, -np.inf)
    np.minimum.at(tmin, piece, tpar)
    np.maximum.at(tmax, piece, tpar)
    lo, hi = np.minimum(t0, t1), np.maximum(t0, t1)
    h = np.abs(dt)
    lo, hi = lo - h, hi + h  # a step may leave the segment, not the neighbourhood
    for it in range(iterations + 1):
        uv = np.empty((len(t), 2))
        for p, sel in _groups(pc):
            s = surfaces[fc[sel[0]]]
            (u0, u1), (v0, v1) = s.domain
            # the curve's own domain: a step stays within the piece's sampled parameters
            t[sel] = np.clip(t[sel], tmin[p], tmax[p])
            q = fns[p](t[sel])
            uv[sel] = np.column_stack([into_domain(q[:, 0], u0, u1), into_domain(q[:, 1], v0, v1)])
        pts = np.empty((len(t), 3))
        for k, sel in _groups(fc):
            pts[sel] = surfaces[k].evaluate(uv[sel, 0], uv[sel, 1])
        if it == iterations:
            # a foot at the end of the other boundary piece: that edge ended before this point (a T-junction, a
            # corner): no partner there
            ended = ((t == tmin[pc]) | (t == tmax[pc])) & (np.linalg.norm(P - pts, axis=1) > 0)
            return pts, uv, ended
        step = np.einsum("ij,ij->i", P - pts, chord) / np.where(cc > 0, cc, 1.0)
        t = np.clip(t + np.where(cc > 0, step, 0.0), lo, hi)


def _seams(surfaces, sgn, X, UV, T, face, piece, tpar, fns, qi, other, js, lam, size, tol_gap, tol_angle, tol_curv,
           per_seam=64):
    """Per face pair a :class:`Seam` of the matched samples, measured with the oriented normals."""
    if qi.size == 0:
        return []
    # at most ``per_seam`` samples of each face pair, evenly along the matched samples
    key = np.minimum(face[qi], other) * len(surfaces) + np.maximum(face[qi], other)
    pick = []
    for _, idx in _groups(key):
        idx = np.sort(idx)
        pick.append(idx[np.unique(np.linspace(0, idx.size - 1, min(idx.size, per_seam)).round().astype(int))])
    pick = np.concatenate(pick)
    qi, other, js, lam = qi[pick], other[pick], js[pick], lam[pick]
    fa, fb = face[qi], other
    uva = UV[qi]
    pb, uvb, ended = _foot(surfaces, X, UV, face, piece, tpar, fns, X[qi], js, lam)
    dist = np.linalg.norm(X[qi] - pb, axis=1)
    tang = T[qi]
    m = qi.size
    na, nb, ka, kb = np.empty((m, 3)), np.empty((m, 3)), np.empty(m), np.empty(m)
    for fs, uv, n_out, k_out in ((fa, uva, na, ka), (fb, uvb, nb, kb)):
        for k, idx in _groups(fs):
            s = surfaces[k]
            (u0, u1), (v0, v1) = s.domain
            u = into_domain(uv[idx, 0], u0, u1)
            v = into_domain(uv[idx, 1], v0, v1)
            SKL = s.derivatives(u, v, 2)
            n = s._normal(u, v, SKL) * sgn[k]
            n_out[idx] = n
            k_out[idx] = normal_curvature(SKL, n, np.cross(n, tang[idx]))
    angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", na, nb), -1.0, 1.0)))
    jump = np.abs(ka - kb)
    scale = np.maximum(np.maximum(np.abs(ka), np.abs(kb)), 1.0 / size)
    lo, hi = np.minimum(fa, fb), np.maximum(fa, fb)
    key = lo * len(surfaces) + hi
    out = []
    for kk, sel in _groups(key):
        sel = np.sort(sel)
        if (~ended[sel]).sum() < 3:  # faces touching at a corner, no edge shared
            continue
        sel = sel[~ended[sel]]
        a, b = divmod(kk, len(surfaces))
        gap, ang, jmp = dist[sel], np.nan_to_num(angle[sel]), np.nan_to_num(jump[sel])
        level = classify(gap, ang, jmp / scale[sel], size, tol_gap, tol_angle, tol_curv)
        out.append(Seam(a, "boundary", b, "boundary", X[qi[sel]], gap, ang, jmp, level))
    return out
