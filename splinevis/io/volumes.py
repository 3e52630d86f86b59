"""Volume data on uniform, axis-aligned grids: :class:`VolumeGrid` and :func:`read_volume`.

``VolumeGrid.values[k, j, i]`` is the sample at the world point
``origin + (i * dx, j * dy, k * dz)``; index-space coordinates are ``(x, y, z) = (i, j, k)``.

:func:`read_volume` accepts

* a 3-D numpy array (``spacing``/``origin`` keywords, defaults ``(1, 1, 1)`` and ``(0, 0, 0)``) in the axis
  order ``order=`` gives: ``"xyz"`` (the default, as ``pyvista.wrap``: ``arr[i, j, k]`` is the sample at
  ``origin + (i * dx, j * dy, k * dz)``, shape ``(nx, ny, nz)``) or ``"zyx"`` (``arr[k, j, i]``, shape
  ``(nz, ny, nx)``: what ``np.mgrid`` unpacked as ``z, y, x`` gives, and the order of ``VolumeGrid.values``);
  see *Axis order of numpy arrays* below,
* a pyvista ``ImageData`` or a ``vtkImageData`` (point data; cell data see below), a uniform
  ``RectilinearGrid`` or an axis-aligned uniform ``StructuredGrid``,
* a file:

  ========================  ===============================================================
  ``.vti``                  VTK XML ImageData (pyvista), direction matrix honoured
  ``.vtk``                  legacy VTK STRUCTURED_POINTS (or uniform rectilinear/structured)
  ``.vtr`` ``.vts``         VTK XML RectilinearGrid / StructuredGrid, uniform (else ``resample=True``)
  ``.mha`` ``.mhd``         MetaImage (``vtkMetaImageReader``), TransformMatrix honoured
  ``.nrrd`` ``.nhdr``       NRRD, parsed here (raw, gzip, bzip2, ascii, hex encodings)
  ``.slc``                  SLC (``vtkSLCReader``; 8-bit, no origin in the format)
  ``.raw`` ``.bin``         headerless samples: pass ``shape``, ``dtype``, ``byteorder``
  ``.cube``                 Gaussian cube (parsed here), rotated orthogonal lattice -> ``direction``
  ``.nii`` ``.nii.gz``      NIfTI-1/-2 (nibabel: ``splinevis[nifti]``), placed by the sform, else the qform, else ``pixdim``
  folder or glob            stack of raw slices (``shape=(ny, nx)``, ``dtype``, ``byteorder``)
  ========================  ===============================================================

This module holds the result and the dispatch; the readers live in :mod:`.volume_vtk` (pyvista/VTK
objects and the files VTK reads), :mod:`.nrrd`, :mod:`.cube`, :mod:`.nifti` and :mod:`.raw`, each with its
format notes, on the common checks of :mod:`.volume_samples`.

Conventions kept by every reader
--------------------------------
* Samples are converted to float64 exactly (uint8 ... int32, float32, float64; int64/uint64 when
  every value is below 2**53 in magnitude); ``VolumeGrid.dtype`` records the stored type. A NIfTI file's
  ``scl_slope``/``scl_inter`` are applied in float64 after the conversion and kept in ``VolumeGrid.rescale``.
* Spacing may differ per axis; spacing and origin are kept in float64 as the source gives them
  (an origin of ``1e6`` with spacing ``1e3`` stays exact). Sources that carry their own geometry
  refuse ``spacing=``/``origin=`` rather than silently override it (SLC has no origin: ``origin=`` is
  allowed there).
* **Direction matrices.** A grid whose direction matrix is diagonal with entries +-1 (axis flips) is
  normalised: every flipped axis is reversed in the array and the origin moves to the sample with the
  smallest coordinate, so the returned grid shows the same picture with positive spacing. Negative
  spacings (VTK, NRRD ``spacings``) are treated the same way. Any other orthonormal direction (a rotation, a
  permutation of the axes) is kept in ``VolumeGrid.direction`` (rotated orthogonal lattices, below); a shear
  raises ValueError, dropping it would draw a wrong picture. Orthonormality is judged at the precision the
  source carries (:func:`.volume_samples.orthonormal_direction`).
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
* **Non-uniform lattices** (a ``RectilinearGrid`` or axis-aligned ``StructuredGrid`` whose steps vary) are
  refused with the Python lines that resample them; ``resample=True`` resamples instead, with a warning
  (:func:`.volume_vtk.resample_to_image`).
* **Slice stacks.** A folder of headerless slice files (or a glob such as ``"ct/s_*.raw"``) with
  ``shape=(ny, nx)``, ``dtype=``, ``byteorder=`` reads as one volume, the files sorted naturally by name
  (:mod:`.slices`).
* **Rotated orthogonal lattices.** Gaussian cube files (``.cube``, :mod:`.cube`), NRRD and NIfTI files
  (:mod:`.nifti`) with rotated or permuted orthogonal axes keep them in ``VolumeGrid.direction``; spacing and
  origin are in the file's units and its world frame (Bohr for cube files; NIfTI's RAS+ millimetres and the
  NRRD ``space`` are kept as given, not converted into each other).
* **Axis order of numpy arrays.** ``order="xyz"`` is the default because ``pyvista.wrap`` reads a 3-D array that
  way (``dimensions = arr.shape``); ``VolumeGrid.values`` stays ``[k, j, i]`` and an ``"xyz"`` array is
  transposed on reading. The two orders read different volumes unless the array equals itself with its first
  and last axes swapped (then the order does not matter, e.g. a sphere sampled on a cube). splinevis used to
  read arrays as ``"zyx"`` only, so an array read without ``order=`` whose two readings differ warns,
  once per calling line, with its shape and what each order makes of it; passing ``order=`` (either) says
  which was meant and gives no warning. Files, pyvista grids and raw data carry their own order: ``order=``
  applies to numpy arrays (and lists) only.
* DICOM series, Analyze/NIfTI header-image pairs (``.hdr``/``.img``) and MINC are not read (VTK's readers
  ignore parts of their orientation); convert them to NIfTI (``.nii``), NRRD or MetaImage first.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validation import as_float64_array
from .._warnings import warn_user
from ._common import (VTK_FILES, check_geometry, fill_nearest, first_gap, freeze_grid, gap_error,
                      refuse_own_geometry, require_regular_file, source_kind, unsupported_extension)
from .nrrd import read_nrrd
from .raw import read_raw
from .cube import read_cube
from .nifti import read_nifti
from .slices import is_glob, read_slices
from .volume_samples import GEOMETRY_ARGS_APPLY_TO, VolumeSamples, from_array, orthonormal_direction
from .volume_vtk import from_pyvista, metaimage_direction, read_vtk_file

__all__ = ["VolumeGrid", "read_volume", "VOLUME_EXTENSIONS", "ARRAY_ORDERS"]

#: Axis orders of a numpy volume (``read_volume(order=)``): ``"xyz"`` reads ``arr[i, j, k]`` (pyvista.wrap's
#: order, the default), ``"zyx"`` reads ``arr[k, j, i]`` (``VolumeGrid.values``' order).
ARRAY_ORDERS = ("xyz", "zyx")

_RAW_EXTENSIONS = (".raw", ".bin")
# What a volume needs of each VTK file kind (said in the error messages).
_VTK_LIMITS = {".vtk": " structured points", ".vtr": ", uniform spacing", ".vts": ", axis-aligned uniform"}
#: File name extensions :func:`read_volume` reads, and by what.
VOLUME_EXTENSIONS = {
    **{ext: f"{kind}{_VTK_LIMITS.get(ext, '')} (pyvista)" for ext, kind in VTK_FILES.items()},
    ".mha": "MetaImage (vtkMetaImageReader)",
    ".mhd": "MetaImage with detached data (vtkMetaImageReader)",
    ".nrrd": "NRRD (parsed by splinevis)",
    ".nhdr": "NRRD detached header (parsed by splinevis)",
    ".slc": "SLC (vtkSLCReader)",
    ".cube": "Gaussian cube, rotated orthogonal lattice (parsed by splinevis)",
    ".nii": "NIfTI-1/-2, sform/qform placement (nibabel: splinevis[nifti])",
    ".nii.gz": "gzip-compressed NIfTI-1/-2, sform/qform placement (nibabel: splinevis[nifti])",
    **dict.fromkeys(_RAW_EXTENSIONS, "headerless samples (shape=, dtype=, byteorder=)"),
}
_UNSUPPORTED = {
    ".dcm": "DICOM", ".gz": "gzip-compressed (other than .nii.gz)", ".img": "Analyze/NIfTI pair",
    ".hdr": "Analyze/NIfTI pair", ".mnc": "MINC",
}


def _extension(path) -> str:
    """The lower-case extension that names the format: ``.nii.gz`` for compressed NIfTI, else the suffix."""
    name = Path(path).name.lower()
    return ".nii.gz" if name.endswith(".nii.gz") else Path(name).suffix


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
        applied). ``(1.0, 0.0)`` for files, except NIfTI files with a valid ``scl_slope`` (their
        ``(scl_slope, scl_inter)``); quantised synthetic samples (``datasets_synthetic.volumes``) record their
        scale here.
    direction : (3, 3) nested tuples, orthonormal columns
        World direction of the lattice axes x, y, z (the columns). Default: the identity. A rotated
        orthogonal lattice (e.g. a Gaussian cube file) has world point ``origin + direction @ (i*dx, j*dy,
        k*dz)``; ``bounds``, ``axes``, ``to_index``, ``to_world`` and ``to_pyvista`` describe the *lattice
        frame* (the grid before the rotation); :meth:`lattice_to_world` applies the direction. A shear or
        non-orthogonal direction raises ValueError.

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
    direction: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def __post_init__(self):
        v = as_float64_array(self.values, "values", ndim=3)
        freeze_grid(self, "values", v, axes=3)
        object.__setattr__(self, "direction", orthonormal_direction(self.direction, "VolumeGrid direction"))
        r = tuple(float(x) for x in self.rescale)
        if len(r) != 2 or not all(np.isfinite(r)) or r[0] == 0:
            raise ValueError(f"rescale must be (slope != 0, intercept), finite, got {self.rescale!r}.")
        object.__setattr__(self, "rescale", r)

    @property
    def shape(self) -> tuple:
        """``(nz, ny, nx)``.

        >>> VolumeGrid(np.zeros((2, 3, 4))).shape
        (2, 3, 4)
        """
        return self.values.shape

    @property
    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of the sample positions (pyvista order).

        >>> VolumeGrid(np.zeros((2, 3, 4)), spacing=(0.5, 1.0, 2.0), origin=(-1.0, 0.0, 10.0)).bounds
        (-1.0, 0.5, 0.0, 2.0, 10.0, 12.0)
        """
        (nz, ny, nx), (dx, dy, dz), (x0, y0, z0) = self.shape, self.spacing, self.origin
        return (x0, x0 + (nx - 1) * dx, y0, y0 + (ny - 1) * dy, z0, z0 + (nz - 1) * dz)

    @property
    def value_range(self) -> tuple:
        """``(min, max)`` of the samples.

        >>> VolumeGrid(np.arange(24.0).reshape(2, 3, 4) - 5).value_range
        (-5.0, 18.0)
        """
        return (float(self.values.min()), float(self.values.max()))

    def axes(self) -> tuple:
        """``(x, y, z)``: the (nx,), (ny,), (nz,) float64 coordinates of the sample planes.

        >>> x, y, z = VolumeGrid(np.zeros((2, 3, 4)), spacing=(0.5, 1.0, 2.0), origin=(-1.0, 0.0, 10.0)).axes()
        >>> x, z
        (array([-1. , -0.5,  0. ,  0.5]), array([10., 12.]))
        """
        (nz, ny, nx), (dx, dy, dz), (x0, y0, z0) = self.shape, self.spacing, self.origin
        return (x0 + np.arange(nx) * dx, y0 + np.arange(ny) * dy, z0 + np.arange(nz) * dz)

    def to_index(self, points) -> np.ndarray:
        """World points ``(..., 3)`` to index-space coordinates ``(x, y, z) = (i, j, k)`` (float64).

        >>> g = VolumeGrid(np.zeros((2, 3, 4)), spacing=(0.5, 1.0, 2.0), origin=(-1.0, 0.0, 10.0))
        >>> g.to_index([[0.0, 1.0, 11.0]])
        array([[2. , 1. , 0.5]])
        """
        p = np.asarray(points, dtype=np.float64)
        return (p - np.asarray(self.origin)) / np.asarray(self.spacing)

    def to_world(self, index_points) -> np.ndarray:
        """Index-space coordinates ``(..., 3)`` to world points (float64).

        >>> g = VolumeGrid(np.zeros((2, 3, 4)), spacing=(0.5, 1.0, 2.0), origin=(-1.0, 0.0, 10.0))
        >>> g.to_world([2.0, 1.0, 0.5])
        array([ 0.,  1., 11.])
        """
        q = np.asarray(index_points, dtype=np.float64)
        return np.asarray(self.origin) + q * np.asarray(self.spacing)

    @property
    def is_rotated(self) -> bool:
        """True unless ``direction`` is the identity.

        >>> VolumeGrid(np.zeros((2, 2, 2))).is_rotated
        False
        """
        return not np.array_equal(np.asarray(self.direction), np.eye(3))

    def lattice_to_world(self, points) -> np.ndarray:
        """Lattice-frame points ``(..., 3)`` (as :meth:`to_world` gives them) to true world points:
        ``origin + direction @ (p - origin)``.

        >>> g = VolumeGrid(np.zeros((2, 2, 2)), origin=(1.0, 0.0, 0.0), direction=((0, -1, 0), (1, 0, 0), (0, 0, 1)))
        >>> g.lattice_to_world([2.0, 0.0, 0.0]).tolist()
        [1.0, 1.0, 0.0]
        """
        p = np.asarray(points, dtype=np.float64)
        o = np.asarray(self.origin)
        return o + (p - o) @ np.asarray(self.direction).T

    def to_pyvista(self):
        """A ``pyvista.ImageData`` with the samples as point data ``"values"`` (x fastest, VTK order).

        >>> image = VolumeGrid(np.arange(24.0).reshape(2, 3, 4), spacing=(0.5, 1.0, 2.0)).to_pyvista()
        >>> image.dimensions, image.spacing, image.point_data["values"][:5].tolist()
        ((4, 3, 2), (0.5, 1.0, 2.0), [0.0, 1.0, 2.0, 3.0, 4.0])
        """
        import pyvista as pv

        img = pv.ImageData(dimensions=self.shape[::-1], spacing=self.spacing, origin=self.origin)
        img.point_data["values"] = np.ascontiguousarray(self.values).ravel(order="C")
        return img


# --------------------------------------------------------------------------------------------------
# Public entry point
# --------------------------------------------------------------------------------------------------
def read_volume(source, *, order=None, scalars=None, spacing=None, origin=None, shape=None, dtype=None, byteorder=None,
                header_bytes=0, fill=None, component=None, resample=False) -> VolumeGrid:
    """Read volume data into a :class:`VolumeGrid` (see the module notes for formats and conventions).

    Parameters
    ----------
    source : array_like, pyvista/VTK ImageData, RectilinearGrid, StructuredGrid, str or Path
        The samples: a 3-D numpy array in the axis order ``order``, or a grid, or a file (a str or Path; see
        ``VOLUME_EXTENSIONS``).
    order : {"xyz", "zyx"}, optional
        Numpy arrays only: ``"xyz"`` (default, as ``pyvista.wrap``): ``arr[i, j, k]``, shape ``(nx, ny, nz)``, lies
        at ``origin + (i*dx, j*dy, k*dz)``; ``"zyx"``: ``arr[k, j, i]``, shape ``(nz, ny, nx)``. Omitted for an
        array whose two readings differ, it warns (the default was ``"zyx"`` before; module notes).
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
        For arrays with several components: pick one (0-based) or take the Euclidean norm. For a 4-D NIfTI
        file (a series of volumes): the index of the volume to read (required there).
    resample : bool
        For a ``RectilinearGrid`` or axis-aligned ``StructuredGrid`` (object or ``.vtr``/``.vts``/``.vtk`` file)
        whose steps are not uniform: False (default) raises ValueError with the lines that resample it; True
        resamples it onto a uniform ``ImageData`` (cell data made point data, the finest step of each axis, the
        same bounds, trilinear; :func:`.volume_vtk.resample_to_image`) with a warning saying so. Uniform
        lattices and the other sources are not affected.

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
        Not 3-D, fewer than 2 samples on an axis, shear, non-uniform spacing without ``resample=True``,
        ambiguous or missing array, multi-component array without ``component=``, missing samples
        without ``fill=``, raw file of the wrong size, unreadable file.

    Examples
    --------
    >>> import numpy as np
    >>> g = read_volume(np.arange(24, dtype=np.uint16).reshape(2, 3, 4), order="zyx", spacing=(0.5, 0.5, 2.0),
    ...                 origin=(1e6, 0.0, -3.0))
    >>> g.shape, g.dtype, float(g.values[1, 2, 3]), g.to_world([3, 2, 1]).tolist()
    ((2, 3, 4), 'uint16', 23.0, [1000001.5, 1.0, -1.0])
    >>> x = read_volume(np.arange(24.0).reshape(4, 3, 2), order="xyz")  # arr[i, j, k]: nx, ny, nz = 4, 3, 2
    >>> x.shape, x.bounds, float(x.values[1, 2, 3])  # values[k, j, i] = arr[i, j, k]
    ((2, 3, 4), (0.0, 3.0, 0.0, 2.0, 0.0, 1.0), 23.0)
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
    if not isinstance(resample, (bool, np.bool_)):
        raise TypeError(f"resample must be True or False, got {resample!r}.")
    if order is not None and (not isinstance(order, str) or order not in ARRAY_ORDERS):
        raise ValueError(f"order {order!r} is not known; choose 'xyz' (arr[i, j, k], as pyvista.wrap) or 'zyx' "
                         "(arr[k, j, i]).")
    if scalars is not None and not isinstance(scalars, str):
        raise TypeError(f"scalars must be the name (str) of a data array, got {type(scalars).__name__}.")
    if spacing is not None:
        if isinstance(spacing, (int, float, np.integer, np.floating)) and not isinstance(spacing, bool):
            spacing = (spacing,) * 3
        spacing = check_geometry(spacing, "spacing", axes=3, positive=True)
    if origin is not None:
        origin = check_geometry(origin, "origin", axes=3)

    is_path = isinstance(source, (str, os.PathLike))
    raw_args = {"shape": shape, "dtype": dtype, "byteorder": byteorder}
    stack = is_path and (is_glob(source) or Path(source).is_dir())
    if not stack and (not is_path or _extension(source) not in _RAW_EXTENSIONS):
        given = [k for k, v in raw_args.items() if v is not None] + (["header_bytes"] if header_bytes else [])
        if given and not (is_path and _extension(source) not in VOLUME_EXTENSIONS):
            raise ValueError(f"{' and '.join(given)}= describe headerless raw files (.raw, .bin); "
                             f"{_describe(source)} carries that information itself. Drop the argument.")

    if order is not None and source_kind(source) != "array":
        raise ValueError(f"order= gives the axis order of a numpy array; {_describe(source)} carries its own. "
                         "Drop the argument.")
    if source_kind(source) == "array":
        source = _array_in_zyx(np.asarray(source), order)
    samples = _dispatch(source, scalars=scalars, spacing=spacing, origin=origin, shape=shape, dtype=dtype,
                    byteorder=byteorder, header_bytes=header_bytes, component=component, resample=bool(resample))
    return _finish(samples, fill)


def _array_in_zyx(arr: np.ndarray, order) -> np.ndarray:
    """``arr`` given in axis ``order`` as ``[k, j, i]`` (components, if any, stay last); ``order=None`` reads
    ``"xyz"`` and warns when the two readings differ (module notes). Other ranks are left to the checks."""
    if arr.ndim not in (3, 4) or arr.dtype.kind not in "biuf":
        return arr  # the checks say what is wrong (rank, strings, complex numbers)
    if order is None:
        if not _same_in_both_orders(arr):
            warn_user(_order_warning(arr.shape))
        order = "xyz"
    return np.ascontiguousarray(arr.swapaxes(0, 2)) if order == "xyz" else arr


def _same_in_both_orders(arr: np.ndarray) -> bool:
    """True when ``arr`` equals itself with axes 0 and 2 swapped, to rounding (both orders read the same volume);
    compared slab by slab, stopping at the first difference.

    Floating-point samples count as equal within ``8 eps max|arr|``: a field symmetric in x and z evaluated on a
    cube, such as ``x**2 + y**2 + z**2``, sums the same terms in another order at the swapped sample; a sum of
    three terms rounds twice, each time by at most ``eps/2`` of a partial sum, so the two orders differ by at
    most ``2 eps`` times the sum of the terms' magnitudes (the value itself for nonnegative terms). A field
    whose terms cancel more than that warns: the safe side. Integers and booleans must be equal.

    >>> z, y, x = np.mgrid[-1:1:5j, -1:1:5j, -1:1:5j]
    >>> _same_in_both_orders(x**2 + y**2 + z**2), _same_in_both_orders(x + 2 * z), _same_in_both_orders(x + 2 * y)
    (True, False, False)
    """
    if arr.shape[0] != arr.shape[2]:
        return False
    swapped = arr.swapaxes(0, 2)
    if arr.dtype.kind == "f":
        tol = 8 * np.finfo(arr.dtype).eps * float(np.max(np.abs(arr)))
        return all(np.all(np.abs(arr[s] - swapped[s]) <= tol) for s in range(arr.shape[0]))
    return all(np.array_equal(arr[s], swapped[s]) for s in range(arr.shape[0]))


def _order_warning(shape) -> str:
    """What each axis order makes of a numpy array of ``shape`` read without ``order=``.

    >>> print(_order_warning((4, 3, 2)))
    read_volume: a numpy array of shape (4, 3, 2) read without order=, as order='xyz' (arr[i, j, k], as pyvista.wrap): nx, ny, nz = 4, 3, 2; order='zyx' (arr[k, j, i], splinevis's former default) reads nx, ny, nz = 2, 3, 4. Pass order='xyz' or order='zyx' to say which (no warning then).
    """
    a, b, c = shape[:3]
    other = (f"reads nx, ny, nz = {c}, {b}, {a}" if a != c else
             "reads the same nx, ny, nz, but x and z swapped (a different volume)")
    return (f"read_volume: a numpy array of shape {tuple(shape)} read without order=, as order='xyz' (arr[i, j, k], "
            f"as pyvista.wrap): nx, ny, nz = {a}, {b}, {c}; order='zyx' (arr[k, j, i], splinevis's former "
            f"default) {other}. Pass order='xyz' or order='zyx' to say which (no warning then).")


def _describe(source) -> str:
    if isinstance(source, (str, os.PathLike)):
        return str(source)
    if isinstance(source, np.ndarray):
        return "a numpy array"
    name = type(source).__name__
    return f"{'an' if name[:1] in 'AEIOU' else 'a'} {name}"


def _dispatch(source, *, scalars, spacing, origin, shape, dtype, byteorder, header_bytes, component,
              resample) -> VolumeSamples:
    kind = source_kind(source)
    if kind == "path" and (is_glob(source) or Path(source).is_dir()):
        if scalars is not None:
            raise ValueError(f"{source}: scalars= names an array of a VTK file; raw slices hold one array.")
        return read_slices(source, shape, dtype, byteorder, header_bytes, spacing, origin, component)
    if kind == "path":
        return _read_file(Path(source), scalars=scalars, spacing=spacing, origin=origin, shape=shape, dtype=dtype,
                          byteorder=byteorder, header_bytes=header_bytes, component=component, resample=resample)
    if kind == "vtk":
        import pyvista as pv

        grid = pv.wrap(source)
        name = f"pyvista.{type(grid).__name__}"
        refuse_own_geometry(spacing, origin, name, applies_to=GEOMETRY_ARGS_APPLY_TO)
        return from_pyvista(grid, name, scalars, component, resample=resample)
    if kind == "array":
        if scalars is not None:
            raise ValueError("scalars= names a data array of a pyvista grid or a file; a numpy array has none.")
        return from_array(np.asarray(source), spacing, origin, component, "numpy array")
    raise TypeError(f"source of type {type(source).__name__} is not supported; pass a 3-D numpy array "
                    "(nz, ny, nx), a pyvista ImageData / vtkImageData, or a file path "
                    f"({', '.join(VOLUME_EXTENSIONS)}).")


def _read_file(path: Path, *, scalars, spacing, origin, shape, dtype, byteorder, header_bytes,
               component, resample) -> VolumeSamples:
    ext = _extension(path)
    if ext in _UNSUPPORTED:
        raise ValueError(f"{path}: {_UNSUPPORTED[ext]} files are not read (VTK's readers ignore parts of their "
                         "orientation); convert to NIfTI (.nii), NRRD (.nrrd) or MetaImage (.mha) first. Supported: "
                         + ", ".join(VOLUME_EXTENSIONS) + ".")
    is_raw = ext in _RAW_EXTENSIONS or (ext not in VOLUME_EXTENSIONS and shape is not None)
    if not is_raw and ext not in VOLUME_EXTENSIONS:
        raise unsupported_extension(path, VOLUME_EXTENSIONS, " A headerless file is read with shape=, dtype= and "
                                                             "byteorder=.")
    require_regular_file(path, "volume")
    if path.stat().st_size == 0:
        raise ValueError(f"{path} is empty (0 bytes).")
    if is_raw:
        if scalars is not None:
            raise ValueError(f"{path}: scalars= names an array of a VTK file; a raw file holds one array.")
        return read_raw(path, shape, dtype, byteorder, header_bytes, spacing, origin, component)
    if ext == ".cube":
        refuse_own_geometry(spacing, origin, str(path), applies_to=GEOMETRY_ARGS_APPLY_TO)
        return read_cube(path, scalars, component)
    if ext in (".nii", ".nii.gz"):
        refuse_own_geometry(spacing, origin, str(path), applies_to=GEOMETRY_ARGS_APPLY_TO)
        return read_nifti(path, scalars, component)
    if ext in (".nrrd", ".nhdr"):
        refuse_own_geometry(spacing, origin, str(path), applies_to=GEOMETRY_ARGS_APPLY_TO)
        return read_nrrd(path, scalars, component)
    if ext == ".slc":
        refuse_own_geometry(spacing, origin, f"{path} (SLC has a spacing, no origin)",
                            applies_to=GEOMETRY_ARGS_APPLY_TO, allow_origin=True)
        samples = from_pyvista(read_vtk_file(path, VOLUME_EXTENSIONS[ext]), str(path), scalars, component)
        if origin is not None:
            samples.origin = origin
        return samples
    refuse_own_geometry(spacing, origin, str(path), applies_to=GEOMETRY_ARGS_APPLY_TO)
    header = metaimage_direction(path, str(path)) if ext in (".mha", ".mhd") else None
    direction, rounding = header if header is not None else (None, None)
    return from_pyvista(read_vtk_file(path, VOLUME_EXTENSIONS[ext]), str(path), scalars, component,
                        resample=resample, direction=direction, rounding=rounding)


# --------------------------------------------------------------------------------------------------
# flips, gaps, conversion, result
# --------------------------------------------------------------------------------------------------
def _finish(samples: VolumeSamples, fill) -> VolumeGrid:
    src_dtype = np.dtype(samples.values.dtype)
    values = samples.oriented().astype(np.float64)
    rescale = getattr(samples, "rescale", (1.0, 0.0))  # NIfTI scl_slope/scl_inter (read_nifti)
    if rescale != (1.0, 0.0):
        values = rescale[0] * values + rescale[1]
    bad = ~np.isfinite(values)
    n_bad, first = first_gap(bad, samples.source, "NaN/inf")
    if n_bad:
        if fill is None:
            k, j, i = first
            x, y, z = (samples.origin[a] + idx * samples.spacing[a] for a, idx in enumerate((i, j, k)))
            flipped = "".join(a for a, fl in zip("xyz", samples.flips) if fl)
            note = f" (after reversing the flipped axes {', '.join(flipped)})" if flipped else ""
            raise gap_error(samples.source, n_bad, values.size, "NaN/inf",
                            f"voxel [k, j, i] = [{k}, {j}, {i}]{note}, world (x, y, z) = ({x!r}, {y!r}, {z!r})",
                            float(values[k, j, i]), "Pass fill='nearest' (value of the nearest valid voxel) or a "
                            "number, e.g. fill=0.0, to fill them.")
        if isinstance(fill, str):
            dx, dy, dz = samples.spacing
            values = fill_nearest(values, bad, (dz, dy, dx))
        else:
            values = np.where(bad, float(fill), values)
    dtype = src_dtype.name if src_dtype.kind != "b" else "bool"
    return VolumeGrid(values=values, spacing=samples.spacing, origin=samples.origin, source=samples.source,
                      scalars=samples.scalars, dtype=dtype, direction=samples.direction, rescale=rescale)
