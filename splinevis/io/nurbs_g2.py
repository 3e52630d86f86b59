"""GoTools/splipy ``.g2`` files: the stream of numbers, its objects and ``read_g2``.

Format
------
**G2** (GoTools [GoTools2025]; also written by splipy's ``splipy.io.G2``): a stream of numbers (GoTools
  reads it with ``>>``: line breaks carry no meaning). Each object starts with a header ``<class> <major>
  <minor> <n>`` and ``n`` auxiliary numbers (e.g. a colour). Read:

  - **200 (spline surface)**: ``dim rational``, per direction ``n order`` and ``n + order`` knots, then
    ``n_u * n_v`` coefficients, **u varying fastest**; rational ones homogeneous ``(w x, w y, w z, w)``.
  - **210 (bounded surface)**, a trimmed surface: the underlying surface's class and body (no header), the
    number of loops, per loop ``n epsilon`` (the loop's space tolerance) and ``n`` curves on the surface,
    each ``prefer_parameter parameter_class space_class`` (class 0: absent; 1: old name of 100) followed by
    the parameter curve (2-D, in the surface's ``(u, v)``) and the space curve (3-D). GoTools writes the
    outer loop first, counter-clockwise in ``(u, v)``, holes clockwise; the loops are kept in the file's
    order and direction (the inside test is even-odd and needs neither). Underlying surfaces read:

    * 200, with its parameter curves as they are (exact);
    * 250 (plane: ``dim, location, normal, x axis, bounded flag [u0 u1 v0 v1] [domain], swapped``): its
      point is ``location + a x + b y`` with ``y = normal x x``, the domain mapped linearly onto the
      bounds, u and v exchanged when swapped. That map is affine, so the patch is an exact bilinear one
      over the domain (over the trim curves' box when the plane is unbounded), parameter curves are kept
      as they are and space curves mapped by the inverse, both exact;
    * 260 cylinder, 270 sphere, 280 cone, 290 torus, 292 disc: GoTools' ``point(u, v)`` (angles in
      radians) has no rational form, so the patch is their exact NURBS form over the parameter bounds (an
      open cylinder or cone over the trims' heights) and every trim curve, a parameter curve mapped into
      space by ``point`` or a space curve, is pulled back onto it within the loop's epsilon.

    Trim curves read: 100 (spline curve), 120 (line), 130 (circle), 140 (ellipse: exact rational quadratic
    arcs [PieglTiller1997, A7.1]) and 150 (bounded curve) of a line or conic; the parameter curve is used
    when present. Pull-backs use :func:`splinevis.nurbs.pullback.pull_back`; their deviations are listed
    in the model's ``source``. A curve up to 100 epsilons off the surface is fitted as closely as it allows,
    the face drawn and the deviation beyond the epsilon warned about; farther, the face is skipped. Loop
    joints are made one point bit for bit where the ends meet within the epsilon (or the deviation
    accepted) in space; wider gaps (GoTools only warns about them) are bridged by segments, with a warning.
  - Bounded surfaces on 261 (linear extrusion) and 291 (surface of revolution), or whose trim curves do not
    pull back, and every object of classes 100-150, 250-292 (untrimmed elementary surfaces) and 700, are
    parsed to their end and counted in ``skipped`` by class (a skipped 210 as ``"210 (bounded surface) on
    <class>"`` or with the reason, and a warning naming its line). An unknown class is an error naming
    its line.

The NURBS forms of the underlying surfaces and trim curves, and the loops, are in :mod:`.nurbs_g2_geometry`.
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np

from ..nurbs import NurbsModel
from .nurbs_common import build_model
from .nurbs_g2_geometry import _G2_NAMES, _bounded_patch, _g2_name, _Obj, _spline_surface, _Unsupported

__all__ = ["read_g2"]

# --------------------------------------------------------------------------------------------------
# GoTools .g2: a stream of whitespace-separated numbers (GoTools reads it with ``>>``, so line breaks carry
# no meaning); every token keeps its line number for the messages.
class _Tokens:
    def __init__(self, path, text: str):
        self.path, self.toks, self.lines, self.pos = path, [], [], 0
        for n, line in enumerate(text.splitlines(), 1):
            for t in line.split():
                self.toks.append(t)
                self.lines.append(n)

    def more(self) -> bool:
        return self.pos < len(self.toks)

    def line(self) -> int:
        """Line of the next token (of the last one at the end)."""
        return self.lines[min(self.pos, len(self.lines) - 1)] if self.lines else 1

    def error(self, msg: str, line: int | None = None) -> ValueError:
        return ValueError(f"{self.path}: line {self.line() if line is None else line}: {msg}")

    def take(self, what: str) -> str:
        if self.pos >= len(self.toks):
            raise ValueError(f"{self.path}: the file ends (line {self.line()}) inside {what}; is it truncated?")
        self.pos += 1
        return self.toks[self.pos - 1]

    def int(self, what: str, allowed=None) -> int:
        t = self.take(what)
        try:
            v = int(t)
        except ValueError:
            raise ValueError(f"{self.path}: line {self.lines[self.pos - 1]}: {what}: expected an integer, "
                             f"got {t!r}.") from None
        if allowed is not None and v not in allowed:
            raise ValueError(f"{self.path}: line {self.lines[self.pos - 1]}: {what}: expected one of "
                             f"{', '.join(map(str, allowed))}, got {v}.")
        return v

    def floats(self, count: int, what: str) -> np.ndarray:
        if self.pos + count > len(self.toks):
            self.pos = len(self.toks)
            self.take(what)  # raises: the file ends inside `what`
        chunk = self.toks[self.pos: self.pos + count]
        try:
            out = np.array(chunk, dtype=np.float64)
        except ValueError:
            out = None
        if out is None or np.isnan(out).any():
            for k, t in enumerate(chunk):  # find the culprit, for its line
                try:
                    bad = np.isnan(float(t))
                except ValueError:
                    bad = True
                if bad:
                    raise ValueError(f"{self.path}: line {self.lines[self.pos + k]}: {what}: expected a number, "
                                     f"got {t!r}.")
        self.pos += count
        return out

    def float(self, what: str) -> float:
        return float(self.floats(1, what)[0])


def _g2_spline(tok: _Tokens, cls: int, what: str) -> _Obj:
    """Classes 100/200/700 (and 1, the old name of 100 inside a 110): ``dim rational``, per direction
    ``n order`` and ``n + order`` knots, then the coefficients (homogeneous ``w x, ..., w`` when rational)."""
    line = tok.line()
    pardim = {1: 1, 100: 1, 200: 2, 700: 3}[cls]
    dim = tok.int(f"{what}: the dimension")
    rational = tok.int(f"{what}: the rational flag", (0, 1))
    if dim < 1:
        raise tok.error(f"{what}: the dimension must be >= 1, got {dim}.")
    bases = []
    for d in range(pardim):
        n = tok.int(f"{what}: the number of coefficients in direction {d}")
        order = tok.int(f"{what}: the order in direction {d}")
        if order < 1 or n < order:
            raise tok.error(f"{what}: direction {d} needs order >= 1 and at least 'order' coefficients, "
                            f"got {n} coefficients of order {order}.")
        bases.append((n, order, tok.floats(n + order, f"{what}: the {n + order} knots of direction {d}")))
    count = int(np.prod([b[0] for b in bases]))
    width = dim + rational
    cps = tok.floats(count * width, f"{what}: the {count} coefficients ({width} numbers each)").reshape(count, width)
    return _Obj(100 if cls == 1 else cls, line, dim=dim, rational=bool(rational), bases=bases, cps=cps)


def _g2_conic(tok: _Tokens, cls: int, what: str) -> _Obj:
    """120 line ``dim, location, direction, bounded flag [bounds] [domain], reversed``; 130 circle ``dim, r,
    centre, normal, x axis, bounds, reversed flag [domain]``; 140 ellipse as 130 with ``r1 r2``. A flag
    >= 10 announces the domain (the curve's parameter interval, mapped linearly onto the bounds)."""
    line = tok.line()
    dim = tok.int(f"{what}: the dimension", (2, 3))
    d = {"dim": dim}
    if cls == 120:
        d["location"], d["direction"] = (tok.floats(dim, f"{what}: the {name}") for name in ("location", "direction"))
        flag = tok.int(f"{what}: the bounded flag", (0, 1, 10, 11))
        d["bounds"] = tuple(tok.floats(2, f"{what}: the parameter bounds")) if flag % 10 else (-np.inf, np.inf)
        d["domain"] = tuple(tok.floats(2, f"{what}: the parameter domain")) if flag >= 10 else d["bounds"]
        d["reversed"] = tok.int(f"{what}: the reversed flag", (0, 1)) == 1
    else:
        d["radii"] = tuple(tok.floats(1 if cls == 130 else 2, f"{what}: the radius"))
        d["centre"], d["normal"], d["xaxis"] = (tok.floats(dim, f"{what}: the {name}")
                                                for name in ("centre", "normal", "x axis"))
        d["bounds"] = tuple(tok.floats(2, f"{what}: the parameter bounds (angles)"))
        flag = tok.int(f"{what}: the reversed flag", (0, 1, 10, 11))
        d["domain"] = tuple(tok.floats(2, f"{what}: the parameter domain")) if flag >= 10 else d["bounds"]
        d["reversed"] = flag % 10 == 1
    return _Obj(cls, line, **d)


def _g2_bounded_curve(tok: _Tokens, cls: int, what: str) -> _Obj:
    """150: ``class``, ``prefer_parameter start end``, ``dim start point end point``, the curve."""
    line = tok.line()
    inner = tok.int(f"{what}: the class of the bounded curve's curve")
    tok.int(f"{what}: the prefer-parameter flag", (0, 1))
    start, end = tok.floats(2, f"{what}: the start and end parameters")
    dim = tok.int(f"{what}: the dimension of the end points")
    tok.floats(2 * dim, f"{what}: the start and end points")
    curve = _g2_curve(tok, inner, f"{what}'s curve")
    return _Obj(cls, line, curve=curve, start=float(start), end=float(end), dim=curve.data["dim"])


def _g2_curve(tok: _Tokens, cls: int, what: str) -> _Obj:
    if cls in (1, 100):
        return _g2_spline(tok, cls, what)
    if cls in (120, 130, 140):
        return _g2_conic(tok, cls, what)
    if cls == 150:
        return _g2_bounded_curve(tok, cls, what)
    raise tok.error(f"{what}: curve class {cls} ({_g2_name(cls)}) is not a GoTools curve this reader knows "
                    "(100, 120, 130, 140, 150).")


def _g2_elementary(tok: _Tokens, cls: int, what: str) -> _Obj:
    """250 plane, 260 cylinder, 270 sphere, 280 cone, 290 torus, 292 disc, 261 linear extrusion, 291 surface of
    revolution: their fields in GoTools' order (261 and 291 are consumed, not kept)."""
    line = tok.line()
    dim = tok.int(f"{what}: the dimension")
    d = {"dim": dim}

    def bounds_then_swap(bounded_flag: bool, swap_has_domain: bool):
        if bounded_flag:
            flag = tok.int(f"{what}: the bounded flag", (0, 1, 10, 11))
            n = 4 if flag % 10 else (0 if cls == 250 else 2)
            d["bounds"] = tok.floats(n, f"{what}: the parameter bounds")
            if flag >= 10 and (flag % 10 or cls != 250):
                d["domain"] = tok.floats(n, f"{what}: the parameter domain")
        else:
            d["bounds"] = tok.floats(4, f"{what}: the parameter bounds")
        flag = tok.int(f"{what}: the swapped flag", (0, 1, 10, 11) if swap_has_domain else (0, 1))
        if flag >= 10:
            d["domain"] = tok.floats(4, f"{what}: the parameter domain")
        d["swapped"] = flag % 10 == 1

    if cls == 250:
        d["location"], d["normal"], d["xaxis"] = (tok.floats(dim, f"{what}: the {n}")
                                                  for n in ("location", "normal", "x axis"))
        bounds_then_swap(True, False)
    elif cls in (260, 270, 280):
        d["radius"] = tok.float(f"{what}: the radius")
        d["location"], d["zaxis"], d["xaxis"] = (tok.floats(dim, f"{what}: the {n}")
                                                 for n in ("location", "z axis", "x axis"))
        if cls == 280:
            d["angle"] = tok.float(f"{what}: the cone angle")
        bounds_then_swap(cls != 270, cls == 270)
    elif cls == 290:
        d["major"], d["minor"] = tok.floats(2, f"{what}: the major and minor radius")
        d["location"], d["zaxis"], d["xaxis"] = (tok.floats(dim, f"{what}: the {n}")
                                                 for n in ("location", "z axis", "x axis"))
        tok.int(f"{what}: the select-outer flag", (0, 1))
        bounds_then_swap(False, True)
    elif cls == 292:
        d["location"] = tok.floats(dim, f"{what}: the centre")
        d["radius"] = tok.float(f"{what}: the radius")
        d["zaxis"], d["xaxis"] = (tok.floats(dim, f"{what}: the {n}") for n in ("z axis", "x axis"))
        tok.int(f"{what}: the centre-degenerate flag", (0, 1))
        tok.floats(4, f"{what}: the 4 degenerate angles")
        bounds_then_swap(False, True)
    elif cls == 261:
        _g2_spline(tok, 100, f"{what}'s curve")
        tok.floats(dim, f"{what}: the axis")
        flag = tok.int(f"{what}: the bounded flag", (0, 1))
        tok.floats(4 if flag else 2, f"{what}: the parameter bounds")
        tok.int(f"{what}: the swapped flag", (0, 1))
    elif cls == 291:
        tok.floats(2 * dim, f"{what}: location and axis")
        _g2_spline(tok, 100, f"{what}'s curve")
        tok.floats(2, f"{what}: the angle bounds")
        tok.int(f"{what}: the swapped flag", (0, 1))
    return _Obj(cls, line, **d)


def _g2_surface(tok: _Tokens, cls: int, what: str) -> _Obj:
    if cls == 200:
        return _g2_spline(tok, cls, what)
    if cls in (250, 260, 261, 270, 280, 290, 291, 292):
        return _g2_elementary(tok, cls, what)
    if cls == 210:
        return _g2_bounded_surface(tok, cls, what)
    raise tok.error(f"{what}: surface class {cls} ({_g2_name(cls)}) is not one this reader can parse "
                    "(200, 210, 250, 260, 261, 270, 280, 290, 291, 292).")


def _g2_bounded_surface(tok: _Tokens, cls: int, what: str) -> _Obj:
    """210: the surface's class and body (no header), the number of loops, per loop ``n epsilon`` and n
    curves-on-surface, each ``prefer_parameter parameter_class space_class`` (0: absent) and the bodies."""
    line = tok.line()
    scls = tok.int(f"{what}: the class of the underlying surface")
    surface = _g2_surface(tok, scls, f"{what}'s underlying surface")
    loops = []
    for i in range(tok.int(f"{what}: the number of boundary loops")):
        n = tok.int(f"{what}: loop {i}: the number of curves")
        if n < 1:
            raise tok.error(f"{what}: loop {i} must have at least one curve, got {n}.")
        eps = tok.float(f"{what}: loop {i}: the space epsilon")
        curves = []
        for j in range(n):
            at = tok.line()
            cwhat = f"{what}: loop {i} curve {j}"
            prefer = tok.int(f"{cwhat}: the prefer-parameter flag", (0, 1))
            pcls = tok.int(f"{cwhat}: the parameter curve's class (0: none)")
            ccls = tok.int(f"{cwhat}: the space curve's class (0: none)")
            if pcls == 0 and ccls == 0:
                raise tok.error(f"{cwhat}: neither a parameter curve nor a space curve (both classes 0).", at)
            pcurve = _g2_curve(tok, pcls, f"{cwhat}'s parameter curve") if pcls else None
            scurve = _g2_curve(tok, ccls, f"{cwhat}'s space curve") if ccls else None
            curves.append(_Obj(110, at, prefer=prefer, pcurve=pcurve, scurve=scurve))
        loops.append((eps, curves))
    return _Obj(cls, line, surface=surface, loops=loops)


def read_g2(path) -> NurbsModel:
    """Read the spline surfaces (class 200) and bounded surfaces (class 210) of a GoTools ``.g2`` file (see
    the module notes).

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
    tok = _Tokens(path, path.read_text())
    surfaces, trims, skipped, contents, notes = [], [], {}, {}, []
    index = 0
    while tok.more():
        line = tok.line()
        cls = tok.int("an object header '<class> <major> <minor> <n> [n numbers]'")
        tok.int(f"object {index} (class {cls}): the header's major version")
        tok.int(f"object {index} (class {cls}): the header's minor version")
        naux = tok.int(f"object {index} (class {cls}): the header's number of auxiliary numbers (e.g. a colour)")
        if naux < 0:
            raise tok.error(f"object {index} (class {cls}): the header's auxiliary count must be >= 0, got {naux}.")
        tok.floats(naux, f"object {index} (class {cls}): the header's auxiliary numbers")
        entity = f"object {index} (class {cls}, line {line})"
        index += 1
        name = _g2_name(cls)
        contents[name] = contents.get(name, 0) + 1
        if cls not in _G2_NAMES:
            raise tok.error(f"{entity}: unknown G2 class {cls} in an object header; this reader parses "
                            f"{', '.join(str(c) for c in sorted(_G2_NAMES))}.", line)
        if cls in (100, 120, 130, 140, 150):
            _g2_curve(tok, cls, entity)
        elif cls == 700:
            _g2_spline(tok, cls, entity)
        else:
            obj = _g2_surface(tok, cls, entity)
            pname = f"surface {len(surfaces)}"
            if cls == 200:
                surfaces.append(_spline_surface(path, entity, obj, pname))
                trims.append(None)
                continue
            if cls == 210:
                try:
                    surf, loops, note = _bounded_patch(path, entity, obj, pname)
                except _Unsupported as why:
                    key = why.args[0]
                    detail = f" ({why.args[1]})" if len(why.args) > 1 else ""
                    warnings.warn(f"{path}: {entity} skipped: {key}{detail}", UserWarning, stacklevel=2)
                    skipped[key] = skipped.get(key, 0) + 1
                    continue
                surfaces.append(surf)
                trims.append(loops)
                if note:
                    notes.append(f"{pname}: {note}")
                continue
        skipped[name] = skipped.get(name, 0) + 1
    model = build_model(path, "G2 text", surfaces, trims, skipped, contents)
    if not notes:
        return model
    return dataclasses.replace(model, source=model.source + "; " + "; ".join(notes))
