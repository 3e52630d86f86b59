"""What every NURBS file reader shares: entity errors prefixed with the file, and the model assembled with
what was skipped (see :mod:`.nurbs_files` for the conventions)."""

from __future__ import annotations

import warnings

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve

__all__ = ["build_model", "checked", "flip_v"]


def checked(path, entity: str, make):
    """Call ``make()`` (which builds a NurbsSurface or TrimCurve); prefix its ValueError with the file and entity.

    Examples
    --------
    >>> checked("a.igs", "entity 128 #3", lambda: TrimCurve(1, [0, 0, 1, 1], [[0, 0], [1, 1]], [1, 0]))
    Traceback (most recent call last):
    ValueError: a.igs: entity 128 #3: trim curve weights must be 2 positive numbers, got [1, 0].
    """
    try:
        return make()
    except ValueError as err:
        raise ValueError(f"{path}: {entity}: {err}") from None


def build_model(path, kind: str, surfaces, trims, skipped: dict, contents: dict | None = None) -> NurbsModel:
    """Assemble a reader's result: warn about skipped entities, refuse a file without surfaces.

    Parameters
    ----------
    path : path-like
        The file, for the messages and ``source``.
    kind : str
        The format and the library that read it, e.g. ``"IGES (OCP)"``.
    surfaces, trims : lists
        One trims entry (None or a list of loops) per surface.
    skipped : dict
        Entity type -> count of what was not read.
    contents : dict, optional
        Entity type -> count of everything in the file (for the error when nothing was read); defaults
        to ``skipped``.

    Examples
    --------
    >>> s = NurbsSurface.bilinear([[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]], name="quad")
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     m = build_model("a.igs", "IGES (pyiges)", [s], [None], {"110 (line)": 2})
    >>> m.source, m.skipped, str(w[0].message)
    ('a.igs (IGES (pyiges)); skipped 2 x 110 (line)', {'110 (line)': 2}, 'a.igs: skipped unsupported entities: 2 x 110 (line)')
    >>> build_model("b.igs", "IGES (pyiges)", [], [], {"110 (line)": 2})
    Traceback (most recent call last):
    ValueError: b.igs holds no supported NURBS surface (IGES (pyiges)); it contains: 2 x 110 (line).
    """
    skipped = {k: int(v) for k, v in skipped.items() if v}
    listing = ", ".join(f"{n} x {k}" for k, n in skipped.items())
    if not surfaces:
        everything = contents if contents is not None else skipped
        what = ", ".join(f"{n} x {k}" for k, n in everything.items() if n) or "nothing"
        raise ValueError(f"{path} holds no supported NURBS surface ({kind}); it contains: {what}.")
    source = f"{path} ({kind})" + (f"; skipped {listing}" if skipped else "")
    if skipped:
        warnings.warn(f"{path}: skipped unsupported entities: {listing}", UserWarning, stacklevel=3)
    return NurbsModel(surfaces, trims, source=source, skipped=skipped)


def flip_v(surface: NurbsSurface, loops):
    """The same surface with v running backwards (so S_u x S_v flips), and its trim loops mapped alike: how a
    reversed face (its outside the surface's back) is brought to the convention normal = outside.

    >>> from splinevis.nurbs.exact import saddle
    >>> s, _ = flip_v(saddle(), None)
    >>> bool(np.allclose(s.normal([0.3], [0.4]), -saddle().normal([0.3], [0.6]), atol=1e-15))
    True
    """
    V = surface.knots[1]
    a, b = surface.domain[1]
    flipped = NurbsSurface(surface.degree, (surface.knots[0], (a + b) - V[::-1]), surface.control_points[:, ::-1],
                           None if surface.weights is None else surface.weights[:, ::-1], name=surface.name)
    if loops is None:
        return flipped, None
    mirror = np.array([1.0, -1.0])
    new = [[TrimCurve(c.degree, c.knots, c.control_points * mirror + [0.0, a + b], c.weights) for c in loop]
           for loop in loops]
    return flipped, new
