"""Height data (terrain) from numpy arrays, pyvista grids and files, as one checked :class:`HeightGrid`.

:func:`read_heights` accepts

* a 2-D numpy array (``heights[j, i]``; ``spacing`` and ``origin`` default to ``(1, 1)`` and ``(0, 0)``),
* a pyvista ``ImageData`` (or ``vtkImageData``) that is one x-y slice, ``dims == (nx, ny, 1)``,
* a pyvista ``RectilinearGrid`` or ``StructuredGrid`` whose x, y coordinates form an axis-aligned lattice,
* a file: ``.vti .vtk .vtr .vts`` (through :func:`pyvista.read`), ``.dem`` (USGS ASCII DEM, our own
  parser: see :mod:`.dem` for what GDAL's driver gets wrong; a USGS DEM is recognized by its content
  whatever its extension, so one named ``.tif`` does not go to GDAL) and, through rasterio/GDAL (see
  :mod:`.raster`), ``.tif .tiff`` (GeoTIFF/COG), ``.hgt`` (SRTM), ``.asc`` (ESRI ASCII grid), ``.img``,
  ``.bil``, ``.dt0 .dt1 .dt2`` (DTED), ``.grd``, ``.vrt``; a file with any other extension is tried
  with GDAL too.

This module holds the result and the dispatch; the readers live in :mod:`.height_vtk` (pyvista grids
and VTK files), :mod:`.dem` and :mod:`.raster`, each with its format notes; gap filling and resampling
in :mod:`.height_interp`.

Conventions kept by every reader
--------------------------------
* ``heights[j, i]`` is the height at ``(x0 + i*dx, y0 + j*dy)``: **rows run south to north** (y
  increasing). North-up rasters (GeoTIFF, ...) store the northern row first and are flipped; the error
  messages still count rows and columns as the file stores them.
* ``spacing`` may differ in x and y, and the origin is kept in float64 (UTM coordinates such as
  ``(5e5, 5.1e6)`` stay exact). A source that carries its own spacing/origin refuses ``spacing=`` and
  ``origin=`` arguments instead of silently overriding or dropping either.
* Missing samples (NaN, +-inf, the ``nodata`` value, a raster band's nodata value or mask, the DEM
  void value -32767) raise a ValueError by default, naming the first one by (row, col) and (x, y).
  ``fill="nearest"`` or ``fill="linear"`` fills them (nearest valid sample in world distance, or
  linear interpolation that reproduces a plane).
* Non-uniform coordinates (RectilinearGrid, StructuredGrid) raise a ValueError naming the largest
  relative deviation from uniform spacing. ``resample=True`` (or ``"linear"``) resamples linearly
  (``"cubic"`` for cubic) onto a uniform grid over the same extent whose spacing is at most the
  smallest input step. Gaps are filled before resampling.
* RectilinearGrid/StructuredGrid spacing is ``(last - first) / (n - 1)`` of the stored coordinates;
  float32 coordinates count as uniform within their rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validation import as_float64_array, check_choice
from ._common import (VTK_FILES, check_geometry, first_gap, freeze_grid, gap_error, nonuniform_message,
                      refuse_own_geometry, require_regular_file, source_kind, step_deviation,
                      unsupported_extension)
from .dem import looks_like_usgs_dem, read_dem
from .height_interp import fill_gaps, resample_uniform
from .height_samples import GEOMETRY_ARGS_APPLY_TO, HeightSamples, from_array
from .height_vtk import from_pyvista, read_vtk_file
from .raster import RASTER_EXTENSIONS, RasterOpenError, read_raster

__all__ = ["HeightGrid", "read_heights", "SUPPORTED_EXTENSIONS"]

#: File name extensions :func:`read_heights` reads, and by what (any other extension is tried with GDAL).
SUPPORTED_EXTENSIONS = {
    **{ext: f"{kind} (pyvista.read)" for ext, kind in VTK_FILES.items()},
    ".dem": "USGS ASCII DEM (own parser)",
    **{ext: f"{kind} (rasterio/GDAL)" for ext, kind in RASTER_EXTENSIONS.items()},
}

_FILL_CHOICES = {"nearest", "linear"}
_RESAMPLE_CHOICES = {False, True, "linear", "cubic"}
_MISSING = "missing (NaN/inf/nodata)"


# --------------------------------------------------------------------------------------------------
# The result
# --------------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class HeightGrid:
    """Heights on a uniform, axis-aligned grid.

    Parameters
    ----------
    heights : (ny, nx) ndarray of float64
        ``heights[j, i]`` is the height at ``(x0 + i*dx, y0 + j*dy)``; rows run south to north. Stored
        as a read-only copy; every value finite; ``nx, ny >= 2``.
    spacing : (dx, dy) floats > 0
        May differ (anisotropic).
    origin : (x0, y0) floats
        Position of ``heights[0, 0]`` (south-west sample), kept in float64.
    source : str
        Where the data came from: a file path, ``"numpy array"``, ``"pyvista.ImageData"``, ...
    crs : str or None
        Coordinate reference system if the source names one (``"EPSG:32633"``, ``"UTM zone 33"``).
    units : str or None
        Unit of the heights if the source names it (``"m"``, ``"ft"``).

    Examples
    --------
    >>> g = HeightGrid([[1, 2, 3], [4, 5, 6]], spacing=(30.0, 10.0), origin=(5e5, 5e6), units="m")
    >>> g.heights.dtype, g.heights.flags.writeable, g.extent
    (dtype('float64'), False, (500000.0, 500060.0, 5000000.0, 5000010.0))
    """

    heights: np.ndarray
    spacing: tuple
    origin: tuple
    source: str = "numpy array"
    crs: str | None = None
    units: str | None = None

    def __post_init__(self):
        h = as_float64_array(self.heights, "heights", ndim=2)
        if h.shape[0] < 2 or h.shape[1] < 2:
            raise ValueError(f"heights must have at least 2 x 2 samples, got shape {h.shape}.")
        freeze_grid(self, "heights", h, axes=2)

    @property
    def shape(self) -> tuple:
        """``(ny, nx)``.

        >>> HeightGrid(np.zeros((2, 3)), spacing=(1.0, 1.0), origin=(0.0, 0.0)).shape
        (2, 3)
        """
        return self.heights.shape

    @property
    def x(self) -> np.ndarray:
        """(nx,) x coordinates of the columns.

        >>> HeightGrid(np.zeros((2, 3)), spacing=(30.0, 10.0), origin=(100.0, 0.0)).x
        array([100., 130., 160.])
        """
        return self.origin[0] + np.arange(self.shape[1]) * self.spacing[0]

    @property
    def y(self) -> np.ndarray:
        """(ny,) y coordinates of the rows (increasing: south to north).

        >>> HeightGrid(np.zeros((2, 3)), spacing=(30.0, 10.0), origin=(100.0, 0.0)).y
        array([ 0., 10.])
        """
        return self.origin[1] + np.arange(self.shape[0]) * self.spacing[1]

    @property
    def extent(self) -> tuple:
        """``(xmin, xmax, ymin, ymax)`` of the sample positions.

        >>> HeightGrid(np.zeros((2, 3)), spacing=(30.0, 10.0), origin=(100.0, 0.0)).extent
        (100.0, 160.0, 0.0, 10.0)
        """
        (ny, nx), (dx, dy), (x0, y0) = self.shape, self.spacing, self.origin
        return (x0, x0 + (nx - 1) * dx, y0, y0 + (ny - 1) * dy)

    @property
    def height_range(self) -> tuple:
        """``(min, max)`` of the heights.

        >>> HeightGrid([[3, -1], [2, 7]], spacing=(1.0, 1.0), origin=(0.0, 0.0)).height_range
        (-1.0, 7.0)
        """
        return (float(self.heights.min()), float(self.heights.max()))

    def points(self) -> np.ndarray:
        """(ny*nx, 3) float64 sample positions ``(x, y, height)``, x varying fastest (VTK order).

        >>> HeightGrid([[1, 2], [3, 4]], spacing=(10.0, 20.0), origin=(0.0, 0.0)).points()
        array([[ 0.,  0.,  1.],
               [10.,  0.,  2.],
               [ 0., 20.,  3.],
               [10., 20.,  4.]])
        """
        xx, yy = np.meshgrid(self.x, self.y)
        return np.column_stack([xx.ravel(), yy.ravel(), self.heights.ravel()])


# --------------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------------
def read_heights(source, *, scalars=None, spacing=None, origin=None, nodata=None, fill=None,
                 resample=False, band=1, crs=None, keep_geographic=False, reproject="bilinear",
                 source_crs=None) -> HeightGrid:
    """Read height data into a :class:`HeightGrid`.

    Parameters
    ----------
    source : (ny, nx) array_like, pyvista.ImageData, pyvista.RectilinearGrid, pyvista.StructuredGrid, str or Path
        The heights. A str or Path is a file name; see ``SUPPORTED_EXTENSIONS`` (a file with another
        extension is tried with GDAL).
    scalars : str, optional
        Name of the point array holding the heights (pyvista grids and VTK files). Default: the active
        point scalars; for a StructuredGrid with varying z the z coordinates are the heights.
    spacing, origin : (2,) floats, optional
        Only for numpy arrays (defaults ``(1, 1)`` and ``(0, 0)``) and rasters (TIFF, ...) without
        georeference. A scalar spacing applies to both axes.
    nodata : float, optional
        Value marking missing samples, in addition to NaN/inf. Replaces a raster band's nodata value.
    fill : {None, "nearest", "linear"}
        None (default): missing samples raise ValueError. Otherwise fill them (see module notes).
    resample : {False, True, "linear", "cubic"}
        What to do with non-uniform RectilinearGrid/StructuredGrid coordinates: False raises
        ValueError; True/"linear"/"cubic" resample to a uniform grid (see module notes).
    band : int
        1-based band of a raster file read through GDAL (:mod:`.raster`).
    crs : str, optional
        A grid in a geographic CRS (degrees) is reprojected to a local metric CRS: by default the UTM
        zone of its centre, UPS when it reaches beyond 84 N / 80 S (reported in ``source``), or this projected
        CRS (``"EPSG:32632"``). With ``fill=`` the new grid keeps all of the footprint (nodes outside it
        filled as gaps), without it the largest north-up rectangle inside (the rest warned; a grid
        reaching a polar cap then raises). See :mod:`.georef`.
    keep_geographic : bool
        Keep a geographic grid on its degree lattice instead, x and y scaled by the length of a degree
        at its centre latitude (stated in ``source``; true there only).
    reproject : {"bilinear", "cubic", "nearest"}
        How the heights are interpolated when a geographic grid is reprojected.
    source_crs : str, optional
        The CRS the grid is in when the source names none (an ASCII grid without its ``.prj``, an array): e.g.
        ``"EPSG:4326"`` for longitudes and latitudes, which are then projected like any geographic grid
        (``crs=`` is the CRS to project *to*). A source that names another CRS raises ValueError. A grid that
        names none but whose x, y look like degrees under heights of metres is warned about.

    Returns
    -------
    HeightGrid

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    TypeError
        Unsupported source type or non-numeric data.
    ValueError
        Bad shape, spacing or origin; missing samples without ``fill``; non-uniform grid without
        ``resample``; rotated georeferencing; a file GDAL cannot open or read (truncated, corrupt);
        a band out of range.

    Examples
    --------
    >>> import numpy as np
    >>> g = read_heights(np.zeros((3, 4)), spacing=(2.0, 0.5), origin=(5e5, 5.1e6))
    >>> g.shape, g.extent
    ((3, 4), (500000.0, 500006.0, 5100000.0, 5100001.0))
    """
    if fill is not None:
        check_choice(fill, "fill", _FILL_CHOICES)
    if not any(resample is c or (isinstance(c, str) and resample == c) for c in _RESAMPLE_CHOICES):
        raise ValueError(f"resample {resample!r} is not known; choose one of: False, True, 'linear', 'cubic'.")
    if scalars is not None and not isinstance(scalars, str):
        raise TypeError(f"scalars must be the name (str) of a point array, got {type(scalars).__name__}.")
    if nodata is not None:
        if isinstance(nodata, (str, bytes)) or not np.isscalar(nodata) and np.ndim(nodata) != 0:
            raise TypeError(f"nodata must be one real number, got {nodata!r}.")
        nodata = float(nodata)
        if math.isnan(nodata):
            raise ValueError("nodata=nan is not needed: NaN samples are always treated as missing.")
    if spacing is not None:
        spacing = check_geometry(spacing, "spacing", axes=2, positive=True)
    if origin is not None:
        origin = check_geometry(origin, "origin", axes=2)

    samples = _dispatch(source, scalars=scalars, spacing=spacing, origin=origin, nodata=nodata, band=band)
    grid = _with_source_crs(_finish(samples, fill=fill, resample=resample), source_crs)
    return _georeference(grid, crs, keep_geographic, reproject, fill)


def _with_source_crs(grid: HeightGrid, source_crs) -> HeightGrid:
    """``grid`` with ``source_crs`` as its CRS where it names none; a warning where it names none and its x, y
    look like degrees (inside +-180 x +-90, steps under 0.1) under a relief 100 times the footprint's width."""
    from dataclasses import replace

    from .georef import _crs

    if source_crs is not None:
        wanted = _crs(source_crs, grid.source, f"source_crs={source_crs!r}")
        if grid.crs is None:
            return replace(grid, crs=wanted.to_string())
        if _crs(grid.crs, grid.source) != wanted:
            raise ValueError(f"{grid.source}: source_crs={source_crs!r} is for grids that name no CRS; this one names "
                             f"{grid.crs}. Drop source_crs (crs= reprojects a geographic grid to another CRS).")
        return grid
    x0, x1, y0, y1 = grid.extent
    degrees = -180.0 <= x0 and x1 <= 360.0 and -90.0 <= y0 and y1 <= 90.0 and max(grid.spacing) < 0.1
    if grid.crs is None and degrees and float(np.ptp(grid.heights)) > 100.0 * max(x1 - x0, y1 - y0):
        from .._warnings import warn_user

        warn_user(f"{grid.source}: names no CRS, and its x, y ({x0:.6g}..{x1:.6g}, {y0:.6g}..{y1:.6g}, steps "
                  f"{grid.spacing[0]:.3g} x {grid.spacing[1]:.3g}) look like degrees under heights {np.ptp(grid.heights):.4g} "
                  "high: drawn as they are, the terrain is a needle. If they are longitudes and latitudes, pass "
                  "source_crs='EPSG:4326' (or put the .prj file beside it).")
    return grid


def _georeference(grid: HeightGrid, crs, keep_geographic, reproject, fill=None) -> HeightGrid:
    """A grid in a geographic CRS to metres (:mod:`.georef`); other grids as they are."""
    from .georef import is_geographic, scale_geographic, to_metric

    geographic = is_geographic(grid.crs)
    asked = "keep_geographic=True" if keep_geographic else (f"crs={crs!r}" if crs is not None else None)
    if not geographic:
        if asked is not None:
            raise ValueError(f"{grid.source}: {asked} applies to a grid in a geographic CRS (degrees); this one is "
                             f"in {grid.crs or 'no named CRS'}. Drop the argument (reproject it with gdalwarp first "
                             "if you need another projected CRS).")
        return grid
    if keep_geographic and crs is not None:
        raise ValueError(f"{grid.source}: pass either crs= (reproject to that CRS) or keep_geographic=True, not both.")
    if keep_geographic:
        m = scale_geographic(grid.heights, grid.spacing, grid.origin, grid.crs, source=grid.source)
    else:
        m = to_metric(grid.heights, grid.spacing, grid.origin, grid.crs, target=crs, resampling=reproject,
                      source=grid.source, fill=fill)
    return HeightGrid(heights=m.heights, spacing=m.spacing, origin=m.origin, source=f"{grid.source}, {m.note}",
                      crs=m.crs, units=grid.units)


def _dispatch(source, *, scalars, spacing, origin, nodata, band) -> HeightSamples:
    kind = source_kind(source)
    if kind == "path":
        return _read_file(Path(source), scalars=scalars, spacing=spacing, origin=origin, nodata=nodata, band=band)
    if kind == "vtk":
        import pyvista as pv

        refuse_own_geometry(spacing, origin, f"pyvista.{type(source).__name__}", applies_to=GEOMETRY_ARGS_APPLY_TO)
        grid = pv.wrap(source)
        return from_pyvista(grid, f"pyvista.{type(grid).__name__}", scalars, nodata)
    if kind == "array":
        if scalars is not None:
            raise ValueError("scalars= names a point array of a pyvista grid; a numpy array has none.")
        return from_array(source, spacing, origin, nodata)
    raise TypeError(
        f"source of type {type(source).__name__} is not supported; pass a 2-D numpy array, a pyvista "
        f"ImageData/RectilinearGrid/StructuredGrid, or a file path ({', '.join(SUPPORTED_EXTENSIONS)})."
    )


def _read_file(path: Path, *, scalars, spacing, origin, nodata, band) -> HeightSamples:
    ext = path.suffix.lower()
    require_regular_file(path, "height")
    if ext not in VTK_FILES and ext != ".dem" and looks_like_usgs_dem(path):
        # by content, whatever the name: GDAL's USGSDEM driver would snap the origin (module notes of .dem)
        ext = ".dem"
    if ext in VTK_FILES or ext == ".dem":
        refuse_own_geometry(spacing, origin, str(path), applies_to=GEOMETRY_ARGS_APPLY_TO)
        if band != 1:
            raise ValueError(f"{path}: band={band!r} picks a band of a raster read through GDAL; "
                             f"a {SUPPORTED_EXTENSIONS[ext]} file has one field of heights.")
        if ext == ".dem":
            if scalars is not None:
                raise ValueError(f"{path}: scalars= names a VTK point array; a DEM has one elevation field.")
            return read_dem(path, nodata)
        return read_vtk_file(path, SUPPORTED_EXTENSIONS[ext], scalars, nodata)
    if scalars is not None:
        raise ValueError(f"{path}: scalars= names a VTK point array; a raster has bands (pass band=).")
    try:
        return read_raster(path, spacing, origin, nodata, band=band)
    except RasterOpenError as exc:
        if ext in SUPPORTED_EXTENSIONS:
            raise
        raise unsupported_extension(path, SUPPORTED_EXTENSIONS,
                                    f" GDAL could not open it either ({exc.gdal_message}).") from None


# --------------------------------------------------------------------------------------------------
# gaps, uniformity, result
# --------------------------------------------------------------------------------------------------
def _finish(samples: HeightSamples, *, fill, resample) -> HeightGrid:
    values = np.asarray(samples.values)
    n_missing, first = first_gap(samples.missing, samples.source, _MISSING)
    if n_missing and fill is None:
        r, c = first
        x, y = (float(v) for v in samples.xy_of(r, c))
        raise gap_error(samples.source, n_missing, values.size, _MISSING,
                        f"(row, col) = ({r}, {c}) [{samples.order_note}], (x, y) = ({x!r}, {y!r})",
                        values[r, c].item(), "Pass fill='nearest' or fill='linear' to fill them.")
    h = samples.oriented(values).astype(np.float64)
    miss = samples.oriented(samples.missing)
    spacing, origin = samples.spacing, samples.origin
    if samples.xcoords is not None:
        xc, yc = samples.xcoords, samples.ycoords
        # uniform = every step within 1e-6 of the mean step, plus the rounding of the stored coordinates
        # (float32 UTM coordinates are only good to ~0.03 m)
        sx, dev_x, tol_x = step_deviation(xc, samples.coord_eps)
        sy, dev_y, tol_y = step_deviation(yc, samples.coord_eps)
        local = (xc - xc[0], yc - yc[0])
    else:
        local = (np.arange(h.shape[1]) * spacing[0], np.arange(h.shape[0]) * spacing[1])
    if samples.xcoords is not None and resample == "cubic" and min(h.shape) < 4:
        raise ValueError(f"{samples.source}: resample='cubic' needs at least 4 samples per axis, got shape "
                         f"{h.shape}; use resample='linear'.")
    if n_missing:
        h = fill_gaps(h, miss, local, fill)
    if samples.xcoords is not None:
        if dev_x <= tol_x and dev_y <= tol_y:
            spacing, origin = (sx, sy), (float(xc[0]), float(yc[0]))
        elif resample is False:
            worst = ("x", dev_x) if dev_x / tol_x >= dev_y / tol_y else ("y", dev_y)
            raise ValueError(nonuniform_message(samples.source, *worst) + "; the spline scheme needs a uniform "
                             "grid. Pass resample=True (linear) or resample='cubic' to resample onto a uniform grid.")
        else:
            h, spacing = resample_uniform(h, local, "linear" if resample is True else resample)
            origin = (float(xc[0]), float(yc[0]))
    return HeightGrid(heights=h, spacing=spacing, origin=origin, source=samples.source, crs=samples.crs,
                      units=samples.units)
