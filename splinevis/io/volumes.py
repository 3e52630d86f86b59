"""Volume data on uniform, axis-aligned grids (issue 4): :class:`VolumeGrid` and :func:`read_volume`.

``VolumeGrid.values[k, j, i]`` is the sample at the world point
``origin + (i * dx, j * dy, k * dz)``; index-space coordinates are ``(x, y, z) = (i, j, k)``.

:func:`read_volume` accepts

* a 3-D numpy array ``values[k, j, i]`` (``spacing``/``origin`` keywords, defaults ``(1, 1, 1)`` and
  ``(0, 0, 0)``),
* a pyvista ``ImageData`` or a ``vtkImageData`` (point data; cell data see below), a uniform
  ``RectilinearGrid`` or an axis-aligned uniform ``StructuredGrid``,
* a file:

  ========================  ===============================================================
  ``.vti``                  VTK XML ImageData (pyvista), direction matrix honoured
  ``.vtk``                  legacy VTK STRUCTURED_POINTS (or uniform rectilinear/structured)
  ``.vtr`` ``.vts``         VTK XML RectilinearGrid / StructuredGrid with uniform spacing
  ``.mha`` ``.mhd``         MetaImage (``vtkMetaImageReader``), TransformMatrix honoured
  ``.nrrd`` ``.nhdr``       NRRD, parsed here (raw, gzip, bzip2, ascii, hex encodings)
  ``.slc``                  SLC (``vtkSLCReader``; 8-bit, no origin in the format)
  ``.raw`` ``.bin``         headerless samples: pass ``shape``, ``dtype``, ``byteorder``
  ========================  ===============================================================

Conventions kept by every reader
--------------------------------
* Samples are converted to float64 exactly (uint8 ... int32, float32, float64; int64/uint64 when
  every value is below 2**53 in magnitude); ``VolumeGrid.dtype`` records the stored type.
* Spacing may differ per axis; spacing and origin are kept in float64 as the source gives them
  (an origin of ``1e6`` with spacing ``1e3`` stays exact). Sources that carry their own geometry
  refuse ``spacing=``/``origin=`` rather than silently override it (SLC has no origin: ``origin=`` is
  allowed there).
* **Direction matrices.** A grid whose direction matrix is diagonal with entries +-1 (axis flips) is
  normalised: every flipped axis is reversed in the array and the origin moves to the sample with the
  smallest coordinate, so the returned grid shows the same picture with positive spacing. Negative
  spacings (VTK, NRRD ``spacings``) are treated the same way. Any other direction (a rotation, or a
  permutation of the axes) raises ValueError: the spline schemes need axis-aligned grids, and dropping
  the direction would draw a wrong picture. Off-diagonal entries below ``1e-9`` times the axis length
  count as rounding and are ignored.
* **Cell data.** VTK cell data of an ``ImageData`` hold one value per voxel; they are read as samples
  at the voxel centres: a grid of ``(nz-1, ny-1, nx-1)`` samples whose origin is half a voxel inside.
  Point data are preferred when both exist; ``scalars=`` picks an array by name from either.
* **Several arrays.** With more than one data array and no ``scalars=``, the call is ambiguous and the
  error lists the arrays. Arrays with several components raise unless ``component=`` picks one
  (an int) or asks for ``"magnitude"`` (Euclidean norm per sample).
* **Missing samples.** NaN and +-inf raise ValueError naming the first bad voxel ``[k, j, i]`` of the
  returned grid and its world position. ``fill="nearest"`` takes the value of the nearest valid voxel
  in world distance (anisotropic spacing counts, ``scipy.ndimage.distance_transform_edt``); a number
  ``fill=0.0`` puts that value into every gap.
* At least 2 samples per axis (the spline schemes themselves need 3 and check that).

Format notes (VTK 9.7.1)
------------------------
* NRRD is parsed here because ``vtkNrrdReader`` takes the first axis as vector components whenever it
  has 9 or fewer samples, reads only the length of each ``space directions`` vector (rotations and
  flips are lost) and does not support ``byte skip``. ``space origin``/``space directions`` are used as
  given (coordinates of the file's ``space``, e.g. LPS or RAS, are not converted). Without them,
  ``spacings`` and ``axis mins`` (cell centering adds half a step) give the geometry.
* Legacy ``.vtk`` files written by VTK carry spacing and origin with 6 significant digits only (an
  origin of ``1e6 + 0.1`` is written as ``1e+06``); the reader keeps what the file says.
  ``datasets_synthetic.volumes.write_volume`` writes full precision.
* ``vtkMetaImageReader`` returns a grid of uninitialised values with only a warning when the data are
  short; such warnings are turned into errors here.
* DICOM series and NIfTI are not read (VTK's readers ignore parts of their orientation); convert them
  to NRRD or MetaImage first.
"""

from __future__ import annotations

import bz2
import gzip
import math
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validation import as_float64_array

__all__ = ["VolumeGrid", "read_volume", "VOLUME_EXTENSIONS"]

#: File name extensions :func:`read_volume` reads, and by what.
VOLUME_EXTENSIONS = {
    ".vti": "VTK XML ImageData (pyvista)",
    ".vtk": "legacy VTK structured points (pyvista)",
    ".vtr": "VTK XML RectilinearGrid, uniform spacing (pyvista)",
    ".vts": "VTK XML StructuredGrid, axis-aligned uniform (pyvista)",
    ".mha": "MetaImage (vtkMetaImageReader)",
    ".mhd": "MetaImage with detached data (vtkMetaImageReader)",
    ".nrrd": "NRRD (parsed by splinevis)",
    ".nhdr": "NRRD detached header (parsed by splinevis)",
    ".slc": "SLC (vtkSLCReader)",
    ".raw": "headerless samples (shape=, dtype=, byteorder=)",
    ".bin": "headerless samples (shape=, dtype=, byteorder=)",
}
_RAW_EXTENSIONS = (".raw", ".bin")
_UNSUPPORTED = {
    ".dcm": "DICOM", ".nii": "NIfTI", ".gz": "a compressed file (NIfTI .nii.gz?)", ".img": "Analyze/NIfTI",
    ".hdr": "Analyze/NIfTI", ".mnc": "MINC",
}
_VTK_INTERNAL_ARRAYS = {"vtkGhostType", "vtkValidPointMask"}


def _check_triple(value, name: str, *, positive: bool = False) -> tuple:
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be three numbers (x, y, z), got the string {value!r}.")
    try:
        t = tuple(float(v) for v in value)
    except TypeError:
        raise TypeError(f"{name} must be three numbers (x, y, z), got {type(value).__name__}.") from None
    if len(t) != 3:
        raise ValueError(f"{name} must have 3 entries (x, y, z), got {len(t)}: {value!r}.")
    if not all(np.isfinite(t)):
        raise ValueError(f"{name} must be finite, got {t}.")
    if positive and min(t) <= 0:
        raise ValueError(f"{name} must be > 0 on every axis, got {t}.")
    return t


@dataclass(frozen=True, eq=False)
class VolumeGrid:
    """Samples of a scalar field on a uniform, axis-aligned grid.

    Parameters
    ----------
    values : (nz, ny, nx) ndarray
        ``values[k, j, i]`` is the sample at ``origin + (i*dx, j*dy, k*dz)``. Stored as a read-only
        float64 copy; every value finite.
    spacing : (dx, dy, dz) floats > 0
        May differ per axis (anisotropic).
    origin : (x0, y0, z0) floats
        World position of ``values[0, 0, 0]``, kept in float64.
    source : str
        Where the data came from (a file path, ``"numpy array"``, ``"pyvista.ImageData"``, ...).
    scalars : str or None
        Name of the array read, if the source names it.
    dtype : str
        The data type of the source samples before conversion (``"uint8"``, ``"int16"``, ...).
    rescale : (slope, intercept)
        How the values relate to the stored samples: ``values = slope * stored + intercept`` (already
        applied). ``(1.0, 0.0)`` for everything read from files; quantised synthetic samples
        (``datasets_synthetic.volumes``) record their scale here.

    Examples
    --------
    >>> import numpy as np
    >>> g = VolumeGrid(np.zeros((2, 3, 4)), spacing=(1.0, 2.0, 3.0), origin=(1e6, 0.0, 0.0))
    >>> g.shape, g.bounds
    ((2, 3, 4), (1000000.0, 1000003.0, 0.0, 4.0, 0.0, 3.0))
    >>> g.to_world([3, 2, 1]).tolist()
    [1000003.0, 4.0, 3.0]
    """

    values: np.ndarray
    spacing: tuple = (1.0, 1.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)
    source: str = "numpy array"
    scalars: str | None = None
    dtype: str = "float64"
    rescale: tuple = (1.0, 0.0)

    def __post_init__(self):
        v = as_float64_array(self.values, "values", ndim=3)
        v = np.array(v, dtype=np.float64, copy=True)
        v.flags.writeable = False
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "spacing", _check_triple(self.spacing, "spacing", positive=True))
        object.__setattr__(self, "origin", _check_triple(self.origin, "origin"))
        if not isinstance(self.source, str):
            raise TypeError(f"source must be a str, got {type(self.source).__name__}.")
        r = tuple(float(x) for x in self.rescale)
        if len(r) != 2 or not all(np.isfinite(r)) or r[0] == 0:
            raise ValueError(f"rescale must be (slope != 0, intercept), finite, got {self.rescale!r}.")
        object.__setattr__(self, "rescale", r)

    @property
    def shape(self) -> tuple:
        """``(nz, ny, nx)``."""
        return self.values.shape

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the sample positions (pyvista order)."""
        (nz, ny, nx), (dx, dy, dz), (x0, y0, z0) = self.shape, self.spacing, self.origin
        return (x0, x0 + (nx - 1) * dx, y0, y0 + (ny - 1) * dy, z0, z0 + (nz - 1) * dz)

    @property
    def value_range(self) -> tuple:
        """``(min, max)`` of the samples."""
        return (float(self.values.min()), float(self.values.max()))

    def axes(self) -> tuple:
        """``(x, y, z)``: the (nx,), (ny,), (nz,) float64 coordinates of the sample planes."""
        (nz, ny, nx), (dx, dy, dz), (x0, y0, z0) = self.shape, self.spacing, self.origin
        return (x0 + np.arange(nx) * dx, y0 + np.arange(ny) * dy, z0 + np.arange(nz) * dz)

    def to_index(self, points) -> np.ndarray:
        """World points ``(..., 3)`` to index-space coordinates ``(x, y, z) = (i, j, k)`` (float64)."""
        p = np.asarray(points, dtype=np.float64)
        return (p - np.asarray(self.origin)) / np.asarray(self.spacing)

    def to_world(self, index_points) -> np.ndarray:
        """Index-space coordinates ``(..., 3)`` to world points (float64)."""
        q = np.asarray(index_points, dtype=np.float64)
        return np.asarray(self.origin) + q * np.asarray(self.spacing)

    def to_pyvista(self):
        """A ``pyvista.ImageData`` with the samples as point data ``"values"`` (x fastest, VTK order)."""
        import pyvista as pv

        img = pv.ImageData(dimensions=self.shape[::-1], spacing=self.spacing, origin=self.origin)
        img.point_data["values"] = np.ascontiguousarray(self.values).ravel(order="C")
        return img


# --------------------------------------------------------------------------------------------------
# Internal: what a reader hands over before flips, gaps and conversion
# --------------------------------------------------------------------------------------------------
@dataclass
class _Raw:
    """``values`` (nz, ny, nx) in the source's dtype and order; ``flips[a]`` reverses axis a (x, y, z).

    ``origin`` and ``spacing`` already describe the flipped (returned) grid.
    """

    values: np.ndarray
    spacing: tuple
    origin: tuple
    source: str
    scalars: str | None = None
    flips: tuple = (False, False, False)

    def oriented(self) -> np.ndarray:
        v = self.values
        fx, fy, fz = self.flips
        v = v[::-1 if fz else 1, ::-1 if fy else 1, ::-1 if fx else 1]
        return v


# --------------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------------
def read_volume(source, *, scalars=None, spacing=None, origin=None, shape=None, dtype=None, byteorder=None,
                header_bytes=0, fill=None, component=None) -> VolumeGrid:
    """Read volume data into a :class:`VolumeGrid` (see the module notes for formats and conventions).

    Parameters
    ----------
    source : (nz, ny, nx) array_like, pyvista/VTK ImageData, RectilinearGrid, StructuredGrid, str or Path
        The samples; ``values[k, j, i]`` of a numpy array lies at ``origin + (i*dx, j*dy, k*dz)``. A str
        or Path is a file; see ``VOLUME_EXTENSIONS``.
    scalars : str, optional
        Name of the data array (pyvista/VTK sources and files with named arrays). Needed when there
        are several arrays.
    spacing, origin : (3,) floats, optional
        Geometry of numpy arrays and raw files (defaults ``(1, 1, 1)``, ``(0, 0, 0)``); ``origin`` also
        for SLC files. A single number as ``spacing`` applies to every axis.
    shape : (nz, ny, nx) ints
        Raw files only: the number of samples per axis, slowest (z) first.
    dtype : str or numpy dtype
        Raw files only: ``"uint8"``, ``"uint16"``, ``"int16"``, ``"int32"``, ``"float32"``, ``"float64"``...
    byteorder : {"little", "big"}
        Raw files with samples wider than one byte. Required: guessing it wrong gives plausible-looking
        garbage. (A dtype such as ``">u2"`` carries it too.)
    header_bytes : int
        Raw files only: bytes to skip before the samples.
    fill : {None, "nearest"} or float
        None (default): NaN/inf samples raise ValueError. ``"nearest"``: fill each with the nearest valid
        voxel (world distance). A number: fill with that number.
    component : None, int or "magnitude"
        For arrays with several components: pick one (0-based) or take the Euclidean norm.

    Returns
    -------
    VolumeGrid

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    TypeError
        Unsupported source type or non-numeric samples.
    ValueError
        Not 3-D, fewer than 2 samples on an axis, rotated or permuted grid, non-uniform spacing,
        ambiguous or missing array, multi-component array without ``component=``, missing samples
        without ``fill=``, raw file of the wrong size, unreadable file.

    Examples
    --------
    >>> import numpy as np
    >>> g = read_volume(np.arange(24, dtype=np.uint16).reshape(2, 3, 4), spacing=(0.5, 0.5, 2.0),
    ...                 origin=(1e6, 0.0, -3.0))
    >>> g.shape, g.dtype, float(g.values[1, 2, 3]), g.to_world([3, 2, 1]).tolist()
    ((2, 3, 4), 'uint16', 23.0, [1000001.5, 1.0, -1.0])
    >>> import pyvista as pv
    >>> img = pv.ImageData(dimensions=(4, 3, 2), spacing=(1.0, 2.0, 3.0))
    >>> img.point_data["density"] = np.arange(24.0)
    >>> read_volume(img).scalars
    'density'
    """
    if fill is not None and not (isinstance(fill, str) and fill == "nearest"):
        if isinstance(fill, (str, bytes, bool)) or not isinstance(fill, (int, float, np.integer, np.floating)):
            raise ValueError(f"fill {fill!r} is not known; choose 'nearest' or a finite number (e.g. fill=0.0).")
        if not math.isfinite(float(fill)):
            raise ValueError(f"fill must be finite to fill NaN/inf samples, got {fill!r}.")
    if component is not None and not (component == "magnitude" if isinstance(component, str) else
                                      isinstance(component, (int, np.integer)) and not isinstance(component, bool)):
        raise ValueError(f"component {component!r} is not known; pass an int (0-based component) or 'magnitude'.")
    if scalars is not None and not isinstance(scalars, str):
        raise TypeError(f"scalars must be the name (str) of a data array, got {type(scalars).__name__}.")
    if spacing is not None:
        if isinstance(spacing, (int, float, np.integer, np.floating)) and not isinstance(spacing, bool):
            spacing = (spacing,) * 3
        spacing = _check_triple(spacing, "spacing", positive=True)
    if origin is not None:
        origin = _check_triple(origin, "origin")

    is_path = isinstance(source, (str, os.PathLike))
    raw_args = {"shape": shape, "dtype": dtype, "byteorder": byteorder}
    if not is_path or Path(source).suffix.lower() not in _RAW_EXTENSIONS:
        given = [k for k, v in raw_args.items() if v is not None] + (["header_bytes"] if header_bytes else [])
        if given and not (is_path and Path(source).suffix.lower() not in VOLUME_EXTENSIONS):
            raise ValueError(f"{' and '.join(given)}= describe headerless raw files (.raw, .bin); "
                             f"{_describe(source)} carries that information itself. Drop the argument.")

    raw = _dispatch(source, scalars=scalars, spacing=spacing, origin=origin, shape=shape, dtype=dtype,
                    byteorder=byteorder, header_bytes=header_bytes, component=component)
    return _finish(raw, fill)


def _describe(source) -> str:
    if isinstance(source, (str, os.PathLike)):
        return str(source)
    if isinstance(source, np.ndarray):
        return "a numpy array"
    return f"a {type(source).__name__}"


def _dispatch(source, *, scalars, spacing, origin, shape, dtype, byteorder, header_bytes, component) -> _Raw:
    if isinstance(source, (str, os.PathLike)):
        return _read_file(Path(source), scalars=scalars, spacing=spacing, origin=origin, shape=shape, dtype=dtype,
                          byteorder=byteorder, header_bytes=header_bytes, component=component)
    if _is_vtk_object(source):
        import pyvista as pv

        grid = pv.wrap(source)
        name = f"pyvista.{type(grid).__name__}"
        _refuse_own_geometry(spacing, origin, name)
        return _from_pyvista(grid, name, scalars, component)
    if isinstance(source, (np.ndarray, list, tuple)):
        if scalars is not None:
            raise ValueError("scalars= names a data array of a pyvista grid or a file; a numpy array has none.")
        return _from_array(np.asarray(source), spacing, origin, component, "numpy array")
    raise TypeError(f"source of type {type(source).__name__} is not supported; pass a 3-D numpy array "
                    "(nz, ny, nx), a pyvista ImageData / vtkImageData, or a file path "
                    f"({', '.join(VOLUME_EXTENSIONS)}).")


def _is_vtk_object(source) -> bool:
    mod = type(source).__module__ or ""
    if not (mod.startswith("pyvista") or mod.startswith("vtk")):
        return False
    from vtkmodules.vtkCommonDataModel import vtkDataObject

    return isinstance(source, vtkDataObject)


def _refuse_own_geometry(spacing, origin, what: str, *, allow_origin: bool = False):
    given = [n for n, v in (("spacing", spacing), ("origin", None if allow_origin else origin)) if v is not None]
    if given:
        raise ValueError(f"{what} carries its own spacing and origin; {' and '.join(given)}= would override "
                         "them. Drop the argument (spacing=/origin= apply to numpy arrays and raw files).")


# --------------------------------------------------------------------------------------------------
# numpy arrays and components
# --------------------------------------------------------------------------------------------------
def _check_dtype(arr: np.ndarray, where: str):
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{where}: samples must be real numbers, got dtype {arr.dtype}"
                        f"{' (strings)' if arr.dtype.kind in 'USO' else ''}.")
    if arr.dtype.kind in "iu" and arr.dtype.itemsize == 8 and arr.size:
        big = np.abs(arr.astype(np.float64)).max() if arr.dtype.kind == "i" else float(arr.max())
        if big > 2.0 ** 53:
            raise ValueError(f"{where}: {arr.dtype} samples up to {big:.17g} are not exact in float64 "
                             "(|value| > 2**53); rescale them first.")


def _pick_component(arr: np.ndarray, ncomp: int, label: str, where: str, component) -> np.ndarray:
    """``arr`` has its components on the last axis."""
    if component is None:
        raise ValueError(f"{where}: array {label!r} has {ncomp} components per sample; a volume needs one. "
                         f"Pass component=0..{ncomp - 1} to pick one or component='magnitude' for the norm.")
    if component == "magnitude":
        return np.sqrt(np.sum(np.square(arr.astype(np.float64)), axis=-1))
    if not -ncomp <= int(component) < ncomp:
        raise ValueError(f"{where}: component={component} is out of range; array {label!r} has {ncomp} "
                         f"components (0..{ncomp - 1}).")
    return arr[..., int(component)]


def _from_array(arr: np.ndarray, spacing, origin, component, where) -> _Raw:
    _check_dtype(arr, where)
    if arr.ndim == 4:
        arr = _pick_component(arr, arr.shape[3], "the last axis", where, component)
    elif component is not None:
        raise ValueError(f"{where}: component= applies to multi-component data; this array has shape {arr.shape}.")
    if arr.ndim != 3:
        hint = (" A 2-D image is a height field: use splinevis.io.read_heights." if arr.ndim == 2 else
                " A 4-D array (nz, ny, nx, c) is read with component=." if arr.ndim > 4 else "")
        raise ValueError(f"{where}: volume samples must be a 3-D array (nz, ny, nx), got shape {arr.shape}.{hint}")
    _check_size(arr.shape, where)
    return _Raw(values=arr, spacing=spacing or (1.0, 1.0, 1.0), origin=origin or (0.0, 0.0, 0.0), source=where)


def _check_size(shape, where):
    if min(shape) < 2:
        axis = "zyx"[int(np.argmin(shape))]
        raise ValueError(f"{where}: a volume needs at least 2 samples on every axis; shape (nz, ny, nx) = "
                         f"{tuple(int(s) for s in shape)} has {min(shape)} along {axis}."
                         + (" A single slice is a 2-D image (see splinevis.io.read_heights)." if min(shape) == 1
                            else ""))


# --------------------------------------------------------------------------------------------------
# pyvista / VTK objects
# --------------------------------------------------------------------------------------------------
def _arrays(grid):
    """[(association, name, ncomp)] of the data arrays of ``grid``, point data first."""
    out = []
    for assoc, data in (("point", grid.point_data), ("cell", grid.cell_data)):
        for name in data.keys():
            if name in _VTK_INTERNAL_ARRAYS:
                continue
            a = np.asarray(data[name])
            out.append((assoc, name, 1 if a.ndim == 1 else int(a.shape[1])))
    return out


def _list_arrays(arrays) -> str:
    if not arrays:
        return "none"
    return ", ".join(f"{n!r} ({a} data" + (f", {c} components)" if c > 1 else ")") for a, n, c in arrays)


def _choose_array(grid, where, scalars):
    arrays = _arrays(grid)
    if scalars is not None:
        hits = [a for a in arrays if a[1] == scalars]
        if not hits:
            raise ValueError(f"{where}: no data array named {scalars!r}; arrays: {_list_arrays(arrays)}.")
        assoc, name, _ = hits[0]  # point data first
    else:
        if not arrays:
            raise ValueError(f"{where}: the grid has no data arrays; nothing to read.")
        if len(arrays) > 1:
            raise ValueError(f"{where}: {len(arrays)} data arrays, which one? Pass scalars= with one of: "
                             f"{_list_arrays(arrays)}.")
        assoc, name, _ = arrays[0]
    data = grid.point_data if assoc == "point" else grid.cell_data
    return assoc, name, np.asarray(data[name])


def _from_pyvista(grid, where, scalars, component) -> _Raw:
    import pyvista as pv

    if isinstance(grid, pv.ImageData):
        dims = tuple(int(d) for d in grid.dimensions)
        spacing = np.array(grid.spacing, dtype=np.float64)
        origin = np.array(grid.origin, dtype=np.float64)
        extent = np.array(grid.extent, dtype=np.int64)[0::2]
        direction = np.asarray(grid.direction_matrix, dtype=np.float64)
        sign = _axis_signs(direction, where)
        first = origin + direction @ (extent * spacing)  # world position of the first stored point
        axes_step = sign * spacing  # world step of the stored index along each axis
        assoc, name, arr = _choose_array(grid, where, scalars)
        if assoc == "cell":
            first = first + 0.5 * axes_step
            dims = tuple(max(d - 1, 1) for d in dims)
        return _lattice_raw(arr, dims, first, axes_step, where, name, component)
    if isinstance(grid, pv.RectilinearGrid):
        coords = [np.asarray(c, dtype=np.float64) for c in (grid.x, grid.y, grid.z)]
        return _coords_raw(grid, coords, where, scalars, component)
    if isinstance(grid, pv.StructuredGrid):
        dims = tuple(int(d) for d in grid.dimensions)
        pts = np.asarray(grid.points, dtype=np.float64).reshape(dims[2], dims[1], dims[0], 3)
        x, y, z = pts[0, 0, :, 0], pts[0, :, 0, 1], pts[:, 0, 0, 2]
        ref = np.stack(np.broadcast_arrays(x[None, None, :], y[None, :, None], z[:, None, None]), axis=-1)
        scale = max(float(np.abs(pts).max()), 1e-300)
        dev = float(np.abs(pts - ref).max())
        if dev > 1e-6 * max(float(np.ptp(pts.reshape(-1, 3), axis=0).max()), 1e-300) + 8 * np.finfo(
                np.asarray(grid.points).dtype).eps * scale:
            raise ValueError(f"{where}: the points are not an axis-aligned lattice (a point is {dev:.3g} away "
                             "from the lattice of its row, column and slice coordinates); curvilinear or "
                             "rotated grids are not supported. Resample onto an ImageData first "
                             "(e.g. pyvista's grid.sample(image)).")
        return _coords_raw(grid, [x, y, z], where, scalars, component,
                           eps=float(np.finfo(np.asarray(grid.points).dtype).eps))
    raise TypeError(f"{where} is not supported; volumes come from ImageData (or uniform RectilinearGrid/"
                    "StructuredGrid), a 3-D numpy array or a file.")


def _axis_signs(direction: np.ndarray, where: str) -> np.ndarray:
    """+-1 per axis when ``direction`` is diagonal with entries +-1 (to rounding); else ValueError."""
    d = np.asarray(direction, dtype=np.float64)
    if d.shape != (3, 3) or not np.isfinite(d).all():
        raise ValueError(f"{where}: direction matrix {d.tolist()} is not a finite 3 x 3 matrix.")
    off = d - np.diag(np.diag(d))
    diag = np.diag(d)
    if np.abs(off).max() <= 1e-9 and np.all(np.abs(np.abs(diag) - 1.0) <= 1e-9):
        return np.sign(diag)
    perm = np.all(np.abs(np.round(d) - d) <= 1e-9) and np.all(np.abs(np.round(d)).sum(axis=0) == 1) and \
        np.all(np.abs(np.round(d)).sum(axis=1) == 1)
    what = "permutes the axes" if perm else "is not axis-aligned (a rotation or shear)"
    raise ValueError(f"{where}: the direction matrix {np.round(d, 12).tolist()} {what}; only axis-aligned "
                     "grids (the identity up to axis flips, i.e. diagonal +-1) are supported, and dropping the "
                     "direction would draw a wrong picture. Resample onto an axis-aligned grid first "
                     "(e.g. in 3D Slicer or SimpleITK), or set the direction to the identity if you know the "
                     "orientation does not matter.")


def _lattice_raw(arr, dims, first, axes_step, where, name, component) -> _Raw:
    """Flat VTK-ordered ``arr`` on ``dims`` (nx, ny, nz) with stored first point and signed steps."""
    _check_dtype(arr, f"{where} array {name!r}")
    nx, ny, nz = dims
    if arr.ndim == 2:
        arr = _pick_component(arr, arr.shape[1], name, where, component)
    elif component is not None:
        raise ValueError(f"{where}: component= applies to multi-component arrays; {name!r} has one component.")
    if arr.shape[0] != nx * ny * nz:
        raise ValueError(f"{where}: array {name!r} has {arr.shape[0]} values, dims {dims} need {nx * ny * nz}.")
    _check_size((nz, ny, nx), where)
    values = arr.reshape(nz, ny, nx)
    flips = tuple(bool(s < 0) for s in axes_step)
    n = np.array([nx, ny, nz], dtype=np.float64)
    origin = tuple(float(f + s * (m - 1)) if s < 0 else float(f) for f, s, m in zip(first, axes_step, n))
    spacing = tuple(float(abs(s)) for s in axes_step)
    if min(spacing) <= 0:
        raise ValueError(f"{where}: spacing {spacing} must be nonzero on every axis.")
    return _Raw(values=values, spacing=spacing, origin=origin, source=where, scalars=name, flips=flips)


def _coords_raw(grid, coords, where, scalars, component, eps=None) -> _Raw:
    steps, firsts = [], []
    for label, c in zip("xyz", coords):
        if c.size < 2:
            _check_size((coords[2].size, coords[1].size, coords[0].size), where)
        if not np.isfinite(c).all():
            raise ValueError(f"{where}: {label} coordinates must be finite.")
        step = (c[-1] - c[0]) / (c.size - 1)
        e = eps if eps is not None else float(np.finfo(np.float64).eps)
        dev = float(np.abs(np.diff(c) - step).max() / abs(step)) if step != 0 else float("inf")
        tol = 1e-6 + 8 * e * float(np.abs(c).max()) / abs(step) if step != 0 else 0.0
        if not dev <= tol:
            raise ValueError(f"{where}: {label} coordinates are not uniformly spaced (largest relative deviation "
                             f"of a step from the mean step: {dev:.3g}); the spline schemes need a uniform grid. "
                             "Resample onto an ImageData first (e.g. pyvista's grid.sample(image)).")
        steps.append(float(step))
        firsts.append(float(c[0]))
    assoc, name, arr = _choose_array(grid, where, scalars)
    dims = tuple(c.size for c in coords)
    first = np.array(firsts)
    if assoc == "cell":
        first = first + 0.5 * np.array(steps)
        dims = tuple(d - 1 for d in dims)
    return _lattice_raw(arr, dims, first, np.array(steps), where, name, component)


# --------------------------------------------------------------------------------------------------
# files
# --------------------------------------------------------------------------------------------------
def _read_file(path: Path, *, scalars, spacing, origin, shape, dtype, byteorder, header_bytes, component) -> _Raw:
    ext = path.suffix.lower()
    if path.is_dir():
        raise ValueError(f"{path} is a directory; DICOM series are not read (VTK's reader drops parts of "
                         "their orientation). Convert the series to NRRD or MetaImage first (e.g. with "
                         "3D Slicer, SimpleITK or dcm2niix + conversion) and pass that file.")
    if ext in _UNSUPPORTED:
        raise ValueError(f"{path}: {_UNSUPPORTED[ext]} files are not read (VTK's readers ignore parts of their "
                         "orientation); convert to NRRD (.nrrd) or MetaImage (.mha) first. Supported: "
                         + ", ".join(VOLUME_EXTENSIONS) + ".")
    is_raw = ext in _RAW_EXTENSIONS or (ext not in VOLUME_EXTENSIONS and shape is not None)
    if not is_raw and ext not in VOLUME_EXTENSIONS:
        raise ValueError(f"{path}: extension {path.suffix!r} is not supported; supported: "
                         + ", ".join(f"{e} ({w})" for e, w in VOLUME_EXTENSIONS.items())
                         + ". A headerless file is read with shape=, dtype= and byteorder=.")
    if not path.exists():
        raise FileNotFoundError(f"volume file not found: {path}")
    if not path.is_file():
        raise ValueError(f"{path} is not a regular file.")
    if path.stat().st_size == 0:
        raise ValueError(f"{path} is empty (0 bytes).")
    if is_raw:
        if scalars is not None:
            raise ValueError(f"{path}: scalars= names an array of a VTK file; a raw file holds one array.")
        return _read_raw(path, shape, dtype, byteorder, header_bytes, spacing, origin, component)
    if ext in (".nrrd", ".nhdr"):
        _refuse_own_geometry(spacing, origin, str(path))
        return _read_nrrd(path, scalars, component)
    if ext == ".slc":
        _refuse_own_geometry(spacing, origin, f"{path} (SLC has a spacing, no origin)", allow_origin=True)
        raw = _from_pyvista(_vtk_read(path), str(path), scalars, component)
        if origin is not None:
            raw.origin = origin
        return raw
    _refuse_own_geometry(spacing, origin, str(path))
    return _from_pyvista(_vtk_read(path), str(path), scalars, component)


def _vtk_read(path: Path):
    """``pyvista.read`` with VTK errors and reader warnings turned into ValueError naming the file."""
    import pyvista as pv

    try:
        with warnings.catch_warnings(record=True) as caught, pv.VtkErrorCatcher(raise_errors=False) as catcher:
            warnings.simplefilter("always")
            grid = pv.read(path)
    except Exception as exc:  # pyvista and VTK raise a variety of types for unreadable files
        raise ValueError(f"{path}: could not be read as {VOLUME_EXTENSIONS[path.suffix.lower()]}: {exc}") from exc
    problems = [str(e) for e in getattr(catcher, "events", [])]
    problems += [str(w.message) for w in caught if "error" in str(w.message).lower()]
    if problems:
        msg = " ".join(problems[0].split())
        raise ValueError(f"{path}: could not be read as {VOLUME_EXTENSIONS[path.suffix.lower()]} (the VTK reader "
                         f"reported: {msg[:300]}). Is the file complete and of this format?")
    if grid is None or grid.n_points == 0:
        raise ValueError(f"{path}: the reader returned no samples; is the file complete and of this format?")
    if isinstance(grid, pv.MultiBlock):
        raise ValueError(f"{path}: holds a MultiBlock dataset; save one ImageData block instead.")
    return grid


# ---- raw -------------------------------------------------------------------------------------------
def _read_raw(path, shape, dtype, byteorder, header_bytes, spacing, origin, component) -> _Raw:
    missing = [n for n, v in (("shape", shape), ("dtype", dtype)) if v is None]
    if missing:
        raise ValueError(f"{path}: a headerless raw file needs {' and '.join(m + '=' for m in missing)}, e.g. "
                         f"read_volume({str(path)!r}, shape=(nz, ny, nx), dtype='uint16', byteorder='little', "
                         "spacing=(dx, dy, dz), origin=(x0, y0, z0)); shape lists the slowest axis (z) first.")
    try:
        dt = np.dtype(dtype)
    except TypeError:
        raise ValueError(f"{path}: dtype {dtype!r} is not a numpy dtype; use e.g. 'uint8', 'uint16', 'int16', "
                         "'int32', 'float32', 'float64'.") from None
    if dt.kind not in "biuf":
        raise TypeError(f"{path}: dtype {dt} is not a real number type.")
    if isinstance(shape, (int, np.integer)) or len(tuple(shape)) != 3:
        raise ValueError(f"{path}: shape must be three sample counts (nz, ny, nx), got {shape!r}.")
    shape = tuple(int(s) for s in shape)
    if min(shape) < 1:
        raise ValueError(f"{path}: shape {shape} must be positive on every axis.")
    marker = dtype[0] if isinstance(dtype, str) and dtype[:1] in ("<", ">") else dt.byteorder
    explicit = {"<": "little", ">": "big"}.get(marker)
    if byteorder is not None and byteorder not in ("little", "big"):
        raise ValueError(f"{path}: byteorder {byteorder!r} is not known; choose 'little' or 'big'.")
    if explicit and byteorder and explicit != byteorder:
        raise ValueError(f"{path}: dtype {dtype!r} says {explicit}-endian but byteorder={byteorder!r}.")
    order = byteorder or explicit
    if dt.itemsize > 1:
        if order is None:
            raise ValueError(f"{path}: {dt.name} samples take {dt.itemsize} bytes; pass byteorder='little' "
                             "(most files from PCs) or byteorder='big' - a wrong guess reads plausible garbage.")
        dt = dt.newbyteorder("<" if order == "little" else ">")
    if isinstance(header_bytes, bool) or not isinstance(header_bytes, (int, np.integer)) or header_bytes < 0:
        raise ValueError(f"{path}: header_bytes must be a non-negative int, got {header_bytes!r}.")
    n = int(np.prod(shape))
    expected = int(header_bytes) + n * dt.itemsize
    actual = path.stat().st_size
    if actual != expected:
        data = actual - int(header_bytes)
        hints = []
        if data > 0 and data % n == 0 and data // n != dt.itemsize:
            hints.append(f"the data are {data // n} bytes per sample, not {dt.itemsize}: check dtype")
        if actual > expected:
            hints.append(f"a header of {actual - n * dt.itemsize} bytes would explain the size: "
                         f"header_bytes={actual - n * dt.itemsize}")
        if data > 0 and data % dt.itemsize == 0:
            hints.append(f"the file holds {data // dt.itemsize} samples of {dt.itemsize} bytes, shape {shape} "
                         f"needs {n}: check shape (nz, ny, nx), slowest axis first")
        raise ValueError(f"{path}: expected {expected} bytes ({header_bytes} header + {shape[0]} x {shape[1]} x "
                         f"{shape[2]} samples x {dt.itemsize} bytes of {dt.name}), the file has {actual}. "
                         "Likely fix: " + "; or ".join(hints or ["check shape, dtype and header_bytes"]) + ".")
    arr = np.fromfile(path, dtype=dt, count=n, offset=int(header_bytes)).reshape(shape)
    arr = arr.astype(dt.newbyteorder("="), copy=False)
    return _from_array(arr, spacing, origin, component, str(path))


# ---- NRRD ------------------------------------------------------------------------------------------
_NRRD_TYPES = {
    "signed char": "int8", "int8": "int8", "int8_t": "int8",
    "uchar": "uint8", "unsigned char": "uint8", "uint8": "uint8", "uint8_t": "uint8",
    "short": "int16", "short int": "int16", "signed short": "int16", "signed short int": "int16",
    "int16": "int16", "int16_t": "int16",
    "ushort": "uint16", "unsigned short": "uint16", "unsigned short int": "uint16", "uint16": "uint16",
    "uint16_t": "uint16",
    "int": "int32", "signed int": "int32", "int32": "int32", "int32_t": "int32",
    "uint": "uint32", "unsigned int": "uint32", "uint32": "uint32", "uint32_t": "uint32",
    "longlong": "int64", "long long": "int64", "long long int": "int64", "signed long long": "int64",
    "signed long long int": "int64", "int64": "int64", "int64_t": "int64",
    "ulonglong": "uint64", "unsigned long long": "uint64", "unsigned long long int": "uint64",
    "uint64": "uint64", "uint64_t": "uint64",
    "float": "float32", "double": "float64",
}
_NRRD_VECTOR = re.compile(r"\(([^)]*)\)|none")
_NRRD_SPATIAL_KINDS = {"domain", "space", "time"}


def _nrrd_header(path: Path):
    """(fields, bytes offset of the data in ``path``) of an NRRD file or detached header."""
    with open(path, "rb") as fh:
        blob = fh.read(1 << 16)
        magic = blob[:8]
        if not magic.startswith(b"NRRD000"):
            raise ValueError(f"{path}: not an NRRD file (the first bytes are {magic!r}, expected b'NRRD000x').")
        fields = {}
        pos = blob.index(b"\n") + 1
        while True:
            end = blob.find(b"\n", pos)
            if end < 0:
                more = fh.read(1 << 16)
                if not more:
                    end = len(blob)
                    if pos >= end:
                        break
                else:
                    blob += more
                    continue
            line = blob[pos:end].decode("latin-1").rstrip("\r")
            pos = end + 1
            if line == "":
                break
            if line.startswith("#") or ":=" in line and ": " not in line.split(":=")[0]:
                continue
            if ": " not in line:
                if ":=" in line:
                    continue
                raise ValueError(f"{path}: header line {line!r} is not 'field: description'.")
            key, desc = line.split(": ", 1)
            fields[key.strip().lower()] = desc.strip()
    return fields, pos


def _nrrd_vectors(text: str, path) -> list:
    out = []
    for m in _NRRD_VECTOR.finditer(text):
        if m.group(0) == "none":
            out.append(None)
        else:
            out.append([float(v) for v in m.group(1).split(",")])
    if not out:
        raise ValueError(f"{path}: cannot parse the vectors {text!r}.")
    return out


def _read_nrrd(path: Path, scalars, component) -> _Raw:
    f, data_offset = _nrrd_header(path)
    where = str(path)
    for req in ("type", "dimension", "sizes", "encoding"):
        if req not in f:
            raise ValueError(f"{path}: NRRD header lacks the required field '{req}:'.")
    tname = " ".join(f["type"].lower().split())
    if tname not in _NRRD_TYPES:
        raise ValueError(f"{path}: NRRD type {f['type']!r} is not supported (block or unknown).")
    dt = np.dtype(_NRRD_TYPES[tname])
    ndim = int(f["dimension"])
    sizes = [int(s) for s in f["sizes"].split()]
    if len(sizes) != ndim:
        raise ValueError(f"{path}: 'sizes' has {len(sizes)} entries, 'dimension' says {ndim}.")
    kinds = f.get("kinds", "").split() or [None] * ndim
    directions = _nrrd_vectors(f["space directions"], path) if "space directions" in f else None
    if directions is not None and len(directions) != ndim:
        raise ValueError(f"{path}: 'space directions' has {len(directions)} entries, 'dimension' says {ndim}.")
    # spatial axes: a direction vector, or kind domain/space; otherwise (e.g. vector, RGB-color, list) components
    spatial = []
    for a in range(ndim):
        if directions is not None:
            spatial.append(directions[a] is not None)
        elif kinds[a] is not None:
            spatial.append(kinds[a].lower() in _NRRD_SPATIAL_KINDS)
        else:
            spatial.append(True)
    if ndim == 4 and all(spatial) and kinds[0] is None:
        spatial[0] = False  # 4-D without kinds: the fastest axis holds the components (NRRD convention)
    if sum(spatial) != 3 or ndim - sum(spatial) > 1:
        raise ValueError(f"{path}: NRRD with {ndim} axes of sizes {sizes} ({sum(spatial)} spatial); a volume needs "
                         "3 spatial axes (plus at most one component axis)."
                         + (" A 2-D image is a height field: use splinevis.io.read_heights." if ndim == 2 else ""))
    if scalars is not None:
        label = f.get("content")
        if scalars != label:
            raise ValueError(f"{path}: scalars={scalars!r}, but an NRRD file holds one array"
                             + (f" (content: {label!r})" if label else "") + "; drop scalars=.")
    # ---- data
    encoding = f["encoding"].lower()
    if "data file" in f or "datafile" in f:
        desc = f.get("data file", f.get("datafile"))
        if desc.split()[0] == "LIST" or len(desc.split()) >= 4:
            raise ValueError(f"{path}: NRRD data split over several files ({desc!r}) is not supported; join them "
                             "into one file (e.g. unu join).")
        data_path = (path.parent / desc).resolve()
        data_offset = 0
        if not data_path.is_file():
            raise FileNotFoundError(f"{path}: its data file {data_path} was not found.")
    else:
        if path.suffix.lower() == ".nhdr":
            raise ValueError(f"{path}: a detached NRRD header (.nhdr) needs a 'data file:' field.")
        data_path = path
    n = int(np.prod(sizes))
    order = f.get("endian", "").lower()
    if dt.itemsize > 1 and encoding not in ("ascii", "text", "txt"):
        if order not in ("little", "big"):
            raise ValueError(f"{path}: NRRD 'endian:' must be 'little' or 'big' for {dt.name} data, got {order!r}.")
        dt = dt.newbyteorder("<" if order == "little" else ">")
    line_skip = int(f.get("line skip", f.get("lineskip", 0)))
    byte_skip = int(f.get("byte skip", f.get("byteskip", 0)))
    with open(data_path, "rb") as fh:
        fh.seek(data_offset)
        for _ in range(line_skip):
            fh.readline()
        payload = fh.read()
    if encoding == "raw":
        if byte_skip == -1:
            payload = payload[len(payload) - n * dt.itemsize:] if len(payload) >= n * dt.itemsize else payload
        else:
            payload = payload[byte_skip:]
    elif encoding in ("gzip", "gz", "bzip2", "bz2"):
        try:
            payload = (gzip.decompress if encoding in ("gzip", "gz") else bz2.decompress)(payload)
        except Exception as exc:
            raise ValueError(f"{path}: the {encoding} data could not be decompressed: {exc}") from exc
        payload = payload[byte_skip:] if byte_skip >= 0 else payload[len(payload) - n * dt.itemsize:]
    if encoding in ("raw", "gzip", "gz", "bzip2", "bz2", "hex"):
        if encoding == "hex":
            try:
                payload = bytes.fromhex("".join(payload.decode("ascii").split()))
            except ValueError as exc:
                raise ValueError(f"{path}: hex data could not be decoded: {exc}") from exc
        if len(payload) < n * dt.itemsize:
            raise ValueError(f"{path}: the data hold {len(payload)} bytes, sizes {sizes} of {dt.name} need "
                             f"{n * dt.itemsize}; the file is truncated or the header is wrong.")
        arr = np.frombuffer(payload, dtype=dt, count=n)
    elif encoding in ("ascii", "text", "txt"):
        tokens = payload.decode("ascii", errors="replace").split()
        if len(tokens) < n:
            raise ValueError(f"{path}: {len(tokens)} ascii values, sizes {sizes} need {n}.")
        try:
            arr = np.array(tokens[:n], dtype=np.float64 if dt.kind == "f" else np.int64).astype(dt.newbyteorder("="))
        except ValueError as exc:
            raise ValueError(f"{path}: ascii data are not all numbers: {exc}") from None
    else:
        raise ValueError(f"{path}: NRRD encoding {f['encoding']!r} is not supported (raw, gzip, bzip2, ascii, hex).")
    arr = arr.astype(dt.newbyteorder("="), copy=False).reshape(sizes[::-1])  # first NRRD axis fastest
    # ---- components
    if ndim == 4:
        comp_axis = spatial.index(False)
        arr = np.moveaxis(arr, ndim - 1 - comp_axis, -1)
        label = kinds[comp_axis] or "component"
        arr = _pick_component(arr, sizes[comp_axis], f"{label} axis", where, component)
        sizes = [s for s, sp in zip(sizes, spatial) if sp]
        sp_dirs = [d for d, sp in zip(directions, spatial) if sp] if directions is not None else None
        keep = [a for a in range(ndim) if spatial[a]]
    else:
        if component is not None:
            raise ValueError(f"{where}: component= applies to multi-component data; this NRRD has one value "
                             "per sample.")
        sp_dirs = directions
        keep = list(range(ndim))
    _check_dtype(arr, where)
    _check_size(arr.shape, where)
    # ---- geometry
    if sp_dirs is not None:
        if any(len(v) != 3 for v in sp_dirs):
            raise ValueError(f"{path}: space directions {sp_dirs} are not 3-D vectors; a volume needs a 3-D space.")
        m = np.array(sp_dirs, dtype=np.float64).T  # columns = world step of each index axis
        lengths = np.linalg.norm(m, axis=0)
        if np.any(lengths == 0):
            raise ValueError(f"{path}: a space direction is the zero vector: {sp_dirs}.")
        _axis_signs(np.where(np.abs(m) <= 1e-9 * lengths[None, :], 0.0, m) / lengths[None, :], where)
        step = np.diag(m).copy()
        origin = np.zeros(3)
        if "space origin" in f:
            origin = np.array(_nrrd_vectors(f["space origin"], path)[0], dtype=np.float64)
            if origin.shape != (3,):
                raise ValueError(f"{path}: space origin {f['space origin']!r} is not a 3-D point.")
    else:
        def per_axis(key):
            if key not in f:
                return None
            vals = [float(v) for v in f[key].split()]
            return [vals[a] for a in keep] if len(vals) == ndim else None

        sp = per_axis("spacings")
        mins = per_axis("axis mins") or per_axis("axismins")
        maxs = per_axis("axis maxs") or per_axis("axismaxs")
        cent = [c.lower() for c in f.get("centers", f.get("centerings", "")).split()]
        cent = [cent[a] for a in keep] if len(cent) == ndim else ["node"] * 3
        step = np.ones(3)
        origin = np.zeros(3)
        for a in range(3):
            cell = cent[a] == "cell"
            if sp is not None and np.isfinite(sp[a]):
                step[a] = sp[a]
            elif mins is not None and maxs is not None and np.isfinite(mins[a]) and np.isfinite(maxs[a]):
                step[a] = (maxs[a] - mins[a]) / (sizes[a] if cell else sizes[a] - 1)
            if mins is not None and np.isfinite(mins[a]):
                origin[a] = mins[a] + (0.5 * step[a] if cell else 0.0)
        if np.any(step == 0) or not np.isfinite(step).all():
            raise ValueError(f"{path}: spacings {step.tolist()} must be finite and nonzero.")
    flips = tuple(bool(s < 0) for s in step)
    origin = tuple(float(o + s * (m - 1)) if s < 0 else float(o) for o, s, m in zip(origin, step, sizes))
    return _Raw(values=arr, spacing=tuple(float(abs(s)) for s in step), origin=origin, source=where,
                scalars=f.get("content"), flips=flips)


# --------------------------------------------------------------------------------------------------
# flips, gaps, conversion, result
# --------------------------------------------------------------------------------------------------
def _finish(raw: _Raw, fill) -> VolumeGrid:
    src_dtype = np.dtype(raw.values.dtype)
    values = raw.oriented().astype(np.float64)
    bad = ~np.isfinite(values)
    n_bad = int(bad.sum())
    if n_bad:
        if n_bad == values.size:
            raise ValueError(f"{raw.source}: all {values.size} samples are NaN/inf; nothing to read.")
        if fill is None:
            k, j, i = (int(v) for v in np.argwhere(bad)[0])
            x, y, z = (raw.origin[a] + idx * raw.spacing[a] for a, idx in enumerate((i, j, k)))
            flipped = "".join(a for a, fl in zip("xyz", raw.flips) if fl)
            note = f" (after reversing the flipped axes {', '.join(flipped)})" if flipped else ""
            raise ValueError(
                f"{raw.source}: {n_bad} of {values.size} samples are NaN/inf; the first at voxel [k, j, i] = "
                f"[{k}, {j}, {i}]{note}, world (x, y, z) = ({x!r}, {y!r}, {z!r}), value {float(values[k, j, i])!r}. "
                "Pass fill='nearest' (value of the nearest valid voxel) or a number, e.g. fill=0.0, to fill them.")
        if isinstance(fill, str):
            from scipy import ndimage

            dx, dy, dz = raw.spacing
            idx = ndimage.distance_transform_edt(bad, sampling=(dz, dy, dx), return_distances=False,
                                                 return_indices=True)
            values = values[tuple(idx)]
        else:
            values = np.where(bad, float(fill), values)
    dtype = src_dtype.name if src_dtype.kind != "b" else "bool"
    return VolumeGrid(values=values, spacing=raw.spacing, origin=raw.origin, source=raw.source,
                      scalars=raw.scalars, dtype=dtype)
