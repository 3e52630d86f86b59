"""Stacks of headerless slice files: a folder of raw slices, or a glob pattern, read as one volume.

Each file holds one z slice of ``ny x nx`` samples (x fastest), without a header or with a header of
``header_bytes`` bytes. The files are sorted *naturally* by name (``slice2.raw`` before ``slice10.raw``);
the first file is ``z = 0``. The caller says what the bytes are, as for a single raw file:
``shape=(ny, nx)`` (or ``(nz, ny, nx)`` with ``nz`` equal to the number of files), ``dtype=``, and
``byteorder=`` for samples wider than one byte; ``spacing=``/``origin=`` as for raw files. Every file's
size is checked, and an error names the first file that does not fit. Hidden files (``.name``) are
skipped in a folder. DICOM series are not read here (their geometry lives in per-file headers).
"""

from __future__ import annotations

import glob
import re
from pathlib import Path

import numpy as np

from .raw import sample_dtype
from .volume_samples import VolumeSamples, from_array

__all__ = ["read_slices", "natural_key", "is_glob"]


def natural_key(name: str) -> list:
    """Sort key comparing digit runs as numbers: ``"s2" < "s10"``.

    >>> sorted(["s10.raw", "s2.raw", "s1.raw"], key=natural_key)
    ['s1.raw', 's2.raw', 's10.raw']
    """
    return [(0, int(t), "") if t.isdigit() else (1, 0, t.lower()) for t in re.split(r"(\d+)", name) if t]


def is_glob(source) -> bool:
    """True for a str holding glob characters ``*``, ``?`` or ``[``.

    >>> is_glob("ct/slice_*.raw"), is_glob("ct/slice.raw")
    (True, False)
    """
    return isinstance(source, str) and any(c in source for c in "*?[")


def _files(source) -> list:
    if is_glob(source):
        files = [Path(p) for p in glob.glob(source) if Path(p).is_file()]
        if not files:
            raise FileNotFoundError(f"no file matches the slice pattern {source!r}; check the folder and the "
                                    "pattern (e.g. 'ct/slice_*.raw').")
    else:
        files = [p for p in Path(source).iterdir() if p.is_file() and not p.name.startswith(".")]
        if not files:
            raise ValueError(f"{source} is an empty folder; a slice stack needs one raw file per z slice.")
    return sorted(files, key=lambda p: natural_key(p.name))


def read_slices(source, shape, dtype, byteorder, header_bytes, spacing, origin, component) -> VolumeSamples:
    """Read a folder (or glob) of raw slices as one volume ``values[k, j, i]`` (file ``k`` is slice ``k``).

    Parameters
    ----------
    source : str or Path
        A folder of slice files, or a glob pattern such as ``"ct/slice_*.raw"``.
    shape : (ny, nx) or (nz, ny, nx) ints
        Samples per slice (and optionally the number of slices, checked against the file count).
    dtype, byteorder, header_bytes, spacing, origin, component
        As for :func:`splinevis.io.raw.read_raw`; ``header_bytes`` is skipped in every file.

    Returns
    -------
    VolumeSamples
        The slices stacked along z in natural name order (``s2`` before ``s10``).

    Examples
    --------
    Three slices written out of order come back sorted by the numbers in their names:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for z in (10, 2, 1):
    ...         _ = (Path(folder) / f"s{z}.raw").write_bytes(np.full((2, 3), z, dtype=np.uint8).tobytes())
    ...     s = read_slices(folder, (2, 3), "uint8", None, 0, None, None, None)
    >>> s.values.shape, s.values[:, 0, 0].tolist()  # natural order: s1, s2, s10
    ((3, 2, 3), [1, 2, 10])
    """
    where = str(source)
    if shape is None or dtype is None:
        missing = " and ".join(n + "=" for n, v in (("shape", shape), ("dtype", dtype)) if v is None)
        raise ValueError(f"{where}: a folder or pattern is read as a stack of headerless raw slices and needs "
                         f"{missing}, e.g. read_volume({where!r}, shape=(ny, nx), dtype='uint16', "
                         "byteorder='little', spacing=(dx, dy, dz)). DICOM series are not read: convert them to "
                         "NRRD or MetaImage first.")
    if component is not None:
        raise ValueError(f"{where}: raw slices hold one value per sample; drop component={component!r}.")
    dt = sample_dtype(where, dtype, byteorder, header_bytes)
    if isinstance(shape, (int, np.integer)) or len(tuple(shape)) not in (2, 3):
        raise ValueError(f"{where}: shape must be the slice size (ny, nx) or (nz, ny, nx), got {shape!r}.")
    shape = tuple(int(s) for s in shape)
    if min(shape) < 1:
        raise ValueError(f"{where}: shape {shape} must be positive on every axis.")
    files = _files(source)
    ny, nx = shape[-2:]
    if len(shape) == 3 and shape[0] != len(files):
        raise ValueError(f"{where}: shape {shape} says {shape[0]} slices, found {len(files)} files "
                         f"({files[0].name} ... {files[-1].name}); fix shape or the folder/pattern.")
    expected = int(header_bytes) + ny * nx * dt.itemsize
    stack = np.empty((len(files), ny, nx), dtype=dt.newbyteorder("="))
    for k, f in enumerate(files):
        size = f.stat().st_size
        if size != expected:
            raise ValueError(f"{f}: slice {k} has {size} bytes, expected {expected} ({header_bytes} header + "
                             f"{ny} x {nx} samples x {dt.itemsize} bytes of {dt.name}); check shape=(ny, nx), "
                             "dtype= and header_bytes=, or remove the file that is not a slice.")
        stack[k] = np.fromfile(f, dtype=dt, count=ny * nx, offset=int(header_bytes)).reshape(ny, nx)
    return from_array(stack, spacing, origin, None, where)
