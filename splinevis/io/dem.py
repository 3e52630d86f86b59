"""USGS ASCII DEM files (``.dem``): type A header and type B profiles parsed here.

Why our own parser and not ``vtkDEMReader`` nor GDAL's USGSDEM driver (through rasterio, which reads
every other raster, :mod:`.raster`):

* The type A header is parsed in float64 (corners D24.15: 16 significant digits; resolution E12.6:
  7 significant digits); ``vtkDEMReader`` works in float32 and applies its own unit factors.
* Heights are the stored integers times the z resolution in float64, in the file's units (``units``
  and ``crs`` of the result say what the file uses). The void value -32767 is a gap.
* ``vtkDEMReader`` ignores each profile's starting (x, y): profiles clipped by the quadrangle (USGS
  7.5-minute DEMs) land rows off and uncovered nodes get the file minimum; it also accepts truncated
  files. So the profiles are parsed here: each placed by its own start, uncovered nodes missing (the
  gap logic of :func:`read_heights` reports or fills them), truncated files a ValueError.
* GDAL 3.10's USGSDEM driver (measured on files of
  :func:`datasets_synthetic.dem_files.write_usgs_ascii_dem` with known sample positions) places
  clipped profiles right, marks uncovered nodes nodata and fails the read of a truncated file, but:

  - it snaps the raster to multiples of the spacing: with 30 m samples starting at
    (500010, 5100020) every sample is read 10 m north of its true position (the northing is not a
    multiple of 30), and the raster gains a row of nodata;
  - it cannot read elevations whose I6 fields touch (six-digit integers such as 100000 = 1000 m at
    z resolution 0.01, valid in the format): the read fails ("IReadBlock failed");
  - it returns float32, so heights are not exactly the stored integers times the z resolution.

  ``tests/test_io_heights.py`` checks that our parser reads those files at their true positions.
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


def _dem_profiles(path: Path, dx: float, dy: float):
    """Every type B profile placed by its own first-sample (x, y): integer elevations, origin, count.

    Returns ``(k, (west, south), nprofiles)`` with ``k[row, col]`` south row first; nodes no profile
    covers hold ``DEM_VOID`` (missing, never filled with a real height).
    """
    with open(path, "rb") as fh:
        fh.seek(1024)
        body = fh.read().decode("ascii", errors="replace")
    if "\n" not in body and "\r" not in body:
        return _place(path, _fixed_width_profiles(path, body), dx, dy)
    # Files with line breaks: tokens, not whitespace-split fields ("  1234-12345" touch).
    tokens = _DEM_TOKEN.findall(body)
    profiles, pos = [], 0
    try:
        while pos < len(tokens):
            row_id, col_id, m, n = (int(t) for t in tokens[pos:pos + 4])
            x0, y0 = _dem_float(tokens[pos + 4]), _dem_float(tokens[pos + 5])
            pos += 9  # 4 integers, then x, y of the first sample, datum elevation, min, max
            data = [int(t) for t in tokens[pos:pos + m * n]]
            if len(data) != m * n:
                raise ValueError(f"profile {len(profiles) + 1} (column {col_id}) announces {m * n} "
                                 f"elevations but the file ends after {len(data)}")
            profiles.append((x0, y0, np.asarray(data, dtype=np.int64)))
            pos += m * n
    except (ValueError, IndexError) as exc:
        raise ValueError(f"{path}: truncated or malformed type B (profile) record near token {pos} ({exc}). "
                         "The file is incomplete or corrupt; download it again.") from None
    return _place(path, profiles, dx, dy)


def _fixed_width_profiles(path: Path, body: str) -> list:
    """Type B records in 1024-character blocks: 144-character profile header, then I6 elevations
    (146 in the first block, 170 in each further one). Six-digit elevations may touch, so fields are
    cut by column, not by whitespace."""
    profiles, pos = [], 0
    while pos < len(body) and body[pos:].strip():
        try:
            head = body[pos:pos + 144]
            row_id, col_id, m, n = (int(head[6 * q:6 * q + 6]) for q in range(4))
            x0, y0 = _dem_float(head[24:48]), _dem_float(head[48:72])
            count, cells, off, room = m * n, [], pos + 144, 146
            while len(cells) < count:
                take = min(room, count - len(cells))
                chunk = body[off:off + 6 * take]
                if len(chunk) < 6 * take:
                    raise ValueError(f"profile {len(profiles) + 1} (column {col_id}) announces {count} "
                                     f"elevations but the file ends after {len(cells) + len(chunk) // 6}")
                cells.extend(int(chunk[6 * q:6 * q + 6]) for q in range(take))
                off = (off - (off - pos) % 1024) + 1024 if len(cells) < count else off
                room = 170
        except ValueError as exc:
            raise ValueError(f"{path}: truncated or malformed type B (profile) record at byte {1024 + pos} "
                             f"({exc}). The file is incomplete or corrupt; download it again.") from None
        profiles.append((x0, y0, np.asarray(cells, dtype=np.int64)))
        nblocks = 1 + max(0, -(-(count - 146) // 170))
        pos += 1024 * nblocks
    return profiles


def _place(path: Path, profiles: list, dx: float, dy: float):
    if not profiles:
        raise ValueError(f"{path}: no type B (profile) records after the header; the file is truncated.")
    west = min(p[0] for p in profiles)
    south = min(p[1] for p in profiles)
    cols = [(p[0] - west) / dx for p in profiles]
    rows = [(p[1] - south) / dy for p in profiles]
    for what, idx in (("x", cols), ("y", rows)):
        bad = [i for i, v in enumerate(idx) if abs(v - round(v)) > 1e-3]
        if bad:
            raise ValueError(f"{path}: profile {bad[0] + 1} starts at {what} off the sample lattice "
                             f"(offset {idx[bad[0]]:.4g} steps); the DEM cannot be placed on one grid.")
    cols, rows = [int(round(v)) for v in cols], [int(round(v)) for v in rows]
    ncols = max(cols) + 1
    nrows = max(r + p[2].size for r, p in zip(rows, profiles))
    k = np.full((nrows, ncols), DEM_VOID, dtype=np.int64)
    for c, r, p in zip(cols, rows, profiles):
        k[r:r + p[2].size, c] = p[2]
    return k, (west, south), len(profiles)


def read_dem(path: Path, nodata) -> HeightSamples:
    """Read a USGS ASCII DEM (north-up; each profile placed by its own starting x, y).

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
    dx, dy, dz = hdr["res"]
    # Every profile is placed by its own starting (x, y) (USGS 7.5-minute DEMs clip profiles at the
    # quadrangle, so each starts at its own northing); the origin is the south-west lattice node,
    # not the quadrangle corner (which is off the lattice).
    k, (west, south), nprof = _dem_profiles(path, dx, dy)
    if nprof != hdr["ncols"]:
        raise ValueError(f"{path}: header says {hdr['ncols']} profiles but the file holds {nprof}; "
                         "the file is truncated or corrupt.")
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

