"""NURBS surfaces from text formats: GoTools/splipy ``.g2``, geomdl JSON and Newell's teapot ``.bpt``.

Formats and orderings
---------------------
* **G2** (GoTools, written by splipy's ``splipy.io.G2``): objects start with a header line
  ``<class> 1 0 0``. Class 200 (spline surface) is read: ``dim rational``, then per direction ``n order``
  and a line of ``n + order`` knots, then ``n_u * n_v`` control points, one per line, **u varying
  fastest**; rational points are homogeneous ``(w x, w y, w z, w)``. Curves (100), volumes (700) and the
  elementary/trimmed classes (120 ... 292, parsed with splipy when installed) are counted as skipped.
* **geomdl JSON** (``geomdl.exchange.export_json``): ``{"shape": {"type": "surface", "data": [...]}}``,
  each entry with ``degree_u, degree_v, knotvector_u, knotvector_v, size_u, size_v`` and
  ``control_points: {"points": [...], "weights": [...]}``; points are Cartesian (not weighted) with
  **v varying fastest** (``points[i * size_v + j]`` is ``P[i, j]``). Trim curves (``"trims"``) are
  counted as skipped.
* **BPT** (the Bezier patch format of the Utah teapot files): the first number is the patch count; each
  patch is ``n m`` (its degrees in u and v) followed by ``(n+1)(m+1)`` points ``x y z``, **u-major**:
  the points run over v fastest, ``point[i * (m+1) + j]`` is ``P[i, j]`` (u index i, v index j). Bezier
  patches become clamped B-splines on ``[0, 1]^2``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface
from .nurbs_common import build_model, checked

__all__ = ["read_g2", "read_geomdl_json", "read_bpt"]

_G2_NAMES = {100: "100 (spline curve)", 200: "200 (spline surface)", 700: "700 (spline volume)", 120: "120 (line)", 130: "130 (circle)",
             140: "140 (ellipse)", 250: "250 (plane)", 260: "260 (cylinder)", 261: "261 (linear extrusion)",
             270: "270 (sphere)", 290: "290 (torus)", 292: "292 (disc)", 210: "210 (bounded surface)"}


def _bezier_knots(p: int) -> list:
    return [0.0] * (p + 1) + [1.0] * (p + 1)


# --------------------------------------------------------------------------------------------------
def read_bpt(path) -> NurbsModel:
    """Read Bezier patches in the teapot ``.bpt`` format (see the module notes for the ordering).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "two.bpt"
    ...     _ = f.write_text("2\\n1 1\\n0 0 0\\n0 1 0\\n1 0 0\\n1 1 0\\n1 1\\n0 0 1\\n0 1 1\\n1 0 1\\n1 1 2\\n")
    ...     m = read_bpt(f)
    >>> m.names, m.surfaces[1].evaluate([0.5], [0.5]).tolist()
    (('patch 0', 'patch 1'), [[0.5, 0.5, 1.25]])
    """
    path = Path(path)
    tokens = path.read_text().split()
    pos = 0

    def take(count: int, what: str) -> list:
        nonlocal pos
        if pos + count > len(tokens):
            raise ValueError(f"{path}: the file ends inside {what} (needs {count} more numbers, has "
                             f"{len(tokens) - pos}); is it a truncated .bpt file?")
        out = tokens[pos:pos + count]
        pos += count
        return out

    try:
        npatch = int(take(1, "the patch count")[0])
    except ValueError as err:
        if "ends inside" in str(err):
            raise
        raise ValueError(f"{path}: the first number of a .bpt file must be the patch count, got {tokens[0]!r}.") from None
    if npatch < 1:
        raise ValueError(f"{path}: the patch count must be >= 1, got {npatch}.")
    surfaces = []
    for k in range(npatch):
        try:
            n, m = (int(t) for t in take(2, f"patch {k}'s degrees"))
            xyz = np.array(take(3 * (n + 1) * (m + 1), f"patch {k}'s control points"), dtype=np.float64)
        except ValueError as err:
            if "ends inside" in str(err):
                raise
            raise ValueError(f"{path}: patch {k}: bad number ({err}); each patch is 'n m' (integer degrees) "
                             "then (n+1)(m+1) lines 'x y z'.") from None
        P = xyz.reshape(n + 1, m + 1, 3)  # u-major: v varies fastest
        surfaces.append(checked(path, f"patch {k}", lambda: NurbsSurface(
            (n, m), (_bezier_knots(n), _bezier_knots(m)), P, name=f"patch {k}")))
    if pos != len(tokens):
        raise ValueError(f"{path}: {len(tokens) - pos} numbers left after the {npatch} patches the first line "
                         "announces; is the patch count right?")
    return build_model(path, "Bezier patches (.bpt)", surfaces, [None] * len(surfaces), {})


# --------------------------------------------------------------------------------------------------
def read_geomdl_json(path) -> NurbsModel:
    """Read surfaces from a geomdl JSON file (``shape.data``; points with v varying fastest).

    Examples
    --------
    >>> import tempfile, json
    >>> d = {"shape": {"type": "surface", "count": 1, "data": [{"type": "spline", "rational": False,
    ...      "degree_u": 1, "degree_v": 1, "knotvector_u": [0, 0, 1, 1], "knotvector_v": [0, 0, 1, 1],
    ...      "size_u": 2, "size_v": 2, "control_points": {"points": [[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 1]]}}]}}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "quad.json"
    ...     _ = f.write_text(json.dumps(d))
    ...     m = read_geomdl_json(f)
    >>> m.surfaces[0].evaluate([1.0], [0.0]).tolist()
    [[1.0, 0.0, 0.0]]
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text())
        shape = doc["shape"]
        data = shape["data"]
    except json.JSONDecodeError as err:
        raise ValueError(f"{path}: not valid JSON ({err}).") from None
    except (KeyError, TypeError):
        raise ValueError(f"{path}: not a geomdl JSON file (expected {{'shape': {{'type': ..., 'data': [...]}}}}).") from None
    kind = shape.get("type", "surface")
    if kind != "surface":
        raise ValueError(f"{path} holds no supported NURBS surface (geomdl JSON); it contains: {len(data)} x {kind}.")
    surfaces, skipped = [], {}
    for k, d in enumerate(data):
        entity = f"shape.data[{k}]"
        try:
            nu, nv = int(d["size_u"]), int(d["size_v"])
            p, q = int(d["degree_u"]), int(d["degree_v"])
            P = np.asarray(d["control_points"]["points"], dtype=np.float64)
            W = d["control_points"].get("weights")
            U, V = d["knotvector_u"], d["knotvector_v"]
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError(f"{path}: {entity}: missing or bad field {err} (needs degree_u/v, knotvector_u/v, "
                             "size_u/v, control_points.points).") from None
        if P.shape != (nu * nv, 3):
            raise ValueError(f"{path}: {entity}: control_points.points must be size_u * size_v = {nu * nv} "
                             f"points (x, y, z), got shape {P.shape}.")
        W = None if W is None else np.asarray(W, dtype=np.float64).reshape(nu, nv)
        name = str(d.get("name") or f"surface {k}")
        surfaces.append(checked(path, entity, lambda: NurbsSurface((p, q), (U, V), P.reshape(nu, nv, 3), W,
                                                                   name=name)))
        trims = (d.get("trims") or {}).get("data") or []
        if trims:
            skipped["trim curves (geomdl)"] = skipped.get("trim curves (geomdl)", 0) + len(trims)
    return build_model(path, "geomdl JSON", surfaces, [None] * len(surfaces), skipped)


# --------------------------------------------------------------------------------------------------
def read_g2(path) -> NurbsModel:
    """Read the spline surfaces (class 200) of a GoTools ``.g2`` file (see the module notes).

    Examples
    --------
    >>> import tempfile
    >>> text = "200 1 0 0\\n3 0\\n2 2\\n0 0 1 1\\n2 2\\n0 0 1 1\\n0 0 0\\n1 0 0\\n0 1 0\\n1 1 1\\n"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     f = Path(folder) / "quad.g2"
    ...     _ = f.write_text(text)
    ...     m = read_g2(f)
    >>> m.names, m.surfaces[0].evaluate([1.0], [0.0]).tolist()  # u varies fastest in the file
    (('surface 0',), [[1.0, 0.0, 0.0]])
    """
    path = Path(path)
    lines = iter(path.read_text().splitlines())
    surfaces, skipped, contents = [], {}, {}

    def next_line(what: str) -> str:
        for line in lines:
            if line.strip():
                return line
        raise ValueError(f"{path}: the file ends inside {what}.")

    def numbers(count: int, what: str) -> list:
        out = []
        while len(out) < count:
            out += next_line(what).split()
        if len(out) != count:
            raise ValueError(f"{path}: {what}: expected {count} numbers, got {len(out)}.")
        return [float(t) for t in out]

    def spline(pardim: int, entity: str):
        dim, rational = (int(t) for t in next_line(f"{entity}'s header").split()[:2])
        bases = []
        for d in range(pardim):
            n, order = (int(t) for t in next_line(f"{entity}'s basis {d}").split()[:2])
            bases.append((n, order, numbers(n + order, f"{entity}'s knots {d}")))
        count = int(np.prod([b[0] for b in bases]))
        width = dim + bool(rational)
        cps = np.array([numbers(width, f"{entity}'s control point {i}") for i in range(count)])
        return dim, bool(rational), bases, cps

    index = 0
    for line in lines:
        if not line.strip():
            continue
        try:
            cls = int(line.split()[0])
        except ValueError:
            raise ValueError(f"{path}: expected an object header '<class> 1 0 0', got {line.strip()!r}.") from None
        entity = f"object {index} (class {cls})"
        index += 1
        name = _G2_NAMES.get(cls, f"{cls}")
        contents[name] = contents.get(name, 0) + 1
        if cls in (100, 200, 700):
            try:
                dim, rational, bases, cps = spline({100: 1, 200: 2, 700: 3}[cls], entity)
            except ValueError as err:
                if str(err).startswith(str(path)):
                    raise
                raise ValueError(f"{path}: {entity}: bad number ({err}).") from None
            if cls != 200:
                skipped[name] = skipped.get(name, 0) + 1
                continue
            if dim != 3:
                raise ValueError(f"{path}: {entity}: only 3-D surfaces are read, this one has dimension {dim}.")
            (nu, ou, U), (nv, ov, V) = bases
            H = cps.reshape(nv, nu, -1).transpose(1, 0, 2)  # u varies fastest in the file
            W = H[..., 3].copy() if rational else None
            if W is not None and not (W > 0).all():
                i, j = (int(v) for v in np.argwhere(~(W > 0))[0])
                raise ValueError(f"{path}: {entity}: weights must be positive and finite; weights[{i}, {j}] = "
                                 f"{float(W[i, j])!r} (a zero or negative weight puts the surface at infinity).")
            P = H[..., :3] / W[..., None] if rational else H[..., :3]
            surfaces.append(checked(path, entity, lambda: NurbsSurface((ou - 1, ov - 1), (U, V), P, W,
                                                                       name=f"surface {len(surfaces)}")))
        else:
            _skip_g2_object(path, cls, entity, lines)
            skipped[name] = skipped.get(name, 0) + 1
    return build_model(path, "G2 text", surfaces, [None] * len(surfaces), skipped, contents)


def _skip_g2_object(path, cls: int, entity: str, lines) -> None:
    """Consume an elementary/trimmed G2 object with splipy's parser (its length is not fixed)."""
    try:
        from splipy.io import G2
    except ImportError:
        raise ValueError(f"{path}: {entity}: G2 class {cls} can only be skipped with splipy installed "
                         "(pip install splipy); remove the object or install splipy.") from None
    if cls not in G2.g2_generators:
        raise ValueError(f"{path}: {entity}: unknown G2 class {cls}; supported: 200 (spline surface).")
    reader = G2.__new__(G2)
    reader.fstream, reader.trimming_curves = lines, []
    getattr(reader, G2.g2_generators[cls].__name__)()
