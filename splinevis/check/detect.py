"""Which family a file belongs to, from its content first and its name second.

Users name files as they like: a DEM saved as ``.tif``, IGES as ``.igs`` or ``.iges``, a headerless SRTM tile
whose only description is its name and size. :func:`detect_family` reads the first bytes (decompressing a gzip
stream) and recognises the formats' own signatures; the extension decides only where the content carries none
(``.hgt``, ``.raw``). :func:`companion_files` finds the data files that a header in the same folder names
(``frogtissue.mhd`` -> ``frogtissue.zraw``), so they are read through their header and not judged alone.

Why our own code: no library sniffs across the four families (GDAL knows rasters, VTK volumes, OpenCASCADE CAD);
the signatures are the formats' documented magic numbers and header keywords.
"""

from __future__ import annotations

import gzip
import re
from pathlib import Path

__all__ = ["detect_family", "companion_files", "FAMILIES", "collect_files"]

FAMILIES = ("terrain", "volume", "nurbs", "mesh")

_NOTES = {".md", ".txt", ".rst"}
_MESH_EXT = {".obj", ".off", ".ply", ".stl", ".vtp"}
_NIFTI_MAGICS = (b"n+1\0", b"ni1\0", b"n+2\0")


def _head(path: Path, n: int = 4096) -> bytes:
    with open(path, "rb") as f:
        head = f.read(n)
    if head[:2] == b"\x1f\x8b":  # gzip: look inside
        try:
            with gzip.open(path, "rb") as f:
                return f.read(n)
        except (OSError, EOFError):
            return head
    return head


def _is_iges(head: bytes) -> bool:
    """IGES: 80-column records whose column 73 is the section letter (S, G, D, P, T), starting with S."""
    lines = head.split(b"\n")[:3]
    lines = [ln.rstrip(b"\r") for ln in lines if ln.strip()]
    return bool(lines) and all(len(ln) >= 73 and ln[72:73] in b"SGDPT" for ln in lines) and lines[0][72:73] == b"S"


def _vtk_kind(head: bytes) -> str | None:
    text = head.decode("latin-1")
    m = re.search(r'<VTKFile[^>]*type="(\w+)"', text)
    if m:
        return {"PolyData": "mesh", "UnstructuredGrid": None}.get(m.group(1), "volume")
    if text.startswith("# vtk DataFile"):
        m = re.search(r"DATASET\s+(\w+)", text)
        if m:
            return "mesh" if m.group(1).upper() == "POLYDATA" else "volume"
    return None


def detect_family(path) -> tuple[str | None, str]:
    """``(family, format)`` of a file from its content; ``(None, why)`` when no family reads it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "looks_like.txt"
    >>> _ = p.write_text("ncols 3\\nnrows 2\\nxllcorner 0\\nyllcorner 0\\ncellsize 1\\n1 2 3\\n4 5 6\\n")
    >>> detect_family(p)
    ('terrain', 'ESRI ASCII grid')
    >>> _ = p.write_text("v 0 0 0\\nv 1 0 0\\nv 0 1 0\\nf 1 2 3\\n")
    >>> detect_family(p)
    ('mesh', 'OBJ')
    """
    path = Path(path)
    head = _head(path)
    ext = "".join(path.suffixes[-2:]).lower() if path.suffix.lower() == ".gz" else path.suffix.lower()
    text = head.decode("latin-1")
    stripped = text.lstrip()
    if head[:4] in (b"II*\0", b"MM\0*", b"II+\0", b"MM\0+"):
        return "terrain", "TIFF raster"
    if head.startswith(b"3D Geometry File Format"):
        return "nurbs", "Rhino 3DM"
    if stripped.startswith("ISO-10303-21"):
        return "nurbs", "STEP"
    if _is_iges(head):
        return "nurbs", "IGES"
    if re.match(r"\s*(ncols|nrows)\s", text, re.I):
        return "terrain", "ESRI ASCII grid"
    if head.startswith(b"NRRD000"):
        return "volume", "NRRD"
    if re.search(r"^\s*(ObjectType|NDims)\s*=", text, re.M) and re.search(r"^\s*ElementDataFile\s*=", text, re.M):
        return "volume", "MetaImage"
    if head[344:348] in _NIFTI_MAGICS:
        return "volume", "NIfTI"
    kind = _vtk_kind(head)
    if kind is not None:
        return kind, "VTK"
    if stripped.startswith("OFF") or ext == ".off":
        return "mesh", "OFF"
    if head.startswith(b"ply"):
        return "mesh", "PLY"
    if ext == ".stl" or stripped.startswith("solid "):
        return "mesh", "STL"
    if re.search(r"^\s*v\s+[-+.\d]", text, re.M) and (re.search(r"^\s*f\s+\d", text, re.M) or ext == ".obj"):
        return "mesh", "OBJ"
    if ext == ".hgt":
        return "terrain", "SRTM .hgt"
    if ext == ".dem" or re.match(r".{144}\s*\d+\s+\d+\s+\d+", text[:1024].replace("\n", " "), re.S) and ext != ".raw":
        return "terrain", "USGS DEM"
    if ext in (".g2",):
        return "nurbs", "GoTools .g2"
    if ext in (".cube",):
        return "volume", "Gaussian cube"
    if ext in (".vti", ".vtr", ".vts", ".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd", ".slc"):
        return "volume", ext
    if ext in (".3dm", ".igs", ".iges", ".stp", ".step", ".json", ".bpt"):
        return "nurbs", ext
    if ext in (".tif", ".tiff", ".asc", ".dt0", ".dt1", ".dt2", ".bil"):
        return "terrain", ext
    if ext in _MESH_EXT:
        return "mesh", ext
    return None, f"no known signature (first bytes {head[:16]!r}, extension {ext or 'none'!r})"


def companion_files(paths) -> dict:
    """``{data file: header file}`` for data files a header among ``paths`` names (MetaImage
    ``ElementDataFile``, NRRD ``data file``/``datafile``, ENVI/ESRI ``.hdr`` beside its data).

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "a.mhd").write_text("NDims = 3\\nElementDataFile = a.zraw\\n"); _ = (d / "a.zraw").write_bytes(b"x")
    >>> {k.name: v.name for k, v in companion_files([d / "a.mhd", d / "a.zraw"]).items()}
    {'a.zraw': 'a.mhd'}
    """
    paths = [Path(p) for p in paths]
    by_path = {p.resolve(): p for p in paths}
    out = {}
    for p in paths:
        try:
            text = _head(p, 8192).decode("latin-1")
        except OSError:
            continue
        names = re.findall(r"^\s*ElementDataFile\s*=\s*(.+?)\s*$", text, re.M)
        names += re.findall(r"^\s*data ?file\s*:\s*(.+?)\s*$", text, re.M | re.I)
        for name in names:
            target = (p.parent / name).resolve()
            if target in by_path and target != p.resolve():
                out[by_path[target]] = p
    return out


def collect_files(paths) -> list:
    """Files under ``paths`` (folders walked, sorted; hidden files and ``.md``/``.txt`` notes left out).

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()); _ = (d / "b.obj").write_text("v 0 0 0"); _ = (d / "README.md").write_text("x")
    >>> [p.name for p in collect_files([d])]
    ['b.obj']
    """
    out = []
    for p in paths:
        p = Path(p)
        if not p.exists():
            raise FileNotFoundError(f"{p}: no such file or folder.")
        if p.is_dir():
            out += sorted(q for q in p.rglob("*") if q.is_file() and q.suffix.lower() not in _NOTES
                          and not any(part.startswith(".") for part in q.relative_to(p).parts))
        else:
            out.append(p)
    return out
