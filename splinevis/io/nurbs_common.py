"""What every NURBS file reader shares: entity errors prefixed with the file, the model assembled with what was
skipped (see :mod:`.nurbs_files` for the conventions), and the damage report of a broken file.

Damaged files
-------------
A CAD file can be damaged so that the CAD library still reads part of it without a word (an IGES whose
parameter lines were overwritten or cut off, a STEP whose ``#123`` points nowhere): the model would then be
drawn with faces missing. The IGES and STEP readers therefore check the file's structure first and describe
what they found in a :class:`Damage` (the problems, in the file's own terms, and how many faces they cost).
By default a damaged file raises :class:`DamagedFileError` (a ValueError) naming the file, what was expected
and what was found; with ``partial=True`` the intact faces are read and the loss is announced by a warning,
``NurbsModel.skipped`` (``"damaged <entity>"`` -> count) and ``NurbsModel.source``.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..nurbs import NurbsModel, NurbsSurface, TrimCurve

__all__ = ["build_model", "checked", "flip_v", "Damage", "DamagedFileError"]

#: Problems quoted in a damage message (the rest are counted).
_SHOWN = 6


class Damage:
    """What a structural check of a file found: ``problems`` (sentences in the file's own terms, e.g.
    ``"directory entry 57 (type 128) points to parameter lines 1201-1230, the file ends at line 900"``),
    the faces the file promises (``expected``), the faces lost, by
    entity kind (``lost``: kind -> count), and ``unreadable``: records too damaged to tell what they held (in
    ``"unreadable ..."`` words of the format, ``unreadable_what``); ``cut``: the file was cut off where it
    no longer says which faces followed (``expected`` then counts the faces before the cut).

    >>> d = Damage("IGES", ["the file ends at line 9 without the terminate (T) record"], 3, {"144 (trimmed surface)": 2})
    >>> bool(d), d.lost_total, d.summary()
    (True, 2, '2 of 3 faces cannot be read (2 x 144 (trimmed surface))')
    >>> bool(Damage("IGES", [], 3, {}))
    False
    """

    def __init__(self, fmt: str, problems, expected, lost: dict, unreadable: int = 0,
                 unreadable_what: str = "records", cut: bool = False):
        self.fmt, self.problems, self.expected, self.cut = fmt, list(problems), expected, cut
        self.lost = {k: int(n) for k, n in lost.items() if n}
        self.unreadable, self.unreadable_what = int(unreadable), unreadable_what

    def __bool__(self) -> bool:
        return bool(self.problems)

    @property
    def lost_total(self) -> int:
        """The faces lost, all kinds together.

        >>> Damage("STEP", ["#7 (PLANE, line 9) refers to #99"], 4, {"ADVANCED_FACE": 1, "FACE_SURFACE": 2}).lost_total
        3
        """
        return sum(self.lost.values())

    def summary(self) -> str:
        """How many faces the damage costs, by kind.

        >>> Damage("STEP", ["cut off"], 3, {"ADVANCED_FACE": 1}, cut=True).summary()
        '1 of the 3 faces named before the cut cannot be read (1 x ADVANCED_FACE), and the faces after the cut are lost'
        """
        kinds = ", ".join(f"{n} x {k}" for k, n in self.lost.items())
        if self.cut:
            text = f"{self.lost_total} of the {self.expected} faces named before the cut cannot be read"
        else:
            text = f"{self.lost_total} of {self.expected} faces cannot be read"
        text += f" ({kinds})" if kinds else ""
        if self.unreadable:
            text += f", and {self.unreadable} {self.unreadable_what} are unreadable (what they held is lost)"
        if self.cut:
            text += ", and the faces after the cut are lost"
        return text

    def listing(self) -> str:
        """The first problems, and how many more.

        >>> Damage("IGES", [f"problem {k}" for k in range(8)], 1, {}).listing()
        'problem 0; problem 1; problem 2; problem 3; problem 4; problem 5; ... and 2 more problems'
        """
        shown = "; ".join(self.problems[:_SHOWN])
        more = len(self.problems) - _SHOWN
        return shown + (f"; ... and {more} more problem{'s' if more > 1 else ''}" if more > 0 else "")


class DamagedFileError(ValueError):
    """A file whose structure is broken (see the module notes); ``damage`` holds the :class:`Damage`.

    >>> err = DamagedFileError("a.igs", Damage("IGES", ["line 7 is not an IGES record"], 2, {"128 (rational B-spline surface)": 1}))
    >>> print(err)
    a.igs: damaged IGES file, 1 of 2 faces cannot be read (1 x 128 (rational B-spline surface)): line 7 is not an IGES record. Get an intact copy of the file, or read the intact faces with read_nurbs(path, partial=True).
    """

    def __init__(self, path, damage: Damage):
        self.path, self.damage = path, damage
        what = "no face is intact" if damage.lost_total >= damage.expected else \
            "or read the intact faces with read_nurbs(path, partial=True)"
        super().__init__(f"{path}: damaged {damage.fmt} file, {damage.summary()}: {damage.listing()}. Get an intact "
                         f"copy of the file, {what}.")


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


def build_model(path, kind: str, surfaces, trims, skipped: dict, contents: dict | None = None,
                damage: Damage | None = None) -> NurbsModel:
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
    damage : Damage, optional
        What a partial read of a damaged file lost: added to ``skipped`` as ``"damaged <kind>"``, to
        ``source`` and to a UserWarning with the problems.

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
    if not surfaces and damage:
        raise DamagedFileError(path, damage)
    if not surfaces:
        everything = contents if contents is not None else skipped
        what = ", ".join(f"{n} x {k}" for k, n in everything.items() if n) or "nothing"
        raise ValueError(f"{path} holds no supported NURBS surface ({kind}); it contains: {what}.")
    if skipped:
        warnings.warn(f"{path}: skipped unsupported entities: {listing}", UserWarning, stacklevel=3)
    if damage:
        warnings.warn(f"{path}: damaged {damage.fmt} file read in part: {len(surfaces)} faces read, "
                      f"{damage.summary()}: {damage.listing()}", UserWarning, stacklevel=3)
        kind = f"{kind}; DAMAGED, read in part: {damage.summary()}"
        for k, n in damage.lost.items():
            skipped[f"damaged {k}"] = skipped.get(f"damaged {k}", 0) + n
        if damage.unreadable:
            skipped[f"unreadable {damage.unreadable_what}"] = damage.unreadable
    source = f"{path} ({kind})" + (f"; skipped {listing}" if listing else "")
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
