"""NRRD files (``.nrrd``, detached headers ``.nhdr``), parsed here.

Why our own parser: VTK 9.7.1's ``vtkNrrdReader`` takes the first axis as vector components whenever
it has 9 or fewer samples (a 4-sample x axis becomes a 4-component vector), reads only the length of
each ``space directions`` vector (rotations and flips are lost) and does not support ``byte skip``.

What is read:

* encodings raw, gzip, bzip2, ascii and hex; ``line skip`` and ``byte skip`` (also -1: the data are
  the last bytes); a detached header naming one ``data file``;
* 3 spatial axes, plus at most one component axis (kind ``vector``, ``RGB-color``, ..., or the fastest
  axis of a 4-D file without kinds), picked with ``component=``;
* geometry from ``space origin``/``space directions``, used as given (coordinates of the file's
  ``space``, e.g. LPS or RAS, are not converted); directions axis-aligned up to flips, or
  orthogonal (a rotated lattice: kept as ``VolumeGrid.direction``; a shear raises). Without
  them, ``spacings`` and ``axis mins``/``axis maxs`` (cell centering adds half a step) give it.
"""

from __future__ import annotations

import bz2
import gzip
import re
from pathlib import Path

import numpy as np

from .raw import with_byteorder
from .volume_samples import (VolumeSamples, axis_signs, check_samples, check_size, orthonormal_direction,
                             pick_component, printed_rounding, unit_rounding)

__all__ = ["read_nrrd"]

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


def read_nrrd(path: Path, scalars, component) -> VolumeSamples:
    """Read an NRRD file or detached header with its data.

    Parameters
    ----------
    path : Path
        An existing ``.nrrd`` or ``.nhdr`` file.
    scalars : str or None
        An NRRD file holds one array: only its ``content`` name is accepted.
    component : None, int or "magnitude"
        For a file with a component axis (see :func:`.volume_samples.pick_component`).

    Returns
    -------
    VolumeSamples

    Examples
    --------
    >>> import tempfile
    >>> from datasets_synthetic.volumes import write_volume
    >>> from splinevis.io.volumes import VolumeGrid
    >>> grid = VolumeGrid(np.arange(24.0).reshape(2, 3, 4), spacing=(1.0, 2.0, 3.0), origin=(0.0, 0.0, 1e6))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = write_volume(grid, Path(folder) / "ramp.nrrd", dtype="int16")
    ...     samples = read_nrrd(Path(folder) / "ramp.nrrd", None, None)
    >>> samples.values.dtype.name, samples.values.shape, samples.spacing, samples.origin
    ('int16', (2, 3, 4), (1.0, 2.0, 3.0), (0.0, 0.0, 1000000.0))
    """
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
    arr = _read_data(path, f, data_offset, dt, sizes)
    if ndim == 4:
        comp_axis = spatial.index(False)
        arr = np.moveaxis(arr, ndim - 1 - comp_axis, -1)
        label = kinds[comp_axis] or "component"
        arr = pick_component(arr, sizes[comp_axis], f"{label} axis", where, component)
        sizes = [s for s, sp in zip(sizes, spatial) if sp]
        sp_dirs = [d for d, sp in zip(directions, spatial) if sp] if directions is not None else None
        keep = [a for a in range(ndim) if spatial[a]]
    else:
        if component is not None:
            raise ValueError(f"{where}: component= applies to multi-component data; this NRRD has one value "
                             "per sample.")
        sp_dirs = directions
        keep = list(range(ndim))
    check_samples(arr, where)
    check_size(arr.shape, where)
    step, origin, rotation = _geometry(path, f, sp_dirs, keep, ndim, sizes)
    samples = VolumeSamples.from_steps(arr, origin, step, sizes, where, f.get("content"))
    if rotation is not None:  # a rotated orthogonal lattice: positive steps, the first sample is the origin
        samples.direction = rotation
    return samples


def _read_data(path: Path, f: dict, data_offset: int, dt: np.dtype, sizes: list) -> np.ndarray:
    """The samples, native byte order, shaped ``sizes[::-1]`` (first NRRD axis fastest)."""
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
        dt = with_byteorder(dt, order)
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
    return arr.astype(dt.newbyteorder("="), copy=False).reshape(sizes[::-1])  # first NRRD axis fastest


def _geometry(path: Path, f: dict, sp_dirs, keep: list, ndim: int, sizes: list) -> tuple:
    """``(step, origin, rotation)``: signed world step of each spatial index axis and the first sample's position."""
    if sp_dirs is not None:
        if any(len(v) != 3 for v in sp_dirs):
            raise ValueError(f"{path}: space directions {sp_dirs} are not 3-D vectors; a volume needs a 3-D space.")
        m = np.array(sp_dirs, dtype=np.float64).T  # columns = world step of each index axis
        lengths = np.linalg.norm(m, axis=0)
        if np.any(lengths == 0):
            raise ValueError(f"{path}: a space direction is the zero vector: {sp_dirs}.")
        unit = np.where(np.abs(m) <= 1e-9 * lengths[None, :], 0.0, m) / lengths[None, :]
        rotation = None
        try:
            axis_signs(unit, str(path))
            step = np.diag(m).copy()
        except ValueError:  # rotated orthogonal axes are kept as a direction; a shear raises here
            # judged at the precision the header prints its space directions (half a unit of the last digit)
            printed = [hit.group(1).split(",") for hit in _NRRD_VECTOR.finditer(f["space directions"])
                       if hit.group(0) != "none"]
            rounding = None
            if len(printed) == 3 and all(len(v) == 3 for v in printed):
                rounding = unit_rounding(m, printed_rounding(sum(printed, [])).reshape(3, 3).max(axis=1))
            rotation = orthonormal_direction(unit, str(path), rounding=rounding)
            step = lengths.copy()
        origin = np.zeros(3)
        if "space origin" in f:
            origin = np.array(_nrrd_vectors(f["space origin"], path)[0], dtype=np.float64)
            if origin.shape != (3,):
                raise ValueError(f"{path}: space origin {f['space origin']!r} is not a 3-D point.")
        return step, origin, rotation
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
    return step, origin, None
