"""Height data (terrain) from numpy arrays, pyvista grids and files, as one checked :class:`HeightGrid`.

:func:`read_heights` accepts

* a 2-D numpy array (``heights[j, i]``; ``spacing`` and ``origin`` default to ``(1, 1)`` and ``(0, 0)``),
* a pyvista ``ImageData`` (or ``vtkImageData``) that is one x-y slice, ``dims == (nx, ny, 1)``,
* a pyvista ``RectilinearGrid`` or ``StructuredGrid`` whose x, y coordinates form an axis-aligned lattice,
* a file: ``.vti .vtk .vtr .vts`` (through :func:`pyvista.read`), ``.dem`` (USGS ASCII DEM, through
  ``vtkDEMReader``) and ``.tif .tiff`` (GeoTIFF, through the optional package ``tifffile``).

Conventions kept by every reader
--------------------------------
* ``heights[j, i]`` is the height at ``(x0 + i*dx, y0 + j*dy)``: **rows run south to north** (y
  increasing). GeoTIFF files store the northern row first and are flipped; the error messages still
  count rows and columns as the file stores them.
* ``spacing`` may differ in x and y, and the origin is kept in float64 (UTM coordinates such as
  ``(5e5, 5.1e6)`` stay exact). A source that carries its own spacing/origin refuses ``spacing=`` and
  ``origin=`` arguments instead of silently overriding or dropping either.
* Missing samples (NaN, +-inf, the ``nodata`` value, the GeoTIFF ``GDAL_NODATA`` tag, the DEM void
  value -32767) raise a ValueError by default. ``fill="nearest"`` or ``fill="linear"`` fills them:

  - ``"nearest"``: the value of the nearest valid sample in world distance (anisotropic spacing
    counts), from ``scipy.ndimage.distance_transform_edt``.
  - ``"linear"``: linear interpolation on a Delaunay triangulation (``scipy.interpolate.griddata``) of
    the valid samples within two cells of a gap; points outside their convex hull take the nearest
    value. A plane is reproduced exactly (to rounding).

* Non-uniform coordinates (RectilinearGrid, StructuredGrid) raise a ValueError naming the largest
  relative deviation from uniform spacing. ``resample=True`` (or ``"linear"``) resamples with
  ``scipy.interpolate.RegularGridInterpolator`` (``"cubic"`` for cubic) onto a uniform grid over the
  same extent whose spacing is the extent divided into ``ceil(extent / smallest_step)`` equal steps,
  i.e. at most the smallest input step. Gaps are filled before resampling.

Format notes
------------
* USGS ASCII DEM: the type A header is parsed here in float64 (corners D24.15: 16 significant digits;
  resolution E12.6: 7 significant digits); elevations come from ``vtkDEMReader``, which returns
  ``integer * z_resolution`` in float32 - the integers are recovered and multiplied by the resolution in
  float64, so heights are exact multiples of the file's z resolution, in the file's units (VTK's own
  feet/arc-second factors are not applied; ``units`` and ``crs`` say what the file uses). The void
  value -32767 is a gap. VTK 9.7.1's reader divides by zero (killing the process) on DEMs with fewer
  than 100 profiles, so those are parsed in Python. Only north-up DEMs whose profiles all start on the
  southern row are placed correctly (VTK ignores each profile's start coordinate).
* GeoTIFF: one band; ModelPixelScaleTag + one ModelTiepointTag, or a ModelTransformationTag without
  rotation/shear; GTRasterTypeGeoKey PixelIsArea (the default) puts each sample at its pixel centre,
  half a pixel inside the tiepoint corner; PixelIsPoint puts it on the raster coordinate itself. The
  CRS is ``"EPSG:<code>"`` from ProjectedCSTypeGeoKey or GeographicTypeGeoKey when present.
* A TIFF without georeferencing needs ``spacing=`` and ``origin=``; its first row is taken as north.
* RectilinearGrid/StructuredGrid spacing is ``(last - first) / (n - 1)`` of the stored coordinates;
  float32 coordinates count as uniform within their rounding.
"""

from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validation import as_float64_array, check_choice

__all__ = ["HeightGrid", "read_heights", "SUPPORTED_EXTENSIONS"]

#: File name extensions :func:`read_heights` reads, and by what.
SUPPORTED_EXTENSIONS = {
    ".vti": "VTK XML ImageData (pyvista.read)",
    ".vtk": "legacy VTK (pyvista.read)",
    ".vtr": "VTK XML RectilinearGrid (pyvista.read)",
    ".vts": "VTK XML StructuredGrid (pyvista.read)",
    ".dem": "USGS ASCII DEM (vtkDEMReader)",
    ".tif": "GeoTIFF (tifffile)",
    ".tiff": "GeoTIFF (tifffile)",
}

_FILL_CHOICES = {"nearest", "linear"}
_RESAMPLE_CHOICES = {False, True, "linear", "cubic"}
_DEM_VOID = -32767  # USGS DEM "void area" elevation
_DEM_TOKEN = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[EeDd][-+]?\d+)?")


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
        h = np.array(h, dtype=np.float64, copy=True)
        h.flags.writeable = False
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "spacing", _check_pair(self.spacing, "spacing", positive=True))
        object.__setattr__(self, "origin", _check_pair(self.origin, "origin"))
        if not isinstance(self.source, str):
            raise TypeError(f"source must be a str, got {type(self.source).__name__}.")

    @property
    def shape(self) -> tuple:
        """``(ny, nx)``."""
        return self.heights.shape

    @property
    def x(self) -> np.ndarray:
        """(nx,) x coordinates of the columns."""
        return self.origin[0] + np.arange(self.shape[1]) * self.spacing[0]

    @property
    def y(self) -> np.ndarray:
        """(ny,) y coordinates of the rows (increasing: south to north)."""
        return self.origin[1] + np.arange(self.shape[0]) * self.spacing[1]

    @property
    def extent(self) -> tuple:
        """``(xmin, xmax, ymin, ymax)`` of the sample positions."""
        (ny, nx), (dx, dy), (x0, y0) = self.shape, self.spacing, self.origin
        return (x0, x0 + (nx - 1) * dx, y0, y0 + (ny - 1) * dy)

    @property
    def height_range(self) -> tuple:
        """``(min, max)`` of the heights."""
        return (float(self.heights.min()), float(self.heights.max()))

    def points(self) -> np.ndarray:
        """(ny*nx, 3) float64 sample positions ``(x, y, height)``, x varying fastest (VTK order)."""
        xx, yy = np.meshgrid(self.x, self.y)
        return np.column_stack([xx.ravel(), yy.ravel(), self.heights.ravel()])


def _check_pair(value, name: str, *, positive: bool = False) -> tuple:
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be two real numbers, got the string {value!r}.")
    arr = as_float64_array(value, name, finite=False)
    if arr.ndim == 0:
        arr = np.array([arr, arr]) if positive else arr
    if arr.shape != (2,):
        raise ValueError(f"{name} must be two numbers (x, y), got shape {arr.shape}: {value!r}.")
    if not np.isfinite(arr).all():
        raise ValueError(f"{name} must be finite, got {tuple(float(v) for v in arr)}.")
    if positive and not (arr > 0).all():
        raise ValueError(f"{name} must be > 0 in x and y, got {tuple(float(v) for v in arr)}.")
    return (float(arr[0]), float(arr[1]))


# --------------------------------------------------------------------------------------------------
# Internal: what a reader hands over before gaps are handled
# --------------------------------------------------------------------------------------------------
@dataclass
class _Raw:
    """Samples as stored plus the map to our orientation.

    ``values`` is (rows, cols) in the source's own order; ``missing`` marks gaps in the same order.
    ``flip_rows``/``flip_cols`` say how to reach south-to-north, west-to-east order.
    ``spacing``/``origin`` already refer to the reoriented grid.
    """

    values: np.ndarray
    missing: np.ndarray
    spacing: tuple
    origin: tuple
    source: str
    flip_rows: bool = False
    flip_cols: bool = False
    crs: str | None = None
    units: str | None = None
    order_note: str = "array index"
    xcoords: np.ndarray | None = None  # non-uniform coordinates (Rectilinear/Structured), reoriented
    ycoords: np.ndarray | None = None
    coord_eps: float = float(np.finfo(np.float64).eps)  # machine epsilon of the stored coordinates

    def oriented(self, a):
        if self.flip_rows:
            a = a[::-1, :]
        if self.flip_cols:
            a = a[:, ::-1]
        return np.ascontiguousarray(a)

    def xy_of(self, r: int, c: int) -> tuple:
        rows, cols = self.values.shape
        j = rows - 1 - r if self.flip_rows else r
        i = cols - 1 - c if self.flip_cols else c
        if self.xcoords is not None:
            return float(self.xcoords[i]), float(self.ycoords[j])
        return (self.origin[0] + i * self.spacing[0], self.origin[1] + j * self.spacing[1])


# --------------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------------
def read_heights(source, *, scalars=None, spacing=None, origin=None, nodata=None, fill=None,
                 resample=False) -> HeightGrid:
    """Read height data into a :class:`HeightGrid`.

    Parameters
    ----------
    source : (ny, nx) array_like, pyvista.ImageData, pyvista.RectilinearGrid, pyvista.StructuredGrid, str or Path
        The heights. A str or Path is a file name; see ``SUPPORTED_EXTENSIONS``.
    scalars : str, optional
        Name of the point array holding the heights (pyvista grids and VTK files). Default: the active
        point scalars; for a StructuredGrid with varying z the z coordinates are the heights.
    spacing, origin : (2,) floats, optional
        Only for numpy arrays (defaults ``(1, 1)`` and ``(0, 0)``) and TIFF files without
        georeferencing. A scalar spacing applies to both axes.
    nodata : float, optional
        Value marking missing samples, in addition to NaN/inf. Overrides a GeoTIFF ``GDAL_NODATA`` tag.
    fill : {None, "nearest", "linear"}
        None (default): missing samples raise ValueError. Otherwise fill them (see module notes).
    resample : {False, True, "linear", "cubic"}
        What to do with non-uniform RectilinearGrid/StructuredGrid coordinates: False raises
        ValueError; True/"linear"/"cubic" resample to a uniform grid (see module notes).

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
        ``resample``; rotated georeferencing; unknown extension.
    ImportError
        A GeoTIFF was given and ``tifffile`` is not installed.

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
        spacing = _check_pair(spacing, "spacing", positive=True)
    if origin is not None:
        origin = _check_pair(origin, "origin")

    raw = _dispatch(source, scalars=scalars, spacing=spacing, origin=origin, nodata=nodata)
    return _finish(raw, fill=fill, resample=resample)


def _dispatch(source, *, scalars, spacing, origin, nodata) -> _Raw:
    if isinstance(source, (str, os.PathLike)):
        return _read_file(Path(source), scalars=scalars, spacing=spacing, origin=origin, nodata=nodata)
    pv = _pyvista_if_loaded_or_needed(source)
    if pv is not None:
        _refuse_own_geometry(spacing, origin, f"pyvista.{type(source).__name__}")
        return _from_pyvista(pv.wrap(source), f"pyvista.{type(pv.wrap(source)).__name__}", scalars, nodata)
    if isinstance(source, (np.ndarray, list, tuple)):
        if scalars is not None:
            raise ValueError("scalars= names a point array of a pyvista grid; a numpy array has none.")
        return _from_array(source, spacing, origin, nodata)
    raise TypeError(
        f"source of type {type(source).__name__} is not supported; pass a 2-D numpy array, a pyvista "
        f"ImageData/RectilinearGrid/StructuredGrid, or a file path ({', '.join(SUPPORTED_EXTENSIONS)})."
    )


def _pyvista_if_loaded_or_needed(source):
    """Return the pyvista module when ``source`` is a VTK/pyvista data object, else None."""
    mod = type(source).__module__ or ""
    if not (mod.startswith("pyvista") or mod.startswith("vtkmodules") or mod.startswith("vtk")):
        return None
    import pyvista as pv
    from vtkmodules.vtkCommonDataModel import vtkDataObject

    return pv if isinstance(source, vtkDataObject) else None


def _refuse_own_geometry(spacing, origin, what: str):
    given = [n for n, v in (("spacing", spacing), ("origin", origin)) if v is not None]
    if given:
        raise ValueError(
            f"{what} carries its own spacing and origin; {' and '.join(given)}= would override them. "
            "Drop the argument (spacing=/origin= apply to numpy arrays and TIFFs without georeferencing)."
        )


# --------------------------------------------------------------------------------------------------
# numpy
# --------------------------------------------------------------------------------------------------
def _from_array(values, spacing, origin, nodata, source="numpy array") -> _Raw:
    arr = np.asarray(values)
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{source}: heights must be real numbers, got dtype {arr.dtype}"
                        f"{' (strings)' if arr.dtype.kind in 'USO' else ''}.")
    if arr.ndim != 2:
        hint = " Squeeze a singleton axis or pick one band." if arr.ndim == 3 else ""
        raise ValueError(f"{source}: heights must be a 2-D array (ny, nx), got shape {arr.shape}.{hint}")
    if arr.shape[0] < 2 or arr.shape[1] < 2:
        raise ValueError(f"{source}: heights need at least 2 x 2 samples, got shape {arr.shape}.")
    return _Raw(values=arr, missing=_missing(arr, nodata), spacing=spacing or (1.0, 1.0),
                origin=origin or (0.0, 0.0), source=source, order_note="array index [row, col]")


def _missing(arr: np.ndarray, nodata) -> np.ndarray:
    """True where ``arr`` is non-finite or equals ``nodata`` compared in ``arr``'s own dtype."""
    miss = ~np.isfinite(arr) if arr.dtype.kind == "f" else np.zeros(arr.shape, bool)
    if nodata is not None:
        if arr.dtype.kind == "f":
            miss |= arr == arr.dtype.type(nodata)
        elif float(nodata).is_integer():
            info = np.iinfo(arr.dtype) if arr.dtype.kind in "iu" else None
            if info is None or info.min <= nodata <= info.max:
                miss |= arr == int(nodata)
    return miss


# --------------------------------------------------------------------------------------------------
# pyvista / VTK objects
# --------------------------------------------------------------------------------------------------
def _point_array(grid, name, scalars, *, required=True):
    if scalars is not None:
        if scalars not in grid.point_data:
            raise ValueError(f"{name}: no point array named {scalars!r}; point arrays: "
                             f"{list(grid.point_data.keys()) or 'none'}.")
        arr = np.asarray(grid.point_data[scalars])
        label = scalars
    else:
        label = grid.point_data.active_scalars_name
        if label is None:
            if not required:
                return None, None
            raise ValueError(f"{name}: no active point scalars; pass scalars= with one of the point "
                             f"arrays: {list(grid.point_data.keys()) or 'none'}.")
        arr = np.asarray(grid.point_data[label])
    if arr.ndim != 1:
        raise ValueError(f"{name}: point array {label!r} has {arr.shape[1]} components; heights need 1.")
    return arr, label


def _slice_dims(grid, name):
    nx, ny, nz = (int(d) for d in grid.dimensions)
    if nz != 1:
        raise ValueError(f"{name}: heights must lie on one x-y slice, dims (nx, ny, 1); got dims "
                         f"{(nx, ny, nz)}. Extract a slice, e.g. grid.extract_subset((0, nx-1, 0, ny-1, k, k)).")
    if nx < 2 or ny < 2:
        raise ValueError(f"{name}: heights need at least 2 x 2 samples, got dims {(nx, ny, nz)}.")
    return nx, ny


def _from_pyvista(grid, name, scalars, nodata) -> _Raw:
    import pyvista as pv

    if isinstance(grid, pv.ImageData):
        nx, ny = _slice_dims(grid, name)
        direction = np.asarray(grid.direction_matrix, dtype=float)
        if not np.array_equal(direction, np.eye(3)):
            raise ValueError(f"{name}: direction matrix {direction.tolist()} is not the identity; only "
                             "axis-aligned grids are supported. Resample onto an axis-aligned grid first.")
        arr, _ = _point_array(grid, name, scalars)
        values = arr.reshape(ny, nx)
        _check_numeric(values, name)
        return _Raw(values=values, missing=_missing(values, nodata), spacing=tuple(grid.spacing[:2]),
                    origin=tuple(grid.origin[:2]), source=name, order_note="grid index [j, i]")
    if isinstance(grid, pv.RectilinearGrid):
        nx, ny = _slice_dims(grid, name)
        arr, _ = _point_array(grid, name, scalars)
        values = arr.reshape(ny, nx)
        _check_numeric(values, name)
        return _from_coordinates(values, np.asarray(grid.x), np.asarray(grid.y), name, nodata)
    if isinstance(grid, pv.StructuredGrid):
        nx, ny = _slice_dims(grid, name)
        pts = np.asarray(grid.points)
        X, Y, Z = (pts[:, k].reshape(ny, nx) for k in range(3))
        arr, label = _point_array(grid, name, scalars, required=False)
        z_flat = np.ptp(Z) == 0
        if arr is None or (scalars is None and not z_flat):
            if z_flat and arr is None:
                raise ValueError(f"{name}: the points are flat (z = {Z.flat[0]}) and there are no point "
                                 "scalars; pass scalars= naming the height array.")
            values = Z.astype(np.float64)  # a warped surface: the z coordinates are the heights
        else:
            if not z_flat:
                raise ValueError(f"{name}: scalars={label!r} given but the points' z varies over "
                                 f"[{Z.min()}, {Z.max()}]; heights would be ambiguous. Use a flat lattice "
                                 "or drop scalars= to take z as the heights.")
            values = arr.reshape(ny, nx)
        _check_numeric(values, name)
        if nx > 1 and ny > 1 and X[0, 0] == X[0, 1] and Y[0, 0] == Y[1, 0] and X[0, 0] != X[1, 0]:
            # VTK's i axis runs along y (e.g. built from numpy.meshgrid's default "xy" arrays): transpose
            values, X, Y = values.T, X.T, Y.T
        x, y = _lattice_axes(X, Y, name)
        return _from_coordinates(values, x, y, name, nodata)
    raise TypeError(f"{name} is not supported; heights come from ImageData, RectilinearGrid or "
                    "StructuredGrid (one x-y slice), a 2-D numpy array or a file.")


def _check_numeric(values, name):
    if values.dtype.kind not in "biuf":
        raise TypeError(f"{name}: heights must be real numbers, got dtype {values.dtype}.")


def _lattice_axes(X, Y, name):
    """x from the first row, y from the first column, after checking the lattice is axis-aligned."""
    x, y = X[0, :].astype(np.float64), Y[:, 0].astype(np.float64)
    scale = max(np.ptp(x), np.ptp(y), 1e-300)
    tol = 1e-9 * scale + 4 * np.finfo(X.dtype if X.dtype.kind == "f" else np.float64).eps * max(
        np.abs(X).max(), np.abs(Y).max())
    dev_x, dev_y = np.abs(X - x[None, :]).max(), np.abs(Y - y[:, None]).max()
    if dev_x > tol or dev_y > tol:
        raise ValueError(f"{name}: the points are not an axis-aligned lattice (x varies along a column by "
                         f"up to {dev_x:.3g}, y along a row by up to {dev_y:.3g}); rotated or curvilinear "
                         "grids are not supported. Resample onto an axis-aligned grid first.")
    return X[0, :], Y[:, 0]  # in the stored dtype: its precision sets the uniformity tolerance


def _from_coordinates(values, x, y, name, nodata) -> _Raw:
    """Rows/cols may run in decreasing x/y: flip them. Uniformity is judged later in ``_finish``."""
    x, y = np.asarray(x), np.asarray(y)
    for label, c in (("x", x), ("y", y)):
        if not np.isfinite(c).all():
            raise ValueError(f"{name}: {label} coordinates must be finite, got {c.tolist()[:8]}...")
        d = np.diff(c)
        if not ((d > 0).all() or (d < 0).all()):
            raise ValueError(f"{name}: {label} coordinates must be strictly monotonic; step {np.argmin(np.abs(d))} "
                             f"is {d[np.argmin(np.abs(d))]!r}.")
    eps = max(float(np.finfo(a.dtype).eps) if a.dtype.kind == "f" else 0.0 for a in (x, y))
    eps = eps or float(np.finfo(np.float64).eps)
    flip_c, flip_r = bool(x[1] < x[0]), bool(y[1] < y[0])
    xo, yo = (x[::-1] if flip_c else x), (y[::-1] if flip_r else y)
    return _Raw(values=values, missing=_missing(values, nodata), spacing=(1.0, 1.0), origin=(xo[0], yo[0]),
                source=name, flip_rows=flip_r, flip_cols=flip_c, order_note="grid index [j, i]",
                xcoords=np.asarray(xo, np.float64), ycoords=np.asarray(yo, np.float64), coord_eps=eps)


# --------------------------------------------------------------------------------------------------
# files
# --------------------------------------------------------------------------------------------------
def _read_file(path: Path, *, scalars, spacing, origin, nodata) -> _Raw:
    ext = path.suffix.lower()
    if ext not in SUPPORTED_EXTENSIONS:
        raise ValueError(f"{path}: extension {path.suffix!r} is not supported; supported: "
                         + ", ".join(f"{e} ({w})" for e, w in SUPPORTED_EXTENSIONS.items()) + ".")
    if not path.exists():
        raise FileNotFoundError(f"height file not found: {path}")
    if not path.is_file():
        raise ValueError(f"{path} is not a regular file.")
    if ext in (".tif", ".tiff"):
        if scalars is not None:
            raise ValueError(f"{path}: scalars= names a VTK point array; a TIFF has one band of heights.")
        return _read_geotiff(path, spacing, origin, nodata)
    _refuse_own_geometry(spacing, origin, str(path))
    if ext == ".dem":
        if scalars is not None:
            raise ValueError(f"{path}: scalars= names a VTK point array; a DEM has one elevation field.")
        return _read_dem(path, nodata)
    import pyvista as pv

    try:
        grid = pv.read(path)
    except Exception as exc:  # pyvista raises a variety of types for unreadable files
        raise ValueError(f"{path}: pyvista could not read it as {SUPPORTED_EXTENSIONS[ext]}: {exc}") from exc
    raw = _from_pyvista(grid, str(path), scalars, nodata)
    return raw


# ---- USGS ASCII DEM --------------------------------------------------------------------------------
# Type A record: 1024 characters of fixed-width fields (1-based columns in the USGS standard):
#   145-150 DEM level, 151-156 elevation pattern, 157-162 planimetric system (0 geographic, 1 UTM,
#   2 state plane), 163-168 zone, 169-528 15 projection parameters (D24.15), 529-534 plane unit
#   (0 radians, 1 feet, 2 metres, 3 arc-seconds), 535-540 elevation unit (1 feet, 2 metres),
#   541-546 sides (4), 547-738 corners SW, NW, NE, SE (x, y as D24.15), 739-786 min/max elevation,
#   787-810 rotation angle, 811-816 accuracy code, 817-852 resolution x, y, z (E12.6),
#   853-864 rows, columns (number of profiles).
_PLANE_UNITS = {0: "radians", 1: "ft", 2: "m", 3: "arc-seconds"}
_ELEV_UNITS = {1: "ft", 2: "m"}
# vtkDEMReader's own unit factors (to undo them: we keep the file's units).
_VTK_UNIT_FACTOR = {1: 0.305, 3: 23.111}


def _dem_float(field_text: str) -> float:
    return float(field_text.strip().replace("D", "E").replace("d", "e"))


def _read_dem_header(path: Path) -> dict:
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if len(head) < 864:
        raise ValueError(f"{path}: too short for a USGS ASCII DEM ({len(head)} bytes; the type A "
                         "record alone is 1024).")
    text = head.decode("ascii", errors="replace")

    def f(a, b):  # 1-based inclusive columns
        return text[a - 1:b]

    try:
        hdr = {
            "system": int(f(157, 162)), "zone": int(f(163, 168)),
            "plane_unit": int(f(529, 534)), "elev_unit": int(f(535, 540)),
            "corners": [(_dem_float(f(547 + 48 * k, 570 + 48 * k)), _dem_float(f(571 + 48 * k, 594 + 48 * k)))
                        for k in range(4)],
            "rotation": _dem_float(f(787, 810)),
            "res": tuple(_dem_float(f(817 + 12 * k, 828 + 12 * k)) for k in range(3)),
            "ncols": int(f(859, 864)),
        }
    except ValueError as exc:
        raise ValueError(f"{path}: not a readable USGS ASCII DEM type A record ({exc}).") from None
    if hdr["rotation"] != 0:
        raise ValueError(f"{path}: the DEM is rotated by {hdr['rotation']} rad; only north-up DEMs are supported.")
    if min(hdr["res"]) <= 0:
        raise ValueError(f"{path}: spatial resolution {hdr['res']} must be > 0.")
    return hdr


def _dem_profiles_python(path: Path, nrows: int, ncols: int):
    """Integer elevations (nrows, ncols), south row first, parsed in Python (small DEMs)."""
    with open(path, "rb") as fh:
        fh.seek(1024)
        # Tokens, not whitespace-split fields: fixed-width I6 fields may touch ("  1234-12345").
        tokens = _DEM_TOKEN.findall(fh.read().decode("ascii", errors="replace"))
    k = np.full((nrows, ncols), _DEM_VOID, dtype=np.int64)
    pos = 0
    try:
        for _ in range(ncols):
            row_id, col_id, m, n = (int(t) for t in tokens[pos:pos + 4])
            pos += 9  # 4 integers, then x, y of the first sample, datum elevation, min, max
            k[row_id - 1:row_id - 1 + m * n, col_id - 1] = [int(t) for t in tokens[pos:pos + m * n]]
            pos += m * n
    except (ValueError, IndexError) as exc:
        raise ValueError(f"{path}: malformed type B (profile) record near token {pos} ({exc}).") from None
    return k


def _read_dem(path: Path, nodata) -> _Raw:
    hdr = _read_dem_header(path)
    sw, nw, ne, se = hdr["corners"]
    dx, dy, dz = hdr["res"]
    west, east = min(sw[0], nw[0]), max(ne[0], se[0])
    south, north = min(sw[1], se[1]), max(nw[1], ne[1])
    ncols = int(round((east - west) / dx)) + 1
    nrows = int(round((north - south) / dy)) + 1
    if ncols != hdr["ncols"]:
        raise ValueError(f"{path}: header says {hdr['ncols']} profiles but the corners and x resolution "
                         f"give {ncols}.")
    if ncols >= 100:
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOImage import vtkDEMReader

        reader = vtkDEMReader()
        reader.SetFileName(str(path))
        reader.Update()
        img = reader.GetOutput()
        if tuple(img.GetDimensions()) != (ncols, nrows, 1):
            raise ValueError(f"{path}: vtkDEMReader returned dims {img.GetDimensions()}, the header gives "
                             f"{(ncols, nrows, 1)}.")
        v = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(nrows, ncols)
        # VTK stores int * float32(dz * its unit factor) as float32; recover the integers (exact for
        # |k| < 2**22) so that heights are k * dz in float64 in the file's unit.
        u32 = np.float32(np.float32(dz) * np.float32(_VTK_UNIT_FACTOR.get(hdr["elev_unit"], 1.0)))
        k = np.rint(v.astype(np.float64) / np.float64(u32)).astype(np.int64)
    else:
        # vtkDEMReader (VTK 9.7.1) divides by zero - killing the process - on DEMs with fewer than 100
        # profiles (its progress interval is ncols / 100), so small DEMs are parsed here.
        k = _dem_profiles_python(path, nrows, ncols)
    values = k * dz
    missing = k == _DEM_VOID
    if nodata is not None:
        missing |= values == nodata
    system = {0: "geographic", 1: f"UTM zone {hdr['zone']}", 2: f"state plane zone {hdr['zone']}"}.get(
        hdr["system"], f"USGS planimetric system {hdr['system']} zone {hdr['zone']}")
    plane = _PLANE_UNITS.get(hdr["plane_unit"], f"unit code {hdr['plane_unit']}")
    return _Raw(values=values, missing=missing, spacing=(dx, dy), origin=(west, south), source=str(path),
                crs=f"{system} (x, y in {plane})", units=_ELEV_UNITS.get(hdr["elev_unit"]),
                order_note="row counted from the south, column = profile")


# ---- GeoTIFF -----------------------------------------------------------------------------------------
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


def _read_geotiff(path: Path, spacing, origin, nodata) -> _Raw:
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
    missing = _missing(values, nodata)

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
        return _Raw(values=values, missing=missing, spacing=spacing, origin=origin, source=str(path),
                    flip_rows=True, order_note="(row, col) as stored, row 0 = north")
    if spacing is not None or origin is not None:
        _refuse_own_geometry(spacing, origin, f"{path} (georeferenced)")
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
    return _Raw(values=values, missing=missing, spacing=(abs(ax), abs(ay)), origin=(x_first, y_first),
                source=str(path), flip_rows=flip_rows, flip_cols=flip_cols, crs=crs, units=units,
                order_note="(row, col) as stored" + (", row 0 = north" if flip_rows else ""))


# --------------------------------------------------------------------------------------------------
# gaps, uniformity, result
# --------------------------------------------------------------------------------------------------
def _finish(raw: _Raw, *, fill, resample) -> HeightGrid:
    values = np.asarray(raw.values)
    n_missing = int(raw.missing.sum())
    if n_missing == values.size:
        raise ValueError(f"{raw.source}: all {values.size} samples are missing (NaN/inf/nodata); "
                         "nothing to read.")
    if n_missing and fill is None:
        r, c = (int(v) for v in np.argwhere(raw.missing)[0])
        x, y = (float(v) for v in raw.xy_of(r, c))
        raise ValueError(
            f"{raw.source}: {n_missing} of {values.size} samples are missing (NaN/inf/nodata); the first at "
            f"(row, col) = ({r}, {c}) [{raw.order_note}], (x, y) = ({x!r}, {y!r}), value {values[r, c].item()!r}. "
            "Pass fill='nearest' or fill='linear' to fill them."
        )
    h = raw.oriented(values).astype(np.float64)
    miss = raw.oriented(raw.missing)
    spacing, origin = raw.spacing, raw.origin
    if raw.xcoords is not None:
        xc, yc = raw.xcoords, raw.ycoords
        sx, dev_x = _uniform_step(xc)
        sy, dev_y = _uniform_step(yc)
        local = (xc - xc[0], yc - yc[0])
    else:
        dev_x = dev_y = 0.0
        local = (np.arange(h.shape[1]) * spacing[0], np.arange(h.shape[0]) * spacing[1])
    if raw.xcoords is not None and resample == "cubic" and min(h.shape) < 4:
        raise ValueError(f"{raw.source}: resample='cubic' needs at least 4 samples per axis, got shape "
                         f"{h.shape}; use resample='linear'.")
    if n_missing:
        h = _fill(h, miss, local, fill)
    if raw.xcoords is not None:
        # uniform = every step within 1e-6 of the mean step, plus the rounding of the stored coordinates
        # (float32 UTM coordinates are only good to ~0.03 m)
        tol_x = 1e-6 + 8 * raw.coord_eps * np.abs(xc).max() / sx
        tol_y = 1e-6 + 8 * raw.coord_eps * np.abs(yc).max() / sy
        if dev_x <= tol_x and dev_y <= tol_y:
            spacing, origin = (sx, sy), (float(xc[0]), float(yc[0]))
        elif resample is False:
            worst = ("x", dev_x) if dev_x / tol_x >= dev_y / tol_y else ("y", dev_y)
            raise ValueError(
                f"{raw.source}: {worst[0]} coordinates are not uniformly spaced (largest relative deviation "
                f"of a step from the mean step: {worst[1]:.3g}); the spline scheme needs a uniform grid. "
                "Pass resample=True (linear) or resample='cubic' to resample onto a uniform grid."
            )
        else:
            h, spacing = _resample(h, local, "linear" if resample is True else resample)
            origin = (float(xc[0]), float(yc[0]))
    return HeightGrid(heights=h, spacing=spacing, origin=origin, source=raw.source, crs=raw.crs, units=raw.units)


def _uniform_step(c: np.ndarray):
    """Mean step and the largest relative deviation of a step from it."""
    step = (c[-1] - c[0]) / (c.size - 1)
    return float(step), float(np.abs(np.diff(c) - step).max() / step)


def _fill(h, miss, local, method):
    from scipy import interpolate, ndimage

    (xl, yl) = local
    if method == "nearest":
        # sampling = (row step, col step): nearest in world distance on anisotropic grids
        dy = float(np.min(np.diff(yl)))
        dx = float(np.min(np.diff(xl)))
        idx = ndimage.distance_transform_edt(miss, sampling=(dy, dx), return_distances=False,
                                             return_indices=True)
        return h[tuple(idx)]
    # linear: triangulate the valid samples near the gaps only (cost scales with the gaps, not the grid)
    near = ndimage.binary_dilation(miss, iterations=2) & ~miss
    XX, YY = np.meshgrid(xl, yl)
    src = np.column_stack([XX[near], YY[near]])
    dst = np.column_stack([XX[miss], YY[miss]])
    out = h.copy()
    vals = np.full(dst.shape[0], np.nan)
    if src.shape[0] >= 3:
        try:
            vals = interpolate.griddata(src, h[near], dst, method="linear")
        except Exception:  # collinear support (e.g. one row of valid samples): fall back to nearest
            pass
    outside = ~np.isfinite(vals)
    if outside.any():
        vals[outside] = interpolate.griddata(np.column_stack([XX[~miss], YY[~miss]]), h[~miss],
                                             dst[outside], method="nearest")
    out[miss] = vals
    return out


def _resample(h, local, method):
    from scipy.interpolate import RegularGridInterpolator

    xl, yl = local
    new = []
    for c in (xl, yl):
        n = int(math.ceil(c[-1] / float(np.min(np.diff(c))) - 1e-9)) + 1
        new.append(np.linspace(0.0, c[-1], n))
    interp = RegularGridInterpolator((yl, xl), h, method=method)
    YY, XX = np.meshgrid(new[1], new[0], indexing="ij")
    out = interp(np.column_stack([YY.ravel(), XX.ravel()])).reshape(YY.shape)
    spacing = (float(xl[-1] / (new[0].size - 1)), float(yl[-1] / (new[1].size - 1)))
    return out, spacing
