"""Scaffolding shared by the height and volume readers of :mod:`splinevis.io`.

Both :func:`~splinevis.io.read_heights` and :func:`~splinevis.io.read_volume` take a numpy array, a
pyvista/VTK data object or a file name, check spacing and origin the same way, refuse geometry
arguments for sources that carry their own, report missing samples by position and fill them with the
nearest valid sample. The pieces they share live here, so that both speak with one voice: every error
names the source (a file path, ``"numpy array"``, ``"pyvista.ImageData"``), the offending value or
position, and what to do about it.

Nothing here is public API; the readers' own modules hold their formats and conventions.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from .._validation import as_float64_array

__all__ = [
    "VTK_FILES", "source_kind", "check_geometry", "freeze_grid", "refuse_own_geometry", "unsupported_extension",
    "require_regular_file", "check_real_dtype", "check_exact_in_float64", "step_deviation", "nonuniform_message",
    "first_gap", "gap_error", "fill_nearest",
]

#: The VTK file formats both readers take through :func:`pyvista.read`, by file name extension.
VTK_FILES = {".vti": "VTK XML ImageData", ".vtk": "legacy VTK", ".vtr": "VTK XML RectilinearGrid",
             ".vts": "VTK XML StructuredGrid"}

# Words of the geometry checks, by the number of axes: what the value must be, where it must be > 0.
_GEOMETRY_WORDS = {2: ("two real numbers", "in x and y"), 3: ("three numbers (x, y, z)", "on every axis")}


# --------------------------------------------------------------------------------------------------
# what kind of source
# --------------------------------------------------------------------------------------------------
def source_kind(source) -> str | None:
    """Classify a reader's ``source`` argument.

    Parameters
    ----------
    source : object
        What the caller passed to a reader.

    Returns
    -------
    {"path", "vtk", "array"} or None
        ``"path"`` for a str or path-like, ``"vtk"`` for a pyvista or VTK data object, ``"array"`` for a
        numpy array, list or tuple; None for anything else (the reader raises TypeError naming it).

    Examples
    --------
    >>> import pyvista as pv
    >>> source_kind("head.nrrd"), source_kind(pv.ImageData()), source_kind([[1, 2]]), source_kind(3.0)
    ('path', 'vtk', 'array', None)
    """
    if isinstance(source, (str, os.PathLike)):
        return "path"
    mod = type(source).__module__ or ""
    if mod.startswith("pyvista") or mod.startswith("vtk"):
        from vtkmodules.vtkCommonDataModel import vtkDataObject

        if isinstance(source, vtkDataObject):
            return "vtk"
    if isinstance(source, (np.ndarray, list, tuple)):
        return "array"
    return None


# --------------------------------------------------------------------------------------------------
# spacing and origin
# --------------------------------------------------------------------------------------------------
def check_geometry(value, name: str, *, axes: int, positive: bool = False) -> tuple:
    """Return ``value`` as a tuple of ``axes`` finite floats (a spacing or an origin).

    Parameters
    ----------
    value : sequence of real numbers
        With ``axes=2`` also a single number when ``positive`` (a spacing used for both axes).
    name : str
        The argument's name, for the error messages.
    axes : {2, 3}
        2 for ``(x, y)`` (heights), 3 for ``(x, y, z)`` (volumes).
    positive : bool
        Require every entry to be > 0.

    Returns
    -------
    tuple of float

    Raises
    ------
    TypeError
        A string or a value that is not a sequence of numbers.
    ValueError
        Wrong number of entries, a non-finite entry, or an entry <= 0 when ``positive``.

    Examples
    --------
    >>> check_geometry(30, "spacing", axes=2, positive=True)  # one number: both axes
    (30.0, 30.0)
    >>> check_geometry((1, 1, 0), "spacing", axes=3, positive=True)
    Traceback (most recent call last):
    ValueError: spacing must be > 0 on every axis, got (1.0, 1.0, 0.0).
    """
    what, where = _GEOMETRY_WORDS[axes]
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be {what}, got the string {value!r}.")
    if axes == 2:
        arr = as_float64_array(value, name, finite=False)
        if arr.ndim == 0:
            arr = np.array([arr, arr]) if positive else arr
        if arr.shape != (2,):
            raise ValueError(f"{name} must be two numbers (x, y), got shape {arr.shape}: {value!r}.")
        t = (float(arr[0]), float(arr[1]))
    else:
        try:
            t = tuple(float(v) for v in value)
        except TypeError:
            raise TypeError(f"{name} must be {what}, got {type(value).__name__}.") from None
        if len(t) != 3:
            raise ValueError(f"{name} must have 3 entries (x, y, z), got {len(t)}: {value!r}.")
    if not all(math.isfinite(v) for v in t):
        raise ValueError(f"{name} must be finite, got {t}.")
    if positive and min(t) <= 0:
        raise ValueError(f"{name} must be > 0 {where}, got {t}.")
    return t


def freeze_grid(grid, field: str, samples: np.ndarray, *, axes: int) -> None:
    """Finish the ``__post_init__`` of a frozen grid dataclass (``HeightGrid``, ``VolumeGrid``).

    Stores ``samples`` in ``field`` as a read-only float64 copy, checks the grid's ``spacing`` (> 0)
    and ``origin`` with :func:`check_geometry` and that its ``source`` is a str.

    Parameters
    ----------
    grid : dataclass instance, frozen
        With the fields ``field``, ``spacing``, ``origin`` and ``source``.
    field : str
        Name of the samples field (``"heights"``, ``"values"``).
    samples : ndarray
        The samples, already checked (dimensions, finiteness).
    axes : {2, 3}
        Entries of ``spacing`` and ``origin``.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Grid:
    ...     heights: np.ndarray
    ...     spacing: tuple = (1.0, 1.0)
    ...     origin: tuple = (0.0, 0.0)
    ...     source: str = "numpy array"
    ...     def __post_init__(self):
    ...         freeze_grid(self, "heights", self.heights, axes=2)
    >>> g = Grid([[1, 2], [3, 4]], spacing=[2, 2])
    >>> g.heights.dtype, g.heights.flags.writeable, g.spacing
    (dtype('float64'), False, (2.0, 2.0))
    """
    v = np.array(samples, dtype=np.float64, copy=True)
    v.flags.writeable = False
    object.__setattr__(grid, field, v)
    object.__setattr__(grid, "spacing", check_geometry(grid.spacing, "spacing", axes=axes, positive=True))
    object.__setattr__(grid, "origin", check_geometry(grid.origin, "origin", axes=axes))
    if not isinstance(grid.source, str):
        raise TypeError(f"source must be a str, got {type(grid.source).__name__}.")


def refuse_own_geometry(spacing, origin, what: str, *, applies_to: str, allow_origin: bool = False) -> None:
    """Raise ValueError when ``spacing=``/``origin=`` are given for a source that carries its own.

    Parameters
    ----------
    spacing, origin : object or None
        The caller's arguments; None means not given.
    what : str
        The source, as the message names it (a path, ``"pyvista.ImageData"``, ...).
    applies_to : str
        The sources the arguments are meant for, e.g. ``"numpy arrays and raw files"``.
    allow_origin : bool
        The source has a spacing but no origin (SLC): ``origin=`` is allowed.

    Examples
    --------
    >>> refuse_own_geometry(None, None, "dem.tif", applies_to="numpy arrays")  # nothing given: fine
    >>> refuse_own_geometry((30, 30), None, "dem.tif", applies_to="numpy arrays")
    Traceback (most recent call last):
    ValueError: dem.tif carries its own spacing and origin; spacing= would override them. Drop the argument (spacing=/origin= apply to numpy arrays).
    """
    given = [n for n, v in (("spacing", spacing), ("origin", None if allow_origin else origin)) if v is not None]
    if given:
        raise ValueError(f"{what} carries its own spacing and origin; {' and '.join(given)}= would override "
                         f"them. Drop the argument (spacing=/origin= apply to {applies_to}).")


# --------------------------------------------------------------------------------------------------
# files
# --------------------------------------------------------------------------------------------------
def unsupported_extension(path: Path, extensions: dict, hint: str = "") -> ValueError:
    """The error for a file name extension no reader handles, listing the ones that are read.

    Parameters
    ----------
    path : Path
        The file.
    extensions : dict
        Extension -> description of the reader, as in ``SUPPORTED_EXTENSIONS``.
    hint : str
        Appended to the message (starts with a space).

    Returns
    -------
    ValueError
        For the caller to raise (``raise unsupported_extension(...)``), so that the traceback ends in
        the reader.

    Examples
    --------
    >>> print(unsupported_extension(Path("heights.xyz"), {".dem": "USGS DEM", ".tif": "GeoTIFF"}))
    heights.xyz: extension '.xyz' is not supported; supported: .dem (USGS DEM), .tif (GeoTIFF).
    """
    return ValueError(f"{path}: extension {path.suffix!r} is not supported; supported: "
                      + ", ".join(f"{e} ({w})" for e, w in extensions.items()) + "." + hint)


def require_regular_file(path: Path, kind: str) -> None:
    """Raise unless ``path`` is an existing regular file.

    Parameters
    ----------
    path : Path
        The file.
    kind : str
        What the file should hold (``"height"``, ``"volume"``), for the not-found message.

    Raises
    ------
    FileNotFoundError
        ``path`` does not exist.
    ValueError
        ``path`` exists but is not a regular file.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     require_regular_file(Path(folder), "height")
    Traceback (most recent call last):
    ValueError: ... is not a regular file.
    >>> require_regular_file(Path("no/such/dem.tif"), "height")
    Traceback (most recent call last):
    FileNotFoundError: height file not found: no/such/dem.tif
    """
    if not path.exists():
        raise FileNotFoundError(f"{kind} file not found: {path}")
    if not path.is_file():
        raise ValueError(f"{path} is not a regular file.")


# --------------------------------------------------------------------------------------------------
# samples
# --------------------------------------------------------------------------------------------------
def check_real_dtype(arr: np.ndarray, where: str, what: str, *, note_strings: bool = True) -> None:
    """Raise TypeError unless ``arr`` holds real numbers (bool, integers or floats).

    Parameters
    ----------
    arr : ndarray
        The samples.
    where : str
        The source, first in the message.
    what : str
        What the samples are (``"heights"``, ``"samples"``).
    note_strings : bool
        Say ``(strings)`` after a string or object dtype.

    Examples
    --------
    >>> check_real_dtype(np.array([1, 2], dtype=np.uint16), "raw file", "samples")  # fine
    >>> check_real_dtype(np.array(["1", "2"]), "numpy array", "heights")
    Traceback (most recent call last):
    TypeError: numpy array: heights must be real numbers, got dtype <U1 (strings).
    """
    if arr.dtype.kind not in "biuf":
        note = " (strings)" if note_strings and arr.dtype.kind in "USO" else ""
        raise TypeError(f"{where}: {what} must be real numbers, got dtype {arr.dtype}{note}.")


def check_exact_in_float64(arr: np.ndarray, where: str) -> None:
    """Raise ValueError when 64-bit integer samples exceed 2**53 in magnitude (not exact in float64).

    Parameters
    ----------
    arr : ndarray
        The samples, any real dtype; only int64/uint64 are checked.
    where : str
        The source, first in the message.

    Examples
    --------
    >>> check_exact_in_float64(np.array([2 ** 53], dtype=np.int64), "numpy array")  # still exact
    >>> check_exact_in_float64(np.array([2 ** 60], dtype=np.int64), "numpy array")
    Traceback (most recent call last):
    ValueError: numpy array: int64 samples up to 1.152921504606847e+18 are not exact in float64 (|value| > 2**53); rescale them first.
    """
    if arr.dtype.kind in "iu" and arr.dtype.itemsize == 8 and arr.size:
        big = np.abs(arr.astype(np.float64)).max() if arr.dtype.kind == "i" else float(arr.max())
        if big > 2.0 ** 53:
            raise ValueError(f"{where}: {arr.dtype} samples up to {big:.17g} are not exact in float64 "
                             "(|value| > 2**53); rescale them first.")


def step_deviation(coords: np.ndarray, eps: float) -> tuple:
    """How uniform a row of sample coordinates is.

    Parameters
    ----------
    coords : (n,) ndarray of float64, n >= 2
        Coordinates of the samples along one axis, monotonic.
    eps : float
        Machine epsilon of the coordinates as stored (float32 coordinates are only good to their
        rounding).

    Returns
    -------
    step : float
        The mean step ``(last - first) / (n - 1)`` (negative for decreasing coordinates).
    deviation : float
        The largest relative deviation of a step from ``step`` (inf when ``step`` is 0).
    tolerance : float
        The deviation still counted as uniform: ``1e-6`` plus the rounding of the stored coordinates.

    Examples
    --------
    >>> step, deviation, tolerance = step_deviation(np.array([0.0, 1.0, 2.0, 3.5]), 2.0 ** -52)
    >>> step, round(deviation, 12), deviation > tolerance  # the last step is 1.5, the mean 7/6
    (1.1666666666666667, 0.285714285714, True)
    """
    step = (coords[-1] - coords[0]) / (coords.size - 1)
    if step == 0:
        return float(step), float("inf"), 0.0
    dev = float(np.abs(np.diff(coords) - step).max() / abs(step))
    tol = 1e-6 + 8 * eps * float(np.abs(coords).max()) / abs(step)
    return float(step), dev, float(tol)


def nonuniform_message(where: str, axis: str, deviation: float) -> str:
    """Start of the error for coordinates that are not uniformly spaced; the caller adds the remedy.

    Parameters
    ----------
    where : str
        The source.
    axis : str
        ``"x"``, ``"y"`` or ``"z"``.
    deviation : float
        From :func:`step_deviation`.

    Returns
    -------
    str

    Examples
    --------
    >>> nonuniform_message("grid.vtr", "x", 0.25)
    'grid.vtr: x coordinates are not uniformly spaced (largest relative deviation of a step from the mean step: 0.25)'
    """
    return (f"{where}: {axis} coordinates are not uniformly spaced (largest relative deviation of a step from "
            f"the mean step: {deviation:.3g})")


# --------------------------------------------------------------------------------------------------
# missing samples
# --------------------------------------------------------------------------------------------------
def first_gap(missing: np.ndarray, source: str, what: str) -> tuple:
    """Count the missing samples and find the first; refuse a source where all are missing.

    Parameters
    ----------
    missing : ndarray of bool
        True where a sample is missing.
    source : str
        The source, first in the message.
    what : str
        What missing means here, e.g. ``"NaN/inf"``.

    Returns
    -------
    count : int
    first : tuple of int or None
        Index of the first missing sample in C order, None when none is missing.

    Raises
    ------
    ValueError
        Every sample is missing.

    Examples
    --------
    >>> first_gap(np.array([[False, True], [True, False]]), "numpy array", "NaN/inf")
    (2, (0, 1))
    >>> first_gap(np.ones(3, dtype=bool), "dem.tif", "nodata")
    Traceback (most recent call last):
    ValueError: dem.tif: all 3 samples are nodata; nothing to read.
    """
    count = int(missing.sum())
    if count == missing.size:
        raise ValueError(f"{source}: all {missing.size} samples are {what}; nothing to read.")
    first = tuple(int(v) for v in np.argwhere(missing)[0]) if count else None
    return count, first


def gap_error(source: str, count: int, size: int, what: str, position: str, value, remedy: str) -> ValueError:
    """The error for missing samples when no ``fill=`` was given.

    Parameters
    ----------
    source : str
        The source, first in the message.
    count, size : int
        Missing samples and all samples.
    what : str
        What missing means here, e.g. ``"NaN/inf"``.
    position : str
        Where the first missing sample is, in the reader's terms (index and world coordinates).
    value : object
        The stored value of that sample (its repr is shown).
    remedy : str
        What to do, e.g. which ``fill=`` to pass.

    Returns
    -------
    ValueError
        For the caller to raise, as with :func:`unsupported_extension`.

    Examples
    --------
    >>> print(gap_error("numpy array", 2, 4, "NaN/inf", "row 0, column 1", float("nan"), "Pass fill='nearest'."))
    numpy array: 2 of 4 samples are NaN/inf; the first at row 0, column 1, value nan. Pass fill='nearest'.
    """
    return ValueError(f"{source}: {count} of {size} samples are {what}; the first at {position}, value "
                      f"{value!r}. {remedy}")


def fill_nearest(values: np.ndarray, missing: np.ndarray, sampling: tuple) -> np.ndarray:
    """Replace each missing sample by the nearest valid one in world distance.

    Parameters
    ----------
    values : ndarray
        The samples; at least one is valid.
    missing : ndarray of bool, same shape
        True where a sample is missing.
    sampling : tuple of float
        The world step along each array axis (in array axis order, e.g. ``(dz, dy, dx)``), so that
        anisotropic spacing counts.

    Returns
    -------
    ndarray
        A new array; valid samples are unchanged.

    Examples
    --------
    >>> v = np.array([[1.0, np.nan, np.nan, 4.0]])
    >>> fill_nearest(v, np.isnan(v), (1.0, 1.0))
    array([[1., 1., 4., 4.]])
    """
    from scipy import ndimage

    idx = ndimage.distance_transform_edt(missing, sampling=sampling, return_distances=False, return_indices=True)
    return values[tuple(idx)]
