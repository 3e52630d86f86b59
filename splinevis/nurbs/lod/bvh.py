"""The view-frustum hierarchy over super-surfaces and conservative back-patch culling [Kumar1997, sec. 4.4, 5.2].

**The hierarchy.** A binary tree of axis-aligned boxes built top-down [Kumar1997, sec. 4.4]: a node's boxes are
split at the median of their centres along the longest axis of the centres' bounding box, until a node holds at
most ``leaf_size`` boxes (default one: each leaf is a super-surface, as in the paper's fig. 2). The tree is built
one level at a time, every node of a level at once (a sort per level), and lives in flat arrays.

**Frustum culling.** Each plane ``n . x + d >= 0`` (inward normal) has over a box the extremes
``d + sum_i max(n_i lo_i, n_i hi_i)`` and ``d + sum_i min(...)``: a node whose maximum is negative for some plane
is *not visible*, one whose minimum is non-negative for all planes is *totally visible* (all its leaves are output
without further tests), the rest are *partially visible* and descend [Kumar1997, sec. 5.2]. The traversal takes
a whole level of nodes per numpy batch. A node's box holds its children's, so (floating-point rounding being
monotone) the result equals the per-box test exactly, and that test is conservative: a box meeting the frustum
is never dropped (a box outside no single plane but outside the frustum, near an edge, may be kept).

**Planes from a matrix.** With ``clip = M (x, y, z, 1)`` and rows ``r0..r3`` of ``M``, a point is inside the
OpenGL clip volume when ``-w <= x_c, y_c, z_c <= w``, i.e. ``(r3 +- r_i) . (x, y, z, 1) >= 0``: the six planes
are those sums and differences (left, right, bottom, top, near, far), scaled to unit normals [GribbHartmann2001]
( for a ``0 <= z_c <= w`` depth range the near plane is ``r2`` itself).

**Back-patch culling.** A super-surface with points ``p`` in a ball (centre ``c``, radius ``r``, the box's
circumscribed ball) and normals ``n`` in a convex cone (axis ``a``, half-angle ``h < pi / 2``) is back-facing from
the eye ``e`` when ``(p - e) . n > 0`` for all such ``p, n`` [Kumar1997, sec. 2.2; ShirmanAbiEzzi1993]. With ``D = |c - e| > r`` every
direction ``p - e`` is within ``beta = asin(r / D)`` of ``c - e``, and every ``n`` within ``h`` of ``a``; by the
triangle inequality for angles the angle between ``p - e`` and ``n`` is at most ``theta + beta + h`` with
``theta = angle(a, c - e)``. Hence

``theta + asin(r / D) + h < pi / 2``  implies  ``(p - e) . n > 0`` for every point and normal: back-facing,

tested with a small margin for rounding. It needs consistently oriented normals (``w^3 S_u x S_v`` pointing out
of a closed solid); a surface seen from both sides must not be culled this way.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

__all__ = ["BVH", "build_bvh", "frustum_planes", "frustum_cull", "back_facing"]


class BVH(NamedTuple):
    """A bounding-volume tree in flat arrays (node 0 is the root, nodes of one level are consecutive).

    ``box[k]`` (xmin, xmax, ymin, ymax, zmin, zmax) bounds node ``k``; ``child[k]`` holds its two children or
    ``(-1, -1)`` for a leaf; the node covers the input boxes ``order[start[k]:start[k] + count[k]]``;
    ``level_start[l]`` is the first node of depth ``l`` (one past the last at the end); ``items`` are the input
    boxes (S, 6).

    Examples
    --------
    >>> t = build_bvh([[0, 1, 0, 1, 0, 1], [4, 5, 0, 1, 0, 1]])
    >>> t.child.tolist(), t.box[0].tolist(), t.order.tolist()
    ([[1, 2], [-1, -1], [-1, -1]], [0.0, 5.0, 0.0, 1.0, 0.0, 1.0], [0, 1])
    """

    box: np.ndarray
    child: np.ndarray
    start: np.ndarray
    count: np.ndarray
    order: np.ndarray
    level_start: np.ndarray
    items: np.ndarray


def _ranges(starts, counts):
    """Concatenated ``arange(s, s + c)`` for each pair, vectorized."""
    counts = np.asarray(counts, dtype=np.int64)
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    ends = np.cumsum(counts)
    offs = np.repeat(np.asarray(starts, dtype=np.int64) - (ends - counts), counts)
    return np.arange(total, dtype=np.int64) + offs


def build_bvh(boxes, leaf_size: int = 1) -> BVH:
    """Build the hierarchy over axis-aligned boxes (S, 6) = (xmin, xmax, ymin, ymax, zmin, zmax).

    Median split of the box centres on the longest axis of their bounding box, level by level; the left child
    gets ``count // 2`` boxes. Deterministic (stable sorts, ties kept in input order).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> lo = rng.random((100, 3)); boxes = np.stack([lo, lo + 0.01], axis=2).reshape(100, 6)
    >>> t = build_bvh(boxes)
    >>> len(t.box), int((t.child[:, 0] < 0).sum()), len(t.level_start) - 1  # nodes, leaves, depth + 1
    (199, 100, 8)
    """
    B = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
    if not np.isfinite(B).all() or (B[:, 1::2] < B[:, 0::2]).any():
        raise ValueError("boxes must be finite with min <= max per axis: (S, 6) = "
                         "(xmin, xmax, ymin, ymax, zmin, zmax).")
    leaf_size = max(1, int(leaf_size))
    S = B.shape[0]
    if S == 0:
        z = np.zeros(0, dtype=np.int64)
        return BVH(np.zeros((0, 6)), np.zeros((0, 2), dtype=np.int64), z, z, z, np.zeros(1, dtype=np.int64), B)
    centre = 0.5 * (B[:, 0::2] + B[:, 1::2])
    order = np.arange(S, dtype=np.int64)
    # the current tiling of [0, S): segments of this level's nodes (node id) and finished leaves (-1)
    seg_start, seg_count, seg_node = np.zeros(1, np.int64), np.full(1, S, np.int64), np.zeros(1, np.int64)
    boxes_out, child_out, start_out, count_out = [], [], [], []
    level_start, n_nodes = [0], 1
    while True:
        ob, oc = B[order], centre[order]
        act = seg_node >= 0
        lo = np.minimum.reduceat(ob[:, 0::2], seg_start)[act]
        hi = np.maximum.reduceat(ob[:, 1::2], seg_start)[act]
        nb = np.empty((lo.shape[0], 6))
        nb[:, 0::2], nb[:, 1::2] = lo, hi
        boxes_out.append(nb)
        start_out.append(seg_start[act])
        count_out.append(seg_count[act])
        split = act & (seg_count > leaf_size)
        ch = np.full((lo.shape[0], 2), -1, dtype=np.int64)
        n_split = int(split.sum())
        ch[split[act]] = n_nodes + np.arange(2 * n_split, dtype=np.int64).reshape(-1, 2)
        child_out.append(ch)
        if n_split == 0:
            break
        level_start.append(n_nodes)
        n_nodes += 2 * n_split
        ext = np.maximum.reduceat(oc, seg_start) - np.minimum.reduceat(oc, seg_start)
        axis = np.argmax(ext, axis=1)
        seg_id = np.repeat(np.arange(seg_start.size), seg_count)
        key = np.where(split[seg_id], oc[np.arange(S), axis[seg_id]], 0.0)
        order = order[np.lexsort((key, seg_id))]
        # every split segment becomes two: (start, count // 2) and the rest
        rep = np.where(split, 2, 1)
        new_start = np.repeat(seg_start, rep)
        new_count = np.repeat(seg_count, rep)
        new_node = np.full(new_start.size, -1, dtype=np.int64)
        first = np.cumsum(rep) - rep  # index of each old segment's first piece
        fs = first[split]
        half = seg_count[split] // 2
        new_count[fs] = half
        new_start[fs + 1] = seg_start[split] + half
        new_count[fs + 1] = seg_count[split] - half
        new_node[fs] = n_nodes - 2 * n_split + 2 * np.arange(n_split)
        new_node[fs + 1] = new_node[fs] + 1
        seg_start, seg_count, seg_node = new_start, new_count, new_node
    level_start.append(n_nodes)
    return BVH(np.concatenate(boxes_out), np.concatenate(child_out), np.concatenate(start_out),
               np.concatenate(count_out), order, np.array(level_start, dtype=np.int64), B)


def frustum_planes(matrix, zero_to_one: bool = False) -> np.ndarray:
    """The six frustum planes (6, 4) of a 4x4 view-projection matrix (column vectors: ``clip = M @ (x, 1)``),
    inward unit normals, ``a x + b y + c z + d >= 0`` inside; order left, right, bottom, top, near, far
    (the rows' sums and differences ``r3 +- r_i``; ``zero_to_one`` for a ``0 <= z_c <= w`` depth range).

    Examples
    --------
    >>> frustum_planes(np.eye(4))  # the identity: the cube [-1, 1]^3
    array([[ 1.,  0.,  0.,  1.],
           [-1.,  0.,  0.,  1.],
           [ 0.,  1.,  0.,  1.],
           [ 0., -1.,  0.,  1.],
           [ 0.,  0.,  1.,  1.],
           [ 0.,  0., -1.,  1.]])
    """
    M = np.asarray(matrix, dtype=np.float64)
    if M.shape != (4, 4):
        raise ValueError(f"matrix must be 4x4, got {M.shape}.")
    r = M
    P = np.stack([r[3] + r[0], r[3] - r[0], r[3] + r[1], r[3] - r[1],
                  r[2] if zero_to_one else r[3] + r[2], r[3] - r[2]])
    norm = np.linalg.norm(P[:, :3], axis=1, keepdims=True)
    return P / np.where(norm > 0, norm, 1.0)


def _classify(boxes, planes):
    """``(outside, inside)`` masks of boxes (k, 6) against planes (6, 4)."""
    n, d = planes[:, :3], planes[:, 3]
    a = boxes[:, None, 0::2] * n[None]
    b = boxes[:, None, 1::2] * n[None]
    hi = np.maximum(a, b).sum(axis=2) + d
    lo = np.minimum(a, b).sum(axis=2) + d
    return (hi < 0).any(axis=1), (lo >= 0).all(axis=1)


def frustum_cull(bvh: BVH, planes, return_nodes: bool = False):
    """Ids of the input boxes not outside the frustum (sorted), by a level-by-level traversal of ``bvh``.

    Nodes are classified as not visible (dropped with their subtree), totally visible (all their leaves output,
    no more tests) or partially visible (children tested next); a partially visible leaf's boxes are tested one
    by one [Kumar1997, sec. 5.2]. With ``return_nodes`` also the totally visible nodes (the paper's activity
    list, in traversal order) are returned.

    Examples
    --------
    >>> t = build_bvh([[0, 1, 0, 1, 0, 1], [4, 5, 0, 1, 0, 1], [0.5, 0.6, 0.5, 0.6, 0.5, 0.6]])
    >>> planes = frustum_planes(np.diag([0.5, 0.5, 0.5, 1.0]))  # the cube [-2, 2]^3
    >>> frustum_cull(t, planes).tolist()
    [0, 2]
    >>> ids, nodes = frustum_cull(t, planes, return_nodes=True); nodes.tolist()  # leaves of boxes 0 and 2
    [1, 3]
    """
    planes = np.asarray(planes, dtype=np.float64).reshape(-1, 4)
    if bvh.box.shape[0] == 0:
        empty = np.zeros(0, dtype=np.int64)
        return (empty, empty) if return_nodes else empty
    nodes = np.zeros(1, dtype=np.int64)
    whole, parts, activity = [], [], []
    while nodes.size:
        out, inside = _classify(bvh.box[nodes], planes)
        leaf = bvh.child[nodes, 0] < 0
        full = nodes[inside]
        activity.append(full)
        whole.append(_ranges(bvh.start[full], bvh.count[full]))
        partial = ~out & ~inside
        pl = nodes[partial & leaf]
        if pl.size:
            ids = bvh.order[_ranges(bvh.start[pl], bvh.count[pl])]
            o, _ = _classify(bvh.items[ids], planes)
            parts.append(ids[~o])
        nodes = bvh.child[nodes[partial & ~leaf]].ravel()
    ids = np.sort(np.concatenate([bvh.order[np.concatenate(whole)]] + parts))
    return (ids, np.concatenate(activity)) if return_nodes else ids


def back_facing(cone_axis, cone_half_angle, boxes, eye, margin: float = 1e-9) -> np.ndarray:
    """True where a super-surface is surely back-facing from ``eye`` [Kumar1997, sec. 2.2] (module docstring):
    ``angle(a, c - e) + asin(r / |c - e|) + h + margin < pi / 2`` with ``c, r`` the centre and half-diagonal of
    its box; never true for no cone (``h >= pi / 2``) or an eye inside the ball.

    Parameters
    ----------
    cone_axis : (S, 3), cone_half_angle : (S,)
        Normal cones of ``w^3 S_u x S_v`` (:func:`splinevis.nurbs.lod.gauss.normal_cone`); unit axes.
    boxes : (S, 6)
        Bounds of the points (e.g. of the control points: a rational patch lies in their convex hull).
    eye : (3,)

    Examples
    --------
    A patch facing +z around the origin, seen from below and from above:

    >>> box = [[-1, 1, -1, 1, -0.1, 0.1]]
    >>> [back_facing([[0, 0, 1]], [0.2], box, eye).tolist() for eye in ([0, 0, -10], [0, 0, 10])]
    [[True], [False]]
    """
    a = np.asarray(cone_axis, dtype=np.float64).reshape(-1, 3)
    h = np.asarray(cone_half_angle, dtype=np.float64).reshape(-1)
    B = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
    e = np.asarray(eye, dtype=np.float64).reshape(3)
    c = 0.5 * (B[:, 0::2] + B[:, 1::2])
    r = 0.5 * np.linalg.norm(B[:, 1::2] - B[:, 0::2], axis=1)
    dv = c - e
    D = np.linalg.norm(dv, axis=1)
    ok = (D > r * (1.0 + 1e-12)) & (h < 0.5 * math.pi) & (np.linalg.norm(a, axis=1) > 0.5)
    theta = np.arctan2(np.linalg.norm(np.cross(a, dv), axis=1), np.einsum("ij,ij->i", a, dv))
    beta = np.arcsin(np.clip(r / np.where(ok, D, 1.0), 0.0, 1.0))
    return ok & (theta + beta + h + margin < 0.5 * math.pi)
