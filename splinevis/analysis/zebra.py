"""The exact reflection lines (zebra) of any registered program's model, per pixel, from its float64 twin: the
reference a rendered zebra picture is compared with (the effect's GLSL is ``glsl/lib/effects/reflection_lines.glsl``:
stripes of the mirrored view ray's angle about the light lines' axis), and the stripe count a view can show
without aliasing (:func:`stripes_for_view`)."""

from __future__ import annotations

import numpy as np

__all__ = ["zebra_reference", "reflection_phase", "stripes_for_view"]


def zebra_reference(model, matrix, window, stripes: int, axis, pixels=None) -> tuple:
    """``(bright, hit, edge_distance)`` per pixel of a ``window = (W, H)`` seen through ``matrix``: the exact
    stripe colour (True bright), the twin's hit mask, and each pixel's distance to the nearest stripe edge in
    stripe widths (both colours are right within rounding of an edge).

    ``pixels`` (an ``(H, W)`` bool mask, optional) casts only those pixels' rays (the float64 twin costs per
    ray); the others read as missed (``hit`` False, ``bright`` False, distance 0).

    Examples
    --------
    The analytic patch seen through the identity matrix (world = normalized device coordinates), 8 x 6 pixels:

    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> bright, hit, edge = zebra_reference(QuarticTrianglePatch.demo(), np.eye(4), (8, 6), 4, (1, 0, 0))
    >>> bright.shape, int(hit.sum()), int((bright & hit).sum()), bool(edge[hit].max() <= 0.5)
    ((6, 8), 29, 11, True)

    Only the left half of the pixels:

    >>> left = np.zeros((6, 8), bool); left[:, :4] = True
    >>> b2, h2, e2 = zebra_reference(QuarticTrianglePatch.demo(), np.eye(4), (8, 6), 4, (1, 0, 0), pixels=left)
    >>> bool((h2 == (hit & left)).all() and (b2[left] == bright[left]).all() and not b2[~left].any())
    True
    """
    from ..gl.camera import pixel_rays
    from ..programs import program_for

    w, h = window
    o, d = pixel_rays(matrix, w, h)
    mask = np.ones((h, w), bool) if pixels is None else np.asarray(pixels, dtype=bool)
    if mask.shape != (h, w):
        raise ValueError(f"pixels must be an (H, W) = {(h, w)} mask of the window, got shape {mask.shape}.")
    o, d = o[mask], d[mask]
    hits = program_for(model).raycast(model, o, d, 0.0)
    x = reflection_phase(d, hits.normals, axis) * stripes
    f = x - np.floor(x)
    bright, hit, edge = np.zeros((h, w), bool), np.zeros((h, w), bool), np.zeros((h, w))
    bright[mask], hit[mask] = f >= 0.5, hits.hit
    edge[mask] = np.minimum(np.abs(f - 0.5), np.minimum(f, 1 - f))
    return bright, hit, edge


def reflection_phase(directions, normals, axis) -> np.ndarray:
    """The reflection-line phase ``atan2(r . b, r . c) / pi`` in [-1, 1] of view rays ``directions`` mirrored at
    ``normals`` (either orientation), ``(a, b, c)`` the light lines' frame (``effects.line_frame(axis)``): the
    stripe colour of ``Style(reflection_lines=n)`` is ``fract(n * phase) < 1/2`` (dark), as in
    ``glsl/lib/effects/reflection_lines.glsl``.

    >>> float(reflection_phase([[0.0, 0.0, -1.0]], [[0.0, 0.0, 1.0]], (1, 0, 0))[0])  # mirrored up: r = +z = c
    0.0
    """
    from ..effects import line_frame

    d = np.asarray(directions, dtype=np.float64)
    rd = d / np.linalg.norm(d, axis=-1, keepdims=True)
    n = np.asarray(normals, dtype=np.float64)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.where((np.einsum("...i,...i", n, rd) > 0)[..., None], -n, n)
    r = rd - 2 * np.einsum("...i,...i", rd, n)[..., None] * n
    b, c = (np.asarray(v) for v in line_frame(axis))
    return np.arctan2(r @ b, r @ c) / np.pi


def stripes_for_view(model, matrix, window, axis, *, pixels_per_pair: float = 4.0, quantile: float = 0.75,
                     step: int = 4, max_stripes: int = 64) -> dict:
    """The largest reflection-line count (``Style(reflection_lines=n)``) whose stripes a view can show: a
    dark/bright pair spans at least ``pixels_per_pair`` pixels on ``quantile`` of the surface's pixels.

    One sample per pixel shows a stripe pattern only where a pair is wider than two pixels (Nyquist); the
    pattern's rate on screen is ``n |grad phase|`` pairs per pixel, ``phase`` the mirrored ray's angle about
    the light lines (:func:`reflection_phase`). Its gradient is measured here from the float64 twin's normals at
    pixel centres and their right and lower neighbours (every ``step``-th pixel; pairs across a silhouette or
    an occlusion, where the depth jumps by more than 5 %, are not counted), so the count follows the model's
    size on screen and its curvature: twice the pixels across the same view give twice the stripes. Where the
    mirrored rays turn about the light lines' axis the stripes converge to a point and alias at any count:
    those pixels are the ``1 - quantile`` left out.

    Returns ``{"stripes", "rate_quantile" (phase per pixel at the quantile), "pixels" (sampled surface
    pixels)}``.

    Examples
    --------
    The analytic patch through the identity matrix (world = normalized device coordinates), at two sizes:

    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> small = stripes_for_view(QuarticTrianglePatch.demo(), np.eye(4), (80, 60), (1, 0, 0), step=1)
    >>> large = stripes_for_view(QuarticTrianglePatch.demo(), np.eye(4), (160, 120), (1, 0, 0), step=1)
    >>> small["stripes"], large["stripes"]
    (10, 20)
    """
    from ..gl.camera import pixel_rays
    from ..programs import program_for

    if not pixels_per_pair > 2.0:
        raise ValueError(f"pixels_per_pair must exceed 2 (the Nyquist limit of one sample per pixel), got "
                         f"{pixels_per_pair!r}.")
    if not 0.0 < quantile <= 1.0:
        raise ValueError(f"quantile must lie in (0, 1], got {quantile!r}.")
    w, h = (int(v) for v in window)
    o, d = pixel_rays(matrix, w, h)
    ys, xs = np.meshgrid(np.arange(0, h - 1, step), np.arange(0, w - 1, step), indexing="ij")
    ys, xs = ys.ravel(), xs.ravel()
    idx = [(ys, xs), (ys, xs + 1), (ys + 1, xs)]
    O = np.concatenate([o[i] for i in idx])
    D = np.concatenate([d[i] for i in idx])
    hits = program_for(model).raycast(model, O, D, 0.0)
    m = ys.size
    t = hits.t.reshape(3, m)
    phase = np.full((3, m), np.nan)
    phase.ravel()[hits.hit] = reflection_phase(D[hits.hit], hits.normals[hits.hit], axis)
    ok = np.isfinite(t).all(axis=0) & (np.abs(t[1:] - t[0]) <= 0.05 * np.abs(t[0])).all(axis=0)
    dphi = phase[1:, ok] - phase[0, ok]
    dphi = np.mod(dphi + 1.0, 2.0) - 1.0  # the phase wraps at +-1
    rate = np.hypot(dphi[0], dphi[1])
    if rate.size == 0:
        return {"stripes": 1, "rate_quantile": 0.0, "pixels": 0}
    q = float(np.quantile(rate, quantile))
    n = max_stripes if q * max_stripes * pixels_per_pair <= 1.0 else max(1, int(np.floor(1.0 / (q * pixels_per_pair))))
    return {"stripes": int(n), "rate_quantile": q, "pixels": int(rate.size)}
