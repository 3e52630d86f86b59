"""Dynamic tessellation: super-surfaces tessellated finer than level 0 when the view needs it, cached, and drawn
without cracks beside neighbours at any static level [Kumar1997, sec. 2.2, 4.4, 5.2].

**What is asked.** Where even level 0 projects to more than ``pixel_error`` pixels,
:func:`.select.select_levels` gives the number ``j`` of finer steps the view needs (``stats["finer_steps"]``): the
coarsest tolerance ``delta_0 / ratio**j`` that projects within the bound (``j <= max_steps``).

**How a refined super-surface is made** (:class:`Refiner`, run by the mesh builder ``T`` of
:mod:`.pipeline`, never by the renderer):

1. *Chains.* Every edge of its patches gets the chains ``curve_chain(net, delta_0 / ratio**i)``, ``i = 0..j``, of
   the curve :mod:`.levels` uses (the edge's first side). The chains are nested (:mod:`.levels` docstring: a
   segment is split at a point that depends on the segment only), so the chain of step ``j`` holds the level-0
   chain, whose vertex ids are kept, and every coarser step's; only its new points become new vertices, evaluated
   once from the edge's curve (numbered after the model's vertices). The nesting is checked, not assumed: an
   edge whose level-0 chain is not ``curve_chain``'s (trim crossings, stitched open edges of a trimmed model) or
   whose finer chain does not hold the coarser one is not refined across, and the super-surfaces on it stay
   static, as do those with a trimmed patch (counted in ``capped``). Each point has a *birth*: the first step
   whose chain holds it (0: the level-0 chain).
2. *Patches.* Each patch is tessellated at ``delta_j`` by the paper's adaptive algorithm
   (:func:`.adaptive.adaptive_tessellation`, batched) with its four sides' chains at step ``j`` fixed: every
   triangle's proven bound is at most ``delta_j`` (the chords meet ``delta_j``, so no chain segment lifts a
   target; a triangle a guard left above it keeps its own bound, reported as the mesh's ``bound``).
3. *Assembly* (the paper's common boundary strip, sec. 4.4). Every drawn super-surface has a *rank*: its static
   level ``l >= 0``, or ``-j`` when refined. Every edge is drawn at the finest rank of its drawn sides, and the
   coarser side's triangles along it are split into fans through the finer chain's extra points, exactly as
   :func:`.levels.assemble` does between static levels, refined sides included. The chain points lie on the
   domain triangle's straight side, so the fan partitions it and each piece lies in the old triangle's smallest
   enclosing disc: the old proven bound holds for every piece. Every vertex on a drawn edge is used by both
   sides: no crack, at any mixture of static levels and refined steps.

**Cache and caps.** Refined meshes are kept by ``(super-surface, j)`` with their fan rows, least recently used
dropped beyond ``cache_triangles`` triangles; edge chains are kept per edge (its finest step so far, with births).
When the vertices of dropped meshes outnumber the live ones (plus 200,000), everything is dropped and numbered
anew (``resets``): memory stays bounded. Caps: ``j <= max_steps`` (the selection counts where it binds,
``finer_capped``); a mesh whose estimated size ``triangles[s, 0] * ratio**j`` exceeds ``mesh_triangles`` gets the
largest ``j`` that fits (``capped``); one build tessellates meshes of at most ``triangles_per_build`` estimated
triangles (at least one mesh), the most steps and then the nearest first; the rest are ``pending`` (drawn at the
finest step already cached, or level 0) and made by the next builds; a finer mesh already cached is drawn
instead of making the one asked (it meets the bound too). (The adaptive tessellation makes some
10,000-20,000 triangles a second here: a build of the default 5,000 takes a few tenths of a second; ``T`` publishes
the newest view with the cached meshes first, then one such build.)
"""

from __future__ import annotations

import time
from collections import OrderedDict

import numpy as np

from .adaptive import _check_chains, _curve_chains, _tessellate
from .bounds import curve_points, side_net
from .levels import _SIDE_ENDS, _between, _corner_labels, _fan_rows, _fan_split, _patch_finish, vertex_normals
from .select import _box_distance

__all__ = ["Refiner"]

_BATCH = 512  # patches tessellated in lockstep at once
_RESET_SLACK = 200_000  # dead vertices tolerated beyond the live ones before the store is rebuilt


def _side_uv(k, t):
    z, o = np.zeros_like(t), np.ones_like(t)
    return np.column_stack([t, z] if k == 0 else [o, t] if k == 1 else [t, o] if k == 2 else [z, t])


class Refiner:
    """Finer-than-level-0 tessellations of a :class:`~splinevis.nurbs.lod.levels.LodModel`'s super-surfaces and
    their crack-free assembly with the static levels (module docstring) [Kumar1997, sec. 2.2, 4.4].

    Parameters
    ----------
    lod : LodModel
    ratio : float
        Step ``j`` has the tolerance ``lod.tolerance[0] / ratio**j``.
    max_steps : int
        Largest ``j`` (the selection caps there too).
    cache_triangles : int
        Triangles of refined meshes kept (least recently used dropped first).
    mesh_triangles : int
        Largest estimated size of one refined mesh (``j`` lowered until ``triangles[s, 0] * ratio**j`` fits).
    triangles_per_build : int
        Estimated triangles (``triangles[s, 0] * ratio**j``) one :meth:`build` tessellates at most (at least one
        mesh); the rest are pending.

    Examples
    --------
    The sphere's eight super-surfaces: two refined one step, one two steps, the rest at static levels.

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
    >>> r = Refiner(lod)
    >>> levels, steps = np.array([0, 0, 0, 1, 0, 1, 0, 0]), np.array([1, 2, 1, 0, 0, 0, 0, 0])
    >>> points, normals, tri, info = r.build(levels, steps)
    >>> info["refined"], info["pending"], info["bound"]  # the largest bound drawn: the static level 1's
    (3, 0, 0.2)
    >>> e = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    >>> bool((np.unique(e, axis=0, return_counts=True)[1] == 2).all())  # closed: no crack
    True
    """

    def __init__(self, lod, *, ratio: float = 4.0, max_steps: int = 4, cache_triangles: int = 2_000_000,
                 mesh_triangles: int = 200_000, triangles_per_build: int = 5_000):
        if not (np.isfinite(ratio) and ratio > 1):
            raise ValueError(f"ratio must be a number > 1, got {ratio!r}.")
        if min(int(max_steps), int(cache_triangles), int(mesh_triangles), int(triangles_per_build)) < 1:
            raise ValueError("max_steps, cache_triangles, mesh_triangles and triangles_per_build must be >= 1, got "
                             f"{max_steps!r}, {cache_triangles!r}, {mesh_triangles!r}, {triangles_per_build!r}.")
        for name in ("bezier", "edges", "supers", "vertices", "edge_ids", "meshes", "super_edges", "tolerance"):
            if not hasattr(lod, name):
                raise TypeError(f"lod must be a LodModel (build_lod), got {type(lod).__name__} without {name!r}.")
        self.lod = lod
        self.ratio, self.max_steps = float(ratio), int(max_steps)
        self.cache_triangles, self.mesh_triangles = int(cache_triangles), int(mesh_triangles)
        self.triangles_per_build = int(triangles_per_build)
        self._V0 = int(lod.vertices.shape[0])
        self._corner, _ = _corner_labels(lod.bezier, lod.edges)
        self._members = [np.asarray(m, dtype=np.int64) for m in lod.supers.members]
        status = getattr(lod, "status", None)
        # super-surfaces left static: a trimmed patch (its clipping is the static levels'), or a bad edge (below)
        self._static = ({s for s, m in enumerate(self._members) if (np.asarray(status)[m] != 0).any()}
                        if status is not None else set())
        self._bad = set()  # edges whose chains are not curve_chain's nested chains
        self.resets = 0
        self._clear()

    def _clear(self):
        self._blocks, self._nblocks, self._count = [], [], 0
        self._arrays = None  # (count, points, normals) of the last concatenation
        self._chains = {}  # edge -> (t, ids, birth) up to its finest step so far
        self._depth = {}  # edge -> that step
        self._meshes = OrderedDict()  # (s, j) -> (triangles, fan rows, bound, interior vertex count)
        self._cached = 0  # triangles in _meshes
        self._chain_points = 0

    # ------------------------------------------------------------------ vertices
    def _alloc(self, points, normals):
        ids = self._V0 + self._count + np.arange(points.shape[0], dtype=np.int64)
        if points.shape[0]:
            self._blocks.append(np.asarray(points, dtype=np.float64))
            self._nblocks.append(normals)
            self._count += points.shape[0]
        return ids

    def _normals(self, patch, uv):
        if getattr(self.lod, "normals", None) is None:
            return np.zeros((uv.shape[0], 3))
        return vertex_normals(self.lod.bezier, np.full(uv.shape[0], patch, dtype=np.int64), uv)

    def arrays(self):
        """``(points, normals)`` of every vertex: the model's, then the refined ones (a new array only when vertices
        were added: the renderer re-uploads nothing otherwise).

        >>> from splinevis.nurbs.exact import torus
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(torus(), 0.05, levels=1, progress=False)
        >>> Refiner(lod).arrays()[0] is lod.vertices
        True
        """
        if self._count == 0:
            return self.lod.vertices, getattr(self.lod, "normals", None)
        if self._arrays is None or self._arrays[0] != self._count:
            self._blocks = [np.concatenate(self._blocks)]
            self._nblocks = [np.concatenate(self._nblocks)]
            points = np.concatenate([self.lod.vertices, self._blocks[0]])
            normals = (None if getattr(self.lod, "normals", None) is None
                       else np.concatenate([self.lod.normals, self._nblocks[0]]))
            self._arrays = (self._count, points, normals)
        return self._arrays[1], self._arrays[2]

    # ------------------------------------------------------------------ chains
    def _ensure_chains(self, needs: dict):
        """Every edge ``e`` of ``needs`` gets its chains up to step ``needs[e]`` (nested; births)."""
        lod, bs, edges = self.lod, self.lod.bezier, self.lod.edges
        delta0 = float(lod.tolerance[0])
        todo = [(e, self._depth.get(e, -1), j) for e, j in needs.items() if self._depth.get(e, -1) < j]
        if not todo:
            return
        by_shape: dict = {}
        nets = {}
        for e, have, j in todo:
            f = int(edges.edge_side[e])
            nets[e] = side_net(bs.control(f // 4), f % 4)
            by_shape.setdefault(nets[e].shape, []).append((e, have, j))
        for group in by_shape.values():
            rows, deltas = [], []
            for e, have, j in group:
                steps = np.arange(have + 1, j + 1)
                rows += [nets[e]] * steps.size
                deltas.append(delta0 / self.ratio ** steps.astype(np.float64))
            got = iter(_curve_chains(np.stack(rows), np.concatenate(deltas)))
            for e, have, j in group:
                f = int(edges.edge_side[e])
                for step in range(have + 1, j + 1):
                    t = next(got)
                    if step == 0:
                        ids = np.asarray(lod.edge_ids[e], dtype=np.int64)
                        if t.size != ids.size or not np.array_equal(lod.vertices[ids[1:-1]],
                                                                    curve_points(nets[e], t[1:-1])):
                            self._bad.add(e)  # trim crossings or a stitched edge: not curve_chain's chain
                            break
                        self._chains[e] = (t, ids, np.zeros(t.size, dtype=np.int64))
                        continue
                    t0, ids0, birth0 = self._chains[e]
                    pos = np.clip(np.searchsorted(t, t0), 0, t.size - 1)
                    if not np.array_equal(t[pos], t0):  # not nested: never refined across
                        self._bad.add(e)
                        break
                    new = np.ones(t.size, dtype=bool)
                    new[pos] = False
                    ids, birth = np.empty(t.size, dtype=np.int64), np.full(t.size, step, dtype=np.int64)
                    ids[pos], birth[pos] = ids0, birth0
                    tn = t[new]
                    ids[new] = self._alloc(curve_points(nets[e], tn), self._normals(f // 4, _side_uv(f % 4, tn)))
                    self._chain_points += int(tn.size)
                    self._chains[e] = (t, ids, birth)
                self._depth[e] = j if e not in self._bad else np.iinfo(np.int64).max
                if e in self._bad:
                    for step in range(step + 1, j + 1):  # the rest of this edge's chains
                        next(got)

    def _chain_at(self, e, j):
        t, ids, birth = self._chains[e]
        keep = birth <= j
        return t[keep], ids[keep]

    def _sides(self, i, j):
        edges = self.lod.edges
        side_chain, side_ids = [], []
        for k in range(4):
            e = int(edges.side_edge[i, k])
            if e < 0:  # a pole: both ends are the one corner vertex
                side_chain.append(np.array([0.0, 1.0]))
                side_ids.append(self._corner[i, list(_SIDE_ENDS[k])].astype(np.int64))
                continue
            t, g = self._chain_at(e, j)
            if edges.side_reversed[i, k]:
                t, g = 1.0 - t[::-1], g[::-1]
            side_chain.append(t)
            side_ids.append(g)
        return side_chain, side_ids

    # ------------------------------------------------------------------ refined meshes
    def _make(self, entries):
        """Tessellate the super-surfaces ``entries [(s, j)]`` at step ``j`` and cache them."""
        lod, bs, edges = self.lod, self.lod.bezier, self.lod.edges
        needs: dict = {}
        for s, j in entries:
            for e in edges.side_edge[self._members[s]].ravel():
                if e >= 0:
                    needs[int(e)] = max(needs.get(int(e), -1), j)
        self._ensure_chains(needs)
        for s, _ in entries:
            if any(int(e) in self._bad for e in edges.side_edge[self._members[s]].ravel() if e >= 0):
                self._static.add(s)
        entries = [(s, j) for s, j in entries if s not in self._static]
        jobs = [(s, j, int(i)) + self._sides(int(i), j) for s, j in entries for i in self._members[s]]
        delta0 = float(lod.tolerance[0])
        by_degree: dict = {}
        for n, job in enumerate(jobs):
            by_degree.setdefault(int(bs.group[job[2]]), []).append(n)
        tess = [None] * len(jobs)
        for group in by_degree.values():
            for a in range(0, len(group), _BATCH):
                part = group[a:a + _BATCH]
                items = [(bs.control(jobs[n][2]), delta0 / self.ratio ** jobs[n][1], _check_chains(jobs[n][3]))
                         for n in part]
                for n, t in zip(part, _tessellate(items)):
                    tess[n] = t
        n = 0
        for s, j in entries:
            tris, bound, inner = [], delta0 / self.ratio ** j, 0
            for _ in self._members[s]:
                _, _, i, side_chain, side_ids = jobs[n]
                new, tri, _, uv = _patch_finish(bs, edges, i, tess[n], side_chain, side_ids, self._V0 + self._count)
                self._alloc(new, self._normals(i, uv))
                inner += new.shape[0]
                bound = max(bound, float(tess[n].bound.max(initial=0.0)))
                tris.append(tri)
                n += 1
            tri = np.concatenate(tris)
            border = lod.super_edges[s]
            chain_ids = {int(e): self._chain_at(int(e), j)[1] for e in border}
            fans = _fan_rows(tri, border, chain_ids, {e: np.zeros(g.size, dtype=np.int64)
                                                     for e, g in chain_ids.items()}, 0)
            self._meshes[(s, j)] = (tri, fans, bound, inner)
            self._cached += tri.shape[0]
        return entries

    def _between(self, e, a, b, rank):
        if rank >= 0:
            return _between(self.lod, e, a, b, rank)
        t, ids, birth = self._chains[e]
        ia, ib = int(np.flatnonzero(ids == a)[0]), int(np.flatnonzero(ids == b)[0])
        mid = np.arange(min(ia, ib) + 1, max(ia, ib))
        mid = mid[birth[mid] <= -rank]
        return ids[mid[::-1] if ia > ib else mid]

    def _evict(self, keep):
        while self._cached > self.cache_triangles:
            key = next((k for k in self._meshes if k not in keep), None)
            if key is None:
                break
            self._cached -= self._meshes.pop(key)[0].shape[0]

    def _maybe_reset(self):
        live = sum(m[3] for m in self._meshes.values()) + self._chain_points
        if self._count > 2 * live + _RESET_SLACK:
            self._clear()
            self.resets += 1

    def plan(self, levels, steps):
        """``(j used per super-surface, capped count)``: ``steps`` where the level is 0 and drawn, capped at
        ``max_steps`` and by ``mesh_triangles``.

        >>> from splinevis.nurbs.exact import torus
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(torus(), 0.05, levels=1, progress=False)
        >>> j, capped = Refiner(lod, max_steps=2).plan(np.zeros(16, int), np.array([0, 1, 2, 3, 9] + [0] * 11))
        >>> j[:5].tolist(), capped
        ([0, 1, 2, 2, 2], 2)
        """
        levels = np.asarray(levels, dtype=np.int64)
        steps = np.asarray(steps, dtype=np.int64)
        S = len(self._members)
        if levels.shape != (S,) or steps.shape != (S,) or (steps < 0).any():
            raise ValueError(f"levels and steps must be {S} integers (steps >= 0), got shapes {levels.shape}, "
                             f"{steps.shape}.")
        want = np.where(levels == 0, steps, 0)
        if self._static:
            want[np.fromiter(self._static, dtype=np.int64)] = 0  # capped below: asked, not refinable
        tri0 = np.maximum(np.asarray(self.lod.triangles)[:, 0], 1).astype(np.float64)
        fit = np.floor(np.log(self.mesh_triangles / tri0) / np.log(self.ratio) + 1e-9).astype(np.int64)
        j = np.minimum(want, np.clip(fit, 0, self.max_steps))
        return j, int((j < np.where(levels == 0, steps, 0)).sum())

    def build(self, levels, steps, eye=None, budget=None) -> tuple:
        """One crack-free mesh: the super-surfaces at ``levels (S,)`` (-1: not drawn), those at level 0 with
        ``steps (S,) > 0`` refined that many steps (as far as the caps and cache allow: module docstring), the
        most steps first, then (with ``eye``) the nearest boxes first; ``budget`` overrides ``triangles_per_build``
        (0: nothing tessellated, only cached meshes drawn).
        Returns ``(points, normals, triangles, info)``; ``info``: ``triangles``, ``fans``, ``bound`` (the largest
        proven bound drawn), ``refined`` and ``refined_triangles`` (super-surfaces drawn refined and their
        triangles), ``pending`` (drawn coarser than asked, for a later build), ``capped``, ``tessellate_ms``,
        ``made`` (meshes tessellated now), ``cached_triangles``.

        >>> from splinevis.nurbs.exact import torus
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(torus(), 0.05, levels=1, progress=False)
        >>> info = Refiner(lod).build(np.zeros(16, int), np.array([1] + [0] * 15))[3]
        >>> info["refined"], bool(info["refined_triangles"] > lod.triangles[0, 0]), info["made"]
        (1, True, 1)
        """
        lod = self.lod
        levels = np.asarray(levels, dtype=np.int64)
        S = len(self._members)
        if levels.shape != (S,) or levels.max(initial=-1) >= lod.levels or levels.min(initial=0) < -1:
            raise ValueError(f"levels must be {S} integers in -1..{lod.levels - 1}, got shape {levels.shape}.")
        j, capped = self.plan(levels, steps)
        self._maybe_reset()
        want = np.flatnonzero(j > 0)
        near = np.zeros(want.size) if eye is None else _box_distance(np.asarray(lod.boxes)[want], eye)
        want = want[np.lexsort((want, near, -j[want]))]  # the most needed first
        used = np.zeros(S, dtype=np.int64)
        budget = self.triangles_per_build if budget is None else float(budget)
        make, pending = [], 0
        estimate = np.maximum(np.asarray(lod.triangles)[:, 0], 1) * self.ratio ** j.astype(np.float64)
        for s in want:
            s, js = int(s), int(j[s])
            finer = next((k for k in range(js + 1, self.max_steps + 1) if (s, k) in self._meshes), 0)
            if (s, js) in self._meshes:
                used[s] = js
            elif finer:  # a finer mesh cached (the camera moved away): within the bound asked, drawn at once
                used[s] = finer
            elif budget > 0:
                make.append((s, js))
                budget -= estimate[s]
                used[s] = js
            else:
                pending += 1
                used[s] = next((k for k in range(js - 1, 0, -1) if (s, k) in self._meshes), 0)
        t0 = time.perf_counter()
        if make:
            for s, _ in set(make) - set(self._make(make)):  # edges found not refinable: static
                used[s], capped = 0, capped + 1
        tessellate_ms = 1e3 * (time.perf_counter() - t0)
        rank = np.where(used > 0, -used, levels)
        tri, info = self._assemble(levels, rank)
        keep = {(int(s), int(used[s])) for s in np.flatnonzero(used > 0)}
        for key in keep:
            self._meshes.move_to_end(key)
        self._evict(keep)
        points, normals = self.arrays()
        info.update(pending=pending, capped=capped, tessellate_ms=tessellate_ms, made=len(make),
                    cached_triangles=self._cached)
        return points, normals, tri, info

    def _assemble(self, levels, rank):
        lod, edges = self.lod, self.lod.edges
        drawn = levels >= 0
        big = np.iinfo(np.int64).max
        edge_rank = np.full(len(edges), big)
        side_super = np.repeat(lod.supers.labels, 4).reshape(-1, 4)
        on = drawn[side_super] & (edges.side_edge >= 0)
        np.minimum.at(edge_rank, edges.side_edge[on], rank[side_super][on])
        out, fanned, refined_tri, bound = [], 0, 0, 0.0
        for s in np.flatnonzero(drawn):
            r = int(rank[s])
            if r < 0:
                tri, fans, b, _ = self._meshes[(int(s), -r)]
                bound = max(bound, b)
            else:
                tri, fans = lod.meshes[s][r]
                bound = max(bound, float(lod.tolerance[r]))
            if fans.size:
                need = edge_rank[fans[:, 1]] < r
                if need.any():
                    tri, k = _fan_split(tri, fans[need],
                                        lambda eid, a, b: self._between(eid, a, b, int(edge_rank[eid])))
                    fanned += k
            if r < 0:
                refined_tri += tri.shape[0]
            out.append(tri)
        tri = np.concatenate(out) if out else np.zeros((0, 3), dtype=np.int64)
        return tri, {"triangles": int(tri.shape[0]), "fans": fanned, "bound": bound,
                     "refined": int(((rank < 0) & drawn).sum()), "refined_triangles": refined_tri}
