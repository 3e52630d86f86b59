"""Scenes where a float32 terrain ray cast is most likely to part from its float64 twin.

Each is a :class:`~splinevis.gl.contract.HardCase` that the tests and the self-test render and compare per
pixel (:func:`splinevis.analysis.agreement.depth_agreement`): grazing rays, rays along grid lines and through
vertices, the underside, a camera inside the bounding box, UTM-sized coordinates, extreme zoom, flat and almost
flat data, a grid wider than a texture row, and high-relief terrain (crater walls, a cliff of 150 cells)
in every scheme at overview, oblique and close-up views, and parallel rays straight down (top views). Franke's function on 24 x 24 samples, the C2-cubic scheme, unless said otherwise.
"""

from __future__ import annotations

import functools

import numpy as np

from ..gl.contract import HardCase
from .model import TerrainSpline

__all__ = ["hard_cases", "franke_terrain"]


def franke_terrain(n: int = 24, scheme: str = "C2-cubic", spacing=(1.0 / 24, 1.0 / 24), origin=(0.0, 0.0),
                   height_offset: float = 0.0, height_scale: float = 1.0) -> TerrainSpline:
    """Franke's function [Franke1982] sampled on (n + 1) x (n + 1) points of the unit square (n intervals per
    axis) as a terrain spline.

    Examples
    --------
    >>> t = franke_terrain()
    >>> t.scheme, t.shape, t.extent
    ('C2-cubic', (24, 24), (0.0, 1.0, 0.0, 1.0))
    """
    from datasets_synthetic.franke import franke_grid

    z, _ = franke_grid(n)
    return TerrainSpline.from_heights(z.T * height_scale + height_offset, scheme, spacing=spacing, origin=origin)


_franke = functools.lru_cache(maxsize=1)(franke_terrain)


def _utm():
    # UTM-sized origin and heights 2000 +- 0.5: only the local frame keeps float32 precision here.
    return franke_terrain(spacing=(10.0, 10.0), origin=(500_000.0, 5_100_000.0), height_offset=2000.0, height_scale=0.5)


def _utm_camera(t):
    x0, x1, y0, y1 = t.extent
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    return [(cx - 300, cy - 350, 2300.0), (cx, cy, 2000.3), (0, 0, 1)]


def _inside_camera(t):
    eye = (0.3, 0.2, float(t.evaluate(0.3, 0.2)) + 0.05)  # below the top of the bounding box
    return [eye, (0.7, 0.7, 0.2), (0, 0, 1)]


def _zoom_camera(t):
    x, y = 0.51, 0.52
    z = float(t.evaluate(x, y))
    return [(x - 0.01, y - 0.012, z + 0.01), (x, y, z), (0, 0, 1)]


def _flat(almost: bool):
    z = np.full((17, 17), 250.0)
    if almost:
        z[8, 8] += 1e-4
    return TerrainSpline.from_heights(z, "C1", spacing=(1.0, 1.0))


def _wide():
    # 2500 cells in x: 20,000 coefficient texels per grid row, more than a texture row holds (16,384 on llvmpipe
    # and most GPUs); the linear tables must wrap rows without a seam
    from datasets_synthetic.dem_files import fractal_terrain

    z = np.tile(fractal_terrain(129, seed=2, amplitude=40.0)[:33], (1, 20))[:, :2501]
    return TerrainSpline.from_heights(z, "C2", spacing=(1.0, 1.0))


def high_relief(kind: str, n: int = 129) -> np.ndarray:
    """Heights of high-relief test terrain on n x n unit cells: ``"crater"``, a volcano with a crater (walls
    about 120 cells high over 35 cells, a rim, sample noise) or ``"cliff"``, a plateau 150 cells high behind
    a wall one cell wide (slope 89.6 degrees) that curves across the grid.

    >>> z = high_relief("cliff", 33)
    >>> z.shape, float(z.max() - z.min()) > 149
    ((33, 33), True)
    """
    y, x = np.mgrid[0:n, 0:n].astype(float)
    c = (n - 1) / 2
    if kind == "crater":
        r = np.hypot(x - c, y - c) / c
        rim = 0.45
        cone = 120.0 * np.clip(1 - (r - rim) / (1 - rim), 0, 1) ** 1.5
        inner = 108.0 * np.clip(r / rim, 0, 1) ** 8 + 12.0
        return np.where(r < rim, inner, cone) + np.random.default_rng(0).normal(scale=0.5, size=x.shape)
    if kind == "cliff":
        edge = c + 0.25 * c * np.sin(3.0 * y / n)  # the wall's x position varies with y
        return 150.0 * np.clip(x - edge + 0.5, 0.0, 1.0)
    raise ValueError(f"kind must be 'crater' or 'cliff', got {kind!r}.")


@functools.lru_cache(maxsize=12)
def _relief(kind: str, scheme: str) -> TerrainSpline:
    return TerrainSpline.from_heights(high_relief(kind), scheme, spacing=(1.0, 1.0))


def _steep_fractal():
    # 2049^2 fractal heights 0..2000 cells high: median slope 77 degrees, 99th percentile 85 (about 1 GB of
    # coefficients; users saw 50-73 pinholes per frame on such a grid before the rebasing in terrain.glsl)
    from datasets_synthetic.dem_files import fractal_terrain

    return TerrainSpline.from_heights(fractal_terrain(2049, seed=5, amplitude=2000.0), "C2", spacing=(1.0, 1.0))


#: Overview (the whole crater from afar), oblique (down a wall) and close-up (along a wall's foot) views.
RELIEF_VIEWS = {
    "overview": [(-60.0, -90.0, 260.0), (64.0, 64.0, 40.0), (0, 0, 1)],
    "oblique": [(-20.0, 10.0, 90.0), (64.0, 64.0, 60.0), (0, 0, 1)],
    "close-up": [(40.0, 52.0, 30.0), (64.0, 64.0, 20.0), (0, 0, 1)],
}


def hard_cases() -> list:
    """The terrain's hard cases (module docstring), 400 x 300 pixels each (the 36 high-relief views 320 x 240, the
    2049^2 fractal 240 x 180).

    Examples
    --------
    >>> cases = hard_cases()
    >>> len(cases), cases[0].name, cases[0].window_size, cases[5].clipping_range
    (50, 'oblique', (400, 300), (0.001, 5.0))
    """
    size = (400, 300)
    # the 36 high-relief views (two terrains, six schemes, three views) at 0.64 of the pixels: they were a third of
    # the test suite's hard-case time at 400 x 300 (about 100 of 1,000 CPU-seconds); every one of them met the same
    # limits at both sizes (hits, no leak, one-sided pixels, depths within the bound)
    relief_size = (320, 240)
    grazing_z = 1.25
    flat_view = [(-6.0, -9.0, 262.0), (8.0, 8.0, 250.0), (0, 0, 1)]
    x = 12 / 24  # the eye exactly above a grid line, looking along it: a column of rays runs along cell edges
    return [
        HardCase("oblique", _franke, [(-0.6, -0.9, 1.4), (0.5, 0.5, 0.3), (0, 0, 1)], size, min_hits=0.05),
        HardCase("grazing-1-degree", _franke, [(-3.0, 0.45, grazing_z),
                                               (0.5, 0.5, grazing_z - 3.5 * np.tan(np.radians(1.0))), (0, 0, 1)],
                 size, min_hits=0.05),
        HardCase("along-grid-lines", _franke, [(x, -1.0, 1.5), (x, 0.5, 0.2), (0, 0, 1)], size, min_hits=0.05),
        HardCase("along-diagonals", _franke, [(-0.5, -0.5, 1.6), (0.5, 0.5, 0.2), (0, 0, 1)], size, min_hits=0.05),
        HardCase("underside", _franke, [(0.5, -0.8, -1.0), (0.5, 0.5, 0.3), (0, 0, 1)], size, min_hits=0.05),
        HardCase("camera-inside-box", _franke, _inside_camera, size, clipping_range=(1e-3, 5.0), min_hits=0.05),
        HardCase("utm-coordinates", _utm, _utm_camera, size, min_hits=0.05),
        HardCase("extreme-zoom", _franke, _zoom_camera, size, clipping_range=(1e-4, 2.0), min_hits=0.05),
        HardCase("flat", functools.partial(_flat, False), flat_view, size, min_hits=0.05),
        HardCase("almost-flat", functools.partial(_flat, True), flat_view, size, min_hits=0.05),
        HardCase("wider-than-a-texture-row", _wide, [(2290.0, -25.0, 70.0), (2330.0, 16.0, 15.0), (0, 0, 1)], size,
                 min_hits=0.05),
        # parallel rays straight down: no ray crosses a cell edge, every ray is (near) vertical
        HardCase("parallel-top-view", _franke, [(0.5, 0.5, 3.0), (0.5, 0.5, 0.0), (0, 1, 0)], size, min_hits=0.5,
                 parallel_scale=0.55),
        HardCase("parallel-top-view-crater", functools.partial(_relief, "crater", "C2"),
                 [(64.0, 64.0, 400.0), (64.0, 64.0, 0.0), (0, 1, 0)], size, min_hits=0.5, parallel_scale=70.0),
        # 240 x 180: the grid's size is what is hard here (pinholes came from texture rows and large offsets, at
        # 50-73 per 400 x 300 frame before the rebasing: still ~18-26 at 0.36 of the pixels); the float64 twin
        # pays per ray on 4 million steep cells
        HardCase("fractal-2048-steep", _steep_fractal, [(-600.0, -900.0, 4000.0), (1024.0, 1024.0, 900.0), (0, 0, 1)],
                 (240, 180), min_hits=0.05),
    ] + [HardCase(f"{kind}-{scheme}-{view}", functools.partial(_relief, kind, scheme), camera, relief_size,
                  min_hits=0.05)
         for kind in ("crater", "cliff") for scheme in ("linear", "C0", "C1", "C2", "C2-cubic", "C2-interp")
         for view, camera in RELIEF_VIEWS.items()]
