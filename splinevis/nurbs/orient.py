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
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .basis import into_domain
from .continuity import Seam, classify, normal_curvature
from .model import NurbsModel, TrimCurve
from .surface import NurbsSurface
from .shell_volume import _breaks, _piece_params, signed_volumes
from .lazy_report import LazyReport
from .trim import inside, trim_pieces

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
    """``[(uv_function, breaks, sign_hint)]``: the pieces of the face's boundary as functions of a parameter.

    Untrimmed: the four sides counter-clockwise (sign +1). Trimmed: each trim curve (sign decided later)."""
    (u0, u1), (v0, v1) = s.domain
    U, V = s.knots
    if not loops:
        bu, bv = _breaks(U, u0, u1), _breaks(V, v0, v1)
        return [
            (lambda t: np.column_stack([t, np.full_like(t, v0)]), bu, 1),
            (lambda t: np.column_stack([np.full_like(t, u1), t]), bv, 1),
            (lambda t: np.column_stack([t, np.full_like(t, v1)]), bu, -1),  # run u1 -> u0: reversed below
            (lambda t: np.column_stack([np.full_like(t, u0), t]), bv, -1),
        ]
    out = []
    for loop in loops:
        for c in loop:
            t0, t1 = c.domain
            out.append((c.evaluate, _breaks(c.knots, t0, t1), 0))
    return out


def _sample_boundaries(surfaces, trims, size, per_span, max_seg):
    """Boundary samples of every face, dense enough that segments are at most about ``max_seg`` long."""
    UV, RAW, face, piece, sign, tpar, fns = [], [], [], [], [], [], []
    npiece = 0
    for k, (s, loops) in enumerate(zip(surfaces, trims)):
        (u0, u1), (v0, v1) = s.domain
        pieces = _face_pieces(s, loops)
        # pass 1: coarse samples, for the lengths
        params = [_piece_params(b, per_span) for _, b, _ in pieces]
        uvs = [np.column_stack([into_domain(uv[:, 0], u0, u1), into_domain(uv[:, 1], v0, v1)])
               for uv in (f(t) for (f, _, _), t in zip(pieces, params))]
        pts = s.evaluate(np.concatenate(uvs)[:, 0], np.concatenate(uvs)[:, 1])
        splits = np.cumsum([len(t) for t in params])[:-1]
        lengths = [np.linalg.norm(np.diff(p, axis=0), axis=1) for p in np.split(pts, splits)]
        # pass 2: as many samples per span as the longest chord asks
        params2 = []
        for (f, b, _), t, seg in zip(pieces, params, lengths):
            nspan = len(b) - 1
            longest = seg.reshape(nspan, per_span).sum(axis=1).max() if seg.size else 0.0
            n = int(min(max(per_span, np.ceil(longest / max_seg)), 256))
            params2.append(t if n == per_span else _piece_params(b, n))
        raws = [f(t) for (f, _, _), t in zip(pieces, params2)]
        for (f, b, hint), raw, t in zip(pieces, raws, params2):
            if hint < 0:  # a side run backwards (counter-clockwise loop of an untrimmed patch)
                raw, t = raw[::-1], t[::-1]
            RAW.append(raw)  # the trim curve's own points (may leave the domain by the file's tolerance)
            UV.append(np.column_stack([into_domain(raw[:, 0], u0, u1), into_domain(raw[:, 1], v0, v1)]))
            tpar.append(t)
            fns.append(f)
            face.append(np.full(len(raw), k))
            piece.append(np.full(len(raw), npiece))
            sign.append(hint != 0)
            npiece += 1
    UV, RAW = np.concatenate(UV), np.concatenate(RAW)
    face, piece = np.concatenate(face), np.concatenate(piece)
    X = np.empty((len(UV), 3))
    for k, s in enumerate(surfaces):
        sel = face == k
        X[sel] = s.evaluate(UV[sel, 0], UV[sel, 1])
    return X, UV, RAW, face, piece, np.asarray(sign), np.concatenate(tpar), fns


def _trim_directions(pieces, trims, UV, face, piece, known):
    """+1 or -1 per piece: the direction that keeps the face on the left in (u, v) (even-odd inside test just
    left and right of every sample point); untrimmed sides (``known``) are +1 already."""
    npiece = int(piece.max()) + 1
    direction = np.ones(npiece)
    ambiguous = 0
    n = len(UV)
    interior = np.zeros(n, dtype=bool)  # samples with a neighbour on each side in the same piece
    interior[1:-1] = (piece[:-2] == piece[1:-1]) & (piece[2:] == piece[1:-1])
    for k, loops in enumerate(trims):
        if not loops:
            continue
        sel = np.flatnonzero(interior & (face == k))
        if sel.size == 0:
            continue
        # at most 7 votes a piece (each is a bisection of the inside test: the points lie at the boundary)
        pos = np.arange(sel.size) - np.searchsorted(piece[sel], piece[sel])
        cnt = np.bincount(piece[sel])[piece[sel]]
        sel = sel[(pos * 7) // cnt != ((pos - 1) * 7) // cnt]
        lo = UV[face == k].min(axis=0)
        ext = np.maximum(UV[face == k].max(axis=0) - lo, 1e-300)
        d = (UV[sel + 1] - UV[sel - 1]) / ext  # central difference: the tangent at a point of the curve
        norm = np.linalg.norm(d, axis=1)
        ok = norm > 0
        # just left and right of the curve itself (a chord's midpoint lies off it by the sagitta)
        left = np.column_stack([-d[:, 1], d[:, 0]]) / np.where(ok, norm, 1.0)[:, None] * ext * 1e-6
        pl, pr = UV[sel] + left, UV[sel] - left
        ins = inside(pieces, k, np.concatenate([pl[:, 0], pr[:, 0]]), np.concatenate([pl[:, 1], pr[:, 1]]))
        vote = (ins[: sel.size].astype(int) - ins[sel.size:].astype(int)) * ok
        totals = np.bincount(piece[sel], weights=vote, minlength=npiece)
        for p in np.unique(piece[sel]):
            if known[p]:
                continue
            if totals[p] < 0:
                direction[p] = -1.0
            elif totals[p] == 0:
                ambiguous += 1
    return direction, ambiguous


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
    X, UV, RAW, face, piece, known, tpar, fns = _sample_boundaries(surfaces, trims, size, per_span, size / 256)
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
                vols = signed_volumes(surfaces, trims, pieces=pieces)
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
