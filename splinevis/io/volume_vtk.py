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
* Lattices with non-uniform steps (``RectilinearGrid``, axis-aligned ``StructuredGrid``) are refused with the
  Python lines that resample them (:func:`resample_advice`); ``from_pyvista(..., resample=True)`` does it
  (:func:`resample_to_image`: cell data made point data, the finest step of each axis, the same bounds).
* A compressed MetaImage whose header's ``CompressedDataSize`` is shorter than its zlib stream: MetaIO inflates
  the declared bytes only and ``vtkMetaImageReader`` leaves the other samples uninitialised, silently; the whole
  stream is decoded instead, with a warning giving both sizes (measured on frogtissue.mhd: 260,020 declared
  bytes of 262,087 hold 30,963,285 of its 31,960,000 samples).
* A MetaImage's ``TransformMatrix`` is taken from the header (:func:`metaimage_direction`: ``vtkMetaImageReader``
  transposes a rotation) and judged orthonormal at the precision the header prints it, as the NRRD and cube
  readers judge theirs: a rotation printed with 4 decimals reads, with a warning reporting the correction.
* Legacy ``.vtk`` files written by VTK carry spacing and origin with 6 significant digits only (an
  origin of ``1e6 + 0.1`` is written as ``1e+06``); the reader keeps what the file says.
  ``datasets_synthetic.volumes.write_volume`` writes full precision.
"""

from __future__ import annotations

import re
import warnings
import zlib
from pathlib import Path

import numpy as np

from .._warnings import warn_user
from ._common import nonuniform_message, step_deviation
from .volume_samples import (VolumeSamples, axis_signs, check_samples, check_size, orthonormal_direction,
                             pick_component, printed_rounding, unit_rounding)

__all__ = ["from_pyvista", "read_vtk_file", "resample_to_image", "resample_advice"]

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
    if path.suffix.lower() in (".mha", ".mhd"):
        _metaimage_whole_stream(path, grid)
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


def from_pyvista(grid, where: str, scalars, component, resample=None, direction=None,
                 rounding=None) -> VolumeSamples:
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
    resample : None, False or True
        A ``RectilinearGrid``/``StructuredGrid`` lattice with non-uniform steps: True resamples it
        (:func:`resample_to_image`, with a warning saying how); False or None raise ValueError with the
        command that resamples (False: the caller offers ``resample=True``, and the message says so).
    direction : (3, 3) array_like, optional
        An ``ImageData``'s direction matrix as its file gives it, used instead of the grid's (a MetaImage's
        ``TransformMatrix``, :func:`metaimage_direction`: ``vtkMetaImageReader`` transposes a rotation).
    rounding : float or (3,) floats, optional
        Bound on the error of each unit column of ``direction`` as read (the precision the file prints),
        for :func:`.volume_samples.orthonormal_direction`; None: a matrix of unknown provenance.

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
        direction = np.asarray(grid.direction_matrix if direction is None else direction, dtype=np.float64)
        try:
            sign = axis_signs(direction, where)
            rotation = None
        except ValueError:  # a rotated orthogonal lattice is kept with its direction; a shear raises here
            rotation = np.asarray(orthonormal_direction(direction * np.sign(spacing)[None, :], where,
                                                        rounding=rounding))
            direction = rotation * np.sign(spacing)[None, :]  # the positions below at the corrected matrix
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
        return _coords_samples(grid, coords, where, scalars, component, resample=resample)
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
                             "(pyvista: image.sample(grid), cell data made point data first).")
        return _coords_samples(grid, [x, y, z], where, scalars, component, resample=resample,
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


def _coords_samples(grid, coords, where, scalars, component, eps=None, resample=None) -> VolumeSamples:
    steps, firsts, uneven = [], [], []
    for label, c in zip("xyz", coords):
        if c.size < 2:
            check_size((coords[2].size, coords[1].size, coords[0].size), where)
        if not np.isfinite(c).all():
            raise ValueError(f"{where}: {label} coordinates must be finite.")
        step, dev, tol = step_deviation(c, eps if eps is not None else float(np.finfo(np.float64).eps))
        if not dev <= tol:
            d = np.abs(np.diff(c))
            uneven.append(nonuniform_message(where, label, dev)[len(where) + 2:]
                          + f", steps {d.min():.3g} to {d.max():.3g}")
        steps.append(step)
        firsts.append(float(c[0]))
    if uneven and resample:
        image, how = resample_to_image(grid, coords)
        warn_user(f"{where}: {'; '.join(uneven)}: {how}.")
        return from_pyvista(image, where, scalars, component)
    if uneven:
        raise ValueError(f"{where}: {'; '.join(uneven)}. The spline schemes need a uniform grid: "
                         + ("pass resample=True, or " if resample is False else "")
                         + resample_advice(grid, coords, where, scalars))
    assoc, name, arr = _choose_array(grid, where, scalars)
    dims = tuple(c.size for c in coords)
    first = np.array(firsts)
    if assoc == "cell":
        first = first + 0.5 * np.array(steps)
        dims = tuple(d - 1 for d in dims)
    return _lattice_samples(arr, dims, first, np.array(steps), where, name, component)


def _lattice_of(coords) -> tuple:
    """``(dimensions, spacing, origin)`` of the uniform lattice over the coordinates' bounds whose step on each
    axis is at most the finest step there; the last point stays inside (a point outside by a rounding error
    is not sampled by ``vtkResampleWithDataSet``)."""
    dims, spacing, origin = [], [], []
    for c in coords:
        c = np.asarray(c, dtype=np.float64)
        lo, hi, finest = float(c.min()), float(c.max()), float(np.abs(np.diff(c)).min())
        n = max(int(np.ceil((hi - lo) / finest * (1 - 1e-9))) + 1, 2)
        step = (hi - lo) / (n - 1)
        while lo + (n - 1) * step > hi:
            step = float(np.nextafter(step, 0.0))
        dims.append(n)
        spacing.append(step)
        origin.append(lo)
    return tuple(dims), tuple(spacing), tuple(origin)


def resample_to_image(grid, coords) -> tuple:
    """A non-uniform lattice resampled onto a uniform ``ImageData``: ``(image, how in words)``.

    Cell data become point data first (``cell_data_to_point_data``: the mean of the cells around each point);
    then ``image.sample(grid)`` (``vtkResampleWithDataSet``: trilinear inside each cell of ``grid``) on the
    lattice over ``grid``'s bounds whose step on each axis is at most the finest step of ``grid`` there.
    Every array is carried; the spline schemes then approximate this piecewise-trilinear field (they are built
    on a partition of equal cubes, [Kalbe2008, sec. 3]).

    Parameters
    ----------
    grid : pyvista.RectilinearGrid or pyvista.StructuredGrid
        An axis-aligned lattice.
    coords : three 1-D arrays
        Its x, y, z sample coordinates.

    Returns
    -------
    image : pyvista.ImageData
    how : str

    Examples
    --------
    >>> import pyvista as pv
    >>> grid = pv.RectilinearGrid(np.array([0.0, 1.0, 3.0]), np.array([0.0, 1.0]), np.array([0.0, 2.0]))
    >>> grid.cell_data["p"] = np.array([1.0, 2.0])
    >>> image, how = resample_to_image(grid, (grid.x, grid.y, grid.z))
    >>> image.dimensions, image.spacing, np.asarray(image.point_data["p"]).tolist()[:4]
    ((4, 2, 2), (1.0, 1.0, 2.0), [1.0, 1.5, 1.75, 2.0])
    >>> how
    'cell data made point data, resampled trilinearly onto a uniform ImageData of dimensions (4, 2, 2), spacing (1.0, 1.0, 2.0) (the finest step of each axis) over the same bounds'
    """
    import pyvista as pv

    dims, spacing, origin = _lattice_of(coords)
    has_cells = any(a[0] == "cell" for a in _arrays(grid))
    source = grid.cell_data_to_point_data() if has_cells else grid
    image = pv.ImageData(dimensions=dims, spacing=spacing, origin=origin).sample(source, mark_blank=False)
    valid = np.asarray(image.point_data["vtkValidPointMask"])
    if not valid.all():
        raise ValueError(f"resampling left {int((valid == 0).sum())} of {valid.size} points outside the grid's "
                         "cells; the grid does not fill its bounds.")
    del image.point_data["vtkValidPointMask"]
    how = (f"{'cell data made point data, ' if has_cells else ''}resampled trilinearly onto a uniform ImageData "
           f"of dimensions {dims}, spacing {tuple(float(f'{h:.6g}') for h in spacing)} (the finest step of each "
           "axis) over the same bounds")
    return image, how


def resample_advice(grid, coords, where: str, scalars) -> str:
    """What to do with a non-uniform lattice, in words: its arrays (cell or point data) and Python lines that
    resample it (:func:`resample_to_image`'s steps) and read the result, to paste as they are.

    Examples
    --------
    >>> import pyvista as pv
    >>> grid = pv.RectilinearGrid(np.array([0.0, 1.0, 3.0]), np.array([0.0, 1.0]), np.array([0.0, 2.0]))
    >>> grid.cell_data["p"] = np.array([1.0, 2.0])
    >>> print(resample_advice(grid, (grid.x, grid.y, grid.z), "pyvista.RectilinearGrid", None))
    resample onto an ImageData with the finest step of each axis over the same bounds. The grid holds cell data only (1 array: 'p'; no point data); they become point data first. In Python, with the grid as grid: import pyvista as pv; from splinevis.io import read_volume; grid = grid.cell_data_to_point_data(); image = pv.ImageData(dimensions=(4, 2, 2), spacing=(1.0, 1.0, 2.0), origin=(0.0, 0.0, 0.0)); volume = read_volume(image.sample(grid))
    """
    dims, spacing, origin = _lattice_of(coords)
    arrays = _arrays(grid)
    cells = [n for a, n, _ in arrays if a == "cell"]
    points = [n for a, n, _ in arrays if a == "point"]
    names = ", ".join(repr(n) for n in (cells or points))
    count = f"{len(cells or points)} arr{'ays' if len(cells or points) > 1 else 'ay'}: {names}"
    if cells and not points:
        kind = f"cell data only ({count}; no point data); they become point data first"
    elif cells:
        kind = (f"cell data ({', '.join(repr(n) for n in cells)}) and point data "
                f"({', '.join(repr(n) for n in points)}); the cell data become point data first")
    else:
        kind = f"point data ({count})"
    pick = scalars if scalars is not None else next((n for n in cells + points), None)
    lattice = (f"image = pv.ImageData(dimensions={dims}, spacing=({', '.join(repr(float(h)) for h in spacing)}), "
               f"origin=({', '.join(repr(float(o)) for o in origin)}))")
    convert = ".cell_data_to_point_data()" if cells else ""
    pick_arg = f", scalars={pick!r}" if len(arrays) > 1 or scalars is not None else ""
    path = Path(where)
    if path.is_file():
        out = f"{path.stem}_uniform.vti"
        lines = (f"import pyvista as pv; grid = pv.read({str(path)!r}){convert}; {lattice}; "
                 f"image.sample(grid).save({out!r})")
        then = f" Then read_volume({out!r}{pick_arg})."
        return (f"resample onto an ImageData with the finest step of each axis over the file's bounds. The file "
                f"holds {kind}. In Python: {lines}.{then}")
    lines = ("import pyvista as pv; from splinevis.io import read_volume; "
             + (f"grid = grid{convert}; " if convert else "")
             + f"{lattice}; volume = read_volume(image.sample(grid){pick_arg})")
    return (f"resample onto an ImageData with the finest step of each axis over the same bounds. The grid holds "
            f"{kind}. In Python, with the grid as grid: {lines}")


def metaimage_direction(path: Path, where: str):
    """``(direction, rounding)`` of a MetaImage header (``TransformMatrix``/``Orientation``/``Rotation``), or None.

    MetaIO lists the direction vector of each index axis in turn (ITK's convention: the columns of the
    direction matrix); ``vtkMetaImageReader`` takes the list row by row, i.e. it transposes a rotation.
    Axis flips (diagonal) are the same either way. ``rounding`` bounds the error of each unit column as
    the header prints it (:func:`.volume_samples.printed_rounding`, :func:`.volume_samples.unit_rounding`):
    a matrix written with 4 decimals is judged orthonormal at that precision, as the NRRD and cube readers do.
    """
    with open(path, "rb") as fh:
        head = fh.read(1 << 16).decode("latin-1")
    for line in head.splitlines():
        key, sep, val = line.partition("=")
        if sep and key.strip().lower() in ("transformmatrix", "orientation", "rotation"):
            texts = val.split()
            try:
                vals = [float(v) for v in texts]
            except ValueError:
                raise ValueError(f"{where}: {key.strip()} = {val.strip()!r} is not 9 numbers.") from None
            if len(vals) != 9:
                raise ValueError(f"{where}: {key.strip()} has {len(vals)} numbers; a 3-D image needs 9.")
            m = np.array(vals, dtype=np.float64).reshape(3, 3).T
            if not np.isfinite(m).all() or np.any(np.linalg.norm(m, axis=0) == 0):
                raise ValueError(f"{where}: {key.strip()} = {val.strip()!r} has a non-finite entry or a zero "
                                 "axis; each axis needs a direction.")
            return m, unit_rounding(m, printed_rounding(texts).reshape(3, 3).max(axis=1))
        if key.strip().lower() == "elementdatafile":
            break
    return None


def _metaimage_fields(path: Path) -> tuple:
    """``(fields, data_start)``: a MetaImage header's ``key = value`` lines (keys lower-cased) up to
    ``ElementDataFile``, and the byte after that line (where the data of a ``LOCAL`` file start)."""
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    fields, start = {}, 0
    for m in re.finditer(rb"^[ \t]*(\w+)[ \t]*=[ \t]*([^\r\n]*?)[ \t]*(\r\n|\n|\r|$)", head, re.M):
        key = m.group(1).decode("latin-1").lower()
        fields[key] = m.group(2).decode("latin-1")
        if key == "elementdatafile":
            start = m.end()
            break
    return fields, start


def _metaimage_whole_stream(path: Path, grid) -> None:
    """Repair VTK's reading of a compressed MetaImage whose header's ``CompressedDataSize`` is shorter than
    its zlib stream (in place, with a warning naming the file and both sizes).

    MetaIO inflates exactly ``CompressedDataSize`` bytes; when they hold fewer samples than ``DimSize``
    asks, ``vtkMetaImageReader`` returns the rest uninitialised and reports nothing. The rule, measured on
    the file's own bytes: the declared bytes decode short, the whole stream decodes to every sample, and VTK
    agrees with that decode on every sample the declared bytes hold -> the whole stream's samples are taken.
    A stream too short for the samples raises ValueError (the file is cut short).
    """
    fields, start = _metaimage_fields(path)
    if fields.get("compresseddata", "").lower() != "true":
        return
    name = fields.get("elementdatafile", "")
    if name.upper() == "LOCAL":
        data_path = path
    elif name and " " not in name and "%" not in name and name.upper() != "LIST":
        data_path, start = path.parent / name, 0
    else:  # a list or a pattern of slice files: VTK's reading stands
        return
    try:
        declared = int(fields.get("compresseddatasize", ""))
    except ValueError:
        return
    if not data_path.is_file() or declared >= data_path.stat().st_size - start:
        return
    keys = [k for k in grid.point_data.keys() if k not in _VTK_INTERNAL_ARRAYS]
    if len(keys) != 1:
        return
    theirs = grid.point_data[keys[0]]  # VTK's memory: replaced in place
    msb = fields.get("binarydatabyteordermsb", fields.get("elementbyteordermsb", "false")).lower() == "true"
    dt = np.dtype(theirs.dtype).newbyteorder(">" if msb else "<")
    with open(data_path, "rb") as fh:
        fh.seek(start)
        stream = fh.read()
    inflate = zlib.decompressobj(zlib.MAX_WBITS | 32)  # a zlib or gzip header, as MetaIO accepts
    try:
        head = inflate.decompress(stream[:declared])
        whole = head + inflate.decompress(stream[declared:])
    except zlib.error as exc:
        raise ValueError(f"{path}: the compressed data in {data_path.name} are not a valid zlib stream ({exc}); "
                         "is the file complete?") from None
    n, have = theirs.size, len(head) // dt.itemsize
    if have >= n:  # the declared bytes hold every sample (bytes after the stream are VTK's business)
        return
    if len(whole) < theirs.nbytes:
        raise ValueError(f"{path}: the zlib stream in {data_path.name} decodes to {len(whole) // dt.itemsize} "
                         f"samples, DimSize and ElementNumberOfChannels need {n}: the data are cut short.")
    values = np.frombuffer(whole, dtype=dt, count=n)
    flat = np.asarray(theirs).reshape(-1)
    differ = int(np.count_nonzero(flat[:have] != values[:have]))
    if differ:
        raise ValueError(f"{path}: the header's CompressedDataSize = {declared} is shorter than the zlib stream "
                         f"in {data_path.name} ({len(stream)} bytes), and VTK's reading differs from the decode "
                         f"of those bytes at {differ} of the {have} samples they hold; cannot tell which is right.")
    flat[have:] = values[have:]
    end = len(stream) - len(inflate.unused_data)
    warn_user(f"{path}: the header's CompressedDataSize = {declared} is shorter than the zlib stream in "
              f"{data_path.name} ({end} bytes): the declared bytes hold {have} of the {n} samples (VTK's "
              f"vtkMetaImageReader leaves the other {n - have} uninitialised); read the whole stream instead. "
              f"Fix the header: CompressedDataSize = {end}.")
