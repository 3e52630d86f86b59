"""Heights from pyvista/VTK grids and VTK files (``.vti .vtk .vtr .vts``, read with :func:`pyvista.read`).

A grid holds heights when it is one x-y slice, ``dims == (nx, ny, 1)``:

* ``ImageData``: axis-aligned (identity direction matrix); the heights are a point array.
* ``RectilinearGrid``: the x, y coordinates may run in decreasing order (the rows/columns are flipped)
  and may be non-uniform (:func:`splinevis.io.read_heights` then refuses or resamples).
* ``StructuredGrid``: the points must form an axis-aligned lattice. Without ``scalars=`` a surface whose
  z varies takes z as the heights (a warped surface); a flat lattice needs a point array. VTK's i axis
  may run along y (grids built from ``numpy.meshgrid``'s default ``"xy"`` arrays): it is transposed.

The spacing of RectilinearGrid/StructuredGrid coordinates is judged in the stored precision: float32
coordinates count as uniform within their rounding.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import check_real_dtype
from .height_samples import HeightSamples, missing_mask

__all__ = ["from_pyvista", "read_vtk_file"]


def read_vtk_file(path: Path, description: str, scalars, nodata) -> HeightSamples:
    """Read a VTK file with :func:`pyvista.read` and take its heights (see :func:`from_pyvista`).

    Parameters
    ----------
    path : Path
        An existing ``.vti``, ``.vtk``, ``.vtr`` or ``.vts`` file.
    description : str
        The format, for the message when pyvista cannot read the file.
    scalars, nodata
        As in :func:`from_pyvista`, which gets the grid read from the file.

    Returns
    -------
    HeightSamples

    Examples
    --------
    >>> import tempfile
    >>> import pyvista as pv
    >>> image = pv.ImageData(dimensions=(3, 2, 1), spacing=(10, 20, 1))
    >>> image.point_data["z"] = np.arange(6.0)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     image.save(Path(folder) / "heights.vti")
    ...     samples = read_vtk_file(Path(folder) / "heights.vti", "VTK XML ImageData", None, None)
    >>> samples.values, samples.spacing
    (array([[0., 1., 2.],
           [3., 4., 5.]]), (10.0, 20.0))
    """
    import pyvista as pv

    import warnings

    try:
        with warnings.catch_warnings(record=True) as caught:  # pyvista reports VTK reader errors as warnings
            warnings.simplefilter("always")
            grid = pv.read(path)
    except Exception as exc:  # pyvista raises a variety of types for unreadable files
        raise ValueError(f"{path}: pyvista could not read it as {description}: {exc}") from exc
    vtk_errors = [str(w.message) for w in caught if "raised an error" in str(w.message)]
    if vtk_errors or grid.n_points == 0:  # VTK's readers return an empty grid for an empty or cut file, with no error
        size = Path(path).stat().st_size
        why = f" (VTK: {vtk_errors[0].splitlines()[-1].strip()})" if vtk_errors else ""
        raise ValueError(f"{path}: the file could not be read whole ({size} bytes): it is empty or truncated{why}; "
                         f"write or download it again.")
    return from_pyvista(grid, str(path), scalars, nodata)


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


def from_pyvista(grid, name: str, scalars, nodata) -> HeightSamples:
    """Take the heights of a pyvista grid that is one x-y slice (see the module notes).

    Parameters
    ----------
    grid : pyvista.ImageData, pyvista.RectilinearGrid or pyvista.StructuredGrid
        Other types raise TypeError.
    name : str
        How the messages name the source (``"pyvista.ImageData"`` or a file path).
    scalars : str or None
        Name of the point array holding the heights; None: the active point scalars (or, for a
        StructuredGrid with varying z, the z coordinates).
    nodata : float or None
        Value marking missing samples besides NaN/inf.

    Returns
    -------
    HeightSamples

    Examples
    --------
    >>> import pyvista as pv
    >>> image = pv.ImageData(dimensions=(3, 2, 1), spacing=(10, 20, 1), origin=(5e5, 5e6, 0))
    >>> image.point_data["z"] = np.arange(6.0)
    >>> samples = from_pyvista(image, "pyvista.ImageData", "z", 5.0)  # 5.0 marks a gap
    >>> samples.missing.sum(), samples.origin, samples.spacing
    (np.int64(1), (500000.0, 5000000.0), (10.0, 20.0))
    >>> from_pyvista(pv.ImageData(dimensions=(3, 2, 2)), "pyvista.ImageData", None, None)
    Traceback (most recent call last):
    ValueError: pyvista.ImageData: heights must lie on one x-y slice, dims (nx, ny, 1); got dims (3, 2, 2). ...
    """
    import pyvista as pv

    if isinstance(grid, pv.ImageData):
        nx, ny = _slice_dims(grid, name)
        direction = np.asarray(grid.direction_matrix, dtype=float)
        if not np.array_equal(direction, np.eye(3)):
            raise ValueError(f"{name}: direction matrix {direction.tolist()} is not the identity; only "
                             "axis-aligned grids are supported. Resample onto an axis-aligned grid first.")
        arr, _ = _point_array(grid, name, scalars)
        values = arr.reshape(ny, nx)
        check_real_dtype(values, name, "heights", note_strings=False)
        return HeightSamples(values=values, missing=missing_mask(values, nodata), spacing=tuple(grid.spacing[:2]),
                             origin=tuple(grid.origin[:2]), source=name, order_note="grid index [j, i]")
    if isinstance(grid, pv.RectilinearGrid):
        nx, ny = _slice_dims(grid, name)
        arr, _ = _point_array(grid, name, scalars)
        values = arr.reshape(ny, nx)
        check_real_dtype(values, name, "heights", note_strings=False)
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
        check_real_dtype(values, name, "heights", note_strings=False)
        if nx > 1 and ny > 1 and X[0, 0] == X[0, 1] and Y[0, 0] == Y[1, 0] and X[0, 0] != X[1, 0]:
            # VTK's i axis runs along y (e.g. built from numpy.meshgrid's default "xy" arrays): transpose
            values, X, Y = values.T, X.T, Y.T
        x, y = _lattice_axes(X, Y, name)
        return _from_coordinates(values, x, y, name, nodata)
    raise TypeError(f"{name} is not supported; heights come from ImageData, RectilinearGrid or "
                    "StructuredGrid (one x-y slice), a 2-D numpy array or a file.")


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


def _from_coordinates(values, x, y, name, nodata) -> HeightSamples:
    """Rows/cols may run in decreasing x/y: flip them. Uniformity is judged later in ``read_heights``."""
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
    return HeightSamples(values=values, missing=missing_mask(values, nodata), spacing=(1.0, 1.0),
                         origin=(xo[0], yo[0]), source=name, flip_rows=flip_r, flip_cols=flip_c,
                         order_note="grid index [j, i]", xcoords=np.asarray(xo, np.float64),
                         ycoords=np.asarray(yo, np.float64), coord_eps=eps)
