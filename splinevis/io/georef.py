"""Heights in a geographic CRS (degrees) brought to a metric frame, so the picture has its true aspect.

A grid whose x, y are longitude and latitude (EPSG:4326 SRTM, Copernicus, ...) and whose heights are in
metres renders as a thin sliver: one degree is about 111 km. :func:`to_metric` reprojects such a grid with
GDAL's warper (``rasterio.warp.reproject``) to a local metric CRS:

* by default the UTM zone of the grid's centre (WGS84 zones EPSG:326zz north, 327zz south; beyond
  84 degrees N/S the universal polar stereographic EPSG:32661 / 32761), chosen by :func:`local_metric_crs`
  and reported in the grid's ``source``;
* or the CRS the caller names (``crs="EPSG:3035"``).

The new grid covers the largest axis-aligned rectangle inside the footprint of the source's samples
(so no node needs data from outside the file), with the source's metric sample spacing at its centre
(about as many samples as the source). Resampling is bilinear by default (it reproduces a function
linear in longitude and latitude to round-off); ``"cubic"`` (interpolating bicubic spline) and
``"nearest"`` on request. Gaps are filled before (``read_heights(fill=...)``).

:func:`scale_geographic` is the other choice (``keep_geographic=True``): the samples stay on their degree
lattice, unresampled, and x, y become degrees times the length of a degree at the centre latitude on
the CRS's ellipsoid [Snyder1987, ch. 4], with the factors reported. Distances are then true at
the centre latitude only (the relative error in x grows like ``tan(lat0) * dlat`` away from it).

Why our own module and not GDAL's warper (``rasterio.warp.reproject``): the warper interpolates the
coordinate transformation along each row (its approximate transformer, an eighth of a pixel by default)
and rasterio's ``reproject`` does not let us turn that off; measured on a 41 x 31 grid at 45 degrees N,
a height linear in longitude and latitude came back 16 mm off on a 1000 m/degree slope (0.003 pixel).
Here every node goes through PROJ exactly and scipy interpolates; error 1e-11 m on the same data. GDAL
(via rasterio) still supplies the CRS arithmetic; the rule "the local metric frame of this grid" and the
inner rectangle of a warped footprint are a few lines here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["is_geographic", "local_metric_crs", "to_metric", "scale_geographic", "degree_lengths", "Metric"]

_RESAMPLING = ("bilinear", "cubic", "nearest")
_DENSIFY = 64  # points per footprint edge


def _crs(crs):
    from rasterio.crs import CRS

    return CRS.from_user_input(crs)


def is_geographic(crs) -> bool:
    """True when ``crs`` (``"EPSG:4326"``, WKT, ...) has angular x, y; False for None or a projected CRS.

    >>> is_geographic("EPSG:4326"), is_geographic("EPSG:32633"), is_geographic(None), is_geographic("UTM zone 33")
    (True, False, False, False)
    """
    if crs is None:
        return False
    from rasterio.errors import CRSError

    try:
        return bool(_crs(crs).is_geographic)
    except CRSError:  # a description GDAL does not parse ("UTM zone 33" from a USGS DEM header): not degrees
        return False


def local_metric_crs(lon: float, lat: float) -> str:
    """The WGS84 UTM zone containing ``(lon, lat)``, or UPS beyond 84 degrees N / 80 degrees S.

    >>> local_metric_crs(7.5, 45.9), local_metric_crs(-70.6, -33.4), local_metric_crs(179.9, 10.0)
    ('EPSG:32632', 'EPSG:32719', 'EPSG:32660')
    >>> local_metric_crs(20.0, 86.0)
    'EPSG:32661'
    """
    if lat > 84.0:
        return "EPSG:32661"
    if lat < -80.0:
        return "EPSG:32761"
    lon = (lon + 180.0) % 360.0 - 180.0
    zone = min(int((lon + 180.0) // 6.0) + 1, 60)
    return f"EPSG:{(32600 if lat >= 0 else 32700) + zone}"


def degree_lengths(lat: float, crs="EPSG:4326") -> tuple:
    """Metres per degree of longitude and of latitude at latitude ``lat`` on the ellipsoid of ``crs``
    [Snyder1987, ch. 4: meridian radius M, prime-vertical radius N].

    >>> mx, my = degree_lengths(0.0)
    >>> round(mx, 1), round(my, 1)  # WGS84 at the equator
    (111319.5, 110574.3)
    >>> round(degree_lengths(60.0)[0] / mx, 4)  # about cos 60 degrees
    0.5013
    """
    c = _crs(crs)
    a, inv_f = _ellipsoid(c)
    e2 = (2.0 - 1.0 / inv_f) / inv_f
    s = math.sin(math.radians(lat))
    w = 1.0 - e2 * s * s
    n = a / math.sqrt(w)  # prime-vertical radius
    m = a * (1.0 - e2) / w ** 1.5  # meridian radius
    return n * math.cos(math.radians(lat)) * math.pi / 180.0, m * math.pi / 180.0


def _ellipsoid(c) -> tuple:
    """(semi-major axis m, inverse flattening) from the CRS's WKT; WGS84 when it names none."""
    import re

    hit = re.search(r'SPHEROID\["[^"]*",\s*([0-9.eE+-]+),\s*([0-9.eE+-]+)', c.to_wkt())
    if hit is None:
        return 6378137.0, 298.257223563
    a, inv_f = float(hit.group(1)), float(hit.group(2))
    return a, (inv_f if inv_f > 0 else math.inf)


@dataclass(frozen=True)
class Metric:
    """A grid after :func:`to_metric` or :func:`scale_geographic`: heights rows south to north.

    >>> m = Metric(np.zeros((2, 2)), (30.0, 30.0), (5e5, 5e6), "EPSG:32632", "reprojected ...")
    >>> m.crs, m.spacing
    ('EPSG:32632', (30.0, 30.0))
    """

    heights: np.ndarray
    spacing: tuple
    origin: tuple
    crs: str
    note: str


def _inner_rectangle(src_crs, dst_crs, shape, spacing, origin):
    """Largest axis-aligned rectangle (x0, x1, y0, y1) in ``dst_crs`` inside the footprint of the sample
    centres: the edges densified, then the innermost coordinate of each side."""
    from rasterio.warp import transform

    ny, nx = shape
    x0, y0 = origin
    x1, y1 = x0 + (nx - 1) * spacing[0], y0 + (ny - 1) * spacing[1]
    u = np.linspace(0.0, 1.0, _DENSIFY)
    sides = {"west": (np.full_like(u, x0), y0 + u * (y1 - y0)), "east": (np.full_like(u, x1), y0 + u * (y1 - y0)),
             "south": (x0 + u * (x1 - x0), np.full_like(u, y0)), "north": (x0 + u * (x1 - x0), np.full_like(u, y1))}
    out = {}
    for name, (xs, ys) in sides.items():
        tx, ty = transform(src_crs, dst_crs, xs.tolist(), ys.tolist())
        out[name] = (np.asarray(tx), np.asarray(ty))
    left, right = out["west"][0].max(), out["east"][0].min()
    bottom, top = out["south"][1].max(), out["north"][1].min()
    return left, right, bottom, top


def _source_positions(dst_crs, crs, x0, y0, dx, dy, shape, chunk=1 << 20):
    """Longitude, latitude of every node of the new lattice, by PROJ exactly (in row chunks)."""
    from rasterio.warp import transform

    ny, nx = shape
    xs = x0 + dx * np.arange(nx)
    lon, lat = np.empty(shape), np.empty(shape)
    rows = max(1, chunk // nx)
    for j in range(0, ny, rows):
        jj = np.arange(j, min(ny, j + rows))
        X = np.broadcast_to(xs, (len(jj), nx)).ravel()
        Y = np.repeat(y0 + dy * jj, nx)
        lo, la = transform(dst_crs, crs, X, Y)
        lon[jj], lat[jj] = np.asarray(lo).reshape(len(jj), nx), np.asarray(la).reshape(len(jj), nx)
    return lon, lat


def to_metric(heights, spacing, origin, crs, target=None, resampling="bilinear", source="heights") -> Metric:
    """Reproject a gap-free geographic grid (rows south to north) to ``target`` or the UTM zone of its centre.

    Parameters
    ----------
    heights : (ny, nx) array of float
        Finite (fill gaps first).
    spacing, origin : (2,) floats
        Degrees; ``origin`` is the south-west sample.
    crs : str
        The grid's CRS (geographic).
    target : str or None
        A projected CRS (``"EPSG:32632"``); None chooses :func:`local_metric_crs` of the centre.
    resampling : {"bilinear", "cubic", "nearest"}
        ``"cubic"`` is the interpolating bicubic spline of the samples (scipy's ``RectBivariateSpline``,
        ``s=0``: it reproduces cubic polynomials up to the border).

    Examples
    --------
    >>> lon, lat = np.meshgrid(np.linspace(7.0, 7.2, 21), np.linspace(45.0, 45.1, 11))
    >>> m = to_metric(100 + 1000 * (lon - 7) + 500 * (lat - 45), (0.01, 0.01), (7.0, 45.0), "EPSG:4326")
    >>> m.crs, m.heights.shape, [round(s, 1) for s in m.spacing]
    ('EPSG:32632', (10, 20), [787.8, 1111.3])
    """
    from scipy.interpolate import RectBivariateSpline
    from scipy.ndimage import map_coordinates

    if resampling not in _RESAMPLING:
        raise ValueError(f"{source}: resampling for the reprojection must be one of {_RESAMPLING}, got {resampling!r}.")
    h = np.asarray(heights, dtype=np.float64)
    if not np.isfinite(h).all():
        raise ValueError(f"{source}: fill the gaps before reprojecting (fill='nearest' or 'linear').")
    ny, nx = h.shape
    lon_c = origin[0] + 0.5 * (nx - 1) * spacing[0]
    lat_c = origin[1] + 0.5 * (ny - 1) * spacing[1]
    chosen = target is None
    dst = local_metric_crs(lon_c, lat_c) if chosen else str(target)
    dst_crs = _crs(dst)
    if dst_crs.is_geographic:
        raise ValueError(f"{source}: crs={target!r} is geographic (degrees); pass a projected CRS in metres, "
                         "e.g. a UTM zone 'EPSG:326zz', or keep_geographic=True.")
    mx, my = degree_lengths(lat_c, crs)
    dx, dy = spacing[0] * mx, spacing[1] * my
    left, right, bottom, top = _inner_rectangle(crs, dst_crs, h.shape, spacing, origin)
    mx_n, my_n = int(math.floor((right - left) / dx)) + 1, int(math.floor((top - bottom) / dy)) + 1
    if mx_n < 2 or my_n < 2:
        raise ValueError(f"{source}: the grid's footprint in {dst} holds fewer than 2 x 2 samples of "
                         f"{dx:.4g} x {dy:.4g} m; is the CRS {crs!r} right?")
    # centre the new lattice in the inner rectangle
    x0 = left + 0.5 * ((right - left) - (mx_n - 1) * dx)
    y0 = bottom + 0.5 * ((top - bottom) - (my_n - 1) * dy)
    lon, lat = _source_positions(dst_crs, crs, x0, y0, dx, dy, (my_n, mx_n))
    cols, rows = (lon - origin[0]) / spacing[0], (lat - origin[1]) / spacing[1]
    # the inner rectangle keeps every node inside the sample lattice; clip the round-off at its border
    cols, rows = np.clip(cols, 0.0, nx - 1.0), np.clip(rows, 0.0, ny - 1.0)
    if resampling == "cubic":  # not-a-knot interpolating bicubic spline: reproduces cubics up to the border
        out = RectBivariateSpline(np.arange(ny), np.arange(nx), h, kx=3, ky=3, s=0).ev(rows, cols)
    else:
        out = map_coordinates(h, [rows, cols], order={"nearest": 0, "bilinear": 1}[resampling], mode="nearest")
    how = "chosen as the UTM zone of the centre" if chosen else "as asked"
    note = (f"reprojected from {crs} to {dst} ({how}; {resampling}, {mx_n} x {my_n} samples of "
            f"{dx:.6g} x {dy:.6g} m, SW sample at lon {lon[0, 0]:.6f}, lat {lat[0, 0]:.6f})")
    return Metric(out, (dx, dy), (x0, y0), dst, note)


def scale_geographic(heights, spacing, origin, crs) -> Metric:
    """Keep the degree lattice; x, y become degrees times metres per degree at the centre latitude.

    >>> m = scale_geographic(np.zeros((3, 3)), (0.5, 0.5), (10.0, 59.5), "EPSG:4326")
    >>> [round(v, 1) for v in m.spacing], m.crs
    ([27900.0, 55706.1], 'EPSG:4326 scaled to metres at latitude 60')
    """
    h = np.asarray(heights, dtype=np.float64)
    ny = h.shape[0]
    lat_c = origin[1] + 0.5 * (ny - 1) * spacing[1]
    mx, my = degree_lengths(lat_c, crs)
    note = (f"kept on its {crs} lattice (keep_geographic=True): x = longitude x {mx:.6g} m, y = latitude x "
            f"{my:.6g} m (lengths of a degree at latitude {lat_c:.6g}; true there only)")
    return Metric(h, (spacing[0] * mx, spacing[1] * my), (origin[0] * mx, origin[1] * my),
                  f"{crs} scaled to metres at latitude {lat_c:.6g}", note)
