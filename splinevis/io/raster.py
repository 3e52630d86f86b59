"""Georeferenced rasters (GeoTIFF/COG, SRTM ``.hgt``, ESRI ASCII grid, Erdas ``.img``, ...) as heights.

Read through `rasterio <https://rasterio.readthedocs.io>`_, i.e. GDAL: the library the geospatial
field reads rasters with. GDAL decodes the georeference of every format it knows (GeoTIFF geokeys,
``.hgt`` file names, ``xllcorner``/``xllcenter``, world files, ...) into one affine geotransform, names
the CRS, knows each band's nodata value and mask, and reports truncated or corrupt files as read
errors; none of this is re-implemented here.

What is read
------------
* One band (``band=``, 1-based) of any raster GDAL opens.
* Sample ``(row r, col c)`` sits at ``transform * (c + 0.5, r + 0.5)``, the pixel centre. GDAL already
  shifts PixelIsPoint rasters (GeoTIFF ``AREA_OR_POINT=Point``, ``.hgt`` whose corner samples sit on
  whole degrees, ``.asc`` with ``xllcenter``) by half a pixel, so this holds for every format.
* North-up rasters (negative y pixel size) store the northern row first and are flipped
  (``flip_rows``); a south-up raster is kept. The error messages count rows and columns as stored.
  A rotated or sheared geotransform raises: warp the raster north-up first (gdalwarp).
* ``crs`` is ``"EPSG:<code>"`` when GDAL finds an EPSG code, else the WKT, None without a CRS; either
  string round-trips through ``rasterio.crs.CRS.from_user_input`` (e.g. to ask ``is_geographic``). A
  CRS PROJ cannot express so is a ValueError naming the file, not rasterio's CRSError.
  ``units`` is the band's unit (``"m"``, ``"ft"``) when GDAL knows it.
* Missing: NaN/inf, the band's nodata value (``nodata=`` replaces it) and samples GDAL's mask band
  (per-dataset mask or alpha) marks invalid. A band scale/offset is applied (float64) after the gaps
  are found.
* A raster without georeference (identity geotransform, no CRS) needs ``spacing=`` and ``origin=``;
  its first row is taken as north. A georeferenced raster refuses both.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ._common import check_exact_in_float64, check_real_dtype, refuse_own_geometry
from .height_samples import GEOMETRY_ARGS_APPLY_TO, HeightSamples, missing_mask

__all__ = ["read_raster", "RASTER_EXTENSIONS", "RasterOpenError"]

#: File name extensions routed to :func:`read_raster` by :func:`~splinevis.io.read_heights`, and what
#: GDAL reads them as (any other raster GDAL opens is read too).
RASTER_EXTENSIONS = {
    ".tif": "GeoTIFF/COG", ".tiff": "GeoTIFF/COG", ".hgt": "SRTM HGT", ".asc": "ESRI ASCII grid",
    ".img": "Erdas Imagine", ".bil": "ESRI BIL", ".dt0": "DTED 0", ".dt1": "DTED 1", ".dt2": "DTED 2",
    ".grd": "Surfer/GMT grid", ".vrt": "GDAL VRT",
}


class RasterOpenError(ValueError):
    """GDAL could not open the file as a raster: a ValueError whose ``gdal_message`` is GDAL's own words
    (:func:`~splinevis.io.read_heights` quotes them next to the list of what it reads).

    >>> err = RasterOpenError("x.foo: GDAL cannot open it", gdal_message="not recognized")
    >>> isinstance(err, ValueError), err.gdal_message
    (True, 'not recognized')
    """

    def __init__(self, message: str, *, gdal_message: str = ""):
        super().__init__(message)
        self.gdal_message = gdal_message


def _gdal_message(exc: BaseException) -> str:
    """The most specific GDAL message: rasterio chains the CPLE_* error under a generic one."""
    cause = exc.__cause__ or exc.__context__
    text = str(cause) if cause is not None and str(cause) else str(exc)
    return text.strip()


def _crs_string(crs, path) -> str | None:
    """``"EPSG:<code>"``, else the WKT, None without a CRS; a CRS PROJ cannot turn into either is our
    ValueError naming the file (rasterio's CRSError never escapes)."""
    import rasterio
    from rasterio.errors import CRSError

    if crs is None:
        return None
    try:
        with rasterio.Env():  # rasterio's error handler: PROJ's complaint in the exception, not on stderr
            epsg = crs.to_epsg()
            return f"EPSG:{epsg}" if epsg else crs.to_wkt()
    except CRSError as exc:
        raise ValueError(f"{path}: the file's CRS cannot be read ({exc}); set one PROJ knows, e.g. gdal_edit.py "
                         f"-a_srs EPSG:32633 {Path(path).name}.") from None


def read_raster(path, spacing=None, origin=None, nodata=None, band=1) -> HeightSamples:
    """Read one band of a raster GDAL opens as heights.

    Parameters
    ----------
    path : str or Path
        An existing raster file.
    spacing, origin : (2,) tuples or None
        Only for a raster without georeference (then both are needed: sample spacing and the
        south-west sample); refused otherwise.
    nodata : float or None
        Value marking missing samples besides NaN/inf; replaces the band's own nodata value.
    band : int
        1-based band number.

    Returns
    -------
    HeightSamples
        Values in stored order and dtype (float64 when a scale/offset applies).

    Raises
    ------
    RasterOpenError
        GDAL cannot open the file (a ValueError).
    ValueError
        Band out of range, rotated geotransform, truncated or corrupt file, geometry arguments for a
        georeferenced raster or none for a plain one, fewer than 2 x 2 samples.
    TypeError
        Complex samples.

    Examples
    --------
    A 2 x 3 north-up UTM GeoTIFF, 30 m pixels, corner at (500000, 5000060), one nodata sample:

    >>> import tempfile, rasterio
    >>> from affine import Affine
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "dem.tif"
    ...     with rasterio.open(path, "w", driver="GTiff", width=3, height=2, count=1, dtype="float32",
    ...                        crs="EPSG:32633", transform=Affine(30.0, 0.0, 5e5, 0.0, -30.0, 5000060.0),
    ...                        nodata=-9999) as ds:
    ...         ds.write(np.array([[1, 2, 3], [4, 5, -9999]], dtype=np.float32), 1)
    ...     s = read_raster(path)
    >>> s.values.tolist(), s.missing.tolist()
    ([[1.0, 2.0, 3.0], [4.0, 5.0, -9999.0]], [[False, False, False], [False, False, True]])
    >>> s.spacing, s.origin, s.flip_rows, s.crs  # origin: centre of the south-west pixel
    ((30.0, 30.0), (500015.0, 5000015.0), True, 'EPSG:32633')
    """
    import rasterio
    from rasterio.enums import MaskFlags
    from rasterio.errors import NotGeoreferencedWarning, RasterioError, RasterioIOError

    path = Path(path)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NotGeoreferencedWarning)
            ds = rasterio.open(path)
    except (RasterioIOError, RasterioError) as exc:
        said = _gdal_message(exc)
        raise RasterOpenError(
            f"{path}: GDAL cannot open it as a raster ({said}); if it is one, it is truncated or corrupt. "
            "Rasters are read through GDAL: "
            + ", ".join(f"{e} ({w})" for e, w in RASTER_EXTENSIONS.items()) + " and any other format GDAL knows.",
            gdal_message=said) from None
    with ds:
        if isinstance(band, bool) or not isinstance(band, (int, np.integer)) or not 1 <= band <= ds.count:
            raise ValueError(f"{path}: band {band!r} does not exist; the raster has {ds.count} band(s), "
                             f"pass band=1..{ds.count}.")
        rows, cols = ds.height, ds.width
        if rows < 2 or cols < 2:
            raise ValueError(f"{path}: heights need at least 2 x 2 samples, got {rows} rows x {cols} columns.")
        t = ds.transform
        georeferenced = ds.crs is not None or not t.is_identity
        if not georeferenced and ds.gcps[0]:
            raise ValueError(f"{path}: georeferenced by {len(ds.gcps[0])} ground control points only, not a "
                             "geotransform; warp it onto a north-up grid first, e.g. gdalwarp "
                             f"{path.name} north_up.tif.")
        if georeferenced and (t.b != 0 or t.d != 0):
            raise ValueError(f"{path}: the geotransform is rotated/sheared (terms {t.b!r}, {t.d!r}); only north-up "
                             "grids are supported. Warp it north-up first, e.g. gdalwarp -t_srs <its CRS> "
                             f"{path.name} north_up.tif.")
        if georeferenced and not (np.isfinite([t.a, t.e, t.c, t.f]).all() and t.a != 0 and t.e != 0):
            raise ValueError(f"{path}: degenerate geotransform {tuple(t)[:6]} (pixel size x {t.a}, y {t.e}).")
        try:
            values = ds.read(band)
            flags = ds.mask_flag_enums[band - 1]
            own_mask = MaskFlags.per_dataset in flags or MaskFlags.alpha in flags
            gdal_missing = ds.read_masks(band) == 0 if own_mask else None
        except (RasterioIOError, RasterioError) as exc:
            raise ValueError(f"{path}: GDAL could not read band {band} ({_gdal_message(exc)}); the file is "
                             "truncated or corrupt. Download or write it again.") from None
        file_nodata = ds.nodatavals[band - 1]
        scale, offset = ds.scales[band - 1], ds.offsets[band - 1]
        crs, units = _crs_string(ds.crs, path), (ds.units[band - 1] or None)
    check_real_dtype(values, str(path), "heights")
    check_exact_in_float64(values, str(path))
    missing = missing_mask(values, file_nodata if nodata is None else nodata)
    if gdal_missing is not None:
        missing |= gdal_missing
    if scale not in (None, 1.0) or offset not in (None, 0.0):
        values = values.astype(np.float64) * (1.0 if scale is None else scale) + (offset or 0.0)
    if not georeferenced:
        if spacing is None or origin is None:
            raise ValueError(f"{path}: no georeference (identity geotransform, no CRS); pass spacing= and origin= "
                             "to read it as a plain image (first row = north, origin = the south-west sample).")
        return HeightSamples(values=values, missing=missing, spacing=spacing, origin=origin, source=str(path),
                             flip_rows=True, order_note="(row, col) as stored, row 0 = north")
    refuse_own_geometry(spacing, origin, f"{path} (georeferenced)", applies_to=GEOMETRY_ARGS_APPLY_TO)
    flip_cols, flip_rows = bool(t.a < 0), bool(t.e < 0)
    # centre of the south-west sample: the first stored column unless x runs west, the last stored row
    # when y runs south (north-up)
    c0 = cols - 1 if flip_cols else 0
    r0 = rows - 1 if flip_rows else 0
    x0 = t.c + (c0 + 0.5) * t.a
    y0 = t.f + (r0 + 0.5) * t.e
    return HeightSamples(values=values, missing=missing, spacing=(abs(t.a), abs(t.e)), origin=(x0, y0),
                         source=str(path), flip_rows=flip_rows, flip_cols=flip_cols, crs=crs, units=units,
                         order_note="(row, col) as stored" + (", row 0 = north" if flip_rows else ""))
