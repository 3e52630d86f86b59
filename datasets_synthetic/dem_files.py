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


def write_usgs_ascii_dem(path, heights, spacing, origin, *, z_resolution=None, utm_zone: int = 33,
                         label: str = "splinevis synthetic DEM", clip_profiles: bool = False,
                         corners=None) -> Path:
    """Write a minimal USGS ASCII DEM (planimetric system UTM, metres in x, y and z).

    Parameters
    ----------
    path : str or Path
    heights : (ny, nx) array_like
        Rows south to north; NaN becomes the void value -32767.
    spacing : (dx, dy) floats > 0
        Written as E12.6: 7 significant digits.
    origin : (x0, y0)
        South-west sample; corners are written as D24.15 (16 significant digits).
    z_resolution : float, optional
        Elevations are stored as integers times this. Default: the finest of 0.001, 0.01, ..., 100
        that keeps every integer within the 6-character field (-99999 .. 999999).
    utm_zone : int
        Zone written in the header (metadata only; the coordinates need not be real UTM).
    label : str
        First 144 characters of the header.
    clip_profiles : bool
        Write each profile only from its first to its last non-NaN sample, starting at that sample's
        own northing (as USGS 7.5-minute DEMs clipped by the quadrangle do); a column of only NaN
        is written as a one-sample void profile at its southern node.
    corners : four (x, y) pairs, optional
        Quadrangle corners SW, NW, NE, SE for the header (need not lie on the sample lattice).
        Default: the corner samples.

    Returns
    -------
    Path

    Notes
    -----
    Layout: a 1024-character type A record, then one type B record per column (profile), each
    padded to 1024-character blocks (146 elevations in the first block, 170 in each further one),
    elevations south to north. ``vtkDEMReader`` computes the number of columns/rows from the corners
    in float32, so origin and extent should be exact in float32 (e.g. whole metres); this writer
    refuses values for which VTK would count differently. Also, VTK 9.7.1's reader crashes (division
    by zero) on DEMs with fewer than 100 columns; :func:`splinevis.io.read_heights` parses those itself.
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
    a += _i6(1) + _i6(1) + _i6(1) + _i6(utm_zone)  # level 1, regular pattern, UTM, zone
    a += "".join(_d24(0.0) for _ in range(15))  # projection parameters (unused for UTM)
    a += _i6(2) + _i6(2) + _i6(4)  # plane unit metres, elevation unit metres, 4 sides
    for cx, cy in corners or ((x0, y0), (x0, yn), (xe, yn), (xe, y0)):  # SW, NW, NE, SE
        a += _d24(cx) + _d24(cy)
    a += _d24(zmin) + _d24(zmax) + _d24(0.0) + _i6(0)  # elevation bounds, rotation, accuracy code
    a += "".join(f"{v:12.6E}" for v in (dx, dy, z_resolution))
    a += _i6(1) + _i6(nx)  # rows (1 for a regular DEM), columns = number of profiles
    records = [a.ljust(1024)]
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
        cells = [_i6(v) for v in col]
        blocks = [head + "".join(cells[:146])]
        for s in range(146, col.size, 170):
            blocks.append("".join(cells[s:s + 170]))
        records.extend(b.ljust(1024) for b in blocks)
    path = Path(path)
    path.write_bytes("".join(records).encode("ascii"))
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
