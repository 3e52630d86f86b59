"""Headerless sample files (``.raw``, ``.bin``): the caller says what the bytes are.

A raw file has no header, so :func:`splinevis.io.read_volume` needs ``shape=(nz, ny, nx)`` (slowest axis
first), ``dtype=`` and, for samples wider than a byte, ``byteorder=`` - required, because a wrong guess
reads plausible-looking garbage (a dtype such as ``">u2"`` carries it too). ``header_bytes=`` skips a
header of a known size. When the file size does not match, the error says what would explain it (a
header, another dtype, another shape).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .volume_samples import VolumeSamples, from_array

__all__ = ["sample_dtype", "read_raw", "with_byteorder"]


def with_byteorder(dt: np.dtype, order: str) -> np.dtype:
    """``dt`` with the byte order ``"little"`` or ``"big"``.

    Parameters
    ----------
    dt : numpy.dtype
    order : {"little", "big"}

    Returns
    -------
    numpy.dtype

    Examples
    --------
    >>> with_byteorder(np.dtype("int16"), "big"), with_byteorder(np.dtype(">f4"), "little")
    (dtype('>i2'), dtype('<f4'))
    """
    return dt.newbyteorder("<" if order == "little" else ">")


def sample_dtype(where, dtype, byteorder, header_bytes) -> np.dtype:
    """The numpy dtype of headerless samples, byte order applied, after checking ``dtype``, ``byteorder``
    and ``header_bytes`` (errors name ``where``). Shared by raw files and raw slice stacks.

    >>> sample_dtype("ct.raw", "uint16", "big", 0).str
    '>u2'
    """
    try:
        dt = np.dtype(dtype)
    except TypeError:
        raise ValueError(f"{where}: dtype {dtype!r} is not a numpy dtype; use e.g. 'uint8', 'uint16', 'int16', "
                         "'int32', 'float32', 'float64'.") from None
    if dt.kind not in "biuf":
        raise TypeError(f"{where}: dtype {dt} is not a real number type.")
    marker = dtype[0] if isinstance(dtype, str) and dtype[:1] in ("<", ">") else dt.byteorder
    explicit = {"<": "little", ">": "big"}.get(marker)
    if byteorder is not None and byteorder not in ("little", "big"):
        raise ValueError(f"{where}: byteorder {byteorder!r} is not known; choose 'little' or 'big'.")
    if explicit and byteorder and explicit != byteorder:
        raise ValueError(f"{where}: dtype {dtype!r} says {explicit}-endian but byteorder={byteorder!r}.")
    order = byteorder or explicit
    if dt.itemsize > 1:
        if order is None:
            raise ValueError(f"{where}: {dt.name} samples take {dt.itemsize} bytes; pass byteorder='little' "
                             "(most files from PCs) or byteorder='big' - a wrong guess reads plausible garbage.")
        dt = with_byteorder(dt, order)
    if isinstance(header_bytes, bool) or not isinstance(header_bytes, (int, np.integer)) or header_bytes < 0:
        raise ValueError(f"{where}: header_bytes must be a non-negative int, got {header_bytes!r}.")
    return dt


def read_raw(path: Path, shape, dtype, byteorder, header_bytes, spacing, origin, component) -> VolumeSamples:
    """Read a headerless file of samples ``[k, j, i]`` (x fastest).

    Parameters
    ----------
    path : Path
        An existing, non-empty file.
    shape : (nz, ny, nx) ints
        Samples per axis, slowest first.
    dtype : str or numpy dtype
        Sample type; a ``"<"``/``">"`` prefix gives the byte order.
    byteorder : {"little", "big"} or None
        Needed for samples wider than one byte unless ``dtype`` carries it.
    header_bytes : int
        Bytes to skip before the samples.
    spacing, origin : (3,) tuples or None
        Checked already; None gives ``(1, 1, 1)`` and ``(0, 0, 0)``.
    component : None
        Raw files hold one value per sample; anything else raises.

    Returns
    -------
    VolumeSamples

    Examples
    --------
    Big-endian uint16 samples, x fastest, come back in native byte order:

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "ct.raw"
    ...     _ = path.write_bytes(np.arange(24, dtype=">u2").tobytes())
    ...     samples = read_raw(path, (2, 3, 4), "uint16", "big", 0, (0.5, 0.5, 2.0), None, None)
    >>> samples.values.dtype, int(samples.values[1, 2, 3]), samples.spacing
    (dtype('uint16'), 23, (0.5, 0.5, 2.0))
    """
    missing = [n for n, v in (("shape", shape), ("dtype", dtype)) if v is None]
    if missing:
        raise ValueError(f"{path}: a headerless raw file needs {' and '.join(m + '=' for m in missing)}, e.g. "
                         f"read_volume({str(path)!r}, shape=(nz, ny, nx), dtype='uint16', byteorder='little', "
                         "spacing=(dx, dy, dz), origin=(x0, y0, z0)); shape lists the slowest axis (z) first.")
    dt = sample_dtype(path, dtype, byteorder, header_bytes)
    if isinstance(shape, (int, np.integer)) or len(tuple(shape)) != 3:
        raise ValueError(f"{path}: shape must be three sample counts (nz, ny, nx), got {shape!r}.")
    shape = tuple(int(s) for s in shape)
    if min(shape) < 1:
        raise ValueError(f"{path}: shape {shape} must be positive on every axis.")
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
    return from_array(arr, spacing, origin, component, str(path))

