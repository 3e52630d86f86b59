"""The exact reflection lines (zebra) of any registered program's model, per pixel, from its float64 twin: the
reference a rendered zebra picture is compared with (the effect's GLSL is ``glsl/lib/effects/reflection_lines.glsl``:
stripes of the mirrored view ray's angle about the light lines' axis)."""

from __future__ import annotations

import numpy as np

__all__ = ["zebra_reference"]


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
    from ..effects import line_frame
    from ..gl.camera import pixel_rays
    from ..programs import program_for

    w, h = window
    o, d = pixel_rays(matrix, w, h)
    mask = np.ones((h, w), bool) if pixels is None else np.asarray(pixels, dtype=bool)
    if mask.shape != (h, w):
        raise ValueError(f"pixels must be an (H, W) = {(h, w)} mask of the window, got shape {mask.shape}.")
    o, d = o[mask], d[mask]
    hits = program_for(model).raycast(model, o, d, 0.0)
    rd = d / np.linalg.norm(d, axis=-1, keepdims=True)
    n = hits.normals / np.linalg.norm(hits.normals, axis=-1, keepdims=True)
    n = np.where((np.einsum("...i,...i", n, rd) > 0)[..., None], -n, n)
    r = rd - 2 * np.einsum("...i,...i", rd, n)[..., None] * n
    b, c = (np.asarray(v) for v in line_frame(axis))
    x = np.arctan2(r @ b, r @ c) / np.pi * stripes
    f = x - np.floor(x)
    bright, hit, edge = np.zeros((h, w), bool), np.zeros((h, w), bool), np.zeros((h, w))
    bright[mask], hit[mask] = f >= 0.5, hits.hit
    edge[mask] = np.minimum(np.abs(f - 0.5), np.minimum(f, 1 - f))
    return bright, hit, edge
