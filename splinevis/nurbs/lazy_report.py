"""A report dict whose costly entries are measured on first use (the seams' continuity of
:func:`splinevis.nurbs.orient.orient_faces`): reading a model to draw it does not pay for them."""

from __future__ import annotations

__all__ = ["LazyReport"]


class LazyReport(dict):
    """A report dict some of whose entries are measured on first use: any read of the dict (``[]``, ``get``,
    ``in``, iteration, ``len``, printing, pickling) measures them first. The seams' continuity costs as much as
    the orientation itself (second derivatives and curve feet at every shared sample: 1.2 s of a 288-face
    part's 3 s), and a model read only to be drawn never looks at it.

    >>> r = LazyReport({"faces": 2}, lambda: {"seams": ["measured"]})
    >>> r["faces"], r["seams"], sorted(r)
    (2, ['measured'], ['faces', 'seams'])
    """

    def __init__(self, data, pending):
        super().__init__(data)
        self._pending = pending

    def _fill(self):
        if self._pending is not None:
            pending, self._pending = self._pending, None
            super().update(pending())

    def __missing__(self, key):
        self._fill()
        if dict.__contains__(self, key):
            return dict.__getitem__(self, key)
        raise KeyError(key)

    def get(self, key, default=None):
        """``dict.get`` after the pending entries are measured.

        >>> LazyReport({}, lambda: {"a": 1}).get("a")
        1
        """
        self._fill()
        return super().get(key, default)

    def __contains__(self, key):
        self._fill()
        return super().__contains__(key)

    def __iter__(self):
        self._fill()
        return super().__iter__()

    def __len__(self):
        self._fill()
        return super().__len__()

    def keys(self):
        """``dict.keys`` after the pending entries are measured.

        >>> list(LazyReport({"a": 1}, lambda: {"b": 2}).keys())
        ['a', 'b']
        """
        self._fill()
        return super().keys()

    def values(self):
        """``dict.values`` after the pending entries are measured.

        >>> list(LazyReport({"a": 1}, lambda: {"b": 2}).values())
        [1, 2]
        """
        self._fill()
        return super().values()

    def items(self):
        """``dict.items`` after the pending entries are measured.

        >>> list(LazyReport({}, lambda: {"b": 2}).items())
        [('b', 2)]
        """
        self._fill()
        return super().items()

    def copy(self):
        """A plain dict of every entry, the pending ones measured.

        >>> LazyReport({"a": 1}, lambda: {"b": 2}).copy()
        {'a': 1, 'b': 2}
        """
        self._fill()
        return dict(super().items())

    def __repr__(self):
        self._fill()
        return super().__repr__()

    def __eq__(self, other):
        self._fill()
        return super().__eq__(other)

    __hash__ = None

    def __reduce__(self):
        self._fill()
        return (dict, (dict(super().items()),))
