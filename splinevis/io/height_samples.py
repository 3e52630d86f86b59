"""Height samples as a source stores them, before gaps and orientation are dealt with.

Every height reader (numpy arrays here, pyvista grids in :mod:`.height_vtk`, USGS DEMs in :mod:`.dem`,
rasters through GDAL in :mod:`.raster`) hands a :class:`HeightSamples` to :func:`splinevis.io.read_heights`, which
reports or fills the gaps, reorients the rows to south-to-north and returns a
:class:`~splinevis.io.HeightGrid`. Keeping the stored order until then lets the error messages count
rows and columns as the source stores them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._common import check_real_dtype

__all__ = ["HeightSamples", "GEOMETRY_ARGS_APPLY_TO", "from_array", "missing_mask"]

#: The sources ``spacing=``/``origin=`` are meant for (the others carry their own geometry).
GEOMETRY_ARGS_APPLY_TO = "numpy arrays and rasters without georeference"


@dataclass
class HeightSamples:
    """Samples as stored plus the map to our orientation.

    Parameters
    ----------
    values : (rows, cols) ndarray
        In the source's own order and dtype.
    missing : (rows, cols) ndarray of bool
        Gaps, in the same order.
    spacing, origin : (2,) tuples
        Already refer to the reoriented grid (south-to-north, west-to-east).
    source : str
        Where the data came from.
    flip_rows, flip_cols : bool
        How to reach south-to-north, west-to-east order.
    crs, units : str or None
        As in :class:`~splinevis.io.HeightGrid`.
    order_note : str
        How the error messages' (row, col) count, e.g. ``"(row, col) as stored, row 0 = north"``.
    xcoords, ycoords : ndarray or None
        Non-uniform coordinates (RectilinearGrid, StructuredGrid), reoriented; uniformity is judged later.
    coord_eps : float
        Machine epsilon of the stored coordinates.

    Examples
    --------
    >>> s = HeightSamples(np.array([[1, 2], [3, 4]]), np.zeros((2, 2), bool), (1.0, 1.0), (0.0, 0.0),
    ...                   "dem.tif", flip_rows=True)  # stored north row first
    >>> s.oriented(s.values)
    array([[3, 4],
           [1, 2]])
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
    xcoords: np.ndarray | None = None
    ycoords: np.ndarray | None = None
    coord_eps: float = float(np.finfo(np.float64).eps)

    def oriented(self, a):
        """``a`` (rows, cols) in stored order, reordered south-to-north and west-to-east (contiguous).

        Examples
        --------
        >>> s = HeightSamples(np.zeros((2, 3)), np.zeros((2, 3), bool), (1.0, 1.0), (0.0, 0.0), "x", flip_cols=True)
        >>> s.oriented(np.array([[1, 2, 3], [4, 5, 6]]))
        array([[3, 2, 1],
               [6, 5, 4]])
        """
        if self.flip_rows:
            a = a[::-1, :]
        if self.flip_cols:
            a = a[:, ::-1]
        return np.ascontiguousarray(a)

    def xy_of(self, r: int, c: int) -> tuple:
        """World ``(x, y)`` of the stored sample at row ``r``, column ``c``.

        Examples
        --------
        >>> s = HeightSamples(np.zeros((3, 2)), np.zeros((3, 2), bool), (10.0, 5.0), (100.0, 200.0), "x",
        ...                   flip_rows=True)
        >>> s.xy_of(0, 1)  # stored row 0 is the northern row
        (110.0, 210.0)
        """
        rows, cols = self.values.shape
        j = rows - 1 - r if self.flip_rows else r
        i = cols - 1 - c if self.flip_cols else c
        if self.xcoords is not None:
            return float(self.xcoords[i]), float(self.ycoords[j])
        return (self.origin[0] + i * self.spacing[0], self.origin[1] + j * self.spacing[1])


def from_array(values, spacing, origin, nodata, source="numpy array") -> HeightSamples:
    """Check a 2-D array of heights ``[row, col]`` (rows south to north) and wrap it.

    Parameters
    ----------
    values : array_like
        (ny, nx) real numbers, at least 2 x 2.
    spacing, origin : (2,) tuples or None
        Checked already; None gives ``(1, 1)`` and ``(0, 0)``.
    nodata : float or None
        Value marking missing samples besides NaN/inf.
    source : str
        For the messages.

    Returns
    -------
    HeightSamples

    Examples
    --------
    >>> s = from_array([[1, 2], [3, -9999]], None, None, -9999)
    >>> s.missing, s.spacing, s.origin
    (array([[False, False],
           [False,  True]]), (1.0, 1.0), (0.0, 0.0))
    >>> from_array([1, 2, 3], None, None, None)
    Traceback (most recent call last):
    ValueError: numpy array: heights must be a 2-D array (ny, nx), got shape (3,).
    """
    arr = np.asarray(values)
    check_real_dtype(arr, source, "heights")
    if arr.ndim != 2:
        hint = " Squeeze a singleton axis or pick one band." if arr.ndim == 3 else ""
        raise ValueError(f"{source}: heights must be a 2-D array (ny, nx), got shape {arr.shape}.{hint}")
    if arr.shape[0] < 2 or arr.shape[1] < 2:
        raise ValueError(f"{source}: heights need at least 2 x 2 samples, got shape {arr.shape}.")
    return HeightSamples(values=arr, missing=missing_mask(arr, nodata), spacing=spacing or (1.0, 1.0),
                         origin=origin or (0.0, 0.0), source=source, order_note="array index [row, col]")


def missing_mask(arr: np.ndarray, nodata) -> np.ndarray:
    """True where ``arr`` is non-finite or equals ``nodata`` compared in ``arr``'s own dtype.

    Parameters
    ----------
    arr : ndarray
        Real samples.
    nodata : float or None
        An integer dtype only matches an integral ``nodata`` within its range.

    Returns
    -------
    ndarray of bool

    Examples
    --------
    >>> missing_mask(np.array([1.0, np.nan, -9999.0]), -9999)
    array([False,  True,  True])
    >>> missing_mask(np.array([1, 255], dtype=np.uint8), 255), missing_mask(np.array([1, 255], dtype=np.uint8), 300)
    (array([False,  True]), array([False, False]))
    """
    miss = ~np.isfinite(arr) if arr.dtype.kind == "f" else np.zeros(arr.shape, bool)
    if nodata is not None:
        if arr.dtype.kind == "f":
            miss |= arr == arr.dtype.type(nodata)
        elif float(nodata).is_integer():
            info = np.iinfo(arr.dtype) if arr.dtype.kind in "iu" else None
            if info is None or info.min <= nodata <= info.max:
                miss |= arr == int(nodata)
    return miss
