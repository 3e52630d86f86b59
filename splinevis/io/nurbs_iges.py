"""NURBS surfaces from IGES files: 128 (rational B-spline surface), 144 (trimmed surface), 143 (bounded
surface), 186 / 514 / 510 B-rep solids and shells (faces without 144), after a check of the file's structure.

Two back ends, chosen at call time:

* **OpenCASCADE** (``OCP``, optional extra ``cad``: ``pip install cadquery-ocp-novtk``) when it imports:
  every independent (or only logically dependent, as in a 402 group) surface-bearing entity (128, 143, 144,
  186 / 514 / 510 B-reps, analytic surfaces 190-198, ...) is transferred on its own and its faces read with
  :func:`.nurbs_step.shape_faces` (trim loops from the faces' pcurves; analytic faces converted to NURBS;
  transformation matrices applied by OCP). An entity OpenCASCADE cannot transfer is counted in ``skipped``
  as ``"<type> (<name>), not transferred"``.
* **pyiges** (light, pure Python) otherwise: independent 128 entities, and 144 entities whose surface
  is a 128 and whose boundaries (142) have parameter-space curves (``BPTR``) of type 126 or 102
  (composite of 126) -- each 126 in the ``(u, v)`` plane (x = u, y = v). A 144 whose outer boundary is
  the domain boundary (``N1 = 0``) gets the domain rectangle as its outer loop (the even-odd rule needs
  it). 124 transformation matrices of the surface and the 144 are applied to the control points. The
  parameter ranges ``U0..U1, V0..V1`` of a 128 and ``V0..V1`` of a 126 are taken to be the knots'
  full domains (what CAD writers emit).

Control points of a 128 run over the first (u) index fastest (IGES 5.3, sec. 4.24). Patches are named by
the entity label when the file has one, else ``"<type> #<directory sequence number>"`` (for a B-rep
with several faces: ``"<name> face <k>"``). Independent entities of other types are counted in
``skipped`` by IGES type number and name.

Damaged files
-------------
OpenCASCADE and pyiges read a damaged IGES file without a word and return whatever they could parse (a part
cut in half, or with lines overwritten, loads some of its faces). :func:`check_iges` therefore reads the
fixed-format file's structure first (fast: no geometry): every line's section letter and sequence number
(columns 73-80), the terminate record's counts, each directory entry (its two lines, its type on both) and
its parameter record (the lines it points to exist, carry the entry's back pointer in columns 65-72, start
with the entity type and end with the record delimiter; the parameters of geometry and topology entities
are numbers) and the directory pointers in the records of the entities faces are made of (102, 141-144,
186, 504-514, 108-122, 190-198; transformation matrices). A face is lost when anything it reaches is
broken. The problems are told in the file's terms ("directory entry 57 (type 128) points to parameter
lines 1201-1230, the parameter section ends at line 900 (file line 1107)"). ``read_iges`` raises a
:class:`~.nurbs_common.DamagedFileError` with them, or with ``partial=True`` transfers only the intact
face-bearing entities (from a copy whose lines are put back in sequence when lines were lost: a lost
directory entry becomes a null entity, so that every other entry keeps its number) and reports the rest
(:func:`.nurbs_common.build_model`). The compressed ASCII form (``C`` in column 73) is not checked.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve
from .nurbs_common import Damage, DamagedFileError, build_model, checked
from .nurbs_iges_check import _STRUCTURE_TYPES, _SURFACE_TYPES, IGES_TYPES, _child, _type_key, check_iges

__all__ = ["read_iges", "check_iges", "IGES_TYPES"]

def read_iges(path, backend: str | None = None, partial: bool = False) -> NurbsModel:
    """Read the 128/144 surfaces of an IGES file (OCP when installed, else pyiges; see the module notes).

    Parameters
    ----------
    path : str or path-like
    backend : {None, "ocp", "pyiges"}
        Force a back end (None: OCP if it imports, else pyiges).
    partial : bool
        A damaged file (module notes, "Damaged files"): False raises :class:`~.nurbs_common.DamagedFileError`
        naming what is broken; True reads the intact faces and reports the lost ones (warning, ``skipped``,
        ``source``).

    Raises
    ------
    DamagedFileError
        The file's structure is broken (and ``partial`` is False).

    Examples
    --------
    >>> import tempfile, warnings
    >>> from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    >>> from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    >>> from OCP.IGESControl import IGESControl_Writer
    >>> from splinevis.io.nurbs_step import _quiet_occ
    >>> _quiet_occ()
    >>> box = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), True).Shape()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = str(Path(folder) / "box.igs")
    ...     w = IGESControl_Writer("MM", 0); _ = w.AddShape(box); w.ComputeModel(); _ = w.Write(f)
    ...     a, b = read_iges(f, "ocp"), read_iges(f, "pyiges")
    >>> len(a), len(b), a.names[0], b.names[0], a.bounds() == b.bounds()
    (6, 6, '144 #3', '144 #3', True)
    """
    path = Path(path)
    if backend not in (None, "ocp", "pyiges"):
        raise ValueError(f"backend must be None, 'ocp' or 'pyiges', got {backend!r}.")
    damage, lost, repaired = check_iges(path)
    if damage and not partial:
        raise DamagedFileError(path, damage)
    if repaired is None:
        return _read_backend(path, path, backend, damage, lost)
    import tempfile

    with tempfile.TemporaryDirectory(prefix="splinevis-iges-") as folder:  # the lines put back in place
        fixed = Path(folder) / "repaired.igs"
        fixed.write_text(repaired, encoding="latin-1")
        return _read_backend(fixed, path, backend, damage, lost)


def _read_backend(file: Path, path: Path, backend, damage, lost):
    """Read ``file`` (``path`` itself or its repaired copy; ``path`` for names and messages)."""
    if backend in (None, "ocp"):
        from .nurbs_step import OCP_HINT, ocp_available

        if ocp_available():
            return _read_ocp(file, path, damage, lost)
        if backend == "ocp":
            raise ImportError(f"{path}: backend='ocp' needs OpenCASCADE's Python bindings: {OCP_HINT}.")
    return _read_pyiges(file, path, damage, lost)


# --------------------------------------------------------------------------------------------------
def _read_ocp(file: Path, path: Path, damage: Damage, lost: set):
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader

    from .nurbs_step import _quiet_occ, converted_note, shape_faces

    _quiet_occ()
    reader = IGESControl_Reader()
    if reader.ReadFile(str(file)) != IFSelect_RetDone:
        raise ValueError(f"{path}: OpenCASCADE could not read this file as IGES; is it a valid IGES 5.x file?")
    model = reader.Model()
    surfaces, trims, skipped, contents, converted = [], [], {}, {}, {}
    for i in range(1, model.NbEntities() + 1):
        ent = model.Entity(i)
        t = ent.TypeNumber()
        contents[_type_key(t)] = contents.get(_type_key(t), 0) + 1
        if _child(ent.SubordinateStatus()) or t in _STRUCTURE_TYPES:
            continue
        label = ent.ShortLabel() if ent.HasShortLabel() else None
        name = (label.ToCString().strip() if label is not None else "") or f"{t} #{2 * i - 1}"
        if t not in _SURFACE_TYPES:
            skipped[_type_key(t)] = skipped.get(_type_key(t), 0) + 1
            continue
        if 2 * i - 1 in lost:  # reaches a broken record: counted in the damage
            continue
        before = reader.NbShapes()
        if not reader.TransferOne(i) or reader.NbShapes() == before:
            skipped[f"{_type_key(t)}, not transferred"] = skipped.get(f"{_type_key(t)}, not transferred", 0) + 1
            continue
        shape = reader.Shape(reader.NbShapes())
        if shape.IsNull():  # OpenCASCADE gave up on the entity (its check list says why)
            skipped[f"{_type_key(t)}, not transferred"] = skipped.get(f"{_type_key(t)}, not transferred", 0) + 1
            continue
        s, tr = shape_faces(shape, path, skipped, prefix=name, converted=converted)
        surfaces += s
        trims += tr
    return build_model(path, "IGES (OCP)" + converted_note(converted), surfaces, trims, skipped, contents, damage)


# --------------------------------------------------------------------------------------------------
def _read_pyiges(file: Path, path: Path, damage: Damage, lost: set):
    import contextlib
    import io

    import pyiges

    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):  # pyiges prints a line per entity it cannot parse
            iges = pyiges.read(str(file))
        # pyiges drops the entities it cannot parse from its list after indexing them: the pointers of every
        # later entity would point one entity too far; index them again
        iges._pointers = {e.sequence_number: k for k, e in enumerate(iges._entities)}
    except (RuntimeError, ValueError, IndexError, KeyError) as err:
        raise ValueError(f"{path}: pyiges could not parse this file as IGES ({type(err).__name__}: {err}).") from None
    surfaces, trims, skipped, contents = [], [], {}, {}
    for e in iges.items:
        t = int(e.d["entity_type_number"])
        contents[_type_key(t)] = contents.get(_type_key(t), 0) + 1
        status = e.d.get("status_number") or 0
        if _child((status // 10000) % 100) or t in _STRUCTURE_TYPES:
            continue
        name = (e.d.get("entity_label") or "").strip() or f"{t} #{e.sequence_number}"
        if e.sequence_number in lost:  # reaches a broken record: counted in the damage
            continue
        if t == 128:
            surfaces.append(_surface_128(iges, e, path, name, _transform(iges, e)))
            trims.append(None)
        elif t == 144:
            surf, loops = _trimmed_144(iges, e, path, name)
            surfaces.append(surf)
            trims.append(loops)
        else:
            skipped[_type_key(t)] = skipped.get(_type_key(t), 0) + 1
    failed = [int(n) for n in re.findall(r"ending on line (\d+)", out.getvalue())]
    if damage:  # the broken records (in the damage already) are no news
        lines = file.read_text(encoding="latin-1").splitlines()
        records = getattr(damage, "records", set())
        failed = [n for n in failed if not (n <= len(lines) and lines[n - 1][64:72].strip().isdigit()
                                            and int(lines[n - 1][64:72]) in records)]
    if failed or ("Warning" in out.getvalue() and not damage):
        skipped["entities pyiges could not parse"] = max(len(failed), 1)
    return build_model(path, "IGES (pyiges)", surfaces, trims, skipped, contents, damage)


def _transform(iges, e) -> np.ndarray | None:
    ptr = e.d.get("transform") or 0
    if not ptr:
        return None
    M = np.asarray(iges[ptr].to_affine(), dtype=np.float64)
    inner = _transform(iges, iges[ptr])  # a 124 may itself be transformed
    return M if inner is None else inner @ M


def _surface_128(iges, e, path, name: str, M: np.ndarray | None) -> NurbsSurface:
    if not hasattr(e, "_cp"):
        raise ValueError(f"{path}: {name}: pyiges could not parse this 128 entity; install OCP ({_ocp_hint()}).")
    nu, nv = e.k1 + 1, e.k2 + 1
    P = np.asarray(e._cp, dtype=np.float64).reshape(nv, nu, 3).transpose(1, 0, 2)  # u fastest in the file
    W = np.asarray(e.weights, dtype=np.float64).reshape(nv, nu).T
    if M is not None:
        P = P @ M[:3, :3].T + M[:3, 3]
    polynomial = bool(e.flag3) and np.all(W == W.flat[0])
    return checked(path, f"entity {name}", lambda: NurbsSurface(
        (e.m1, e.m2), (e.knot1, e.knot2), P, None if polynomial else W, name=name))


def _trimmed_144(iges, e, path, name: str):
    prm = e.parameters[0]
    try:
        pts, n1, n2, pto = (int(v) for v in prm[1:5])
        ptis = [int(v) for v in prm[5:5 + n2]]
        base = iges[pts]
    except (ValueError, IndexError, KeyError):
        raise ValueError(f"{path}: {name}: malformed 144 parameters {prm[:6]!r}.") from None
    btype = int(base.d["entity_type_number"])
    if btype != 128:
        raise ValueError(f"{path}: {name}: the trimmed surface is a {_type_key(btype)}; without OCP only 128 "
                         f"surfaces are read ({_ocp_hint()}).")
    M = _transform(iges, e)
    inner = _transform(iges, base)
    M = inner if M is None else (M if inner is None else M @ inner)
    surf = _surface_128(iges, base, path, name, M)
    loops = [_boundary_142(iges, iges[p], path, name) for p in ([pto] if n1 else []) + ptis]
    if loops and not n1:  # outer boundary = the domain: give it explicitly for the even-odd rule
        (u0, u1), (v0, v1) = surf.domain
        rect = [[u0, v0], [u1, v0], [u1, v1], [u0, v1], [u0, v0]]
        loops.insert(0, [TrimCurve(1, [0, 0, 1, 2, 3, 4, 4], rect)])
    return surf, (loops or None)


def _boundary_142(iges, e, path, name: str) -> list:
    if int(e.d["entity_type_number"]) != 142:
        raise ValueError(f"{path}: {name}: a 144 boundary points to a {_type_key(int(e.d['entity_type_number']))}, "
                         "not a 142 curve on surface.")
    bptr = int(e.parameters[0][3])
    if not bptr:
        raise ValueError(f"{path}: {name}: a 142 boundary has no parameter-space curve (BPTR = 0); pyiges cannot "
                         f"project the model-space curve; install OCP ({_ocp_hint()}).")
    return _param_curves(iges, iges[bptr], path, name)


def _param_curves(iges, c, path, name: str) -> list:
    t = int(c.d["entity_type_number"])
    if t == 102:
        prm = c.parameters[0]
        return [tc for p in prm[2:2 + int(prm[1])] for tc in _param_curves(iges, iges[int(p)], path, name)]
    if t == 126:
        xy = np.asarray(c.control_points, dtype=np.float64)[:, :2]
        weights = np.asarray(c.W, dtype=np.float64)
        w = None if (c.prop3 == 1 and np.all(weights == weights[0])) else weights
        return [checked(path, f"{name} trim curve 126 #{c.sequence_number}", lambda: TrimCurve(c.M, c.T, xy, w))]
    raise ValueError(f"{path}: {name}: a trim curve is a {_type_key(t)}; without OCP only 126 and 102 (of 126) "
                     f"parameter-space curves are read ({_ocp_hint()}).")


def _ocp_hint() -> str:
    from .nurbs_step import OCP_HINT

    return OCP_HINT
