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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .height_samples import HeightSamples

__all__ = ["read_dem", "read_dem_records", "DemRecords", "looks_like_usgs_dem", "DEM_VOID"]

#: USGS DEM "void area" elevation: a gap.
DEM_VOID = -32767
_DEM_TOKEN = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[EeDd][-+]?\d+)?")

# Type A record: 1024 characters of fixed-width fields (1-based columns in the USGS standard):
#   1-40 file name, 41-80 free text, 145-150 DEM level, 151-156 elevation pattern, 157-162 planimetric
#   system (0 geographic, 1 UTM, 2 state plane), 163-168 zone, 169-528 15 projection parameters (D24.15),
#   529-534 plane unit (0 radians, 1 feet, 2 metres, 3 arc-seconds), 535-540 elevation unit (1 feet,
#   2 metres), 541-546 sides (4), 547-738 corners SW, NW, NE, SE (x, y as D24.15), 739-786 min/max
#   elevation, 787-810 rotation angle, 811-816 accuracy code (1: a type C record follows), 817-852
#   resolution x, y, z (E12.6), 853-864 rows, columns (number of profiles). Optional (blank in old files):
#   865-869 / 870 largest contour interval / its unit, 871-875 / 876 smallest, 877-880 source date,
#   881-884 revision date, 885 inspection flag, 886 validation flag, 887-888 suspect and void flag,
#   889-890 vertical datum (1 local mean sea level, 2 NGVD 29, 3 NAVD 88), 891-892 horizontal datum
#   (1 NAD 27, 2 WGS 72, 3 WGS 84, 4 NAD 83, 5 Old Hawaii, 6 Puerto Rico), 893-896 data edition,
#   897-900 percent void, 901-908 edge match flags, 909-915 vertical datum shift (F7.2).
_PLANE_UNITS = {0: "radians", 1: "ft", 2: "m", 3: "arc-seconds"}
_ELEV_UNITS = {1: "ft", 2: "m"}
_OPTIONAL = {"largest_contour_interval": (865, 869), "largest_contour_unit": (870, 870),
             "smallest_contour_interval": (871, 875), "smallest_contour_unit": (876, 876),
             "source_date": (877, 880), "revision_date": (881, 884), "validation_flag": (886, 886),
             "suspect_void_flag": (887, 888), "vertical_datum": (889, 890), "horizontal_datum": (891, 892),
             "data_edition": (893, 896), "percent_void": (897, 900)}
_VERTICAL_DATUMS = {1: "local mean sea level", 2: "NGVD 29", 3: "NAVD 88"}
#: Horizontal datum code -> (name, EPSG of the geographic CRS, EPSG base of UTM north zones, zones it has).
_DATUMS = {1: ("NAD 27", 4267, 26700, range(1, 23)), 2: ("WGS 72", 4322, 32200, range(1, 61)),
           3: ("WGS 84", 4326, 32600, range(1, 61)), 4: ("NAD 83", 4269, 26900, range(1, 24))}


def _dem_float(field_text: str) -> float:
    return float(field_text.strip().replace("D", "E").replace("d", "e"))


def _optional_int(text: str):
    try:
        return int(text) if text.strip() else None
    except ValueError:
        return None


def _type_a(text: str) -> dict:
    """The type A record's fields by name (module notes); optional ones None when blank or unreadable."""
    def f(a, b):  # 1-based inclusive columns
        return text[a - 1:b]

    hdr = {
        "name": f(1, 40).strip(), "description": f(41, 80).strip(),
        "level": int(f(145, 150)), "pattern": int(f(151, 156)),
        "system": int(f(157, 162)), "zone": int(f(163, 168)),
        "projection": [_dem_float(f(169 + 24 * k, 192 + 24 * k)) for k in range(15)],
        "plane_unit": int(f(529, 534)), "elev_unit": int(f(535, 540)),
        "corners": [(_dem_float(f(547 + 48 * k, 570 + 48 * k)), _dem_float(f(571 + 48 * k, 594 + 48 * k)))
                    for k in range(4)],
        "elevation_range": (_dem_float(f(739, 762)), _dem_float(f(763, 786))),
        "rotation": _dem_float(f(787, 810)),
        "accuracy_code": _optional_int(f(811, 816)) or 0,
        "res": tuple(_dem_float(f(817 + 12 * k, 828 + 12 * k)) for k in range(3)),
        "ncols": int(f(859, 864)),
    }
    hdr.update({key: _optional_int(f(a, b)) for key, (a, b) in _OPTIONAL.items()})
    shift = f(909, 915).strip()
    try:
        hdr["vertical_datum_shift"] = float(shift) if shift else None
    except ValueError:
        hdr["vertical_datum_shift"] = None
    return hdr


def looks_like_usgs_dem(path) -> bool:
    """True when the file starts with a USGS ASCII DEM type A record (content, whatever its name): ASCII, the
    planimetric system, units, sides and resolution fields where the standard puts them, with valid codes.

    >>> import tempfile
    >>> from datasets_synthetic.dem_files import write_usgs_ascii_dem
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     dem = write_usgs_ascii_dem(Path(folder) / "hill.tif", [[1, 2], [3, 4]], 30.0, (5e5, 5e6))
    ...     looks_like_usgs_dem(dem), looks_like_usgs_dem(__file__)
    (True, False)
    """
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if len(head) < 864 or any(c > 126 or (c < 32 and c not in (9, 10, 13)) for c in head):
        return False
    try:
        hdr = _type_a(head.decode("ascii"))
    except ValueError:
        return False
    return (hdr["system"] in (0, 1, 2, 3) and hdr["plane_unit"] in _PLANE_UNITS and hdr["elev_unit"] in _ELEV_UNITS
            and int(head[540:546]) == 4 and min(hdr["res"]) > 0 and hdr["ncols"] > 0)


def _read_dem_header(path: Path) -> dict:
    with open(path, "rb") as fh:
        head = fh.read(1024)
    if len(head) < 864:
        raise ValueError(f"{path}: too short for a USGS ASCII DEM ({len(head)} bytes; the type A "
                         "record alone is 1024).")
    try:
        hdr = _type_a(head.decode("ascii", errors="replace"))
    except ValueError as exc:
        raise ValueError(f"{path}: not a readable USGS ASCII DEM type A record ({exc}).") from None
    if hdr["rotation"] != 0:
        raise ValueError(f"{path}: the DEM is rotated by {hdr['rotation']} rad; only north-up DEMs are supported.")
    if min(hdr["res"]) <= 0:
        raise ValueError(f"{path}: spatial resolution {hdr['res']} must be > 0.")
    if hdr["ncols"] <= 0:
        raise ValueError(f"{path}: the type A record announces {hdr['ncols']} profiles; a DEM needs at least one.")
    return hdr


def _crs(hdr: dict):
    """``(crs, scale)``: an EPSG code when the header names the datum of a UTM or geographic DEM (else a
    description), and the divisor that takes the file's x, y to the CRS's units (3600: arc-seconds to degrees,
    one correctly rounded division).

    A blank datum field (files made before the field was added to the standard) is read as NAD 27, as GDAL's
    USGSDEM driver does, and :func:`read_dem_records` warns that it was assumed."""
    system, zone, code = hdr["system"], hdr["zone"], hdr["horizontal_datum"]
    datum = _DATUMS.get(1 if code in (None, 0) else code)
    plane = _PLANE_UNITS.get(hdr["plane_unit"], f"unit code {hdr['plane_unit']}")
    if datum is not None:
        name, geographic, utm, zones = datum
        if system == 1 and hdr["plane_unit"] == 2 and abs(zone) in zones:
            return f"EPSG:{utm + abs(zone) + (100 if zone < 0 and utm in (32200, 32600) else 0)}", 1.0
        if system == 0 and hdr["plane_unit"] == 3:
            return f"EPSG:{geographic}", 3600.0
    where = {0: "geographic", 1: f"UTM zone {zone}", 2: f"state plane zone {zone}"}.get(
        system, f"USGS planimetric system {system} zone {zone}")
    datum_name = f", {datum[0]}" if datum is not None else ""
    return f"{where}{datum_name} (x, y in {plane})", 1.0


def _dem_profiles(path: Path, dx: float, dy: float, nprofiles: int):
    """The ``nprofiles`` type B profiles (the header's count) placed by their own first-sample (x, y), then the
    optional type C record.

    Returns ``(k, (west, south), accuracy)`` with ``k[row, col]`` south row first; nodes no profile covers hold
    ``DEM_VOID`` (missing, never filled with a real height); ``accuracy`` the type C record's fields (a dict) or
    None when the file has none.
    """
    with open(path, "rb") as fh:
        fh.seek(1024)
        body = fh.read()
    blocks = _as_blocks(body)
    if blocks is not None:
        profiles, rest = _fixed_width_profiles(path, blocks, nprofiles)
    else:
        profiles, rest = _token_profiles(path, body.decode("ascii", errors="replace"), nprofiles)
    k, origin = _place(path, profiles, dx, dy)
    return k, origin, _type_c(path, rest)


def _as_blocks(body: bytes):
    """The records as one byte array of 1024-character blocks, or None when the file is free-format text.

    The standard's layout is 1024-character blocks without line breaks; some distributions end every block
    with a line break (``\n`` or ``\r\n``), which is removed here. Any other line structure is free format.
    """
    if b"\n" not in body and b"\r" not in body:
        return np.frombuffer(body, dtype=np.uint8)
    body = body[2:] if body.startswith(b"\r\n") else body[1:] if body[:1] in (b"\n", b"\r") else body  # A's break
    lines = body.replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    if lines and all(len(line) == 1024 for line in lines):
        return np.frombuffer(b"".join(lines), dtype=np.uint8)
    return None


#: Elevations in the first block of a profile (after its 144-character header) and in each further block.
_FIRST, _MORE = 146, 170


def _cells(count: int) -> np.ndarray:
    """Byte offsets, from the start of a profile's first block, of its ``count`` I6 elevation fields."""
    q = np.arange(count, dtype=np.int64)
    later = np.maximum(q - _FIRST, 0)
    return np.where(q < _FIRST, 144 + 6 * q, 1024 * (1 + later // _MORE) + 6 * (later % _MORE))


def _parse_i6(buf: np.ndarray, starts: np.ndarray):
    """Integers of the right-justified I6 fields of ``buf`` at ``starts``: ``(values, bad)``, ``bad`` the index
    of the first field that is not ``spaces, optional sign, digits`` (None when all are). Vectorized, one column
    of the six at a time (no ``(N, 6)`` temporaries): the fields are cut by column, so six-digit elevations
    that touch ("100000100700") read right."""
    values = np.zeros(len(starts), dtype=np.int64)
    started = np.zeros(len(starts), dtype=bool)
    bad = np.zeros(len(starts), dtype=bool)
    neg = np.zeros(len(starts), dtype=bool)
    for c in range(6):
        ch = buf[starts + c]
        d = ch - np.uint8(48)  # wraps for characters below '0'
        digit = d <= 9
        space = ch == 32
        sign = (ch == 45) | (ch == 43)
        bad |= ~(digit | space | sign) | ((space | sign) & started)  # a space or sign after the number began
        started |= ~space
        neg |= ch == 45
        values = np.where(digit, values * 10 + d, values)
    bad |= ~digit  # the last character is a digit
    return np.where(neg, -values, values), (int(np.argmax(bad)) if bad.any() else None)


def _fixed_width_profiles(path: Path, buf: np.ndarray, nprofiles: int):
    """Type B records in 1024-character blocks (module notes): the profile headers in turn (each says how
    many blocks its profile takes), then every elevation of the file parsed at once. Returns the profiles
    ``[(x0, y0, k)]`` and the text after the last one (the type C record, if any)."""
    heads, starts, templates, pos = [], [], {}, 0
    for j in range(nprofiles):
        head = bytes(buf[pos:pos + 144]).decode("ascii", errors="replace")
        if not head.strip():
            raise ValueError(f"{path}: header says {nprofiles} profiles but the file holds {j}; the file is "
                             "truncated or corrupt.")
        try:
            if len(head) < 144:
                raise ValueError(f"profile {j + 1} announces a 144-character header but the file ends after "
                                 f"{len(head)}")
            col_id, m, n = (int(head[6 * q:6 * q + 6]) for q in (1, 2, 3))
            x0, y0 = _dem_float(head[24:48]), _dem_float(head[48:72])
            count = m * n
            if count <= 0:
                raise ValueError(f"profile {j + 1} (column {col_id}) announces {m} x {n} elevations")
            cells = templates.setdefault(count, _cells(count))
            if pos + cells[-1] + 6 > buf.size:
                have = int(np.searchsorted(pos + cells + 6, buf.size, side="right"))
                raise ValueError(f"profile {j + 1} (column {col_id}) announces {count} elevations but the file "
                                 f"ends after {have}")
        except ValueError as exc:
            raise ValueError(f"{path}: truncated or malformed type B (profile) record at byte {1024 + pos} "
                             f"({exc}). The file is incomplete or corrupt; download it again.") from None
        heads.append((x0, y0, count))
        starts.append(pos + cells)
        pos += 1024 * (1 + max(0, -(-(count - _FIRST) // _MORE)))
    everything = np.concatenate(starts)
    values, bad = _parse_i6(buf, everything)
    if bad is not None:
        at = int(everything[bad])
        j = int(np.searchsorted(np.cumsum([h[2] for h in heads]), bad, side="right"))
        field = bytes(buf[at:at + 6]).decode("ascii", errors="replace")
        raise ValueError(f"{path}: malformed type B (profile) record: elevation field {field!r} of profile "
                         f"{j + 1} at byte {1024 + at} is not an integer. The file is incomplete or corrupt; "
                         "download it again.")
    cuts = np.cumsum([h[2] for h in heads])[:-1]
    profiles = [(x0, y0, v) for (x0, y0, _), v in zip(heads, np.split(values, cuts))]
    return profiles, bytes(buf[pos:]).decode("ascii", errors="replace")


def _token_profiles(path: Path, body: str, nprofiles: int):
    """Free-format records (line breaks anywhere): tokens, not whitespace-split fields ("  1234-12345" touch);
    the elevations of each profile converted at once. Returns the profiles and the text of the tokens after the
    last one."""
    tokens = _DEM_TOKEN.findall(body)
    profiles, pos = [], 0
    try:
        for j in range(nprofiles):
            if pos >= len(tokens):
                raise EOFError(j)
            if pos + 9 > len(tokens):
                raise ValueError(f"profile {j + 1} announces a header but the file ends")
            col_id, m, n = (int(t) for t in tokens[pos + 1:pos + 4])
            x0, y0 = _dem_float(tokens[pos + 4]), _dem_float(tokens[pos + 5])
            pos += 9  # 4 integers, then x, y of the first sample, datum elevation, min, max
            data = tokens[pos:pos + m * n]
            if len(data) != m * n:
                raise ValueError(f"profile {j + 1} (column {col_id}) announces {m * n} elevations but the "
                                 f"file ends after {len(data)}")
            profiles.append((x0, y0, np.array(data).astype(np.int64)))
            pos += m * n
    except EOFError:
        raise ValueError(f"{path}: header says {nprofiles} profiles but the file holds {len(profiles)}; the "
                         "file is truncated or corrupt.") from None
    except (ValueError, IndexError) as exc:
        raise ValueError(f"{path}: truncated or malformed type B (profile) record near token {pos} ({exc}). "
                         "The file is incomplete or corrupt; download it again.") from None
    return profiles, " ".join(tokens[pos:])


#: Type C record (accuracy), USGS DEM standard: ten I6 fields.
_TYPE_C = ("datum_rmse_available", "datum_rmse_x", "datum_rmse_y", "datum_rmse_z", "datum_sample_size",
           "dem_rmse_available", "dem_rmse_x", "dem_rmse_y", "dem_rmse_z", "dem_sample_size")


def _type_c(path: Path, rest: str):
    """The type C record after the profiles (ten I6 fields in columns 1-60, or ten free-format integers), or
    None; anything else there is an error (a profile more than the header announces, or damage)."""
    if not rest.strip():
        return None
    fields = None
    if len(rest) >= 60 and not rest[60:].strip():
        try:
            fields = [int(rest[6 * q:6 * q + 6]) for q in range(10)]
        except ValueError:
            fields = None
    tokens = rest.split()
    if fields is None and len(tokens) == 10 and all(t.lstrip("+-").isdigit() for t in tokens):
        fields = [int(t) for t in tokens]
    if fields is None:
        raise ValueError(f"{path}: after the profiles the header announces, the file holds "
                         f"{len(rest.strip()):,} more characters that are not a type C (accuracy) record: the "
                         "header's profile count is wrong or the file is damaged; download it again.")
    return dict(zip(_TYPE_C, fields))


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
    return k, (west, south)


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
    ('EPSG:32633', 'm')
    """
    dem = read_dem_records(path)
    hdr = dem.header
    dz = hdr["res"][2]
    k = dem.elevations
    values = k * dz
    missing = k == DEM_VOID
    if nodata is not None:
        missing |= values == nodata
    return HeightSamples(values=values, missing=missing, spacing=dem.spacing, origin=dem.origin,
                         source=str(path), crs=dem.crs, units=_ELEV_UNITS.get(hdr["elev_unit"]),
                         order_note="row counted from the south, column = profile")


@dataclass(frozen=True, eq=False)
class DemRecords:
    """A USGS ASCII DEM's three records as read (:func:`read_dem_records`).

    ``header``: the type A record's fields by name (optional ones None when the file leaves them blank);
    ``elevations``: the type B profiles' stored integers on one lattice, ``[row, col]`` south row first, column =
    profile, :data:`DEM_VOID` where no profile reaches; ``origin``, ``spacing``: of ``elevations[0, 0]`` and the
    lattice in ``crs``'s units (degrees for a geographic DEM, whose file stores arc-seconds); ``crs``: an EPSG code
    when the header names the datum of a UTM or geographic DEM, else a description; ``accuracy``: the type C
    record's fields, or None when the file has none.

    >>> import tempfile
    >>> from datasets_synthetic.dem_files import write_usgs_ascii_dem
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = write_usgs_ascii_dem(Path(folder) / "hill.dem", [[1, 2], [3, 4]], 30.0, (5e5, 5e6),
    ...                                 accuracy=(0, 0, 0, 0, 0, 1, 0, 0, 2, 30))
    ...     dem = read_dem_records(path)
    >>> dem.crs, dem.accuracy["dem_rmse_z"], dem.header["vertical_datum"], dem.elevations.tolist()
    ('EPSG:32633', 2, 3, [[1000, 2000], [3000, 4000]])
    """

    header: dict
    elevations: np.ndarray
    origin: tuple
    spacing: tuple
    crs: str
    accuracy: dict | None


def read_dem_records(path) -> DemRecords:
    """Read the records A, B and C of a USGS ASCII DEM (module notes); see :class:`DemRecords`.

    >>> import tempfile
    >>> from datasets_synthetic.dem_files import write_usgs_ascii_dem
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     dem = read_dem_records(write_usgs_ascii_dem(Path(folder) / "a.dem", [[5, 6]] * 2, 10.0, (0.0, 0.0)))
    >>> dem.header["ncols"], dem.spacing, dem.accuracy is None
    (2, (10.0, 10.0), True)
    """
    path = Path(path)
    hdr = _read_dem_header(path)
    dx, dy, _ = hdr["res"]
    # Every profile is placed by its own starting (x, y) (USGS 7.5-minute DEMs clip profiles at the
    # quadrangle, so each starts at its own northing); the origin is the south-west lattice node,
    # not the quadrangle corner (which is off the lattice).
    k, (west, south), accuracy = _dem_profiles(path, dx, dy, hdr["ncols"])
    if hdr["accuracy_code"] == 1 and accuracy is None:
        import warnings

        warnings.warn(f"{path}: the type A record announces a type C (accuracy) record, but the file ends after "
                      "the profiles.", stacklevel=2)
    crs, scale = _crs(hdr)
    if hdr["horizontal_datum"] in (None, 0) and crs.startswith("EPSG:"):
        import warnings

        warnings.warn(f"{path}: the type A record names no horizontal datum (columns 891-892 blank); NAD 27 assumed "
                      f"({crs}), as GDAL does for USGS DEMs made before the field existed. If the file's metadata "
                      "says otherwise, pass the grid on with that CRS.", stacklevel=2)
    return DemRecords(header=hdr, elevations=k, origin=(west / scale, south / scale),
                      spacing=(dx / scale, dy / scale), crs=crs, accuracy=accuracy)
