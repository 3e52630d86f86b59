"""View-dependent choice of a level of detail per super-surface: view-frustum culling, back-patch culling and
the screen-space error of each level [Kumar1997, sec. 4.4, 5.2].

**Culling.** The super-surfaces not outside the frustum are found by the BVH traversal of
:func:`.bvh.frustum_cull` with the planes of the view-projection matrix (:func:`.bvh.frustum_planes`,
[GribbHartmann2001]); of those, the ones whose normal cone faces away from the eye for every point of their
box are dropped by :func:`.bvh.back_facing` [Kumar1997, sec. 2.2; ShirmanAbiEzzi1993]. Both tests are
conservative: a super-surface that shows a pixel is never dropped.

**Screen-space error.** Level ``l`` of every super-surface lies within ``tol_l`` (its proven distance bound)
of the surface. Let ``M = P V`` (column vectors, ``clip = M (x, 1)``), ``V`` a rigid view transform and ``P``
an OpenGL projection with ``P_11 = 1 / tan(fov_y / 2)`` (perspective) or ``P_11 = 1 / h`` (parallel, ``h``
the half height of the view). A world displacement of length ``L`` at view depth ``w`` moves the point by at
most ``L P_11 / w`` in normalized device coordinates on the axis of view (NDC spans 2 over the viewport's
``H`` pixels), so its size in pixels is

``e_l = tol_l * P_11 / w * H / 2 = tol_l / (w * 2 tan(fov_y / 2)) * H``        (perspective),
``e_l = tol_l * P_11 * H / 2``                                              (parallel: no ``w``).

For ``w`` we take ``d``, the distance from the eye to the super-surface's box (0 when the eye is inside the
box: then ``e_l`` is infinite and the finest level is drawn). As ``w = d cos(theta)`` at the angle ``theta``
off the axis of view, ``d`` is the paper's isotropic measure [Kumar1997, sec. 4.4]; near the corners of the
view it underestimates the error by at most ``1 / cos(theta_max)`` (1.05 for a 30 degree ``fov_y`` at 4:3).
The coarsest level with ``e_l <= pixel_error`` is the largest ``l`` with ``tol_l <= pixel_error * d / k``,
``k = H / (2 tan(fov_y / 2))``: one ``searchsorted`` for all super-surfaces at once. When even level 0 is too
coarse the super-surface gets level 0 and is counted in ``stats["needs_finer"]``; ``stats["finer_steps"]`` tells
how many finer steps it needs: the smallest ``j`` with ``tol_0 / finer_ratio**j <= pixel_error * d / k``, capped at
``max_finer`` (``stats["finer_capped"]`` counts where the cap binds, the eye inside the box included), the
tolerance the dynamic tessellation of :mod:`.dynamic` makes [Kumar1997, sec. 2.2, 4.4].

**Normal request.** With ``max_normal_deg`` a super-surface is drawn at the coarsest level, no coarser than the
screen-space error allows, whose proven normal bound (``lod.normal_bounds`` (S, L) radians,
:func:`splinevis.nurbs.normal_bounds.lod_normal_bounds`, plus ``8 u`` for the float32 normals and their
interpolation) is within it; ``stats["normal_limited"]`` counts those drawn finer for it, and
``stats["normal_unmet"]`` those where even level 0 does not meet it (drawn at level 0).

**The projection from the matrix.** The rows of ``M`` are ``r_i = sum_j P_ij v_j`` with ``v_j`` the
orthonormal rows of ``V``'s rotation: ``|r_1[:3]| = P_11`` (symmetric frustum) and ``|r_3[:3]| = 1`` for a
perspective (``w`` is the depth) or 0 for a parallel projection. Hence ``tan(fov_y / 2) = |r_3[:3]| /
|r_1[:3]|`` and the parallel scale is ``|r_1[:3]| / r_3[3]`` (a uniformly scaled ``M`` gives the same).
"""

from __future__ import annotations

import math

import numpy as np

from ..._boxes import box_distance2
from ...gl.error_bounds import U32
from .bvh import back_facing, frustum_cull, frustum_planes

__all__ = ["select_levels", "projection_scale"]


def projection_scale(view_proj, viewport_height, fov_y=None) -> tuple:
    """``(perspective, k)``: pixels per world unit of a displacement at distance ``d`` are ``k / d`` for a
    perspective projection and ``k`` for a parallel one (module docstring). ``fov_y`` (radians) overrides
    the field of view read from the matrix.

    Examples
    --------
    A 90 degree perspective (``P_11 = 1``) on a 100-pixel-high viewport: 50 pixels per unit at distance 1.

    >>> M = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, -0.2], [0, 0, -1, 0]])
    >>> projection_scale(M, 100)
    (True, 50.0)
    >>> projection_scale(np.diag([0.5, 0.5, -0.1, 1.0]), 100)  # parallel, half height 2: 25 pixels per unit
    (False, 25.0)
    """
    M = np.asarray(view_proj, dtype=np.float64).reshape(4, 4)
    H = float(viewport_height)
    r1 = float(np.linalg.norm(M[1, :3]))
    r3 = float(np.linalg.norm(M[3, :3]))
    if fov_y is not None:
        return True, H / (2.0 * math.tan(0.5 * float(fov_y)))
    if r3 > 1e-12 * max(r1, 1e-300):
        return True, H * r1 / (2.0 * r3)
    return False, 0.5 * H * r1 / abs(float(M[3, 3]))


def _box_distance(boxes, eye):
    """Distance from ``eye`` to each box (S, 6); 0 inside."""
    return np.sqrt(box_distance2(eye, boxes[:, 0::2], boxes[:, 1::2]))


def select_levels(lod, eye, view_proj, viewport_height, pixel_error=1.0, cull_back: bool = True, fov_y=None, *,
                  cull_frustum: bool = True, finer_ratio: float = 4.0, max_finer: int = 4, max_normal_deg=None):
    """A level per super-surface for one view: ``(levels (S,) int, stats)``, ``-1`` where not drawn
    (module docstring) [Kumar1997, sec. 4.4].

    Parameters
    ----------
    lod : LodModel
        Uses ``bvh``, ``boxes``, ``supers.axis``, ``supers.half_angle``, ``tolerance`` (finest first) and
        ``triangles`` (:mod:`splinevis.nurbs.lod.levels`).
    eye : (3,)
        The camera position (world).
    view_proj : (4, 4)
        World to clip coordinates, OpenGL depth range (e.g. :func:`splinevis.nurbs.lod.pipeline.view_proj_matrix`).
    viewport_height : int
        Pixels.
    pixel_error : float or None
        Largest projected deviation in pixels; ``None``: no levels of detail (level 0 wherever drawn).
    cull_back : bool
        Back-patch culling (needs outward normals on closed solids).
    fov_y : float, optional
        Vertical field of view in radians (default: from ``view_proj``).
    cull_frustum : bool
        View-frustum culling (off: every super-surface is tested for back-facing and drawn otherwise).
    finer_ratio, max_finer : float, int
        Finer step ``j`` has the tolerance ``tol_0 / finer_ratio**j``, ``j <= max_finer`` (``stats["finer_steps"]``).
    max_normal_deg : float or None
        Largest angle in degrees between the shading normals and the surface's (module docstring); needs
        ``lod.normal_bounds``.

    Returns
    -------
    levels : (S,) int64 array
    stats : dict
        ``visible``, ``culled_frustum``, ``culled_back``, ``needs_finer`` (drawn at level 0 although its
        projected error exceeds ``pixel_error``), ``finer_steps`` ((S,) int: the finer steps each of those needs,
        0 elsewhere), ``finer_capped`` (how many need more than ``max_finer``), ``per_level`` (drawn count per
        level, finest first), ``triangles`` (sum of ``lod.triangles`` of the chosen levels, before the
        assembly's fans), ``normal_limited`` and ``normal_unmet`` (module docstring; 0 without a normal request).

    Examples
    --------
    Two super-surfaces on the axis of a 90 degree view from the origin down -z, 10 and 1000 units away, and
    one behind the eye; levels of tolerance 0.01, 0.1, 1 on a 200-pixel viewport:

    >>> from types import SimpleNamespace
    >>> from splinevis.nurbs.lod.bvh import build_bvh
    >>> boxes = np.array([[-1, 1, -1, 1, -11, -10], [-1, 1, -1, 1, -1001, -1000], [-1, 1, -1, 1, 5, 6.0]])
    >>> supers = SimpleNamespace(axis=np.array([[0, 0, 1.0]] * 3), half_angle=np.full(3, 0.1))
    >>> lod = SimpleNamespace(bvh=build_bvh(boxes), boxes=boxes, supers=supers,
    ...                       tolerance=np.array([0.01, 0.1, 1.0]), triangles=np.array([[400, 40, 4]] * 3))
    >>> M = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1.0002, -0.20002], [0, 0, -1, 0]])  # near 0.1, far 1000
    >>> levels, stats = select_levels(lod, [0, 0, 0], M, 200)
    >>> levels.tolist(), stats["per_level"], stats["culled_frustum"], stats["triangles"]
    ([1, 2, -1], [0, 1, 1], 1, 44)

    At 10 units one pixel is 0.1 units: level 1 (0.1) fits 1 pixel, level 0 is needed for half a pixel. At a
    hundredth of a pixel (0.001 units at 10, 0.1 at 1000) the far one takes level 1 and even level 0 is too
    coarse for the near one: it needs two finer steps of ratio 4 (0.01 / 16 <= 0.001 < 0.01 / 4).

    >>> levels, stats = select_levels(lod, [0, 0, 0], M, 200, pixel_error=0.01)
    >>> levels.tolist(), stats["needs_finer"], stats["finer_steps"].tolist()
    ([0, 1, -1], 1, [2, 0, 0])

    Normal bounds of 1, 5 and 20 degrees per level: a request of 6 degrees draws the far one at level 1 where the
    pixel error allowed 2; one of half a degree is met by no level: level 0, counted.

    >>> lod.normal_bounds = np.radians([[1.0, 5.0, 20.0]] * 3)
    >>> levels, stats = select_levels(lod, [0, 0, 0], M, 200, max_normal_deg=6.0)
    >>> levels.tolist(), stats["normal_limited"], stats["normal_unmet"]
    ([1, 1, -1], 1, 0)
    >>> levels, stats = select_levels(lod, [0, 0, 0], M, 200, max_normal_deg=0.5)
    >>> levels.tolist(), stats["normal_limited"], stats["normal_unmet"]
    ([0, 0, -1], 2, 2)
    """
    S = int(np.asarray(lod.boxes).shape[0])
    boxes = np.asarray(lod.boxes, dtype=np.float64).reshape(S, 6)
    e = np.asarray(eye, dtype=np.float64).reshape(3)
    tol = np.asarray(lod.tolerance, dtype=np.float64).reshape(-1)
    L = tol.size
    if L == 0 or (np.diff(tol) < 0).any():
        raise ValueError("lod.tolerance must hold at least one level, finest (smallest) first.")
    if pixel_error is not None and not (float(pixel_error) >= 0.0):
        raise ValueError(f"pixel_error must be a non-negative number of pixels or None, got {pixel_error!r}.")
    if not (float(finer_ratio) > 1.0 and math.isfinite(float(finer_ratio))) or int(max_finer) < 0:
        raise ValueError(f"finer_ratio must be > 1 and max_finer >= 0, got {finer_ratio!r}, {max_finer!r}.")
    if max_normal_deg is not None:
        if not float(max_normal_deg) > 0.0:
            raise ValueError(f"max_normal_deg must be a positive angle in degrees or None, got {max_normal_deg!r}.")
        if getattr(lod, "normal_bounds", None) is None:
            raise ValueError("lod has no normal_bounds (build it with build_lod) for a max_normal_deg request.")
    if cull_frustum:
        ids = frustum_cull(lod.bvh, frustum_planes(view_proj))
    else:
        ids = np.arange(S, dtype=np.int64)
    culled_frustum = S - int(ids.size)
    culled_back = 0
    if cull_back and ids.size:
        back = back_facing(np.asarray(lod.supers.axis)[ids], np.asarray(lod.supers.half_angle)[ids], boxes[ids], e)
        culled_back = int(back.sum())
        ids = ids[~back]
    levels = np.full(S, -1, dtype=np.int64)
    needs_finer, finer_capped = 0, 0
    finer = np.zeros(S, dtype=np.int64)
    if ids.size:
        if pixel_error is None:
            chosen = np.zeros(ids.size, dtype=np.int64)
        else:
            perspective, k = projection_scale(view_proj, viewport_height, fov_y)
            if perspective:
                d = _box_distance(boxes[ids], e)
                with np.errstate(divide="ignore"):
                    limit = float(pixel_error) * d / k  # the largest tolerance that projects within pixel_error
            else:
                limit = np.full(ids.size, float(pixel_error) / k)
            fits = np.searchsorted(tol, limit, side="right")  # number of levels with tol_l <= limit
            needs_finer = int((fits == 0).sum())
            chosen = np.maximum(fits - 1, 0)
            if needs_finer:
                short = np.flatnonzero(fits == 0)
                lim = limit[short]
                with np.errstate(divide="ignore"):  # limit 0 (eye inside the box): infinitely many steps
                    j = np.ceil(np.log(tol[0] / lim) / math.log(float(finer_ratio)))
                j = np.where(np.isfinite(j), np.maximum(j, 1.0), np.inf)
                j = np.where(tol[0] / float(finer_ratio) ** np.minimum(j, 64.0) > lim, j + 1.0, j)  # rounding of log
                finer_capped = int((j > int(max_finer)).sum())
                finer[ids[short]] = np.minimum(j, int(max_finer)).astype(np.int64)
        levels[ids] = chosen
    limited = unmet = 0
    if max_normal_deg is not None and ids.size:  # the coarsest level <= chosen meeting the normal request
        chosen = levels[ids]
        meets = np.degrees(np.asarray(lod.normal_bounds)[ids] + 8.0 * U32) <= float(max_normal_deg)
        meets &= np.arange(L)[None, :] <= chosen[:, None]
        best = np.where(meets.any(axis=1), L - 1 - np.argmax(meets[:, ::-1], axis=1), 0)
        limited, unmet = int((best < chosen).sum()), int((~meets.any(axis=1)).sum())
        levels[ids] = best
    drawn = levels >= 0
    per_level = np.bincount(levels[drawn], minlength=L)
    tri = np.asarray(lod.triangles)
    triangles = int(tri[np.flatnonzero(drawn), levels[drawn]].sum()) if drawn.any() else 0
    stats = {"visible": int(drawn.sum()), "culled_frustum": culled_frustum, "culled_back": culled_back,
             "needs_finer": needs_finer, "finer_steps": finer, "finer_capped": finer_capped,
             "per_level": per_level.tolist(), "triangles": triangles, "normal_limited": limited,
             "normal_unmet": unmet}
    return levels, stats
