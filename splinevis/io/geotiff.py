"""GeoTIFF files (``.tif``, ``.tiff``) as heights, through the optional package ``tifffile``.

What is read:

* One band; ModelPixelScaleTag + one ModelTiepointTag, or a ModelTransformationTag without
  rotation/shear (a rotated raster raises; warp it north-up first, e.g. with gdalwarp).
* GTRasterTypeGeoKey PixelIsArea (the default) puts each sample at its pixel centre, half a pixel
  inside the tiepoint corner; PixelIsPoint puts it on the raster coordinate itself.
* The CRS is ``"EPSG:<code>"`` from ProjectedCSTypeGeoKey or GeographicTypeGeoKey when present; the
  height unit from VerticalUnitsGeoKey. A ``GDAL_NODATA`` tag marks gaps (``nodata=`` overrides it).
* The file stores the northern row first; the rows are flipped to run south to north, while the error
  messages still count rows and columns as the file stores them.
* A TIFF without georeferencing needs ``spacing=`` and ``origin=``; its first row is taken as north.

The few geokeys above are decoded here from the raw GeoKeyDirectoryTag, so no GDAL installation is
needed; any other key is ignored.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ._common import refuse_own_geometry
from .height_samples import GEOMETRY_ARGS_APPLY_TO, HeightSamples, missing_mask

__all__ = ["read_geotiff"]

_GEOKEY_RASTER_TYPE = 1025  # GTRasterTypeGeoKey: 1 PixelIsArea (default), 2 PixelIsPoint
_GEOKEY_GEOGRAPHIC = 2048  # GeographicTypeGeoKey (EPSG code)
_GEOKEY_PROJECTED = 3072  # ProjectedCSTypeGeoKey (EPSG code)
_GEOKEY_VERTICAL_UNITS = 4099  # VerticalUnitsGeoKey
_EPSG_UNITS = {9001: "m", 9002: "ft", 9003: "US survey ft"}


def _geokeys(directory) -> dict:
    """Short-valued keys of a GeoKeyDirectoryTag (header 4 shorts, then 4 shorts per key)."""
    d = [int(v) for v in directory]
    keys = {}
    for k in range(d[3] if len(d) >= 4 else 0):
        key_id, location, count, value = d[4 + 4 * k: 8 + 4 * k]
        if location == 0 and count == 1:
            keys[key_id] = value
    return keys


def read_geotiff(path: Path, spacing, origin, nodata) -> HeightSamples:
    """Read the first image of a GeoTIFF as heights.

    Parameters
    ----------
    path : Path
        An existing TIFF file.
    spacing, origin : (2,) tuples or None
        Only for a TIFF without georeferencing (then both are needed); refused otherwise.
    nodata : float or None
        Value marking missing samples besides NaN/inf; overrides the ``GDAL_NODATA`` tag.

    Returns
    -------
    HeightSamples

    Raises
    ------
    ImportError
        ``tifffile`` is not installed.

    Examples
    --------
    A 2 x 2 UTM GeoTIFF with one gap, written as ``nodata=-9999``; the values come as stored, north row
    first (``flip_rows``):

    >>> import tempfile
    >>> from datasets_synthetic.dem_files import write_geotiff
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_geotiff(Path(folder) / "dem.tif", [[1.0, np.nan], [3.0, 4.0]], (10.0, 10.0),
    ...                          (100.0, 200.0), nodata=-9999, epsg=32633)
    ...     samples = read_geotiff(path, None, None, None)
    >>> samples.values.tolist(), samples.missing.tolist()
    ([[3.0, 4.0], [1.0, -9999.0]], [[False, False], [False, True]])
    >>> samples.flip_rows, [float(v) for v in samples.spacing + samples.origin], samples.crs
    (True, [10.0, 10.0, 100.0, 200.0], 'EPSG:32633')
    """
    try:
        import tifffile
    except ImportError:
        raise ImportError(f"reading {path} needs the package 'tifffile' (pip install tifffile); "
                          "it is an optional dependency of splinevis.") from None
    try:
        with tifffile.TiffFile(path) as tif:
            page = tif.pages[0]
            tags = {t.code: t.value for t in page.tags}
            values = page.asarray()
    except Exception as exc:
        raise ValueError(f"{path}: tifffile could not read it: {exc}") from exc
    if values.ndim != 2:
        raise ValueError(f"{path}: the first image has shape {values.shape}; heights need one band "
                         "(rows, cols).")
    if values.dtype.kind not in "biuf":
        raise TypeError(f"{path}: samples of dtype {values.dtype} are not real heights.")
    if values.shape[0] < 2 or values.shape[1] < 2:
        raise ValueError(f"{path}: heights need at least 2 x 2 samples, got {values.shape}.")
    keys = _geokeys(tags.get(34735, ()))
    raster_type = keys.get(_GEOKEY_RASTER_TYPE, 1)
    # Raster space: for PixelIsArea the integer raster coordinate is the pixel's top-left corner and the
    # sample sits at the centre (+0.5); for PixelIsPoint the integer coordinate is the sample itself.
    half = 0.5 if raster_type != 2 else 0.0
    if nodata is None and 42113 in tags:
        text = str(tags[42113]).strip().strip("\x00")
        try:
            nodata = float(text)
        except ValueError:
            raise ValueError(f"{path}: GDAL_NODATA tag {text!r} is not a number.") from None
        if math.isnan(nodata):
            nodata = None  # NaN samples are always missing
    missing = missing_mask(values, nodata)

    if 34264 in tags:  # ModelTransformationTag: 4x4 row-major, X = m0*I + m1*J + m3, Y = m4*I + m5*J + m7
        m = np.asarray(tags[34264], dtype=np.float64).reshape(4, 4)
        if m[0, 1] != 0 or m[1, 0] != 0:
            raise ValueError(f"{path}: ModelTransformationTag has rotation/shear terms ({m[0, 1]}, "
                             f"{m[1, 0]}); only north-up grids are supported. Warp it north-up first "
                             "(e.g. gdalwarp).")
        ax, ay, tx, ty, ti, tj = m[0, 0], m[1, 1], m[0, 3], m[1, 3], 0.0, 0.0
    elif 33550 in tags and 33922 in tags:
        scale = np.asarray(tags[33550], dtype=np.float64)
        tie = np.asarray(tags[33922], dtype=np.float64)
        if tie.size != 6:
            raise ValueError(f"{path}: {tie.size // 6} tiepoints (ground control points) are not supported; "
                             "one tiepoint with ModelPixelScaleTag is needed.")
        ti, tj, tx, ty = tie[0], tie[1], tie[3], tie[4]
        ax, ay = scale[0], -scale[1]  # ModelPixelScale y > 0 means y decreases down the rows
    else:
        if spacing is None or origin is None:
            raise ValueError(f"{path}: no GeoTIFF georeferencing (ModelPixelScaleTag + ModelTiepointTag or "
                             "ModelTransformationTag); pass spacing= and origin= to read it as a plain image "
                             "(first row = north, origin = the south-west sample).")
        return HeightSamples(values=values, missing=missing, spacing=spacing, origin=origin, source=str(path),
                             flip_rows=True, order_note="(row, col) as stored, row 0 = north")
    if spacing is not None or origin is not None:
        refuse_own_geometry(spacing, origin, f"{path} (georeferenced)", applies_to=GEOMETRY_ARGS_APPLY_TO)
    if not (np.isfinite([ax, ay, tx, ty]).all() and ax != 0 and ay != 0):
        raise ValueError(f"{path}: degenerate geotransform (pixel size x {ax}, y {-ay}).")
    rows, cols = values.shape

    def world(c, r):
        return tx + (c + half - ti) * ax, ty + (r + half - tj) * ay

    flip_cols, flip_rows = bool(ax < 0), bool(ay < 0)
    x_first = world(cols - 1 if flip_cols else 0, 0)[0]
    y_first = world(0, rows - 1 if flip_rows else 0)[1]
    crs = None
    if keys.get(_GEOKEY_PROJECTED) not in (None, 0, 32767):
        crs = f"EPSG:{keys[_GEOKEY_PROJECTED]}"
    elif keys.get(_GEOKEY_GEOGRAPHIC) not in (None, 0, 32767):
        crs = f"EPSG:{keys[_GEOKEY_GEOGRAPHIC]}"
    units = _EPSG_UNITS.get(keys.get(_GEOKEY_VERTICAL_UNITS))
    return HeightSamples(values=values, missing=missing, spacing=(abs(ax), abs(ay)), origin=(x_first, y_first),
                         source=str(path), flip_rows=flip_rows, flip_cols=flip_cols, crs=crs, units=units,
                         order_note="(row, col) as stored" + (", row 0 = north" if flip_rows else ""))

