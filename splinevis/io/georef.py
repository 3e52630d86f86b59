"""Heights in a geographic CRS (degrees) brought to a metric frame, so the picture has its true aspect.

A grid whose x, y are longitude and latitude (EPSG:4326 SRTM, Copernicus, ...) and whose heights are in
metres renders as a thin sliver: one degree is about 111 km. :func:`to_metric` reprojects such a grid to a
metric CRS:

* by default the UTM zone of the grid's centre (WGS84 zones EPSG:326zz north, 327zz south), or the
  universal polar stereographic CRS (UPS north EPSG:32661, south EPSG:32761) when the grid reaches
  beyond 84 degrees N / 80 degrees S (where UTM ends [Snyder1987, ch. 8, ch. 21]); the choice is reported in
  the grid's ``source``;
* or the CRS the caller names (``crs="EPSG:3035"``).

Which rectangle of the new CRS
------------------------------
The footprint of the source's samples (the rectangle of sample centres in longitude and latitude) is
curved in the new CRS: its meridians converge (by ``dlon sin(lat)`` in UTM, [Snyder1987, ch. 8]) and in
UPS they are rays from the pole, so a cell of 10 x 2 degrees next to the pole is a wedge and a whole
polar cap is a disk. No north-up rectangle equals it; a rectangular grid either leaves part of the
footprint out or has nodes outside it, which hold no data. Rule:

* ``fill=None`` (the caller accepts no made-up heights) and a grid that stays out of the polar caps:
  the largest north-up rectangle inside the footprint (every node interpolates samples). What it
  leaves out along the edges is measured (footprint area by the shoelace formula on the densified
  boundary) and warned with its percentage; about ``tan(gamma) (w/h + h/w)`` for a ``w x h`` tile
  turned by the convergence ``gamma``: 1 to 10 % for one-degree tiles in their zone.
* ``fill="nearest"``/``"linear"`` or a grid reaching a polar cap: the new grid covers **all** of the
  footprint (its bounding box, widened by twice the sag of the densified edges: a curve of radius
  ``rho`` strays ``s^2 / 8 rho`` from a chord of length ``s``, measured at each chord's midpoint). A node is inside the footprint when its longitude and latitude (by PROJ's inverse) fall in
  the sample lattice; the nodes outside are gaps, handled as the file's own gaps are
  (:func:`~splinevis.io.read_heights`): filled by ``fill=`` (the count and percentage are in the note),
  and without ``fill=`` a ValueError says how many there are (about ``1 - pi / 4 = 21.5 %`` for a
  whole cap, half for a thin wedge) and what to pass. For a polar cap the largest inner rectangle would
  lose 36 % (a disk's inscribed square) to all of a wedge, hence no cropping default there.

Spacing: the source's metric sample spacing at the centre latitude (about as many samples as the
source); for a grid reaching a polar cap, where a degree of longitude shrinks to nothing at the pole,
one square spacing whose cell has the source's mean cell area (the footprint's area over its cells).
A source spanning the whole circle of longitude (``nx * dlon = 360``) is periodic: the cell between
its last and first column is interpolated too.

Resampling is bilinear by default (it reproduces a function linear in longitude and latitude to
round-off); ``"cubic"`` (interpolating bicubic spline) and ``"nearest"`` on request. Gaps are filled
before (``read_heights(fill=...)``).

:func:`scale_geographic` is the other choice (``keep_geographic=True``): the samples stay on their degree
lattice, unresampled, and x, y become degrees times the length of a degree at the centre latitude on
the CRS's ellipsoid [Snyder1987, ch. 4], with the factors reported. Distances are then true at
the centre latitude only (the relative error in x grows like ``tan(lat0) * dlat`` away from it).

CRS errors
----------
Every CRS problem is a ValueError naming the source, the CRS and what to do, never rasterio's or
PROJ's own exception: a CRS PROJ does not know (``crs="EPSG:99999"``); coordinates that are not degrees
although the file's label says so (a UTM raster labelled EPSG:4326: latitudes beyond 90); a target
CRS that sends part of the footprint to infinity (web Mercator at a pole). When the coordinates are
not degrees and the caller names a projected ``crs=``, the label is taken as the mistake: the grid is
kept as it is in that CRS, with a warning.

Why our own module and not GDAL's warper (``rasterio.warp.reproject``): the warper interpolates the
coordinate transformation along each row (its approximate transformer, an eighth of a pixel by default)
and rasterio's ``reproject`` does not let us turn that off; measured on a 41 x 31 grid at 45 degrees N,
a height linear in longitude and latitude came back 16 mm off on a 1000 m/degree slope (0.003 pixel).
Here every node goes through PROJ exactly and scipy interpolates; error 1e-11 m on the same data. GDAL
(via rasterio) still supplies the CRS arithmetic; the rule "the local metric frame of this grid", the
footprint and its inner rectangle are a few lines here.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

__all__ = ["is_geographic", "local_metric_crs", "to_metric", "scale_geographic", "degree_lengths", "Metric"]

_RESAMPLING = ("bilinear", "cubic", "nearest")
_FILLS = (None, "nearest", "linear")
_DENSIFY = 64  # points per footprint edge, at least (and one per half degree)
_POLAR_NORTH, _POLAR_SOUTH = 84.0, -80.0  # where UTM ends and UPS takes over
_LOSS_WARN = 1e-4  # relative area left out worth a warning (the shoelace on the densified edges is ~1e-8)
_EPS_INDEX = 1e-6  # a node this close (in sample steps) to the lattice's border is inside (PROJ's round-off)


def _crs(crs, source="heights", what=None):
    """rasterio's CRS for ``crs``; our ValueError (naming ``source``) when PROJ does not know it."""
    import rasterio
    from rasterio.crs import CRS
    from rasterio.errors import CRSError

    try:
        with rasterio.Env():  # rasterio's error handler: PROJ's complaint in the exception, not on stderr
            return CRS.from_user_input(crs)
    except (CRSError, TypeError, ValueError) as exc:
        said = what or f"crs={crs!r}"
        raise ValueError(f"{source}: {said} is not a known CRS ({exc}): pass an EPSG code or WKT PROJ knows, "
                         "e.g. 'EPSG:32633'.") from None


def _transform(src, dst, xs, ys, source, names):
    """PROJ's transform of the points; our ValueError when PROJ refuses them."""
    import rasterio
    from rasterio.errors import CRSError
    from rasterio.warp import transform

    try:
        with rasterio.Env():
            tx, ty = transform(src, dst, np.asarray(xs, float).ravel(), np.asarray(ys, float).ravel())
    except (CRSError, Exception) as exc:  # PROJ's errors come as rasterio's CPLE_* (bare Exception subclasses)
        raise ValueError(f"{source}: PROJ cannot take the grid's coordinates from {names[0]} to {names[1]} ({exc}); "
                         "pass another crs= (read option) or keep_geographic=True.") from None
    return np.asarray(tx, dtype=np.float64), np.asarray(ty, dtype=np.float64)


def is_geographic(crs) -> bool:
    """True when ``crs`` (``"EPSG:4326"``, WKT, ...) has angular x, y; False for None or a projected CRS.

    >>> is_geographic("EPSG:4326"), is_geographic("EPSG:32633"), is_geographic(None), is_geographic("UTM zone 33")
    (True, False, False, False)
    """
    if crs is None:
        return False
    try:
        return bool(_crs(crs).is_geographic)
    except ValueError:  # a description GDAL does not parse ("UTM zone 33" from a USGS DEM header): not degrees
        return False


def local_metric_crs(lon: float, lat: float) -> str:
    """The WGS84 UTM zone containing ``(lon, lat)``, or UPS beyond 84 degrees N / 80 degrees S.

    >>> local_metric_crs(7.5, 45.9), local_metric_crs(-70.6, -33.4), local_metric_crs(179.9, 10.0)
    ('EPSG:32632', 'EPSG:32719', 'EPSG:32660')
    >>> local_metric_crs(20.0, 86.0)
    'EPSG:32661'
    """
    if lat > _POLAR_NORTH:
        return "EPSG:32661"
    if lat < _POLAR_SOUTH:
        return "EPSG:32761"
    lon = (lon + 180.0) % 360.0 - 180.0
    zone = min(int((lon + 180.0) // 6.0) + 1, 60)
    return f"EPSG:{(32600 if lat >= 0 else 32700) + zone}"


def _default_crs(lon0, lon1, lat0, lat1, source) -> str:
    """UPS when the grid reaches a polar cap, else the UTM zone of its centre."""
    north, south = lat1 > _POLAR_NORTH, lat0 < _POLAR_SOUTH
    if north and south:
        raise ValueError(f"{source}: the grid spans latitudes {lat0:.6g}..{lat1:.6g}, into both polar caps: no one "
                         "metric CRS holds it; pass crs= (read option) or keep_geographic=True.")
    if north or south:
        return "EPSG:32661" if north else "EPSG:32761"
    return local_metric_crs(0.5 * (lon0 + lon1), 0.5 * (lat0 + lat1))


def _not_degrees(shape, spacing, origin, crs, source):
    """The error message when the sample lattice cannot be longitude, latitude; None when it can."""
    ny, nx = shape
    lon0, lat0 = origin
    lon1, lat1 = lon0 + (nx - 1) * spacing[0], lat0 + (ny - 1) * spacing[1]
    tol = 1e-9
    if -90.0 - tol <= lat0 and lat1 <= 90.0 + tol and -360.0 <= lon0 and lon1 <= 540.0 and lon1 - lon0 <= 360.0 + tol:
        return None
    name = str(source).replace("\\", "/").rsplit("/", 1)[-1]
    return (f"{source}: coordinates x {lon0:.6g}..{lon1:.6g}, y {lat0:.6g}..{lat1:.6g} are not degrees: the file's "
            f"CRS label {crs} looks wrong; pass crs='EPSG:326zz' (read option; UTM zone zz north, 327zz south, or "
            "whatever CRS they are in) to take them in that CRS, or fix the label (gdal_edit.py -a_srs EPSG:<code> "
            f"{name}). Latitudes lie within -90..90 and longitudes within one turn.")


def degree_lengths(lat: float, crs="EPSG:4326") -> tuple:
    """Metres per degree of longitude and of latitude at latitude ``lat`` on the ellipsoid of ``crs``
    [Snyder1987, ch. 4: meridian radius M, prime-vertical radius N].

    >>> mx, my = degree_lengths(0.0)
    >>> round(mx, 1), round(my, 1)  # WGS84 at the equator
    (111319.5, 110574.3)
    >>> round(degree_lengths(60.0)[0] / mx, 4)  # about cos 60 degrees
    0.5013
    """
    c = _crs(crs, what=f"the CRS {crs!r}")
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


def _footprint(crs, dst_crs, box, source, names):
    """The boundary of the sample rectangle ``box = (lon0, lon1, lat0, lat1)`` in ``dst_crs``, densified
    (south edge west to east, east edge, north edge, west edge), as ``(x, y, sides, area, sag)``; ``sides``
    are index slices of the four edges, ``area`` the enclosed area (shoelace) and ``sag`` the largest
    distance of an edge's true midpoint between two ring points from their chord (the leading term of how
    far the curve strays beyond the ring)."""
    lon0, lon1, lat0, lat1 = box
    n_lon = max(_DENSIFY, int(math.ceil(abs(lon1 - lon0) / 0.5)) + 1)
    n_lat = max(_DENSIFY, int(math.ceil(abs(lat1 - lat0) / 0.5)) + 1)
    u, v = np.linspace(0.0, 1.0, n_lon), np.linspace(0.0, 1.0, n_lat)
    lons = np.concatenate([lon0 + u * (lon1 - lon0), np.full(n_lat, lon1), lon1 - u * (lon1 - lon0), np.full(n_lat, lon0)])
    lats = np.concatenate([np.full(n_lon, lat0), lat0 + v * (lat1 - lat0), np.full(n_lon, lat1), lat1 - v * (lat1 - lat0)])
    mid_lons, mid_lats = 0.5 * (lons + np.roll(lons, -1)), 0.5 * (lats + np.roll(lats, -1))
    x, y = _transform(crs, dst_crs, np.concatenate([lons, mid_lons]), np.concatenate([lats, mid_lats]), source, names)
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise ValueError(f"{source}: {names[1]} cannot hold the grid's footprint (longitude {lon0:.6g}..{lon1:.6g}, "
                         f"latitude {lat0:.6g}..{lat1:.6g}): PROJ sends part of it to infinity; pass another crs= "
                         "(read option; without it the UTM zone or, near a pole, UPS is chosen) or keep_geographic=True.")
    n = lons.size
    x, y, mx, my = x[:n], y[:n], x[n:], y[n:]
    # sag of the curved edges between the ring's points: the true midpoints off the chords' midpoints
    sag = float(np.hypot(mx - 0.5 * (x + np.roll(x, -1)), my - 0.5 * (y + np.roll(y, -1))).max())
    a, b, c = n_lon, n_lon + n_lat, 2 * n_lon + n_lat
    sides = {"south": slice(0, a), "east": slice(a, b), "north": slice(b, c), "west": slice(c, None)}
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    return x, y, sides, area, sag


def _source_positions(dst_crs, crs, x0, y0, dx, dy, shape, source, names, chunk=1 << 20):
    """Longitude, latitude of every node of the new lattice, by PROJ exactly (in row chunks)."""
    ny, nx = shape
    xs = x0 + dx * np.arange(nx)
    lon, lat = np.empty(shape), np.empty(shape)
    rows = max(1, chunk // nx)
    for j in range(0, ny, rows):
        jj = np.arange(j, min(ny, j + rows))
        X = np.broadcast_to(xs, (len(jj), nx)).ravel()
        Y = np.repeat(y0 + dy * jj, nx)
        lo, la = _transform(dst_crs, crs, X, Y, source, names[::-1])
        lon[jj], lat[jj] = lo.reshape(len(jj), nx), la.reshape(len(jj), nx)
    return lon, lat


def _lattice(lo, hi, step, whole):
    """(first node, count) of a lattice of ``step`` centred on ``[lo, hi]``: covering it (``whole``) or inside it."""
    n = (int(math.ceil((hi - lo) / step)) if whole else int(math.floor((hi - lo) / step))) + 1
    return lo + 0.5 * ((hi - lo) - (n - 1) * step), n


def to_metric(heights, spacing, origin, crs, target=None, resampling="bilinear", source="heights",
              fill=None) -> Metric:
    """Reproject a gap-free geographic grid (rows south to north) to ``target`` or its local metric CRS.

    Parameters
    ----------
    heights : (ny, nx) array of float
        Finite (fill gaps first).
    spacing, origin : (2,) floats
        Degrees; ``origin`` is the south-west sample.
    crs : str
        The grid's CRS (geographic).
    target : str or None
        A projected CRS (``"EPSG:32632"``); None chooses the UTM zone of the centre, or UPS when the grid
        reaches beyond 84 N / 80 S (module notes).
    resampling : {"bilinear", "cubic", "nearest"}
        ``"cubic"`` is the interpolating bicubic spline of the samples (scipy's ``RectBivariateSpline``,
        ``s=0``: it reproduces cubic polynomials up to the border).
    source : str
        Named first in messages.
    fill : {None, "nearest", "linear"}
        None: the largest north-up rectangle inside the footprint (the area left out warned), and a
        ValueError for a grid reaching a polar cap; otherwise all of the footprint, the nodes outside it
        filled so (module notes).

    Examples
    --------
    >>> lon, lat = np.meshgrid(np.linspace(7.0, 7.2, 21), np.linspace(45.0, 45.1, 11))
    >>> h = 100 + 1000 * (lon - 7) + 500 * (lat - 45)
    >>> with warnings.catch_warnings(record=True) as said:
    ...     warnings.simplefilter("always")
    ...     m = to_metric(h, (0.01, 0.01), (7.0, 45.0), "EPSG:4326")
    >>> m.crs, m.heights.shape, [round(s, 1) for s in m.spacing], str(said[0].message).split(": ")[1][:42]
    ('EPSG:32632', (10, 20), [787.8, 1111.3], 'the reprojection to EPSG:32632 keeps 85.52')
    >>> m = to_metric(h, (0.01, 0.01), (7.0, 45.0), "EPSG:4326", fill="nearest")  # all of the footprint
    >>> m.heights.shape, m.note.split("; ")[-1]
    ((12, 22), '100.00 % of the footprint kept, 64 nodes (24.24 %) outside it filled (nearest))')
    """
    from scipy.interpolate import RectBivariateSpline
    from scipy.ndimage import map_coordinates

    from .height_interp import fill_gaps

    if resampling not in _RESAMPLING:
        raise ValueError(f"{source}: resampling for the reprojection must be one of {_RESAMPLING}, got {resampling!r}.")
    if fill not in _FILLS:
        raise ValueError(f"{source}: fill must be one of {_FILLS}, got {fill!r}.")
    h = np.asarray(heights, dtype=np.float64)
    if not np.isfinite(h).all():
        raise ValueError(f"{source}: fill the gaps before reprojecting (fill='nearest' or 'linear').")
    ny, nx = h.shape
    (dlon, dlat), (lon0, lat0) = (float(v) for v in spacing), (float(v) for v in origin)
    bad = _not_degrees(h.shape, (dlon, dlat), (lon0, lat0), crs, source)
    if bad is not None:
        if target is None or _crs(target, source).is_geographic:
            raise ValueError(bad)
        said = (f"coordinates are not degrees although the file's CRS label says {crs}: taken as {target} (crs=) "
                "as they are, unresampled")
        warnings.warn(f"{source}: {said}.", stacklevel=2)
        return Metric(h, (dlon, dlat), (lon0, lat0), str(target), said)
    lon1, lat1 = lon0 + (nx - 1) * dlon, lat0 + (ny - 1) * dlat
    chosen = target is None
    dst = _default_crs(lon0, lon1, lat0, lat1, source) if chosen else str(target)
    dst_crs = _crs(dst, source)
    if dst_crs.is_geographic:
        raise ValueError(f"{source}: crs={target!r} is geographic (degrees); pass a projected CRS in metres, "
                         "e.g. a UTM zone 'EPSG:326zz', or keep_geographic=True.")
    names = (str(crs), dst)
    if abs(nx * dlon - 360.0) <= 1e-9 * 360.0:  # the whole circle: the last column's east neighbour is the first
        h = np.concatenate([h, h[:, :1]], axis=1)
        lon1 = lon0 + 360.0
    polar = lat1 > _POLAR_NORTH or lat0 < _POLAR_SOUTH
    fx, fy, sides, area, sag = _footprint(crs, dst_crs, (lon0, lon1, lat0, lat1), source, names)
    cells = (h.shape[1] - 1) * (ny - 1)
    if polar:  # one square spacing with the source's mean cell area
        dx = dy = math.sqrt(area / cells)
    else:
        mx, my = degree_lengths(0.5 * (lat0 + lat1), crs)
        dx, dy = dlon * mx, dlat * my
    whole = fill is not None or polar
    if whole:  # the bounding box, wider by twice the sag of the densified edges
        x0, mx_n = _lattice(fx.min() - 2.0 * sag, fx.max() + 2.0 * sag, dx, True)
        y0, my_n = _lattice(fy.min() - 2.0 * sag, fy.max() + 2.0 * sag, dy, True)
        if fill is None:
            out_pct = 100.0 * max(0.0, 1.0 - area / ((mx_n - 1) * dx * (my_n - 1) * dy))
            raise ValueError(
                f"{source}: the grid reaches the polar cap (latitudes {lat0:.6g}..{lat1:.6g}), where the meridians "
                f"meet: {out_pct:.1f} % of the nodes of the {dst} grid holding all of it lie outside the footprint "
                f"(longitude {lon0:.6g}..{lon1:.6g}) and have no height. Pass fill='nearest' or fill='linear' "
                "(read option) to fill them as gaps, another projected crs=, or keep_geographic=True.")
    else:  # the largest north-up rectangle inside: the innermost coordinate of each side
        left, right = fx[sides["west"]].max(), fx[sides["east"]].min()
        bottom, top = fy[sides["south"]].max(), fy[sides["north"]].min()
        x0, mx_n = _lattice(left, right, dx, False) if right > left else (left, 0)
        y0, my_n = _lattice(bottom, top, dy, False) if top > bottom else (bottom, 0)
        if mx_n < 2 or my_n < 2:
            raise ValueError(f"{source}: no north-up rectangle of 2 x 2 samples of {dx:.4g} x {dy:.4g} m fits inside "
                             f"the grid's footprint in {dst} (it is turned or thin there); pass fill='nearest' (read "
                             "option) to keep all of it (the nodes outside filled as gaps), another crs=, or "
                             "keep_geographic=True.")
    lon, lat = _source_positions(dst_crs, crs, x0, y0, dx, dy, (my_n, mx_n), source, names)
    east = (lon - lon0) % 360.0  # degrees east of the first column, within one turn
    east = np.where(east > 360.0 - _EPS_INDEX * dlon, east - 360.0, east)
    cols, rows = east / dlon, (lat - lat0) / dlat
    last_col, last_row = h.shape[1] - 1.0, ny - 1.0
    inside = ((cols >= -_EPS_INDEX) & (cols <= last_col + _EPS_INDEX) & (rows >= -_EPS_INDEX)
              & (rows <= last_row + _EPS_INDEX))
    cols, rows = np.clip(cols, 0.0, last_col), np.clip(rows, 0.0, last_row)
    if resampling == "cubic":  # not-a-knot interpolating bicubic spline: reproduces cubics up to the border
        out = RectBivariateSpline(np.arange(ny), np.arange(h.shape[1]), h, kx=3, ky=3, s=0).ev(rows, cols)
    else:
        out = map_coordinates(h, [rows, cols], order={"nearest": 0, "bilinear": 1}[resampling], mode="nearest")
    n_out = int((~inside).sum())
    if whole:
        kept = 100.0
        if n_out:
            out = fill_gaps(out, ~inside, (dx * np.arange(mx_n), dy * np.arange(my_n)), fill)
    else:
        kept = min(100.0, 100.0 * (mx_n - 1) * dx * (my_n - 1) * dy / area)
        if kept < 100.0 * (1.0 - _LOSS_WARN):
            warnings.warn(f"{source}: the reprojection to {dst} keeps {kept:.2f} % of the file's footprint: the largest "
                          f"north-up rectangle inside it and the lattice of the source's spacing in that leave out "
                          f"{100.0 - kept:.2f} % along the edges (the meridians converge); pass fill='nearest' (read option) to keep all of it (the nodes "
                          "outside it filled as gaps) or keep_geographic=True.", stacklevel=2)
    if not chosen:
        how = "as asked"
    elif polar:
        how = "chosen as UPS: the grid reaches beyond 84 N / 80 S"
    else:
        how = "chosen as the UTM zone of the centre"
    outside = f", {n_out} nodes ({100.0 * n_out / out.size:.2f} %) outside it filled ({fill})" if whole and n_out else ""
    note = (f"reprojected from {crs} to {dst} ({how}; {resampling}, {mx_n} x {my_n} samples of {dx:.6g} x {dy:.6g} m, "
            f"SW node at lon {lon[0, 0]:.6f}, lat {lat[0, 0]:.6f}; {kept:.2f} % of the footprint kept{outside})")
    return Metric(out, (dx, dy), (x0, y0), dst, note)


def scale_geographic(heights, spacing, origin, crs, source="heights") -> Metric:
    """Keep the degree lattice; x, y become degrees times metres per degree at the centre latitude.

    >>> m = scale_geographic(np.zeros((3, 3)), (0.5, 0.5), (10.0, 59.5), "EPSG:4326")
    >>> [round(v, 1) for v in m.spacing], m.crs
    ([27900.0, 55706.1], 'EPSG:4326 scaled to metres at latitude 60')
    """
    h = np.asarray(heights, dtype=np.float64)
    bad = _not_degrees(h.shape, spacing, origin, crs, source)
    if bad is not None:
        raise ValueError(bad)
    ny = h.shape[0]
    lat_c = origin[1] + 0.5 * (ny - 1) * spacing[1]
    mx, my = degree_lengths(lat_c, crs)
    note = (f"kept on its {crs} lattice (keep_geographic=True): x = longitude x {mx:.6g} m, y = latitude x "
            f"{my:.6g} m (lengths of a degree at latitude {lat_c:.6g}; true there only)")
    return Metric(h, (spacing[0] * mx, spacing[1] * my), (origin[0] * mx, origin[1] * my),
                  f"{crs} scaled to metres at latitude {lat_c:.6g}", note)
