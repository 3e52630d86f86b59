"""NURBS models from CAD and spline files, as one :class:`~splinevis.nurbs.NurbsModel`.

:func:`read_nurbs` picks the reader by the file name extension:

* ``.3dm`` -- Rhino files through ``rhino3dm`` (:mod:`.nurbs_3dm`),
* ``.igs .iges`` -- IGES 128 (rational B-spline surface), 144 (trimmed surface), 143 (bounded surface) and
  186 / 514 / 510 B-reps through OpenCASCADE (``OCP``, the optional extra ``pip install cadquery-ocp-novtk``)
  when installed, else 128 and 144 through ``pyiges`` (:mod:`.nurbs_iges`),
* ``.stp .step`` -- STEP faces (B-spline, and analytic ones converted to NURBS) through OCP only
  (:mod:`.nurbs_step`),
* ``.g2`` (splipy / GoTools), ``.json`` (geomdl ``shape.data``) and ``.bpt`` (Newell's teapot Bezier
  patches) -- text formats (:mod:`.nurbs_text`, :mod:`.nurbs_g2`).

Conventions kept by every reader
--------------------------------
* Each patch keeps its identity: ``NurbsSurface.name`` is the file's object name or id (Rhino), the
  entity label or directory sequence number (IGES), the face's stored name, else its owner's name and index (STEP, through OpenCASCADE's XCAF document), the patch index (text).
* Trim loops come in the patch's own ``(u, v)`` domain, as lists of :class:`~splinevis.nurbs.TrimCurve`;
  the model applies the even-odd rule, so loop orientation does not matter.
* Entities the reader does not turn into surfaces are counted in ``NurbsModel.skipped`` (entity type ->
  count), named in ``NurbsModel.source`` and announced with a :class:`UserWarning`. A file with no
  supported surface at all raises a ValueError listing what it contained.
* Invalid data (zero or negative weights, bad knots) raise the model's ValueError prefixed with the file
  and the entity.
* IGES and STEP files are checked for damage before they are read (lines lost or garbled, cut off,
  references to nothing): a damaged file raises :class:`~.nurbs_common.DamagedFileError` (a ValueError)
  naming the file, what it promised and what was found; ``read_nurbs(path, partial=True)`` reads the intact
  faces and reports the lost ones in a UserWarning, ``NurbsModel.skipped`` and ``NurbsModel.source``.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..nurbs import NurbsModel
from ._common import require_regular_file, unsupported_extension

__all__ = ["read_nurbs", "NURBS_EXTENSIONS"]

#: File name extensions :func:`read_nurbs` reads, and by what.
NURBS_EXTENSIONS = {
    ".3dm": "Rhino 3DM (rhino3dm)",
    ".igs": "IGES 128/143/144/186 (OCP, else pyiges: 128/144)",
    ".iges": "IGES 128/143/144/186 (OCP, else pyiges: 128/144)",
    ".stp": "STEP faces (OCP)",
    ".step": "STEP faces (OCP)",
    ".g2": "GoTools/splipy G2 text",
    ".json": "geomdl JSON (shape.data)",
    ".bpt": "Bezier patches (Newell teapot format)",
}


def read_nurbs(path, partial: bool = False, orient: bool | None = None) -> NurbsModel:
    """Read a NURBS model from a file; the reader is chosen by the extension (see :data:`NURBS_EXTENSIONS`).

    Parameters
    ----------
    path : str or path-like
    partial : bool
        For IGES and STEP files, whose structure is checked before reading: a damaged file (an IGES
        directory entry pointing past the parameter section, garbled or missing lines, a cut file; a STEP
        ``#n`` that points nowhere, a cut file) raises :class:`~.nurbs_common.DamagedFileError` naming the
        file, what it promised and what was found (False), or is read in part (True): the intact faces,
        with the lost ones in a UserWarning, ``NurbsModel.skipped`` (``"damaged <entity>"``) and
        ``NurbsModel.source``.
    orient : bool or None
        Give the faces of each closed shell one outward orientation and measure the seams
        (:func:`splinevis.nurbs.orient.orient_faces`): the report is ``model.report["orientation"]`` (faces
        flipped, shells closed or open, each seam's G0/G1/G2 class with its kink angle). None (default): for
        the formats whose faces carry no outside (IGES, the text formats) or may come without a shell (STEP's
        bare surfaces), not for Rhino files (each Brep face's orientation is applied by the reader, and a
        SubD's patches follow its control net). False keeps the faces as the file has them.

    Returns
    -------
    NurbsModel

    Raises
    ------
    FileNotFoundError, ValueError
        A missing file, an unsupported extension, a file without any supported surface, invalid data.
    ImportError
        A STEP file without OCP installed.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "quad.bpt"
    ...     _ = f.write_text("1\\n1 1\\n0 0 0\\n0 1 0\\n1 0 0\\n1 1 1\\n")
    ...     m = read_nurbs(f)
    >>> len(m), m.names, m.surfaces[0].evaluate([1.0], [1.0]).tolist()
    (1, ('patch 0',), [[1.0, 1.0, 1.0]])
    >>> read_nurbs("model.obj")
    Traceback (most recent call last):
    ValueError: model.obj: extension '.obj' is not supported; supported: .3dm (Rhino 3DM (rhino3dm)), ...
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"read_nurbs takes a file name, got {type(path).__name__}.")
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in NURBS_EXTENSIONS:
        raise unsupported_extension(path, NURBS_EXTENSIONS)
    require_regular_file(path, "NURBS")
    if ext == ".3dm":
        from .nurbs_3dm import read_3dm
        model = read_3dm(path)
    elif ext in (".igs", ".iges"):
        from .nurbs_iges import read_iges
        model = read_iges(path, partial=partial)
    elif ext in (".stp", ".step"):
        from .nurbs_step import read_step
        model = read_step(path, partial=partial)
    else:
        from .nurbs_g2 import read_g2
        from .nurbs_text import read_bpt, read_geomdl_json
        model = {".g2": read_g2, ".json": read_geomdl_json, ".bpt": read_bpt}[ext](path)
    if orient or (orient is None and ext != ".3dm"):
        from ..nurbs.orient import orient_faces

        model = orient_faces(model)[0]
    return model
