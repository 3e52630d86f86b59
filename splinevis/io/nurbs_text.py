"""NURBS surfaces from text formats: geomdl JSON and Newell's teapot ``.bpt`` (GoTools/splipy ``.g2``: :mod:`.nurbs_g2`).

Formats and orderings
---------------------
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

__all__ = ["read_geomdl_json", "read_bpt"]

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
