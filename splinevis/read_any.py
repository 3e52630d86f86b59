"""``splinevis.read(path)``: any file splinevis draws, read by its family's reader, the family found from the
content (:func:`splinevis.check.detect.detect_family`: a DEM named ``.tif``, IGES named ``.igs`` or ``.iges``,
gzip-compressed volumes). One entry point over the four readers, which stay available by name."""

from __future__ import annotations

from pathlib import Path

__all__ = ["read", "family_of"]


def family_of(path, family: str = "auto") -> str:
    """The family of the file ``path`` (``family`` itself unless ``"auto"``): FileNotFoundError for a missing
    file, ValueError naming the reason for one splinevis does not read.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "tiny.asc").write_text("ncols 3\\nnrows 2\\nxllcorner 0\\nyllcorner 0\\ncellsize 10\\n1 2 3\\n4 5 6\\n")
    >>> family_of(d / "tiny.asc")
    'terrain'
    """
    from .check.detect import FAMILIES, detect_family

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file.")
    if family != "auto":
        return family
    found, why = detect_family(path)
    if found is None:
        raise ValueError(f"{path}: not a file splinevis reads ({why}); pass family= (--family) if it is one of "
                         f"{', '.join(FAMILIES)}.")
    return found


def read(path, *, family: str = "auto", **options):
    """Read ``path`` with its family's reader; ``options`` go to that reader.

    ===========  ==========================================================  ==========================
    family       reader                                                      returns
    ===========  ==========================================================  ==========================
    terrain      :func:`splinevis.read_heights`                              :class:`splinevis.HeightGrid`
    volume       :func:`splinevis.read_volume`                               :class:`splinevis.VolumeGrid`
    nurbs        :func:`splinevis.read_nurbs` (3DM, IGES, STEP)              :class:`splinevis.NurbsModel`
    mesh         pyvista's reader, welded into one closed triangle mesh      ``pyvista.PolyData``
    ===========  ==========================================================  ==========================

    A mesh comes back with its seams welded and polygons triangulated (what a geometry image needs,
    :func:`splinevis.geometry_image.repair.prepare_mesh`); each change is warned.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (d / "tiny.asc").write_text("ncols 3\\nnrows 2\\nxllcorner 0\\nyllcorner 0\\ncellsize 10\\n1 2 3\\n4 5 6\\n")
    >>> grid = read(d / "tiny.asc")
    >>> type(grid).__name__, grid.shape
    ('HeightGrid', (2, 3))
    """
    from .check.detect import FAMILIES

    path = Path(path)
    family = family_of(path, family)
    if family == "terrain":
        from .io import read_heights

        return read_heights(path, **options)
    if family == "volume":
        from .io import read_volume

        return read_volume(path, **options)
    if family == "nurbs":
        from .io import read_nurbs

        return read_nurbs(path, **options)
    if family == "mesh":
        from ._warnings import warn_user
        from .geometry_image.repair import prepare_mesh

        mesh, repairs = prepare_mesh(str(path), path.name, **options)
        for r in repairs:
            warn_user(f"{path.name}: {r}")
        return mesh
    raise ValueError(f"family {family!r} is not known; choose one of 'auto', {', '.join(map(repr, FAMILIES))}.")
