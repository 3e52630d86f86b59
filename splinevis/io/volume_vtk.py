"""Volumes from pyvista/VTK data objects and from the files VTK reads for us.

Objects: ``ImageData``/``vtkImageData`` (point or cell data, direction matrix honoured when it only
flips axes; a rotated orthogonal lattice keeps its direction in ``VolumeGrid.direction``, a shear
raises), uniform ``RectilinearGrid`` and axis-aligned uniform ``StructuredGrid``. Files, through
:func:`pyvista.read`: ``.vti .vtk .vtr .vts``, MetaImage ``.mha .mhd`` (``vtkMetaImageReader``) and
``.slc`` (``vtkSLCReader``).

* Cell data hold one value per voxel; they are read as samples at the voxel centres, a grid of
  ``(nz-1, ny-1, nx-1)`` samples whose origin is half a voxel inside. Point data come first when both
  exist; with several arrays ``scalars=`` must pick one.
* VTK's readers report problems as errors or warnings on the side and still return a grid:
  ``vtkMetaImageReader`` returns uninitialised values with only a warning when the data are short.
  :func:`read_vtk_file` turns such reports into a ValueError naming the file.
* Legacy ``.vtk`` files written by VTK carry spacing and origin with 6 significant digits only (an
  origin of ``1e6 + 0.1`` is written as ``1e+06``); the reader keeps what the file says.
  ``datasets_synthetic.volumes.write_volume`` writes full precision.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ._common import nonuniform_message, step_deviation
from .volume_samples import (VolumeSamples, axis_signs, check_samples, check_size, orthonormal_direction,
                             pick_component)

__all__ = ["from_pyvista", "read_vtk_file"]

_VTK_INTERNAL_ARRAYS = {"vtkGhostType", "vtkValidPointMask"}


def read_vtk_file(path: Path, description: str):
    """``pyvista.read`` with VTK errors and reader warnings turned into ValueError naming the file.

    Parameters
    ----------
    path : Path
        An existing, non-empty file.
    description : str
        The format, for the messages (e.g. ``"MetaImage (vtkMetaImageReader)"``).

    Returns
    -------
    pyvista.DataSet
        With at least one point; not a MultiBlock.

    Examples
    --------
    >>> import tempfile
    >>> import pyvista as pv
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     pv.ImageData(dimensions=(4, 3, 2)).save(Path(folder) / "box.vti")
    ...     grid = read_vtk_file(Path(folder) / "box.vti", "VTK XML ImageData")
    ...     _ = (Path(folder) / "broken.vti").write_text("<VTKFile")
    ...     read_vtk_file(Path(folder) / "broken.vti", "VTK XML ImageData")
    Traceback (most recent call last):
    ValueError: ...broken.vti: could not be read as VTK XML ImageData...
    >>> type(grid).__name__, grid.dimensions
    ('ImageData', (4, 3, 2))
    """
    import pyvista as pv

    try:
        with warnings.catch_warnings(record=True) as caught, pv.VtkErrorCatcher(raise_errors=False) as catcher:
            warnings.simplefilter("always")
            grid = pv.read(path)
    except Exception as exc:  # pyvista and VTK raise a variety of types for unreadable files
        raise ValueError(f"{path}: could not be read as {description}: {exc}") from exc
    problems = [str(e) for e in getattr(catcher, "events", [])]
    problems += [str(w.message) for w in caught if "error" in str(w.message).lower()]
    if problems:
        msg = " ".join(problems[0].split())
        raise ValueError(f"{path}: could not be read as {description} (the VTK reader "
                         f"reported: {msg[:300]}). Is the file complete and of this format?")
    if grid is None or grid.n_points == 0:
        raise ValueError(f"{path}: the reader returned no samples; is the file complete and of this format?")
    if isinstance(grid, pv.MultiBlock):
        raise ValueError(f"{path}: holds a MultiBlock dataset; save one ImageData block instead.")
    return grid


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


def from_pyvista(grid, where: str, scalars, component) -> VolumeSamples:
    """Take the samples of a pyvista ``ImageData``, uniform ``RectilinearGrid`` or ``StructuredGrid``.

    Parameters
    ----------
    grid : pyvista.DataSet
        A wrapped grid (``pyvista.wrap``).
    where : str
        The source, for the messages.
    scalars : str or None
        Name of the point or cell array; needed when there are several.
    component : None, int or "magnitude"
        For arrays with several components (see :func:`.volume_samples.pick_component`).

    Returns
    -------
    VolumeSamples

    Examples
    --------
    >>> import pyvista as pv
    >>> image = pv.ImageData(dimensions=(4, 3, 2), spacing=(1.0, 2.0, 3.0))
    >>> image.point_data["density"] = np.arange(24, dtype=np.uint8)
    >>> image.point_data["velocity"] = np.zeros((24, 3))
    >>> samples = from_pyvista(image, "pyvista.ImageData", "density", None)
    >>> samples.values.shape, samples.values.dtype, samples.scalars, samples.spacing
    ((2, 3, 4), dtype('uint8'), 'density', (1.0, 2.0, 3.0))
    >>> from_pyvista(image, "pyvista.ImageData", "velocity", None)
    Traceback (most recent call last):
    ValueError: pyvista.ImageData: array 'velocity' has 3 components per sample; a volume needs one. ...
    """
    import pyvista as pv

    if isinstance(grid, pv.ImageData):
        dims = tuple(int(d) for d in grid.dimensions)
        spacing = np.array(grid.spacing, dtype=np.float64)
        origin = np.array(grid.origin, dtype=np.float64)
        extent = np.array(grid.extent, dtype=np.int64)[0::2]
        direction = np.asarray(grid.direction_matrix, dtype=np.float64)
        try:
            sign = axis_signs(direction, where)
            rotation = None
        except ValueError:  # a rotated orthogonal lattice is kept with its direction; a shear raises here
            rotation = np.asarray(orthonormal_direction(direction * np.sign(spacing)[None, :], where))
            sign = np.ones(3)
        first = origin + direction @ (extent * spacing)  # world position of the first stored point
        assoc, name, arr = _choose_array(grid, where, scalars)
        if rotation is not None:
            if assoc == "cell":
                first = first + direction @ (0.5 * spacing)
                dims = tuple(max(d - 1, 1) for d in dims)
            samples = _lattice_samples(arr, dims, np.zeros(3), np.abs(spacing), where, name, component)
            samples.origin = tuple(float(v) for v in first)
            samples.direction = tuple(tuple(float(x) for x in row) for row in rotation)
            return samples
        axes_step = sign * spacing  # world step of the stored index along each axis
        if assoc == "cell":
            first = first + 0.5 * axes_step
            dims = tuple(max(d - 1, 1) for d in dims)
        return _lattice_samples(arr, dims, first, axes_step, where, name, component)
    if isinstance(grid, pv.RectilinearGrid):
        coords = [np.asarray(c, dtype=np.float64) for c in (grid.x, grid.y, grid.z)]
        return _coords_samples(grid, coords, where, scalars, component)
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
        return _coords_samples(grid, [x, y, z], where, scalars, component,
                               eps=float(np.finfo(np.asarray(grid.points).dtype).eps))
    raise TypeError(f"{where} is not supported; volumes come from ImageData (or uniform RectilinearGrid/"
                    "StructuredGrid), a 3-D numpy array or a file.")


def _lattice_samples(arr, dims, first, axes_step, where, name, component) -> VolumeSamples:
    """Flat VTK-ordered ``arr`` on ``dims`` (nx, ny, nz) with stored first point and signed steps."""
    check_samples(arr, f"{where} array {name!r}")
    nx, ny, nz = dims
    if arr.ndim == 2:
        arr = pick_component(arr, arr.shape[1], name, where, component)
    elif component is not None:
        raise ValueError(f"{where}: component= applies to multi-component arrays; {name!r} has one component.")
    if arr.shape[0] != nx * ny * nz:
        raise ValueError(f"{where}: array {name!r} has {arr.shape[0]} values, dims {dims} need {nx * ny * nz}.")
    check_size((nz, ny, nx), where)
    samples = VolumeSamples.from_steps(arr.reshape(nz, ny, nx), first, axes_step, (nx, ny, nz), where, name)
    if min(samples.spacing) <= 0:
        raise ValueError(f"{where}: spacing {samples.spacing} must be nonzero on every axis.")
    return samples


def _coords_samples(grid, coords, where, scalars, component, eps=None) -> VolumeSamples:
    steps, firsts = [], []
    for label, c in zip("xyz", coords):
        if c.size < 2:
            check_size((coords[2].size, coords[1].size, coords[0].size), where)
        if not np.isfinite(c).all():
            raise ValueError(f"{where}: {label} coordinates must be finite.")
        step, dev, tol = step_deviation(c, eps if eps is not None else float(np.finfo(np.float64).eps))
        if not dev <= tol:
            raise ValueError(nonuniform_message(where, label, dev) + "; the spline schemes need a uniform grid. "
                             "Resample onto an ImageData first (e.g. pyvista's grid.sample(image)).")
        steps.append(step)
        firsts.append(float(c[0]))
    assoc, name, arr = _choose_array(grid, where, scalars)
    dims = tuple(c.size for c in coords)
    first = np.array(firsts)
    if assoc == "cell":
        first = first + 0.5 * np.array(steps)
        dims = tuple(d - 1 for d in dims)
    return _lattice_samples(arr, dims, first, np.array(steps), where, name, component)



def metaimage_direction(path: Path, where: str):
    """The direction matrix of a MetaImage header (``TransformMatrix``/``Orientation``/``Rotation``), or None.

    MetaIO lists the direction vector of each index axis in turn (ITK's convention: the columns of the
    direction matrix); ``vtkMetaImageReader`` takes the list row by row, i.e. it transposes a rotation.
    Axis flips (diagonal) are the same either way.
    """
    with open(path, "rb") as fh:
        head = fh.read(1 << 16).decode("latin-1")
    for line in head.splitlines():
        key, sep, val = line.partition("=")
        if sep and key.strip().lower() in ("transformmatrix", "orientation", "rotation"):
            vals = [float(v) for v in val.split()]
            if len(vals) != 9:
                raise ValueError(f"{where}: {key.strip()} has {len(vals)} numbers; a 3-D image needs 9.")
            return np.array(vals, dtype=np.float64).reshape(3, 3).T
        if key.strip().lower() == "elementdatafile":
            break
    return None
