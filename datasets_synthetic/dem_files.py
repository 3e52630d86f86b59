"""Small elevation files written locally (no downloads) and a fractal terrain for demos.

* :func:`write_usgs_ascii_dem` - a minimal USGS ASCII DEM (type A header + one type B record per
  column), readable by VTK's ``vtkDEMReader`` and :func:`splinevis.io.read_heights`.
* :func:`write_geotiff` - a single-band GeoTIFF (or COG) with CRS, nodata and PixelIsArea or
  PixelIsPoint, through rasterio.
* :func:`fractal_terrain` - spectral-synthesis fractal heights.

All writers take heights in splinevis' orientation: ``heights[j, i]`` at ``(x0 + i*dx, y0 + j*dy)``,
rows running south to north; ``origin`` is the south-west sample. NaN heights are written as gaps
(DEM void -32767, or ``nodata`` in a GeoTIFF).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["write_usgs_ascii_dem", "write_geotiff", "fractal_terrain", "DEM_VOID"]

DEM_VOID = -32767  #: integer elevation marking a void sample in a USGS DEM


def _check_grid(heights, spacing, origin):
    h = np.asarray(heights, dtype=np.float64)
    if h.ndim != 2 or h.shape[0] < 2 or h.shape[1] < 2:
        raise ValueError(f"heights must be a 2-D array with at least 2 x 2 samples, got shape {h.shape}.")
    if np.isinf(h).any():
        raise ValueError("heights must not contain inf (NaN marks a gap).")
    sp = np.broadcast_to(np.asarray(spacing, dtype=np.float64), (2,))
    org = np.asarray(origin, dtype=np.float64)
    if org.shape != (2,) or not np.isfinite(org).all():
        raise ValueError(f"origin must be two finite numbers (x0, y0), got {origin!r}.")
    if not (np.isfinite(sp).all() and (sp > 0).all()):
        raise ValueError(f"spacing must be two finite numbers > 0, got {spacing!r}.")
    return h, (float(sp[0]), float(sp[1])), (float(org[0]), float(org[1]))


# ---- USGS ASCII DEM ---------------------------------------------------------------------------------
def _d24(v: float) -> str:
    """Fortran D24.15 (16 significant digits)."""
    return f"{v:24.15E}".replace("E", "D")


def _i6(v: int) -> str:
    s = f"{int(v):6d}"
    if len(s) != 6:
        raise ValueError(f"{v} does not fit the DEM's 6-character integer field.")
    return s


def _i6_bytes(values) -> bytes:
    """Right-justified I6 fields of the integers ``values``, concatenated (vectorized: a 3000 x 3000 DEM's nine
    million fields in a second)."""
    v = np.asarray(values, dtype=np.int64).ravel()
    a = np.abs(v)
    width = np.maximum(1, np.floor(np.log10(np.maximum(a, 1))).astype(np.int64) + 1) + (v < 0)
    if (width > 6).any():
        bad = v[np.argmax(width > 6)]
        raise ValueError(f"{bad} does not fit the DEM's 6-character integer field.")
    out = np.full((v.size, 6), ord(" "), dtype=np.uint8)
    for p in range(6):  # column p holds the digit of 10^(5 - p)
        digit = (a // 10 ** (5 - p)) % 10
        shown = p >= 6 - width + (v < 0)
        out[:, p] = np.where(shown, 48 + digit, out[:, p])
    neg = np.flatnonzero(v < 0)
    out[neg, 6 - width[neg]] = ord("-")
    return out.tobytes()


def write_usgs_ascii_dem(path, heights, spacing, origin, *, z_resolution=None, utm_zone: int = 33,
                         label: str = "splinevis synthetic DEM", clip_profiles: bool = False,
                         corners=None, geographic: bool = False, horizontal_datum: int | None = 3,
                         vertical_datum: int | None = 3, accuracy=None, line_breaks: bool = False) -> Path:
    """Write a USGS ASCII DEM (records A, B and, with ``accuracy``, C; metres in z).

    Parameters
    ----------
    path : str or Path
    heights : (ny, nx) array_like
        Rows south to north; NaN becomes the void value -32767.
    spacing : (dx, dy) floats > 0
        Written as E12.6: 7 significant digits. Metres, or arc-seconds when ``geographic``.
    origin : (x0, y0)
        South-west sample; corners are written as D24.15 (16 significant digits). Metres (UTM), or
        arc-seconds of longitude and latitude when ``geographic``.
    z_resolution : float, optional
        Elevations are stored as integers times this. Default: the finest of 0.001, 0.01, ..., 100
        that keeps every integer within the 6-character field (-99999 .. 999999).
    utm_zone : int
        Zone written in the header (the coordinates need not be real UTM); ignored when ``geographic``.
    label : str
        First 144 characters of the header.
    clip_profiles : bool
        Write each profile only from its first to its last non-NaN sample, starting at that sample's
        own northing (as USGS 7.5-minute DEMs clipped by the quadrangle do); a column of only NaN
        is written as a one-sample void profile at its southern node.
    corners : four (x, y) pairs, optional
        Quadrangle corners SW, NW, NE, SE for the header (need not lie on the sample lattice).
        Default: the corner samples.
    geographic : bool
        Planimetric system 0 (geographic), x and y in arc-seconds (as the USGS 1-degree DEMs), instead of
        system 1 (UTM) in metres.
    horizontal_datum, vertical_datum : int or None
        Codes of the type A record's columns 891-892 (1 NAD 27, 2 WGS 72, 3 WGS 84, 4 NAD 83) and 889-890
        (1 local mean sea level, 2 NGVD 29, 3 NAVD 88); None leaves them blank, as files made before these
        fields existed do.
    accuracy : ten ints, optional
        The type C (accuracy) record's fields: datum RMSE available (0/1), RMSE x, y, z, sample size, then the
        same for the DEM; written after the profiles, with the type A accuracy code 1.
    line_breaks : bool
        End every 1024-character block with a line break (as some distributions do).

    Returns
    -------
    Path

    Notes
    -----
    Layout: a 1024-character type A record, then one type B record per column (profile), each
    padded to 1024-character blocks (146 elevations in the first block, 170 in each further one),
    elevations south to north, then the optional type C record in one block. ``vtkDEMReader`` computes
    the number of columns/rows from the corners in float32, so origin and extent should be exact in
    float32 (e.g. whole metres); this writer refuses values for which VTK would count differently. Also,
    VTK 9.7.1's reader crashes (division by zero) on DEMs with fewer than 100 columns;
    :func:`splinevis.io.read_heights` parses those itself.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_usgs_ascii_dem(Path(folder) / "a.dem", [[1, 2], [3, 4]], 30.0, (5e5, 5e6),
    ...                                 accuracy=(0,) * 10)
    ...     text = path.read_text()
    >>> len(text), text[156:168], text[888:892], text[810:816]  # A + 2 profiles + C; UTM 33; datums; code
    (4096, '     1    33', ' 3 3', '     1')
    """
    h, (dx, dy), (x0, y0) = _check_grid(heights, spacing, origin)
    ny, nx = h.shape
    finite = h[np.isfinite(h)]
    if finite.size == 0:
        raise ValueError("heights are all NaN; a DEM needs at least one elevation.")
    if z_resolution is None:
        big = float(np.abs(finite).max())
        z_resolution = next((r for r in (0.001, 0.01, 0.1, 1.0, 10.0, 100.0) if big / r <= 99999), None)
        if z_resolution is None:
            raise ValueError(f"heights up to {big} do not fit a DEM's integer field even at z_resolution 100.")
    if not (math.isfinite(z_resolution) and z_resolution > 0):
        raise ValueError(f"z_resolution must be finite and > 0, got {z_resolution!r}.")
    if accuracy is not None and len(accuracy) != 10:
        raise ValueError(f"accuracy must be the type C record's ten integers, got {len(accuracy)}.")
    k = np.where(np.isfinite(h), np.rint(np.nan_to_num(h) / z_resolution), DEM_VOID).astype(np.int64)
    if (np.isfinite(h) & (k == DEM_VOID)).any():
        raise ValueError(f"a height rounds to the void value {DEM_VOID} * z_resolution; change z_resolution.")
    xe, yn = x0 + (nx - 1) * dx, y0 + (ny - 1) * dy
    # What vtkDEMReader will compute (float32 arithmetic, truncation).
    f32 = np.float32
    for n, lo, hi, step, axis in ((nx, x0, xe, dx, "x"), (ny, y0, yn, dy, "y")):
        vtk_n = int((f32(hi) - f32(lo)) / f32(float(f"{step:12.6E}")) + f32(1.0))
        if vtk_n != n:
            raise ValueError(f"vtkDEMReader would count {vtk_n} samples in {axis} instead of {n} (it works in "
                             f"float32); choose an origin/spacing exact in float32, e.g. whole metres.")
    valid = k[k != DEM_VOID]
    zmin, zmax = float(valid.min()) * z_resolution, float(valid.max()) * z_resolution

    a = label[:144].ljust(144)
    system, zone, unit = (0, 0, 3) if geographic else (1, utm_zone, 2)  # arc-seconds or metres
    a += _i6(1) + _i6(1) + _i6(system) + _i6(zone)  # level 1, regular pattern, planimetric system, zone
    a += "".join(_d24(0.0) for _ in range(15))  # projection parameters (unused for UTM and geographic)
    a += _i6(unit) + _i6(2) + _i6(4)  # plane unit, elevation unit metres, 4 sides
    for cx, cy in corners or ((x0, y0), (x0, yn), (xe, yn), (xe, y0)):  # SW, NW, NE, SE
        a += _d24(cx) + _d24(cy)
    a += _d24(zmin) + _d24(zmax) + _d24(0.0) + _i6(0 if accuracy is None else 1)  # bounds, rotation, accuracy
    a += "".join(f"{v:12.6E}" for v in (dx, dy, z_resolution))
    a += _i6(1) + _i6(nx)  # rows (1 for a regular DEM), columns = number of profiles
    a += " " * 24  # 865-888: contour intervals, dates, flags (blank)
    a += "  " if vertical_datum is None else f"{int(vertical_datum):2d}"
    a += "  " if horizontal_datum is None else f"{int(horizontal_datum):2d}"
    records = [a.ljust(1024).encode("ascii")]
    for i in range(nx):
        col, j0 = k[:, i], 0
        if clip_profiles:
            rows = np.flatnonzero(np.isfinite(h[:, i]))
            j0 = int(rows[0]) if rows.size else 0
            col = col[j0:int(rows[-1]) + 1] if rows.size else col[:1]
        good = col[col != DEM_VOID]
        lo_hi = (float(good.min()) * z_resolution, float(good.max()) * z_resolution) if good.size else (0.0, 0.0)
        head = _i6(1) + _i6(i + 1) + _i6(col.size) + _i6(1)
        head += _d24(x0 + i * dx) + _d24(y0 + j0 * dy) + _d24(0.0) + _d24(lo_hi[0]) + _d24(lo_hi[1])
        cells = _i6_bytes(col)
        records.append((head.encode("ascii") + cells[:6 * 146]).ljust(1024))
        records.extend(cells[s:s + 6 * 170].ljust(1024) for s in range(6 * 146, len(cells), 6 * 170))
    if accuracy is not None:
        records.append(_i6_bytes(accuracy).ljust(1024))
    path = Path(path)
    path.write_bytes((b"\n" if line_breaks else b"").join(records) + (b"\n" if line_breaks else b""))
    return path


# ---- GeoTIFF -----------------------------------------------------------------------------------------
def write_geotiff(path, heights, spacing, origin, *, nodata=None, epsg: int | None = None,
                  pixel_is_area: bool = True, dtype=np.float64, driver: str = "GTiff") -> Path:
    """Write a single-band, north-up GeoTIFF through rasterio (GDAL).

    Parameters
    ----------
    path : str or Path
    heights : (ny, nx) array_like
        Rows south to north (they are stored north first, as GeoTIFFs usually are). NaN samples are
        written as ``nodata`` when it is given.
    spacing, origin : (2,) floats
        Sample spacing and the south-west sample position.
    nodata : float, optional
        The band's nodata value (GDAL_NODATA tag).
    epsg : int, optional
        CRS as an EPSG code (projected or geographic).
    pixel_is_area : bool
        ``AREA_OR_POINT``: True writes PixelIsArea (the tiepoint is the outer corner of the north-west
        pixel, half a pixel beyond the sample); False writes PixelIsPoint (tiepoint = the sample).
        Either way each sample is at its own position when read back through GDAL.
    dtype : numpy dtype
        Sample type stored (default float64: exact round trips).
    driver : str
        ``"GTiff"`` or ``"COG"`` (cloud-optimized GeoTIFF).

    Examples
    --------
    >>> import tempfile, rasterio
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_geotiff(Path(folder) / "h.tif", [[1.0, 2.0], [3.0, 4.0]], (10.0, 10.0), (5e5, 5e6),
    ...                          epsg=32633, pixel_is_area=False)
    ...     with rasterio.open(path) as ds:
    ...         stored, corner, point = ds.read(1).tolist(), (ds.transform.c, ds.transform.f), ds.tags()["AREA_OR_POINT"]
    >>> stored, corner, point  # north row first; GDAL's corner is half a pixel beyond the NW sample
    ([[3.0, 4.0], [1.0, 2.0]], (499995.0, 5000015.0), 'Point')
    """
    import rasterio
    from affine import Affine

    h, (dx, dy), (x0, y0) = _check_grid(heights, spacing, origin)
    ny, nx = h.shape
    if nodata is not None:
        h = np.where(np.isnan(h), nodata, h)
    data = np.ascontiguousarray(h[::-1, :]).astype(dtype)  # north row first
    y_top = y0 + (ny - 1) * dy
    # GDAL's geotransform always names the outer corner of the north-west pixel; for PixelIsPoint GDAL
    # itself writes the tiepoint half a pixel inwards, on the sample.
    transform = Affine(dx, 0.0, x0 - 0.5 * dx, 0.0, -dy, y_top + 0.5 * dy)
    path = Path(path)
    with rasterio.open(path, "w", driver=driver, width=nx, height=ny, count=1, dtype=data.dtype,
                       crs=f"EPSG:{int(epsg)}" if epsg else None, transform=transform, nodata=nodata) as ds:
        ds.update_tags(AREA_OR_POINT="Area" if pixel_is_area else "Point")
        ds.write(data, 1)
    return path


# ---- fractal terrain ----------------------------------------------------------------------------------
def fractal_terrain(n: int, seed: int = 0, *, hurst: float = 0.8, amplitude: float = 1.0) -> np.ndarray:
    """(n, n) float64 fractal heights in ``[0, amplitude]`` by spectral synthesis.

    White Gaussian noise is shaped in Fourier space by ``|k|**-(hurst + 1)`` (fractional Brownian
    surface, fractal dimension ``3 - hurst``) and transformed back; the result is periodic
    [Voss1985].
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}.")
    if not (0.0 < hurst < 1.0):
        raise ValueError(f"hurst must be in (0, 1), got {hurst!r}.")
    rng = np.random.default_rng(seed)
    noise = np.fft.rfft2(rng.standard_normal((n, n)))
    ky = np.fft.fftfreq(n)[:, None]
    kx = np.fft.rfftfreq(n)[None, :]
    k = np.hypot(kx, ky)
    k[0, 0] = np.inf  # drop the mean
    z = np.fft.irfft2(noise * k ** -(hurst + 1.0), s=(n, n))
    z -= z.min()
    return z * (amplitude / z.max())
