"""Warnings attributed to the user's line: the first caller outside the splinevis package (Python 3.11 has no
``warnings.warn(skip_file_prefixes=...)``), so a warning raised deep in a reader or a model points at the
``add_*`` or ``read_*`` call that caused it."""

from __future__ import annotations

import os
import sys
import warnings

__all__ = ["warn_user"]

_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def warn_user(message: str, category=UserWarning) -> None:
    """``warnings.warn(message, category)`` with the stack level of the first frame outside splinevis.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_user("look here")
    >>> str(caught[0].message), caught[0].filename.endswith("_warnings.py")
    ('look here', False)
    """
    level, frame = 1, sys._getframe(1)
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level + 1)
