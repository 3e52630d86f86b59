"""Input checks shared by every public entry point: validate first, then call a private worker.

Messages name the argument, the offending value or position, and what is accepted.
"""

from __future__ import annotations

import numpy as np

__all__ = ["as_float64_array", "check_finite", "check_degree", "check_choice"]


def as_float64_array(value, name: str, *, ndim: int | tuple | None = None, shape_tail: tuple | None = None,
                     finite: bool = True) -> np.ndarray:
    """Return ``value`` as a float64 array after checking its dimensions, trailing shape and finiteness.

    ``shape_tail`` lists the required sizes of the last axes (None for "any").

    Examples
    --------
    >>> as_float64_array([[1, 2, 3]], "points", shape_tail=(3,))
    array([[1., 2., 3.]])
    >>> as_float64_array([1, 2], "points", shape_tail=(3,))
    Traceback (most recent call last):
    ValueError: points must have shape (..., 3), got (2,).
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of real numbers; could not convert {type(value).__name__}: {exc}") from None
    if ndim is not None:
        allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
        if arr.ndim not in allowed:
            raise ValueError(f"{name} must have {' or '.join(map(str, allowed))} dimensions, got shape {arr.shape}.")
    if shape_tail is not None:
        tail = arr.shape[arr.ndim - len(shape_tail):] if arr.ndim >= len(shape_tail) else None
        ok = tail is not None and all(w is None or w == t for w, t in zip(shape_tail, tail))
        if not ok:
            want = "(..., " + ", ".join("*" if w is None else str(w) for w in shape_tail) + ")"
            raise ValueError(f"{name} must have shape {want}, got {arr.shape}.")
    if finite:
        check_finite(arr, name)
    return arr


def check_finite(arr: np.ndarray, name: str) -> None:
    """Raise ValueError naming the first non-finite entry of ``arr``.

    Examples
    --------
    >>> check_finite(np.array([[0.0, 1.0], [np.inf, np.nan]]), "heights")
    Traceback (most recent call last):
    ValueError: heights must have finite values; found 2 non-finite, the first inf at index (1, 0).
    """
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        count = int(bad.sum())
        raise ValueError(
            f"{name} must have finite values; found {count} non-finite, the first {float(arr[idx])!r} at index {idx}."
        )


def check_degree(degree, name: str = "degree", *, low: int = 0, high: int | None = None) -> int:
    """Return ``degree`` as an int after checking ``low <= degree <= high``.

    Examples
    --------
    >>> check_degree(np.int64(3), high=4)
    3
    >>> check_degree(5, "newton_iterations", low=1, high=4)
    Traceback (most recent call last):
    ValueError: newton_iterations must be in 1..4, got 5.
    """
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)):
        raise TypeError(f"{name} must be an integer, got {type(degree).__name__} {degree!r}.")
    degree = int(degree)
    if degree < low or (high is not None and degree > high):
        rng = f"{low}..{high}" if high is not None else f">= {low}"
        raise ValueError(f"{name} must be in {rng}, got {degree}.")
    return degree


def check_choice(value, name: str, choices) -> None:
    """Raise ValueError listing the accepted values when ``value`` is not one of ``choices``.

    Examples
    --------
    >>> check_choice("C1", "scheme", {"C1", "C2"})  # accepted: returns None
    >>> check_choice("C3", "scheme", {"C1", "C2"})
    Traceback (most recent call last):
    ValueError: scheme 'C3' is not known; choose one of: 'C1', 'C2'.
    """
    if value not in choices:
        raise ValueError(f"{name} {value!r} is not known; choose one of: {', '.join(map(repr, sorted(choices)))}.")
