"""USGS ASCII DEM files (``.dem``): the type A header parsed here, elevations from ``vtkDEMReader``.

Why partly our own parser:

* The type A header is parsed here in float64 (corners D24.15: 16 significant digits; resolution
  E12.6: 7 significant digits); ``vtkDEMReader`` works in float32.
* ``vtkDEMReader`` returns ``integer * z_resolution`` in float32 and applies its own feet/arc-second
  factors. The integers are recovered and multiplied by the resolution in float64, so heights are
  exact multiples of the file's z resolution, in the file's units (``units`` and ``crs`` of the
  result say what the file uses). The void value -32767 is a gap.
* VTK 9.7.1's reader divides by zero (killing the process) on DEMs with fewer than 100 profiles, so
  those are parsed in Python.

Only north-up DEMs whose profiles all start on the southern row are placed correctly (VTK ignores each
profile's start coordinate).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from .height_samples import HeightSamples

__all__ = ["read_dem", "DEM_VOID"]

#: USGS DEM "void area" elevation: a gap.
DEM_VOID = -32767
_DEM_TOKEN = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[EeDd][-+]?\d+)?")

# Type A record: 1024 characters of fixed-width fields (1-based columns in the USGS standard):
#   145-150 DEM level, 151-156 elevation pattern, 157-162 planimetric system (0 geographic, 1 UTM,
#   2 state plane), 163-168 zone, 169-528 15 projection parameters (D24.15), 529-534 plane unit
#   (0 radians, 1 feet, 2 metres, 3 arc-seconds), 535-540 elevation unit (1 feet, 2 metres),
#   541-546 sides (4), 547-738 corners SW, NW, NE, SE (x, y as D24.15), 739-786 min/max elevation,
#   787-810 rotation angle, 811-816 accuracy code, 817-852 resolution x, y, z (E12.6),
#   853-864 rows, columns (number of profiles).
_PLANE_UNITS = {0: "radians", 1: "ft", 2: "m", 3: "arc-seconds"}
_ELEV_UNITS = {1: "ft", 2: "m"}
# vtkDEMReader's own unit factors (to undo them: we keep the file's units).
_VTK_UNIT_FACTOR = {1: 0.305, 3: 23.111}


def _dem_float(field_text: str) -> float:
    return float(field_text.strip().replace("D", "E").replace("d", "e"))


def _read_dem_header(path: Path) -> dict:
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if len(head) < 864:
        raise ValueError(f"{path}: too short for a USGS ASCII DEM ({len(head)} bytes; the type A "
                         "record alone is 1024).")
    text = head.decode("ascii", errors="replace")

    def f(a, b):  # 1-based inclusive columns
        return text[a - 1:b]

    try:
        hdr = {
            "system": int(f(157, 162)), "zone": int(f(163, 168)),
            "plane_unit": int(f(529, 534)), "elev_unit": int(f(535, 540)),
            "corners": [(_dem_float(f(547 + 48 * k, 570 + 48 * k)), _dem_float(f(571 + 48 * k, 594 + 48 * k)))
                        for k in range(4)],
            "rotation": _dem_float(f(787, 810)),
            "res": tuple(_dem_float(f(817 + 12 * k, 828 + 12 * k)) for k in range(3)),
            "ncols": int(f(859, 864)),
        }
    except ValueError as exc:
        raise ValueError(f"{path}: not a readable USGS ASCII DEM type A record ({exc}).") from None
    if hdr["rotation"] != 0:
        raise ValueError(f"{path}: the DEM is rotated by {hdr['rotation']} rad; only north-up DEMs are supported.")
    if min(hdr["res"]) <= 0:
        raise ValueError(f"{path}: spatial resolution {hdr['res']} must be > 0.")
    return hdr


def _dem_profiles_python(path: Path, nrows: int, ncols: int):
    """Integer elevations (nrows, ncols), south row first, parsed in Python (small DEMs)."""
    with open(path, "rb") as fh:
        fh.seek(1024)
        # Tokens, not whitespace-split fields: fixed-width I6 fields may touch ("  1234-12345").
        tokens = _DEM_TOKEN.findall(fh.read().decode("ascii", errors="replace"))
    k = np.full((nrows, ncols), DEM_VOID, dtype=np.int64)
    pos = 0
    try:
        for _ in range(ncols):
            row_id, col_id, m, n = (int(t) for t in tokens[pos:pos + 4])
            pos += 9  # 4 integers, then x, y of the first sample, datum elevation, min, max
            k[row_id - 1:row_id - 1 + m * n, col_id - 1] = [int(t) for t in tokens[pos:pos + m * n]]
            pos += m * n
    except (ValueError, IndexError) as exc:
        raise ValueError(f"{path}: malformed type B (profile) record near token {pos} ({exc}).") from None
    return k


def read_dem(path: Path, nodata) -> HeightSamples:
    """Read a USGS ASCII DEM (north-up, profiles starting on the southern row).

    Parameters
    ----------
    path : Path
        An existing ``.dem`` file.
    nodata : float or None
        Height (in the file's units, after the z resolution) marking gaps besides the void value.

    Returns
    -------
    HeightSamples
        Row 0 is the southern row, column = profile; ``crs`` names the planimetric system and unit,
        ``units`` the elevation unit.

    Examples
    --------
    >>> import tempfile
    >>> from datasets_synthetic.dem_files import write_usgs_ascii_dem
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_usgs_ascii_dem(Path(folder) / "hill.dem", [[1, 2, 3], [4, 5, 6]], 30.0, (5e5, 5e6))
    ...     samples = read_dem(path, None)
    >>> samples.values, samples.spacing, samples.origin
    (array([[1., 2., 3.],
           [4., 5., 6.]]), (30.0, 30.0), (500000.0, 5000000.0))
    >>> samples.crs, samples.units
    ('UTM zone 33 (x, y in m)', 'm')
    """
    hdr = _read_dem_header(path)
    sw, nw, ne, se = hdr["corners"]
    dx, dy, dz = hdr["res"]
    west, east = min(sw[0], nw[0]), max(ne[0], se[0])
    south, north = min(sw[1], se[1]), max(nw[1], ne[1])
    ncols = int(round((east - west) / dx)) + 1
    nrows = int(round((north - south) / dy)) + 1
    if ncols != hdr["ncols"]:
        raise ValueError(f"{path}: header says {hdr['ncols']} profiles but the corners and x resolution "
                         f"give {ncols}.")
    if ncols >= 100:
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOImage import vtkDEMReader

        reader = vtkDEMReader()
        reader.SetFileName(str(path))
        reader.Update()
        img = reader.GetOutput()
        if tuple(img.GetDimensions()) != (ncols, nrows, 1):
            raise ValueError(f"{path}: vtkDEMReader returned dims {img.GetDimensions()}, the header gives "
                             f"{(ncols, nrows, 1)}.")
        v = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(nrows, ncols)
        # VTK stores int * float32(dz * its unit factor) as float32; recover the integers (exact for
        # |k| < 2**22) so that heights are k * dz in float64 in the file's unit.
        u32 = np.float32(np.float32(dz) * np.float32(_VTK_UNIT_FACTOR.get(hdr["elev_unit"], 1.0)))
        k = np.rint(v.astype(np.float64) / np.float64(u32)).astype(np.int64)
    else:
        # vtkDEMReader (VTK 9.7.1) divides by zero - killing the process - on DEMs with fewer than 100
        # profiles (its progress interval is ncols / 100), so small DEMs are parsed here.
        k = _dem_profiles_python(path, nrows, ncols)
    values = k * dz
    missing = k == DEM_VOID
    if nodata is not None:
        missing |= values == nodata
    system = {0: "geographic", 1: f"UTM zone {hdr['zone']}", 2: f"state plane zone {hdr['zone']}"}.get(
        hdr["system"], f"USGS planimetric system {hdr['system']} zone {hdr['zone']}")
    plane = _PLANE_UNITS.get(hdr["plane_unit"], f"unit code {hdr['plane_unit']}")
    return HeightSamples(values=values, missing=missing, spacing=(dx, dy), origin=(west, south),
                         source=str(path), crs=f"{system} (x, y in {plane})",
                         units=_ELEV_UNITS.get(hdr["elev_unit"]),
                         order_note="row counted from the south, column = profile")

