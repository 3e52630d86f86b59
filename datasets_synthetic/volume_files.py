"""Writers of volume files for the reader tests and examples: a VolumeGrid to .vti/.vtk/.mha/.mhd/.nrrd/.nhdr/
.raw/.slc (:func:`write_volume`), a Gaussian cube file (:func:`write_cube`) or a folder of raw slices
(:func:`write_slices`) with a chosen dtype, byte order and axis direction, so every reader is checked against a file whose
true sample positions are known."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from splinevis.io.volumes import VolumeGrid

__all__ = ["WRITE_FORMATS", "write_volume", "write_cube", "write_slices"]


WRITE_FORMATS = (".vti", ".vtk", ".mha", ".mhd", ".nrrd", ".nhdr", ".raw", ".slc")
_LEGACY = {"int8": "char", "uint8": "unsigned_char", "int16": "short", "uint16": "unsigned_short",
           "int32": "int", "uint32": "unsigned_int", "int64": "vtktypeint64", "uint64": "vtktypeuint64",
           "float32": "float", "float64": "double"}
_MET = {"int8": "MET_CHAR", "uint8": "MET_UCHAR", "int16": "MET_SHORT", "uint16": "MET_USHORT",
        "int32": "MET_INT", "uint32": "MET_UINT", "int64": "MET_LONG_LONG", "uint64": "MET_ULONG_LONG",
        "float32": "MET_FLOAT", "float64": "MET_DOUBLE"}
_NRRD = {"int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16", "int32": "int32",
         "uint32": "uint32", "int64": "int64", "uint64": "uint64", "float32": "float", "float64": "double"}


def _stored(grid: VolumeGrid, dtype):
    if dtype is None:
        name = grid.dtype if grid.dtype in _LEGACY else "float64"
        cast = grid.values.astype(name)
        if not np.array_equal(cast.astype(np.float64), grid.values):
            name, cast = "float64", grid.values
        return cast
    dt = np.dtype(dtype)
    if dt.name not in _LEGACY:
        raise ValueError(f"dtype {dtype!r} cannot be written; choose one of {sorted(_LEGACY)}.")
    cast = grid.values.astype(dt)
    if not np.array_equal(cast.astype(np.float64), grid.values):
        raise ValueError(f"the values are not exactly representable as {dt.name} (range {grid.value_range}, "
                         "fractions?); pass dtype='float64' or quantise first.")
    return cast


def _num(v) -> str:
    return repr(float(v))


def write_volume(grid: VolumeGrid, path, *, dtype=None, byteorder="little", direction=None, scalars=None,
                 compress=False) -> dict:
    """Write ``grid`` to ``path`` (format from the extension, see ``WRITE_FORMATS``) with full-precision
    spacing and origin; return the keyword arguments :func:`splinevis.io.read_volume` needs to read it back
    (empty for self-describing formats).

    Parameters
    ----------
    grid : VolumeGrid
    path : str or Path
        ``.vti`` (pyvista), ``.vtk`` (legacy STRUCTURED_POINTS, binary; written here because VTK's legacy
        writer keeps 6 significant digits of spacing and origin), ``.mha``/``.mhd`` (MetaImage; ``.mhd``
        puts the data in ``<stem>.raw`` beside it), ``.nrrd``/``.nhdr`` (NRRD; ``.nhdr`` puts the data in
        ``<stem>.raw``), ``.raw`` (samples only), ``.slc`` (uint8 only, no origin).
    dtype : str, optional
        Sample type in the file. Default: ``grid.dtype`` when the values fit it exactly, else float64.
        A requested dtype that does not hold the values exactly raises ValueError.
    byteorder : {"little", "big"}
        For .mha/.mhd/.nrrd/.nhdr/.raw (.vtk is big-endian by definition, .vti native).
    direction : (3, 3) array_like, optional
        Direction matrix to record (.vti, .mha/.mhd, .nrrd/.nhdr): the sample ``[k, j, i]`` lies at
        ``origin + direction @ (i*dx, j*dy, k*dz)``. For tests of flipped and rotated grids.
    scalars : str, optional
        Array name (.vti/.vtk; NRRD ``content``). Default ``grid.scalars`` or ``"values"``.
    compress : bool
        gzip the NRRD data / zlib the MetaImage data.

    Examples
    --------
    >>> import tempfile, os
    >>> from splinevis.io import read_volume
    >>> from datasets_synthetic.volumes import sphere_distance
    >>> g = sphere_distance().sample(5)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     kw = write_volume(g, os.path.join(d, "s.raw"))
    ...     back = read_volume(os.path.join(d, "s.raw"), **kw)
    >>> sorted(kw), bool((back.values == g.values).all())
    (['byteorder', 'dtype', 'origin', 'shape', 'spacing'], True)
    """
    if not isinstance(grid, VolumeGrid):
        raise TypeError(f"grid must be a VolumeGrid, got {type(grid).__name__}.")
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in WRITE_FORMATS:
        raise ValueError(f"{path}: cannot write {path.suffix!r}; choose one of {', '.join(WRITE_FORMATS)}.")
    if byteorder not in ("little", "big"):
        raise ValueError(f"byteorder {byteorder!r} is not known; choose 'little' or 'big'.")
    data = _stored(grid, dtype)
    name = scalars or grid.scalars or "values"
    nz, ny, nx = grid.shape
    D = np.eye(3) if direction is None else np.asarray(direction, dtype=np.float64).reshape(3, 3)
    if direction is not None and ext in (".vtk", ".raw", ".slc"):
        raise ValueError(f"{path}: the {ext} format has no direction matrix.")
    bo = "<" if byteorder == "little" else ">"
    path.parent.mkdir(parents=True, exist_ok=True)

    if ext == ".vti":
        import pyvista as pv

        img = pv.ImageData(dimensions=(nx, ny, nz), spacing=grid.spacing, origin=grid.origin)
        img.direction_matrix = D
        img.point_data[name] = np.ascontiguousarray(data).ravel()
        img.save(path, binary=True)
        return {}
    if ext == ".vtk":
        head = (f"# vtk DataFile Version 3.0\n{name} written by splinevis\nBINARY\nDATASET STRUCTURED_POINTS\n"
                f"DIMENSIONS {nx} {ny} {nz}\nSPACING {' '.join(map(_num, grid.spacing))}\n"
                f"ORIGIN {' '.join(map(_num, grid.origin))}\nPOINT_DATA {data.size}\n"
                f"SCALARS {name} {_LEGACY[data.dtype.name]} 1\nLOOKUP_TABLE default\n")
        path.write_bytes(head.encode() + data.astype(data.dtype.newbyteorder(">")).tobytes() + b"\n")
        return {}
    payload = data.astype(data.dtype.newbyteorder(bo)).tobytes()
    if ext == ".raw":
        path.write_bytes(payload)
        return {"shape": (nz, ny, nx), "dtype": data.dtype.name, "byteorder": byteorder,
                "spacing": grid.spacing, "origin": grid.origin}
    if ext == ".slc":
        if data.dtype != np.uint8:
            raise ValueError(f"{path}: SLC holds 8-bit samples; the values need dtype uint8, got {data.dtype}.")
        head = (f"11111 {nx} {ny} {nz} 8\n{' '.join(map(_num, grid.spacing))}\n0 0 0 0\n1 1 X")
        path.write_bytes(head.encode() + b"\0\0\0" + data.tobytes())
        return {} if grid.origin == (0.0, 0.0, 0.0) else {"origin": grid.origin}
    if ext in (".mha", ".mhd"):
        import zlib

        body = zlib.compress(payload) if compress else payload
        detached = ext == ".mhd"
        head = ("ObjectType = Image\nNDims = 3\nBinaryData = True\n"
                f"BinaryDataByteOrderMSB = {'True' if byteorder == 'big' else 'False'}\n"
                f"CompressedData = {'True' if compress else 'False'}\n"
                + (f"CompressedDataSize = {len(body)}\n" if compress else "")
                # MetaIO lists the direction vector of each index axis in turn (columns of D)
                + f"TransformMatrix = {' '.join(_num(v) for v in D.T.ravel())}\n"
                f"Offset = {' '.join(map(_num, grid.origin))}\n"
                f"ElementSpacing = {' '.join(map(_num, grid.spacing))}\n"
                f"DimSize = {nx} {ny} {nz}\nElementType = {_MET[data.dtype.name]}\n"
                f"ElementDataFile = {path.stem + '.raw' if detached else 'LOCAL'}\n")
        _write_header(path, head, body, detached)
        return {}
    # NRRD
    import gzip

    body = gzip.compress(payload) if compress else payload
    detached = ext == ".nhdr"
    dirs = " ".join("(" + ",".join(_num(v) for v in D[:, a] * grid.spacing[a]) + ")" for a in range(3))
    head = (f"NRRD0004\n# written by splinevis\ncontent: {name}\ntype: {_NRRD[data.dtype.name]}\ndimension: 3\n"
            f"space dimension: 3\nsizes: {nx} {ny} {nz}\nkinds: domain domain domain\n"
            f"space directions: {dirs}\nspace origin: ({','.join(map(_num, grid.origin))})\n"
            + (f"endian: {byteorder}\n" if data.dtype.itemsize > 1 else "")
            + f"encoding: {'gzip' if compress else 'raw'}\n"
            + (f"data file: {path.stem}.raw\n" if detached else "") + "\n")
    _write_header(path, head, body, detached)
    return {}


def _write_header(path: Path, head: str, body: bytes, detached: bool) -> None:
    """A text header followed by the samples in one file, or (``detached``: .mhd, .nhdr) the header alone
    beside a ``.raw`` file of the samples."""
    if detached:
        path.write_text(head)
        path.with_suffix(".raw").write_bytes(body)
    else:
        path.write_bytes(head.encode() + body)


def write_cube(grid: VolumeGrid, path, *, direction=None, atoms=((8, 0.0, 0.0, 0.0, 0.0),), per_line=6,
               comments=("splinevis test cube", "synthetic field")) -> Path:
    """Write ``grid`` as a Gaussian cube file (Bohr units: positive counts) on axes ``direction`` (columns;
    default ``grid.direction``). Samples are written first axis slowest, third fastest, ``per_line`` a line,
    with ``repr`` (exact round trip). ``atoms``: rows ``(Z, charge, x, y, z)``.

    >>> import tempfile, numpy as np
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     p = write_cube(VolumeGrid(np.arange(8.0).reshape(2, 2, 2)), Path(folder) / "a.cube")
    ...     print(p.read_text().splitlines()[3])
    2 1.0 0.0 0.0
    """
    path = Path(path)
    D = np.asarray(grid.direction if direction is None else direction, dtype=np.float64).reshape(3, 3)
    nz, ny, nx = grid.shape
    lines = list(comments)
    lines.append(f"{len(atoms)} " + " ".join(map(_num, grid.origin)))
    for n, a in zip((nx, ny, nz), range(3)):
        lines.append(f"{n} " + " ".join(map(_num, D[:, a] * grid.spacing[a])))
    for atom in atoms:
        lines.append(f"{int(atom[0])} " + " ".join(map(_num, atom[1:])))
    data = np.transpose(grid.values, (2, 1, 0)).ravel()  # [k, j, i] -> [i, j, k], k fastest
    for start in range(0, data.size, per_line):
        lines.append(" ".join(map(_num, data[start:start + per_line])))
    path.write_text("\n".join(lines) + "\n")
    return path


def write_slices(grid: VolumeGrid, folder, *, dtype="uint16", byteorder="little", pattern="slice{}.raw",
                 header_bytes=0) -> list:
    """Write each z slice of ``grid`` to ``folder/pattern.format(k)`` (headerless, x fastest), with an
    optional header of ``header_bytes`` zero bytes. Returns the paths (slice order)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    dt = np.dtype(dtype).newbyteorder("<" if byteorder == "little" else ">")
    out = []
    for k in range(grid.shape[0]):
        p = folder / pattern.format(k)
        p.write_bytes(b"\0" * header_bytes + grid.values[k].astype(dt).tobytes())
        out.append(p)
    return out
