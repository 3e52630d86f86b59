r"""The NURBS family's renderers for the choice by accuracy (``Plotter.add_nurbs(..., max_error_px=...,
max_normal_error_deg=...)``, :mod:`splinevis.choice`), declared on its program as :data:`RENDERERS`.

* ``mesh`` (rank 0): :func:`splinevis.nurbs.tessellate.tessellate` with ``k`` samples per knot span and
  direction (each span quad split into the triangles ``(a, b, c)``, ``(a, c, d)``), vertex normals the exact
  unit normals [Kanai2007, sec. 4, Fig. 3 left]. Its position error is **proven** (:func:`chord_bounds`: the
  distance between each triangle and the surface point at the same ``(u, v)``, from second-derivative bounds
  of the rational Bezier patches [Kumar1997, sec. 4.1]), plus the float32 rounding of the vertices
  (:func:`splinevis.gl.renderers.float32_margin`), turned into pixels over the boxes of a fixed grid of cells
  of each patch (:meth:`splinevis.gl.screen_error.View.box_pixels`). Its normal error is **proven**
  (:func:`normal_bounds`: normal cones of the pseudo-Gauss map [Kumar1997, sec. 3], a first-order and a
  second-order bound, the smallest per sub-square; poles are covered by the cones), infinite where none
  holds: across a C0 crease (the shared vertices carry one side's normal: the mesh is really that far off)
  or where ``S_u x S_v`` vanishes and no cone was computed; such a model never meets a normal request with
  the mesh. Trimmed models are refused: the tessellation ignores trim loops.
* ``per_fragment`` (rank 10, exact): the program itself (Newton on the pixel ray per fragment); its error is
  the program's own, :func:`splinevis.choice.raycast_error_px` (an estimate from the float32 depth bound,
  since the program has a float64 twin and a depth bound), with exact normals.

Cost ranks: docs/results/nurbs/nurbs.md (640 x 480, Mesa llvmpipe, a hood panel with zebra stripes) measured
the per-fragment program at 313 ms per frame against 16 ms for the 32-per-span mesh with exact vertex
normals (31 ms at 64 per span): the mesh ranks 0, the program 10.

Cells. Every Bezier patch of the model (:func:`splinevis.nurbs.lod.bezier.bezier_set`: the knot spans the
tessellation cuts) is cut once into ``r x r`` cells of its local domain ``[0, 1]^2`` (``r`` from 16 down to 2
so that the model has at most :data:`CELL_BUDGET` cells); on each cell the Bernstein net of the sub-patch
(:func:`splinevis.nurbs.lod.bounds.subdivide`) gives bounds of the surface's first and second derivatives
and of the pseudo-Gauss map, valid for every ``k``: a sub-square of level ``k`` (side ``1 / k``) lies in the
cells its interior meets (a contiguous range per direction), so its bounds are the maxima over that range.
Cells are widened by the rounding of the tessellation's parameters (:func:`splinevis.nurbs.basis.at_fraction`
in the parent's parameters, a few ``eps (|u0| + |u1|) / (u1 - u0)`` in local ones), so that the vertices'
actual parameters lie in them too.
"""

from __future__ import annotations

import math

import numpy as np

from ..gl.error_bounds import U32
from ..gl.renderers import (MESH_LEVELS, Renderer, add_mesh_actor, float32_margin, mesh_cost, mesh_refuses,
                             raycast_cost)
from ..gl.screen_error import SNAP_PX
from .normal_bounds import CELL_BUDGET, _CHUNK, _bezier, _cells, _grid_boxes, _model

__all__ = ["PER_FRAGMENT_NS_PER_PIXEL", "CELL_BUDGET", "CONE_BUDGET", "chord_bounds", "normal_bounds", "mesh_error_px", "mesh_normal_error_deg",
           "mesh_measure", "mesh_triangles", "nurbs_mesh_refuses", "RENDERERS"]

#: Most level-``k`` sub-patches whose normal cones are computed directly (about 20 us each); beyond, the
#: first-order normal bound alone (:func:`normal_bounds`).
CONE_BUDGET = 65_536


def _ranges(n_from: int, n_to: int):
    """For each of ``n_to`` equal intervals of [0, 1], the first and last of the ``n_from`` equal intervals whose
    interior meets it: ``floor(j n_from / n_to)`` .. ``ceil((j + 1) n_from / n_to) - 1``."""
    j = np.arange(n_to)
    return (j * n_from) // n_to, -((-(j + 1) * n_from) // n_to) - 1


def _range_max(X: np.ndarray, axis: int, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Along ``axis``, entry ``j`` of the result is the maximum of ``X`` over indices ``lo[j]..hi[j]``."""
    out = np.take(X, lo, axis=axis)
    for t in range(1, int((hi - lo).max()) + 1):
        out = np.maximum(out, np.take(X, np.minimum(lo + t, hi), axis=axis))
    return out


def _to_level(X: np.ndarray, n_from: int, n_to: int) -> np.ndarray:
    """``X (P, n_from, n_from, ...)`` per cell to ``(P, n_to, n_to, ...)``: maxima over the ranges that meet."""
    lo, hi = _ranges(n_from, n_to)
    return _range_max(_range_max(X, 1, lo, hi), 2, lo, hi)


def _check_level(k) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"k (samples per span) must be a positive integer, got {k!r}.")
    return int(k)


def chord_bounds(model, k: int, cache: dict | None = None) -> np.ndarray:
    r"""Proven bounds ``(P, k, k)`` (world units) of the distance between each triangle of ``tessellate(model, k)``
    and the surface point at the same ``(u, v)``, per Bezier patch (numbered as
    :func:`splinevis.nurbs.lod.bezier.bezier_set`) and sub-square ``(i, j)`` of its local domain; the float64
    evaluation of the vertices included, the float32 rounding on the GPU not.

    Derivation. For a triangle ``T`` of the domain, ``L`` the linear interpolant of ``F`` at its vertices,
    ``G = F - L`` is smooth and vanishes at the vertices, and ``D^2 G = D^2 F`` (``L`` is linear), so eq. (4) of
    :mod:`splinevis.nurbs.lod.bounds` (Taylor's formula with integral remainder, [Kumar1997, sec. 4.1] after
    [Filip1986]) applies to ``F`` itself: ``|F - L| <= (1/8)(du^2 M1 + 2 du dv M2 + dv^2 M3)`` with ``M`` bounds
    of ``|F_uu|, |F_uv|, |F_vv|`` on ``T``'s box. Both triangles of a sub-square have ``du = dv = 1 / k`` (local
    parameters); no interpolant enters, so one bound per sub-square holds for both and for every ``k``.

    ``M`` of the rational ``F = A / w`` on a cell: with ``c`` the centre of the cell's control-point box,
    ``E = F - c`` and ``A_c = A - c w = w E`` (the Bernstein net ``Q[:3] - c Q[3]``), the product rule gives
    ``E_u = (A_c,u - w_u E) / w`` and ``E_uu = (A_c,uu - w_uu E - 2 w_u E_u) / w``,
    ``E_uv = (A_c,uv - w_uv E - w_u E_v - w_v E_u) / w``; the derivatives of ``A_c`` and ``w`` are bounded by their
    nets' differences (eq. (1) there, [Farin2002, ch. 5]), ``|E| <= R`` (the cell lies in the hull of its control
    points, weights positive) and ``w >= min`` of its coefficients. A sub-square's ``M`` is the maximum over the
    cells its interior meets (module docstring): ``(1/8k^2)(M1 + 2 M2 + M3)`` then bounds both of its triangles.
    A polynomial patch has ``w`` constant: ``M`` is its net's second differences.

    Rounding ([Higham2002, sec. 3.1], worst-case terms as in :mod:`splinevis.nurbs.lod.bounds`): the
    subdivided coefficients are off by ``(m + n + 4) eps max |Q|``, added to each difference; the vertices'
    parameters are off by a few ``eps`` (the cells are widened by that); the model evaluates the vertices to
    ``8 (m + 1)(n + 1) eps max |P| max w / min w``, which is added.

    >>> from splinevis.nurbs.exact import cylinder
    >>> b = chord_bounds(cylinder(1.0), 4)  # 4 quarter arcs, 16 segments: 1 - cos(pi / 16) = 0.019 if equal
    >>> b.shape, round(float(b.max()), 4)  # measured 0.0209 (tessellate.chord_deviation): 2.5x
    ((4, 4, 4), 0.0519)
    """
    k = _check_level(k)
    cache = {} if cache is None else cache
    key = ("nurbs_chord", k)
    if key not in cache:
        cells = _cells(model, cache)
        r, M = cells["r"], cells["M"]
        Mk = _to_level(M, r, k)
        # the vertices' parameters may lie a widening outside the sub-square: extents 1 / k + 2 delta
        _, widen = _bezier(model, cache)
        grow = (1.0 + 2.0 * k * widen.max(axis=1)) ** 2
        chord = (Mk[..., 0] + 2.0 * Mk[..., 1] + Mk[..., 2]) / (8.0 * k * k) * grow[:, None, None]
        cache[key] = chord + cells["eval"][:, None, None]
    return cache[key]


def normal_bounds(model, k: int, cache: dict | None = None) -> np.ndarray:
    r"""Proven bounds ``(P, k, k)`` (radians) of the angle between the normal ``tessellate(model, k)`` shades with
    and the exact normal at the same ``(u, v)``, per Bezier patch and sub-square (as :func:`chord_bounds`); the
    float32 rounding of the normals not included; ``inf`` where none of the bounds below holds.

    The mesh shades with a normalized convex combination of the exact unit normals at the triangle's vertices
    (the rasterizer's interpolation; barycentric in the triangle, which is the interpolation in ``(u, v)``).
    Three proven bounds, the smallest taken per sub-square; ``n = G / |G|`` with ``G = w^3 S_u x S_v`` the
    pseudo-Gauss map, a positive combination of its Bernstein coefficients on each (sub-)patch [Kumar1997,
    sec. 3] (:func:`splinevis.nurbs.lod.gauss.pseudo_gauss_net`):

    * **cone** (computed in decreasing order of the other two bounds until the rest cannot raise the maximum,
      for at most :data:`CONE_BUDGET` sub-squares): a convex cone of half-angle ``theta < 90`` degrees holding
      the coefficients of the sub-patch's ``G`` (:func:`splinevis.nurbs.lod.gauss.normal_cone`) holds every
      normal of the sub-patch; where ``G = 0`` (a pole) the normal is a limit of those, in the closed cone. The
      vertex normals are in it, so is their positive combination (the cone is convex without 0), and so is the
      exact normal at ``(u, v)``: two unit vectors of the cone are at most ``2 theta`` apart. This holds at poles,
      where ``G`` vanishes along a side but its other coefficients (zero ones are ignored) still span a cone.
    * **first order**: ``|dn| <= |dG| / |G|``; on a cell whose net of ``G`` has a cone with axis ``a``,
      ``|G| >= g := min_kl G_kl . a`` and ``|G_u| <= (deg) max |Delta_u G_kl|`` (inf when ``g <= 0``: a pole, a
      fold). The angle between ``n(p)`` and a vertex normal is at most the length of the path of ``n`` along the
      segment (in the triangle), ``rho = (N_u + N_v) / k`` (``N`` the maxima of ``|n_u|, |n_v|`` over the cells
      the sub-square meets); the cap of radius ``rho < 90`` degrees around ``n(p)`` is convex: ``rho``.
    * **second order**: the interpolated vector ``sum l_i n(p_i)`` differs from ``n(p)`` by at most
      ``e = (1/8k^2)(N_uu + 2 N_uv + N_vv)`` (eq. (4) of :mod:`splinevis.nurbs.lod.bounds` applied to the vector
      function ``n``, whose interpolant is that sum), with, from ``G = |G| n`` differentiated twice,
      ``|n_uu| <= (2 |G_uu| + 3 |G_u| |n_u|) / g``, ``|n_uv| <= (2 |G_uv| + 3 |G_u| |n_v|) / g`` (likewise
      ``n_vv``); a vector within ``e < 1`` of a unit vector is within ``arcsin e`` of it in angle.

    Seams: the tessellation shares the vertices of a surface's patches, and a vertex on a knot line carries
    the normal of one side only (the model's evaluation there); where the surface is not G1 across the knot
    line (a C0 crease) the other side's triangles shade with it. Per pair of adjacent patches the one-sided
    normals along the common side are the side rows ``a(t), b(t)`` of their ``G`` nets: ``a x b = 0`` and
    ``a . b >= 0`` (their Bernstein coefficients, to ``1e-12`` relative: rounding) means the same normals;
    else ``sin phi <= max |(a x b)_l| / (min a_l . alpha  min b_l . beta)`` (``alpha, beta`` their cone axes;
    inf when a minimum is not positive). A vertex's normal is then within ``2 Phi`` (``Phi`` the surface's
    largest ``phi``; two seams meet at a corner vertex) of the sub-patch's own, which the bounds add (cone:
    ``2 theta + 2 Phi`` while ``theta + 2 Phi < 90`` degrees; first order ``rho + 2 Phi``; second order ``e``
    plus the chord ``2 Phi``). A C0 crease thus makes the surface's normal bound infinite, as it is (the mesh
    smears the crease's shading over a row of triangles).

    The cones use the sub-patches widened by the parameters' rounding (:func:`chord_bounds`); the float64
    rounding of the nets (relative, ~1e-15) is far below the float32 term that :func:`mesh_normal_error_deg`
    adds (8 u = 4.8e-7 radians).

    >>> from splinevis.nurbs.exact import sphere
    >>> b = normal_bounds(sphere(), 8)  # the poles included (cones of the sub-patches)
    >>> b.shape, round(float(np.degrees(b.max())), 2)
    ((8, 8, 8), 13.25)
    """
    k = _check_level(k)
    cache = {} if cache is None else cache
    key = ("nurbs_normal", k)
    if key not in cache:
        cells = _cells(model, cache)
        r = cells["r"]
        Nk = _to_level(cells["N"], r, k)
        seam = cells["seam"][:, None, None]  # twice the largest seam angle of the patch's surface
        rho = (Nk[..., 0] + Nk[..., 1]) / k
        bound = np.where(rho + seam < 0.5 * math.pi, rho + seam, np.inf)
        e = (Nk[..., 2] + 2.0 * Nk[..., 3] + Nk[..., 4]) / (8.0 * k * k) + seam  # |interpolated - n(p)|
        with np.errstate(invalid="ignore"):
            bound = np.minimum(bound, np.where(e < 1.0, np.arcsin(np.minimum(e, 1.0)), np.inf))
        bs, widen = _bezier(model, cache)
        # cones in decreasing order of the other bounds, until the rest cannot raise the maximum
        flat, order = bound.ravel().copy(), np.argsort(-bound, axis=None, kind="stable")
        pos, block = 0, 1024
        while pos < min(order.size, CONE_BUDGET) and (pos == 0 or flat[order[pos]] > flat[order[:pos]].max()):
            sel = order[pos:pos + min(block, CONE_BUDGET - pos)]
            mask = np.zeros(bound.shape, dtype=bool)
            mask.ravel()[sel] = True
            half = _cone_halves(bs, widen, k, mask).ravel()[sel]
            sm = seam.ravel()[np.unravel_index(sel, bound.shape)[0]]
            flat[sel] = np.minimum(flat[sel], np.where(half + sm < 0.5 * math.pi, 2.0 * half + sm, np.inf))
            pos, block = pos + sel.size, 2 * block
        bound = flat.reshape(bound.shape)
        cache[key] = bound
    return cache[key]


def _cone_halves(bs, widen, k, select) -> np.ndarray:
    """``(P, k, k)``: the half-angle of the normal cone of each (widened) level-``k`` sub-patch where ``select``
    (pi elsewhere and where there is none)."""
    from .lod.bounds import subdivide
    from .lod.gauss import normal_cone, pseudo_gauss_net

    out = np.full(select.shape, math.pi)
    for g in bs.groups:
        p, i, j = np.nonzero(select[g.ids])
        if not p.size:
            continue
        C = g.control
        centre = 0.5 * (bs.bbox[g.ids, 0::2] + bs.bbox[g.ids, 1::2])  # G is translation invariant: no cancellation
        C = np.concatenate([C[..., :3] - centre[:, None, None, :] * C[..., 3:], C[..., 3:]], axis=-1)
        box = _grid_boxes(k, widen[g.ids])[p, i, j]
        half = np.empty(p.size)
        for a in range(0, p.size, _CHUNK):
            rows = slice(a, a + _CHUNK)
            G = pseudo_gauss_net(subdivide(C[p[rows]], box[rows]))
            half[rows] = normal_cone(G.reshape(G.shape[0], -1, 3))[1]
        out[g.ids[p], i, j] = half
    return out


def mesh_error_px(model, view, k, cache):
    """(pixels, True): the proven screen-space error of ``tessellate(model, k)`` for ``view``: the chord bounds
    (:func:`chord_bounds`) of the sub-squares meeting each cell, plus the float32 rounding of the vertices, over
    the cell's box widened by that error (:meth:`splinevis.gl.screen_error.View.box_pixels`), plus the
    sub-pixel snapping.

    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.nurbs.exact import torus
    >>> v = View((4.0, -5.0, 3.0), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(1, 20))
    >>> cache = {}
    >>> [round(mesh_error_px(torus(), v, k, cache)[0], 3) for k in (2, 8, 32)]  # falls as 1 / k^2
    [355.853, 5.086, 0.296]
    """
    cells = _cells(model, cache)
    r = cells["r"]
    chord = chord_bounds(model, k, cache)
    lo, hi = cells["lo"].reshape(-1, 3), cells["hi"].reshape(-1, 3)
    err = _to_level(chord[..., None], k, r)[..., 0].reshape(-1) + float32_margin(lo, hi)
    return float(view.box_pixels(lo - err[:, None], hi + err[:, None], err).max()) + SNAP_PX, True


def mesh_normal_error_deg(model, view, k, cache):
    """(degrees, True): the largest angle between the normal ``tessellate(model, k)`` shades with and the exact
    normal (:func:`normal_bounds`, over the whole model), plus ``8 u`` radians for the float32 normals and
    their interpolation (as the terrain's); inf where no bound holds.

    >>> from splinevis.nurbs.exact import torus
    >>> cache = {}
    >>> [round(mesh_normal_error_deg(torus(), None, k, cache)[0], 2) for k in (2, 8, 32)]  # cones, then 1 / k^2
    [63.72, 8.9, 0.55]
    """
    radians = float(normal_bounds(model, k, cache).max()) + 8.0 * U32
    return (float(np.degrees(radians)) if radians < math.pi else math.inf), True


def mesh_triangles(model, k, cache) -> int:
    """Triangles of ``tessellate(model, k)``: two per sub-square, ``k x k`` per knot span (Bezier patch).

    >>> from splinevis.nurbs.exact import torus
    >>> mesh_triangles(torus(), 4, {})  # 16 spans
    512
    """
    bs, _ = _bezier(model, cache)
    return 2 * _check_level(k) ** 2 * len(bs)


def nurbs_mesh_refuses(model, style) -> str | None:
    """Why the mesh cannot draw ``model`` in ``style``: :func:`splinevis.gl.renderers.mesh_refuses`, or trim
    loops (the tessellation does not cut them), or None.

    >>> from splinevis.effects import Style
    >>> from splinevis.nurbs.hard_cases import trimmed_plate
    >>> nurbs_mesh_refuses(trimmed_plate(), Style())
    'the tessellation ignores trim loops (1 trimmed surface)'
    """
    reason = mesh_refuses(model, style)
    if reason:
        return reason
    trims = sum(t is not None for t in _model(model).trims)
    if trims:
        return f"the tessellation ignores trim loops ({trims} trimmed surface{'s' if trims > 1 else ''})"
    return None


def mesh_measure(model, view, k, cache, samples: int = 20_000, seed: int = 0):
    """(pixels, degrees) measured on the tessellation at ``k`` samples per span against the float64 surface:
    at ``samples`` random points of random triangles, the drawn point against the surface point at the same
    interpolated ``(u, v)`` (their projections' distance in ``view``) and the normalized interpolated vertex
    normal against the surface's normal there.

    >>> from splinevis.gl.screen_error import View
    >>> from splinevis.nurbs.exact import torus
    >>> v = View((0, -5, 3), (0, 0, 0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 20))
    >>> px, deg = mesh_measure(torus(), v, 4, {})
    >>> bool(0 < px <= mesh_error_px(torus(), v, 4, {})[0]), bool(0 < deg <= mesh_normal_error_deg(torus(), v, 4, {})[0])
    (True, True)
    """
    from .tessellate import tessellate

    model = _model(model)
    mesh = tessellate(model, k)
    tri = mesh.faces.reshape(-1, 4)[:, 1:]
    rng = np.random.default_rng(seed)
    t = tri[rng.integers(0, len(tri), samples)]
    lam = rng.dirichlet(np.ones(3), samples)
    P, UV, N, ID = (np.asarray(mesh.point_data[a], dtype=np.float64) if a != "points" else
                    np.asarray(mesh.points, dtype=np.float64) for a in ("points", "uv", "Normals", "patch_id"))
    drawn = np.einsum("nk,nkc->nc", lam, P[t])
    uv = np.einsum("nk,nkc->nc", lam, UV[t])
    shade = np.einsum("nk,nkc->nc", lam, N[t])
    shade /= np.linalg.norm(shade, axis=1, keepdims=True)
    exact, normal = np.empty((samples, 3)), np.empty((samples, 3))
    surface = ID[t[:, 0]].astype(int)
    for i, s in enumerate(model.surfaces):
        sel = surface == i
        exact[sel] = s.evaluate(uv[sel, 0], uv[sel, 1])
        normal[sel] = s.normal(uv[sel, 0], uv[sel, 1])
    px = view.pixel_distance(drawn, exact)
    ok = np.isfinite(normal).all(axis=1) & (np.linalg.norm(normal, axis=1) > 0.5)  # no normal at a pole
    deg = np.degrees(np.arctan2(np.linalg.norm(np.cross(shade[ok], normal[ok]), axis=1),
                                np.einsum("nc,nc->n", shade[ok], normal[ok])))
    return (float(np.nanmax(px)) if np.isfinite(px).any() else 0.0), (float(deg.max()) if ok.any() else 0.0)


def _mesh_build(plotter, model, style, k, cache, spline_options, add_options):
    from .tessellate import tessellate

    model = _model(model)
    actor = add_mesh_actor(plotter, tessellate(model, k), style, spline_options)
    if model.companion_meshes() and hasattr(plotter, "_add_companions"):  # a file's plain geometry, as add_spline
        plotter._add_companions(model, style, spline_options.get("name"))
    return actor


def _on_model(cost):
    """A cost function of a NurbsModel applied to what the program takes (a surface, a list)."""
    return lambda model, view, level, cache: cost(_model(model), view, level, cache)


#: The per-fragment program's frame time per pixel of the model's screen rectangle, ns (Newell's teapot at
#: 800 x 600, pyvista's default view: 786.7 ms for 271,200 pixels, benchmarks/bench_choice.py).
PER_FRAGMENT_NS_PER_PIXEL = 2900.0


#: The NURBS renderers (module docstring), declared on :data:`splinevis.nurbs.program.PROGRAM`.
RENDERERS = (
    Renderer("mesh", 0, MESH_LEVELS, mesh_error_px, _mesh_build, mesh_triangles, nurbs_mesh_refuses,
             normal_error_deg=mesh_normal_error_deg, measure=mesh_measure, cost=_on_model(mesh_cost(mesh_triangles))),
    Renderer("per_fragment", 10, exact=True, cost=_on_model(raycast_cost(PER_FRAGMENT_NS_PER_PIXEL))),
)
