"""The octahedral geometry image: its layout, the X-cut's padding rules and the four cut vertices
[Losasso2003, sec. 3, eq. 1-2].

Layout
------
A geometry image ``G`` is an ``(n, n, C)`` float64 array, ``n = N + 1`` odd (``N`` even; ``N = 2^k`` for the
subsampled levels of detail), ``G[r, c]`` the sample in row ``r`` and column ``c``. Image coordinates
``(s, t) = (c, r)`` run over ``[0, N]^2``; the octahedral coordinates are ``(u, v) = (2 s / N - 1, 2 t / N - 1)``
in ``[-1, 1]^2``.

The octahedral map (:func:`octahedral_to_sphere`, :func:`sphere_to_octahedral`) sends ``-X`` to the image centre
and ``+X`` to the four corners: ``q = p / |p|_1``; if ``q_x <= 0``, ``(u, v) = (-q_y, q_z)``; otherwise
``(u, v) = (sgn(-q_y) (1 - |q_z|), sgn(q_z) (1 - |q_y|))``. Crossing a border of the square is a half turn about
that border's midpoint, ``(u, 1 + e) ~ (-u, 1 - e)`` and ``(1 + e, v) ~ (1 - e, -v)``, so each border is
symmetric about its midpoint (:func:`symmetry_defect`) and the four corners are one point.

Padding [Losasso2003, sec. 3]: for ``k >= 1``

    G[r, N + k] = G[N - r, N - k]      G[r, -k] = G[N - r, k]
    G[N + k, c] = G[N - k, N - c]      G[-k, c] = G[k, N - c]

applied transitively at the corners (:func:`pad`). The bicubic B-spline on the padded image is closed and
``C^2`` except at the four *cut vertices*, the border midpoints (:func:`cut_vertices`), where the closed mesh has
valence 2; the surface is ``C^1`` there when each cut vertex is the centroid of its four neighbours
[Losasso2003, eq. 2] (:func:`cut_neighbours`, :func:`apply_cut_constraint`).

Why our own code: the layout is the paper's; no library has it.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "octahedral_to_sphere",
    "sphere_to_octahedral",
    "image_uv",
    "pad",
    "cut_vertices",
    "cut_neighbours",
    "apply_cut_constraint",
    "symmetry_defect",
    "symmetrize",
]


def _sgn(x):
    return np.where(x < 0.0, -1.0, 1.0)


def sphere_to_octahedral(p) -> np.ndarray:
    """Octahedral coordinates ``(u, v)`` in ``[-1, 1]^2`` of directions ``p`` (``(..., 3)``, any length > 0).

    >>> sphere_to_octahedral([[-1.0, 0, 0], [1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]).tolist()
    [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]]
    """
    p = np.asarray(p, dtype=np.float64)
    q = p / np.abs(p).sum(axis=-1, keepdims=True)
    x, y, z = q[..., 0], q[..., 1], q[..., 2]
    front = x <= 0.0
    u = np.where(front, -y, _sgn(-y) * (1.0 - np.abs(z)))
    v = np.where(front, z, _sgn(z) * (1.0 - np.abs(y)))
    return np.stack([u, v], axis=-1) + 0.0  # + 0.0: no negative zeros


def octahedral_to_sphere(uv) -> np.ndarray:
    """Unit directions of octahedral coordinates ``uv`` (``(..., 2)`` in ``[-1, 1]^2``), the inverse of
    :func:`sphere_to_octahedral`.

    >>> d = np.random.default_rng(0).normal(size=(1000, 3))
    >>> d /= np.linalg.norm(d, axis=1, keepdims=True)
    >>> bool(np.allclose(octahedral_to_sphere(sphere_to_octahedral(d)), d))
    True
    """
    uv = np.asarray(uv, dtype=np.float64)
    u, v = uv[..., 0], uv[..., 1]
    inner = np.abs(u) + np.abs(v) <= 1.0
    # inner diamond: the x <= 0 half, |y| + |z| = 1 + x
    y_in, z_in = -u, v
    # outer triangles: |y| = 1 - |v|, |z| = 1 - |u| with the signs of -u and v
    y_out, z_out = -_sgn(u) * (1.0 - np.abs(v)), _sgn(v) * (1.0 - np.abs(u))
    y = np.where(inner, y_in, y_out)
    z = np.where(inner, z_in, z_out)
    x = np.abs(y) + np.abs(z) - 1.0
    x = np.where(inner, x, -x)
    p = np.stack([x, y, z], axis=-1)
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def image_uv(n: int) -> np.ndarray:
    """Octahedral coordinates of the samples of an ``n x n`` image, ``(n, n, 2)`` with ``[..., 0] = u`` along
    columns and ``[..., 1] = v`` along rows.

    >>> image_uv(3)[0, 2].tolist(), image_uv(3)[1, 1].tolist()
    ([1.0, -1.0], [0.0, 0.0])
    """
    N = _check_n(n)
    w = np.linspace(-1.0, 1.0, N + 1)
    u, v = np.meshgrid(w, w, indexing="xy")
    return np.stack([u, v], axis=-1)


def _check_n(n: int) -> int:
    n = int(n)
    if n < 3 or n % 2 == 0:
        raise ValueError(f"a geometry image has an odd number of samples per side (>= 3), got {n}: the cut vertices "
                         "are the border midpoints.")
    return n - 1


def pad(G, width: int = 1) -> np.ndarray:
    """``G`` (``(n, n, ...)``) with ``width`` samples added on every side by the X-cut's padding rules.

    >>> G = np.arange(9.0).reshape(3, 3)
    >>> pad(G)
    array([[4., 5., 4., 3., 4.],
           [7., 0., 1., 2., 7.],
           [4., 3., 4., 5., 4.],
           [1., 6., 7., 8., 1.],
           [4., 5., 4., 3., 4.]])
    """
    G = np.asarray(G)
    N = _check_n(G.shape[0])
    if G.shape[1] != N + 1:
        raise ValueError(f"a geometry image is square, got {G.shape[0]} x {G.shape[1]} samples.")
    w = int(width)
    if not 1 <= w <= N:
        raise ValueError(f"padding width must be in 1..{N} for a {N + 1} x {N + 1} image, got {width}.")
    idx = np.arange(-w, N + w + 1)
    r, c = np.meshgrid(idx, idx, indexing="ij")
    # fold rows first, then columns, then rows again: each fold is one of the four rules (a half turn)
    for _ in range(2):
        below, above = r < 0, r > N
        r, c = np.where(below, -r, np.where(above, 2 * N - r, r)), np.where(below | above, N - c, c)
        left, right = c < 0, c > N
        c, r = np.where(left, -c, np.where(right, 2 * N - c, c)), np.where(left | right, N - r, r)
    return G[r, c]


def cut_vertices(n: int) -> np.ndarray:
    """``(4, 2)`` (row, column) of the cut vertices of an ``n x n`` image: the midpoints of the top, bottom, left
    and right borders.

    >>> cut_vertices(5).tolist()
    [[0, 2], [4, 2], [2, 0], [2, 4]]
    """
    N = _check_n(n)
    h = N // 2
    return np.array([[0, h], [N, h], [h, 0], [h, N]])


def cut_neighbours(n: int) -> np.ndarray:
    """``(4, 4, 2)``: for each cut vertex (:func:`cut_vertices`), its four neighbours in the closed mesh
    [Losasso2003, eq. 2]: the border neighbour (one of the two equal ones) and the three on the next row or column.

    >>> cut_neighbours(5)[0].tolist()
    [[0, 1], [1, 2], [1, 1], [1, 3]]
    """
    N = _check_n(n)
    h = N // 2
    return np.array([
        [[0, h - 1], [1, h], [1, h - 1], [1, h + 1]],
        [[N, h - 1], [N - 1, h], [N - 1, h - 1], [N - 1, h + 1]],
        [[h - 1, 0], [h, 1], [h - 1, 1], [h + 1, 1]],
        [[h - 1, N], [h, N - 1], [h - 1, N - 1], [h + 1, N - 1]],
    ])


def apply_cut_constraint(G) -> np.ndarray:
    """A copy of ``G`` whose four cut vertices are the centroids of their neighbours [Losasso2003, eq. 2]: the
    perturbation that makes the bicubic surface ``C^1`` there.

    >>> G = np.zeros((5, 5)); G[1, 1:4] = 4.0
    >>> apply_cut_constraint(G)[0, 2]
    np.float64(3.0)
    """
    G = np.array(G, dtype=np.float64, copy=True)
    for (r, c), nb in zip(cut_vertices(G.shape[0]), cut_neighbours(G.shape[0])):
        G[r, c] = G[nb[:, 0], nb[:, 1]].mean(axis=0)
    return G


def symmetry_defect(G) -> float:
    """Largest difference between samples the X-cut identifies (border halves, the four corners): 0 for a valid
    image.

    >>> G = np.arange(9.0).reshape(3, 3)
    >>> symmetry_defect(G), symmetry_defect(symmetrize(G))
    (8.0, 0.0)
    """
    G = np.asarray(G, dtype=np.float64)
    _check_n(G.shape[0])
    d = [np.abs(G[0] - G[0, ::-1]).max(), np.abs(G[-1] - G[-1, ::-1]).max(),
         np.abs(G[:, 0] - G[::-1, 0]).max(), np.abs(G[:, -1] - G[::-1, -1]).max(),
         np.abs(G[[0, 0, -1, -1], [0, -1, 0, -1]] - G[0, 0]).max()]
    return float(max(d))


def symmetrize(G) -> np.ndarray:
    """``G`` with identified samples replaced by their mean, so that :func:`symmetry_defect` is 0.

    >>> symmetrize(np.arange(9.0).reshape(3, 3))
    array([[4., 1., 4.],
           [3., 4., 5.],
           [4., 7., 4.]])
    """
    G = np.array(G, dtype=np.float64, copy=True)
    _check_n(G.shape[0])
    G[0] = 0.5 * (G[0] + G[0, ::-1])
    G[-1] = 0.5 * (G[-1] + G[-1, ::-1])
    G[:, 0] = 0.5 * (G[:, 0] + G[::-1, 0])
    G[:, -1] = 0.5 * (G[:, -1] + G[::-1, -1])
    G[[0, 0, -1, -1], [0, -1, 0, -1]] = G[[0, 0, -1, -1], [0, -1, 0, -1]].mean(axis=0)
    return G
