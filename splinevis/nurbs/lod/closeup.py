"""Close-ups of a walkthrough drawn exactly: the super-surfaces that fill the screen switch from their level-of-
detail mesh to the per-fragment NURBS program (beyond [Kumar1997]: exact pictures up close, LOD meshes far away).

**The rule** (:func:`closeup_candidates`). Of the super-surfaces the drawn mesh holds, a super-surface is a
candidate when the screen rectangle of its projected box covers at least ``coverage`` of the viewport
(:func:`screen_coverage`; 1 when the box reaches behind the eye) or when even its finest level projects to more
than ``pixel_error`` pixels (``tol_0 k / d > pixel_error``, :func:`.select.projection_scale`: the
super-surfaces :func:`.select.select_levels` counts as ``needs_finer``). Candidates are taken by decreasing
coverage (then nearest the axis of view) up to ``max_supers`` super-surfaces and ``max_patches`` Bezier
patches; a shown super-surface stays while it covers ``keep * coverage`` and ranks as if it covered ``1 / keep``
times more (hysteresis: no flicker at the threshold, fewer switches). Boxes whose bounding sphere cannot
cover enough are pruned before the eight corners are projected (:func:`_coverage_bound`). The caps are cost
caps: the program runs Newton per fragment on every pixel its shell covers (both layers of the shell, and no
early depth test since it writes the depth): the NURBS study measured about 0.3 s a frame for a 640x480 view of one
model on Mesa llvmpipe; here four teapot super-surfaces covering half of a 640x480 view took about 1 s a frame
on the shared two cores (the mesh alone: 22 ms), 0.3 s at 320x240. A close-up is for a few patches only;
``coverage`` and the caps trade exact pictures against frame rate.

**The switch** (:class:`CloseUp`). The shown patches, ``lod.bezier.surface(i)`` on ``[0, 1]^2``, make one
:class:`~splinevis.nurbs.model.NurbsModel` drawn by the per-fragment ``nurbs`` program
(:func:`splinevis.nurbs.program.nurbs_program`, [Kanai2007]) in one actor. Its GLSL depends on the defines
only (the style's effects; ``SV_NURBS_POLE_TABLES`` for asymmetric poles; ``SV_NURBS_TRIM`` when the
patches have trims), not on the patches, so a new set re-uses the actor: new shell geometry, tables (textures)
and model offset, the compiled program kept (one actor per define set, built once). The surfaces' trim loops
go with their patches (:func:`.bezier.patch_trims`, in each patch's local domain), as the LOD meshes are cut
to them (:mod:`.trims`); patches trimmed away are left out.

**No gaps at the seams.** The exact surface ends at the patch's true boundary curve, a neighbour's mesh at the
chord of it: up to ``tol`` apart, which is more than a pixel exactly when a super-surface needs finer. The
switched super-surface's own mesh therefore stays drawn as a backstop (the walkthrough's mesh, crack-free with
its neighbours by :func:`.levels.assemble`), and every vertex of it (and of its shared edges' chains) is pushed
away from the eye *along its ray*, by ``p = depth_margin * tol`` (``tol`` the bound of its drawn level), in the
mesh actor's vertex shader. A point moved along its own ray projects to the same pixel, and a triangle whose
vertices move that way covers the same pixels (its points are positive combinations of the same three rays,
and each moves away by a factor between the vertices' factors ``1 + p / t_v >= 1``), so the pushed mesh still
covers every pixel the crack-free mesh did: no background shows. A point at distance ``t`` of a pushed
triangle moves back by at least ``p t / max t_v`` (about ``p`` for a triangle small beside its distance);
along a ray meeting the surface at angle ``theta`` to its normal the mesh lies within about
``tol / cos(theta)`` of the surface, so the exact fragment wins the depth test wherever ``cos(theta) >= 1 /
depth_margin`` (75.5 degrees at the default 4); nearer the silhouette the mesh may show, as it does without a
close-up. Only the switched super-surfaces' vertices move (and with them the sides of neighbour triangles on
the seam), so the exact surface and every other mesh keep their true depth order; in a seam's gap pixels a
surface within ``p`` behind the backstop could show instead (the order of the mesh's own error). Pushing the
whole mesh instead (a scaling about the eye: the same picture, one user matrix) would need a relative push of
``depth_margin * tol / d`` for the nearest distance ``d``: tens of percent up close, where it would hide nearer
meshes (a spout in front of the body) behind the exact surface.

The push is a vertex attribute of the mesh actor's points (``sv_closeup_push``; uploaded when the set or its
levels change) and the eye a uniform set at every render from the camera drawn with (an interactor may render
between updates); the mesh mapper's VBO shift-scale is turned off so that its vertex coordinates are world ones.
Vertices numbered after ``lod.vertices`` (a finer mesh made for the view, :mod:`.dynamic`) are pushed when they
lie in a switched super-surface's box.
"""

from __future__ import annotations

import time

import numpy as np
from vtkmodules.vtkCommonCore import VTK_OBJECT

from .select import _box_distance, projection_scale

__all__ = ["screen_coverage", "closeup_candidates", "push_distances", "CloseUp"]

_ATTR = "sv_closeup_push"
_VS_DEC = f"in float {_ATTR};\nuniform vec3 sv_closeup_eye;\n//VTK::PositionVC::Dec"
_VS_IMPL = ("//VTK::CustomBegin::Impl\n"
            f"  vec3 svCloseupRay = vertexMC.xyz - sv_closeup_eye;\n"
            f"  vec4 svCloseupVertex = vec4(vertexMC.xyz + {_ATTR} * svCloseupRay / max(length(svCloseupRay), 1e-30),"
            " 1.0);\n")


def screen_coverage(boxes, view_proj) -> np.ndarray:
    """Fraction of the viewport covered by the screen rectangle of each box's projection ``(S,)`` in [0, 1]
    (an upper bound of the box's own coverage); 1 for a box with a corner on or behind the eye plane.

    Examples
    --------
    A 90 degree view down -z: a box filling the view, a small one and one beside the eye.

    >>> M = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1.0002, -0.20002], [0, 0, -1, 0]])
    >>> boxes = np.array([[-2, 2, -2, 2, -2, -1.0], [0, 0.1, 0, 0.1, -11, -10], [3, 4, -1, 1, -1, 1]])
    >>> screen_coverage(boxes, M).round(6).tolist()
    [1.0, 2.5e-05, 1.0]
    """
    B = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
    M = np.asarray(view_proj, dtype=np.float64).reshape(4, 4)[[0, 1, 3]]  # x, y, w
    # the corners' (x, y, w): the low corner's plus any of the three edge vectors (linear in the corner)
    base = B[:, 0::2] @ M[:, :3].T + M[:, 3]  # (S, 3)
    edges = (B[:, 1::2] - B[:, 0::2])[:, :, None] * M[:, :3].T[None]  # (S, axis, 3)
    pick = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.float64)  # (8, axis)
    clip = base[:, None, :] + np.einsum("ca,sak->sck", pick, edges)  # (S, 8, 3)
    w = clip[..., 2]
    behind = (w <= 0.0).any(axis=1)
    ndc = clip[..., :2] / np.where(w > 0.0, w, 1.0)[..., None]
    lo = np.clip(ndc.min(axis=1), -1.0, 1.0)
    hi = np.clip(ndc.max(axis=1), -1.0, 1.0)
    cover = np.prod(np.maximum(hi - lo, 0.0), axis=1) / 4.0
    return np.where(behind, 1.0, cover)


def _coverage_bound(boxes, eye, view_proj) -> np.ndarray:
    """An upper bound of :func:`screen_coverage` from each box's bounding sphere, in a few operations per box
    (the exact rectangle takes eight projected corners): a sphere of angular radius ``a`` whose centre is
    ``t`` off the axis of view spans at most ``tan(t + a) - tan(t - a)`` of the image plane (at unit depth) in
    any direction; 1 where the sphere holds the eye or reaches 90 degrees off the axis; parallel projections:
    1 (no pruning)."""
    M = np.asarray(view_proj, dtype=np.float64).reshape(4, 4)
    s = float(np.linalg.norm(M[3, :3]))
    out = np.ones(boxes.shape[0])
    if s <= 1e-12 * float(np.linalg.norm(M[1, :3])):
        return out
    v = 0.5 * (boxes[:, 0::2] + boxes[:, 1::2]) - eye
    d = np.sqrt(np.einsum("ij,ij->i", v, v))
    r = 0.5 * np.linalg.norm(boxes[:, 1::2] - boxes[:, 0::2], axis=1)
    far = d > r * (1.0 + 1e-9)
    theta = np.arccos(np.clip(v[far] @ (M[3, :3] / s) / d[far], -1.0, 1.0))
    alpha = np.arcsin(r[far] / d[far])
    ok = theta + alpha < np.radians(89.0)
    span = np.tan(np.minimum(theta + alpha, np.radians(89.0))) - np.tan(theta - alpha)
    cover = np.linalg.norm(M[0, :3]) * np.linalg.norm(M[1, :3]) / s ** 2 * span ** 2 / 4.0
    out[np.flatnonzero(far)[ok]] = np.minimum(cover[ok], 1.0)
    return out


def closeup_candidates(lod, eye, view_proj, viewport_height, levels, *, pixel_error=1.0, coverage: float = 0.25,
                       max_supers: int = 4, max_patches: int = 64, current=(), keep: float = 0.5):
    """The super-surfaces to draw exactly for one view (module docstring): ``(ids (n,) sorted, info)``.

    Parameters
    ----------
    lod : LodModel
        Uses ``boxes``, ``tolerance`` and ``supers.members``.
    eye, view_proj, viewport_height
        The camera (as :func:`.select.select_levels`).
    levels : (S,) int
        The levels of the drawn mesh (-1: not drawn); only drawn super-surfaces are candidates (their mesh
        is the backstop at the seams).
    pixel_error : float or None
        A drawn super-surface whose finest level projects to more than this many pixels is a candidate
        (None: coverage only).
    coverage : float in (0, 1]
        Fraction of the viewport the screen rectangle of the projected box must cover.
    max_supers, max_patches : int
        Caps (the per-fragment cost grows with the covered pixels; the switch cost with the patches).
    current : sequence of int
        The super-surfaces shown now: they stay while covering ``keep * coverage`` or needing finer, and rank
        as if covering ``1 / keep`` times more.

    Returns
    -------
    ids : (n,) int64
    info : dict
        ``candidates`` (before the caps), ``needs_finer`` (drawn super-surfaces whose level 0 is too coarse)
        and ``coverage`` (the largest of the chosen, 0 if none).

    Examples
    --------
    A sphere's eight super-surfaces seen from far away and from just outside:

    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(sphere(), 0.01, levels=2, progress=False)
    >>> M = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1.0002, -0.20002], [0, 0, -1, 0]])  # eye at 0, down -z
    >>> def moved(z): T = np.eye(4); T[2, 3] = -z; return M @ T  # eye at (0, 0, z)
    >>> drawn = np.zeros(8, dtype=int)
    >>> closeup_candidates(lod, [0, 0, 100], moved(100), 400, drawn)[0].tolist()
    []
    >>> ids, info = closeup_candidates(lod, [0, 0, 1.2], moved(1.2), 400, drawn)
    >>> ids.tolist(), info["needs_finer"]  # the four upper octants face the eye
    ([1, 3, 5, 7], 8)
    """
    if not 0.0 < float(coverage) <= 1.0:
        raise ValueError(f"coverage must be a fraction of the viewport in (0, 1], got {coverage!r}.")
    if int(max_supers) < 0 or int(max_patches) < 0:
        raise ValueError(f"max_supers and max_patches must be >= 0, got {max_supers!r}, {max_patches!r}.")
    boxes = np.asarray(lod.boxes, dtype=np.float64)
    S = boxes.shape[0]
    levels = np.asarray(levels, dtype=np.int64).reshape(-1)
    if levels.shape != (S,):
        raise ValueError(f"levels must hold one level per super-surface ({S}), got shape {levels.shape}.")
    e = np.asarray(eye, dtype=np.float64).reshape(3)
    if not 0.0 < float(keep) <= 1.0:
        raise ValueError(f"keep must be a fraction in (0, 1], got {keep!r}.")
    drawn = np.flatnonzero(levels >= 0)
    finer = np.zeros(drawn.size, dtype=bool)
    if pixel_error is not None and drawn.size:
        perspective, k = projection_scale(view_proj, viewport_height)
        tol0 = float(np.asarray(lod.tolerance)[0])
        if perspective:
            with np.errstate(divide="ignore"):
                finer = tol0 * k / _box_distance(boxes[drawn], e) > float(pixel_error)
        else:
            finer[:] = tol0 * k > float(pixel_error)
    shown = np.isin(drawn, np.asarray(current, dtype=np.int64))
    cov = _coverage_bound(boxes[drawn], e, view_proj)
    exact = finer | shown | (cov >= keep * coverage)  # the rest cannot qualify: their bound is below
    cov[exact] = screen_coverage(boxes[drawn[exact]], view_proj)
    ok = (cov >= coverage) | finer | (shown & (cov >= keep * coverage))
    # largest coverage first, a shown one's counted 1 / keep times (a newcomer displaces it only by covering
    # that much more: fewer switches); among equals (1: boxes around the eye) the shown ones, then the box
    # centres nearest the axis of view (row 3 of a perspective matrix is the view direction, row 2 of a
    # parallel one)
    M = np.asarray(view_proj, dtype=np.float64).reshape(4, 4)
    ahead = M[3, :3] if np.linalg.norm(M[3, :3]) > 1e-12 * np.linalg.norm(M[1, :3]) else M[2, :3]
    to_centre = 0.5 * (boxes[drawn][ok, 0::2] + boxes[drawn][ok, 1::2]) - e
    axial = to_centre @ ahead / np.maximum(np.linalg.norm(to_centre, axis=1) * np.linalg.norm(ahead), 1e-300)
    score = np.where(shown[ok], cov[ok] / keep, cov[ok])
    order = np.lexsort((-axial, ~shown[ok], -score))
    chosen, patches = [], 0
    for s in drawn[ok][order]:
        if len(chosen) >= int(max_supers):
            break
        n = len(lod.supers.members[s])
        if patches + n <= int(max_patches):
            chosen.append(int(s))
            patches += n
    ids = np.array(sorted(chosen), dtype=np.int64)
    top = float(cov[np.isin(drawn, ids)].max()) if ids.size else 0.0
    return ids, {"candidates": int(ok.sum()), "needs_finer": int(finer.sum()), "coverage": top}


def push_distances(lod, levels, ids, depth_margin: float = 4.0) -> np.ndarray:
    """Per vertex of ``lod.vertices``, how far the backstop mesh moves away from the eye (module docstring):
    ``depth_margin * tolerance[levels[s]]`` on every vertex of the switched super-surfaces ``ids`` at their
    drawn level (their triangles and the chains of their shared edges, which fans may use), 0 elsewhere.

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
    >>> d = push_distances(lod, np.zeros(8, dtype=int), [3])
    >>> d.shape == (len(lod.vertices),), np.unique(d).astype(float).round(6).tolist()
    (True, [0.0, 0.2])
    """
    if not float(depth_margin) >= 1.0:
        raise ValueError(f"depth_margin must be >= 1 (a multiple of the mesh's bound), got {depth_margin!r}.")
    out = np.zeros(len(lod.vertices), dtype=np.float32)
    levels = np.asarray(levels, dtype=np.int64)
    tol = np.asarray(lod.tolerance, dtype=np.float64)
    for s in np.asarray(ids, dtype=np.int64).reshape(-1):
        level = int(levels[s])
        if level < 0:
            raise ValueError(f"super-surface {s} is not drawn (level -1): its mesh cannot back the exact surface.")
        tri = lod.meshes[s][level][0]
        ids_s = [tri.ravel()] + [np.asarray(lod.edge_ids[e]) for e in lod.super_edges[s]]
        v = np.concatenate(ids_s)
        out[v] = np.maximum(out[v], float(depth_margin) * tol[level])
    return out


def _push_in_boxes(points, lod, levels, ids, depth_margin) -> np.ndarray:
    """The push of vertices not among ``lod.vertices`` (a finer mesh made on the fly for a view): the push of a
    switched super-surface (:func:`push_distances`) for every point in its box, the largest where boxes
    overlap (a vertex of another surface inside the box moves back by at most the same push)."""
    out = np.zeros(len(points), dtype=np.float32)
    tol = np.asarray(lod.tolerance, dtype=np.float64)
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    for s in np.asarray(ids, dtype=np.int64).reshape(-1):
        b = np.asarray(lod.boxes[s], dtype=np.float64)
        inside = ((P >= b[0::2]) & (P <= b[1::2])).all(axis=1)
        out[inside] = np.maximum(out[inside], float(depth_margin) * tol[max(int(levels[s]), 0)])
    return out


def _poly_mapper(actor):
    """The vtkOpenGLPolyDataMapper drawing ``actor`` (a vtkDataSetMapper's inner one exists after a render)."""
    mapper = actor.GetMapper()
    if mapper is not None and mapper.IsA("vtkDataSetMapper"):
        mapper = mapper.GetPolyDataMapper()
    return mapper if mapper is not None and mapper.IsA("vtkOpenGLPolyDataMapper") else None


class CloseUp:
    """Switches a walkthrough's close super-surfaces to the exact per-fragment program (module docstring).

    Protocol for :class:`.pipeline.Walkthrough`: :meth:`attach` once (with the mesh actor, whose switched
    super-surfaces become the pushed backstop), :meth:`update` on the renderer's thread every frame after the
    frame's mesh is shown and before rendering, :meth:`detach` at the end. :meth:`show` sets a given set (tests,
    pictures).

    Parameters
    ----------
    style : splinevis.Style, optional
        Shading of the exact patches (keywords build or amend it: ``reflection_lines=12``, ``color=...``).
    pixel_error, coverage, max_supers, max_patches, keep
        The rule (:func:`closeup_candidates`).
    depth_margin : float >= 1
        The backstop's push in units of its level's bound (module docstring).
    subdivisions, newton_iterations
        Options of the ``nurbs`` program (:func:`splinevis.nurbs.program.nurbs_program`).

    Examples
    --------
    >>> import pyvista as pv
    >>> from splinevis.nurbs.exact import sphere
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
    >>> pl = pv.Plotter(off_screen=True, window_size=(64, 48))
    >>> cu = CloseUp(color="red")
    >>> cu.attach(pl, lod)
    >>> stats = cu.show([2, 3], np.zeros(8, dtype=int))
    >>> cu.shown.tolist(), stats["closeup_patches"], cu.actor.model.names
    ([2, 3], 2, ('sphere[2]', 'sphere[3]'))
    >>> cu.show([], np.zeros(8, dtype=int))["closeup"], bool(cu.actor.actor.GetVisibility())
    (0, False)
    >>> cu.detach(); pl.close()
    """

    def __init__(self, style=None, *, pixel_error=1.0, coverage: float = 0.25, max_supers: int = 4,
                 max_patches: int = 64, keep: float = 0.5, depth_margin: float = 4.0, subdivisions: int = 8,
                 newton_iterations: int = 12, **style_options):
        from ...effects import Style

        if style is not None and not isinstance(style, Style):
            raise TypeError(f"style must be a splinevis.Style, got {type(style).__name__}.")
        style = Style() if style is None else style
        self.style = style.replace(**style_options) if style_options else style
        if not float(depth_margin) >= 1.0:
            raise ValueError(f"depth_margin must be >= 1 (a multiple of the mesh's bound), got {depth_margin!r}.")
        self.rule = dict(pixel_error=pixel_error, coverage=float(coverage), max_supers=int(max_supers),
                         max_patches=int(max_patches), keep=float(keep))
        self.depth_margin = float(depth_margin)
        self.options = dict(subdivisions=int(subdivisions), newton_iterations=int(newton_iterations))
        self.plotter = self.lod = self.mesh_actor = None
        self.actor = None  # the SplineActor drawing the shown patches (None before the first switch)
        self.shown = np.zeros(0, dtype=np.int64)
        self._actors = {}  # one SplineActor per define set: the GLSL never depends on the patches
        self._levels = None  # levels of the shown super-surfaces the push was made for
        self._hooked = None  # the poly mapper whose shader pushes the backstop
        self._push = self._observer = None
        self._specs = {}  # the last `cache` sets' (model, ProgramSpec), least recently shown first
        self.cache = 8

    # ------------------------------------------------------------------------------------------------ protocol
    def attach(self, plotter, lod, mesh_actor=None) -> None:
        """Draw into ``plotter`` for ``lod``; ``mesh_actor`` (a vtkActor showing ``assemble`` meshes of ``lod``,
        points ``lod.vertices``) is the backstop whose switched super-surfaces are pushed back.

        >>> cu = CloseUp(); cu.attach(None, None)
        Traceback (most recent call last):
        ValueError: CloseUp.attach needs a plotter and a LodModel.
        """
        if plotter is None or lod is None:
            raise ValueError("CloseUp.attach needs a plotter and a LodModel.")
        if self.plotter is not None:
            raise RuntimeError("CloseUp is attached already: detach() first.")
        self.plotter, self.lod, self.mesh_actor = plotter, lod, mesh_actor

    def update(self, camera_record, levels) -> dict:
        """One frame: choose the super-surfaces (:func:`closeup_candidates`), switch if the set changed, push
        the backstop and keep it inside the far plane. ``camera_record`` is ``(frame, eye (3,), view_proj (4, 4),
        viewport_height)``; ``levels`` are those of the mesh drawn this frame. Returns stats to log:
        ``closeup`` (super-surfaces), ``closeup_patches``, ``closeup_switch`` (the set changed),
        ``closeup_build_ms`` (the program's tables and shell), ``closeup_upload_ms`` (into the actor) and
        ``closeup_ms`` (all of this call; the GPU's share comes with the render).

        >>> cu = CloseUp()
        >>> cu.update((0, np.zeros(3), np.eye(4), 100), np.zeros(1, dtype=int))
        Traceback (most recent call last):
        RuntimeError: CloseUp.update before attach(plotter, lod).
        """
        if self.plotter is None:
            raise RuntimeError("CloseUp.update before attach(plotter, lod).")
        t0 = time.perf_counter()
        _frame, eye, view_proj, height = camera_record
        ids, info = closeup_candidates(self.lod, eye, view_proj, height, levels, current=self.shown, **self.rule)
        stats = self.show(ids, levels, eye=eye)
        stats.update(closeup_candidates=info["candidates"], closeup_coverage=info["coverage"],
                     closeup_ms=1e3 * (time.perf_counter() - t0))
        return stats

    def detach(self) -> None:
        """Remove the exact actors and the backstop's push.

        >>> cu = CloseUp(); cu.detach()  # nothing attached: nothing to do
        """
        if self.plotter is not None:
            for spline in self._actors.values():
                self.plotter.remove_actor(spline.actor, render=False)
                owned = getattr(self.plotter, "_spline_actors", None)
                if isinstance(owned, list) and spline in owned:
                    owned.remove(spline)
        if self._hooked is not None:
            sp = self.mesh_actor.GetShaderProperty()
            sp.ClearVertexShaderReplacement("//VTK::PositionVC::Dec", True)
            sp.ClearVertexShaderReplacement("//VTK::CustomBegin::Impl", True)
            sp.ClearVertexShaderReplacement("MCVCMatrix * vertexMC", False)
            sp.ClearVertexShaderReplacement("MCDCMatrix * vertexMC", False)
            self._hooked.RemoveVertexAttributeMapping(_ATTR)
            self._hooked.RemoveObserver(self._observer)
            data = self._hooked.GetInput()
            if data is not None:
                data.GetPointData().RemoveArray(_ATTR)
        self.plotter = self.lod = self.mesh_actor = self.actor = self._hooked = self._push = self._levels = None
        self._actors, self._specs = {}, {}
        self.shown = np.zeros(0, dtype=np.int64)

    # ------------------------------------------------------------------------------------------------ the switch
    def show(self, ids, levels, eye=None) -> dict:
        """Draw the super-surfaces ``ids`` exactly (re-using the actor and its compiled program) and push their
        mesh in the backstop by ``depth_margin`` times the bound of their level in ``levels``, away from the eye
        of the camera each render is drawn with (set at every render); ``eye`` (default: the plotter's camera)
        keeps the pushed mesh inside the far plane. Returns the stats of :meth:`update`.

        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import torus
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(torus(), 0.05, levels=2, progress=False)
        >>> pl = pv.Plotter(off_screen=True, window_size=(64, 48))
        >>> cu = CloseUp(); cu.attach(pl, lod)
        >>> first = cu.show([0, 1], np.zeros(16, dtype=int))
        >>> spline = cu.actor
        >>> again = cu.show([7], np.zeros(16, dtype=int))  # new patches, the same actor (and GLSL)
        >>> first["closeup_switch"], again["closeup_patches"], cu.actor is spline
        (True, 1, True)
        >>> cu.detach(); pl.close()
        """
        from ...gl.inject import SplineActor
        from ..model import NurbsModel
        from ..program import nurbs_program
        from .bezier import patch_trims

        if self.plotter is None:
            raise RuntimeError("CloseUp.show before attach(plotter, lod).")
        S = len(self.lod.supers.members)
        ids = np.unique(np.asarray(ids, dtype=np.int64).reshape(-1))
        levels = np.asarray(levels, dtype=np.int64).reshape(-1)
        if ids.size and (ids[0] < 0 or ids[-1] >= S):
            raise ValueError(f"super-surface ids must be in 0..{S - 1}, got {ids.tolist()}.")
        if levels.shape != (S,):
            raise ValueError(f"levels must hold one level per super-surface ({S}), got shape {levels.shape}.")
        switch = not np.array_equal(ids, self.shown)
        build_ms = upload_ms = 0.0
        status = getattr(self.lod, "status", None)  # patches trimmed away are not drawn
        patches = [int(i) for s in ids for i in self.lod.supers.members[s] if status is None or status[i] >= 0]
        if switch and ids.size:
            t0 = time.perf_counter()
            key = tuple(patches)
            if key in self._specs:  # a set shown before (the camera going back and forth)
                model, spec = self._specs.pop(key)
            else:
                trims = getattr(self.lod, "trims", None)
                model = NurbsModel([self.lod.bezier.surface(i) for i in patches],
                                   trims=[patch_trims(self.lod.bezier, i, trims) for i in patches] if trims else None,
                                   source="close-up")
                spec = nurbs_program(model, **self.options)
            self._specs[key] = (model, spec)  # most recent last
            while len(self._specs) > self.cache:
                self._specs.pop(next(iter(self._specs)))
            t1 = time.perf_counter()
            defines = tuple(sorted(spec.defines.items()))
            spline = self._actors.get(defines)
            if spline is None:
                spline = SplineActor(spec, self.style, self.plotter.renderer, kind="surface")
                self.plotter.add_actor(spline.actor, reset_camera=False, render=False)
                owned = getattr(self.plotter, "_spline_actors", None)
                if isinstance(owned, list):  # a splinevis.Plotter maps shader errors back to the GLSL files
                    owned.append(spline)
                self._actors[defines] = spline
            else:  # same GLSL: new shell, tables and frame; the compiled program is kept
                spline.set_geometry(spec.points, spec.triangles, {**spec.attributes, **spec.varyings})
                for name, table in spec.textures.items():
                    spline.set_texture(name, table)
                spline.spec = spec
                spline.offset = spline.model_position = np.asarray(spec.offset, dtype=np.float64).reshape(3)
                spline.actor.SetPosition(*spline.offset.tolist())
            spline.model = model
            for other in self._actors.values():
                other.actor.SetVisibility(other is spline)
            self.actor = spline
            build_ms, upload_ms = 1e3 * (t1 - t0), 1e3 * (time.perf_counter() - t1)
        elif switch:
            for other in self._actors.values():
                other.actor.SetVisibility(False)
        self.shown = ids
        self._backstop(ids, levels, eye)
        return {"closeup": int(ids.size), "closeup_patches": len(patches), "closeup_switch": bool(switch),
                "closeup_build_ms": build_ms, "closeup_upload_ms": upload_ms}

    # ------------------------------------------------------------------------------------------------ the backstop
    def _on_update_shader(self, caller, event, program=None):
        if program is not None and self.plotter is not None:
            eye = self.plotter.renderer.GetActiveCamera().GetPosition()
            program.SetUniform3f("sv_closeup_eye", [float(x) for x in eye])

    _on_update_shader.CallDataType = VTK_OBJECT

    def _backstop(self, ids, levels, eye):
        """Push the switched super-surfaces' mesh back along the eye rays (module docstring)."""
        if self.mesh_actor is None:
            return
        mapper = _poly_mapper(self.mesh_actor)
        data = mapper.GetInput() if mapper is not None else None
        V = len(self.lod.vertices)
        n = data.GetNumberOfPoints() if data is not None else 0
        if n < V:
            return  # the mesh actor does not show this LodModel's vertices yet (before its first mesh)
        from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
        from vtkmodules.vtkCommonCore import vtkCommand

        key = (ids.tobytes(), levels[ids].tobytes(), n)
        if self._push is None or self._levels != key or data.GetPointData().GetArray(_ATTR) is None:
            push = push_distances(self.lod, levels, ids, self.depth_margin)
            if n > V:  # vertices made after the model's (dynamic tessellation): pushed inside the switched boxes
                push = np.concatenate([push, _push_in_boxes(vtk_to_numpy(data.GetPoints().GetData())[V:],
                                                            self.lod, levels, ids, self.depth_margin)])
            arr = numpy_to_vtk(push, deep=True)
            arr.SetName(_ATTR)
            data.GetPointData().RemoveArray(_ATTR)
            data.GetPointData().AddArray(arr)
            data.Modified()
            self._push, self._levels = push, key
        if self._hooked is not mapper:
            mapper.SetVBOShiftScaleMethod(0)  # vertexMC in world coordinates, like the eye
            mapper.MapDataArrayToVertexAttribute(_ATTR, _ATTR, 0, -1)
            sp = self.mesh_actor.GetShaderProperty()
            sp.AddVertexShaderReplacement("//VTK::PositionVC::Dec", True, _VS_DEC, False)
            sp.AddVertexShaderReplacement("//VTK::CustomBegin::Impl", True, _VS_IMPL, False)
            sp.AddVertexShaderReplacement("MCVCMatrix * vertexMC", False, "MCVCMatrix * svCloseupVertex", True)
            sp.AddVertexShaderReplacement("MCDCMatrix * vertexMC", False, "MCDCMatrix * svCloseupVertex", True)
            # the eye is set at every render from the camera drawn with (an interactor may render between updates)
            self._observer = mapper.AddObserver(vtkCommand.UpdateShaderEvent, self._on_update_shader)
            self._hooked = mapper
        cam = self.plotter.renderer.GetActiveCamera()
        e = np.asarray(cam.GetPosition() if eye is None else eye, dtype=np.float64).reshape(3)
        if ids.size:  # the pushed backstop stays inside the far plane
            b = np.asarray(self.lod.boxes)[ids]
            corners = np.stack(np.meshgrid(*(b[:, 2 * a: 2 * a + 2].ravel() for a in range(3)), indexing="ij"), -1)
            reach = float(np.linalg.norm(corners.reshape(-1, 3) - e, axis=1).max() + self._push.max())
            near, far = cam.GetClippingRange()
            if reach * 1.01 > far:
                cam.SetClippingRange(near, reach * 1.01)
