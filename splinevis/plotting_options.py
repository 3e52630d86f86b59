"""The keyword arguments of :class:`splinevis.Plotter` and its ``add_*`` methods, checked and translated before
anything is drawn: style options into a :class:`~splinevis.Style` (PyVista's names ``cmap`` and ``clim``
taken, its ``smooth_shading`` and the like refused with the reason), ``anti_aliasing``, ``window_size``, and the
reader's keywords (``spacing``, ``origin``, a volume's ``order``) passed with an array."""

from __future__ import annotations

import difflib
from dataclasses import fields

import numpy as np

from .effects import Style

__all__ = ["READ_KEYWORDS", "PYVISTA_ALIASES", "PYVISTA_REFUSED", "split_read_options"]


#: Keywords of ``add_terrain`` / ``add_isosurface`` that go to the reader: a numpy array's lattice and (a volume's)
#: axis order.
READ_KEYWORDS = ("spacing", "origin", "order")
#: PyVista's keyword names that mean one of ours.
PYVISTA_ALIASES = {"cmap": "colormap", "clim": "scalar_range"}
#: PyVista's keywords that do not apply to an exact surface, and why.
PYVISTA_REFUSED = {
    "smooth_shading": "every pixel is shaded with the surface's exact normal: there are no facets to smooth",
    "show_edges": "an exact surface has no edges to show; draw its mesh with add_mesh to see a tessellation",
    "scalars": "a spline is coloured by its own scalar (a terrain's height, a volume's value): colormap='viridis' "
               "shows it; other fields are not drawn on splines yet",
}


#: Why a terrain refuses ``order=``: a height array has one reading (:func:`splinevis.io.read_heights`).
_TERRAIN_ORDER = ("order= applies to volumes: add_isosurface and read_volume read a numpy volume as arr[i, j, k] "
                  "('xyz', as pyvista.wrap) or arr[k, j, i] ('zyx'). A height array has one reading: heights[j, i] "
                  "is the height at (x0 + i*dx, y0 + j*dy), rows along y (south to north), columns along x "
                  "(splinevis.io.read_heights); give an array indexed [x, y] as its transpose, heights.T. Drop "
                  "order=.")


def split_read_options(program: str, read_options, options) -> tuple:
    """``(read_options, other options)`` of ``Plotter.add_terrain`` / ``add_isosurface`` (``program``
    ``"terrain"`` or ``"isosurface"``): the reader's keywords of :data:`READ_KEYWORDS` given plainly, as PyVista
    users pass an array's spacing with it (``pv.wrap``), join ``read_options``. Done before the renderer is
    chosen, so a call reads the same data with or without ``max_error_px``. A keyword given both ways, or
    ``order=`` for a terrain, raises TypeError.

    >>> split_read_options("isosurface", None, {"order": "zyx", "spacing": (1, 1, 2), "colormap": "viridis"})
    ({'spacing': (1, 1, 2), 'order': 'zyx'}, {'colormap': 'viridis'})
    >>> split_read_options("terrain", {"spacing": 1.0}, {"spacing": 2.0})
    Traceback (most recent call last):
    TypeError: spacing given twice: as a keyword and in read_options.
    """
    read_options, options = dict(read_options or {}), dict(options)
    for key in READ_KEYWORDS:
        if key in options:
            if key in read_options:
                raise TypeError(f"{key} given twice: as a keyword and in read_options.")
            read_options[key] = options.pop(key)
    if program == "terrain" and "order" in read_options:
        raise TypeError(_TERRAIN_ORDER)
    return read_options, options


def _style_from(style, style_kwargs) -> Style:
    """The Style of ``style`` with ``style_kwargs`` (PyVista's ``cmap``, ``clim`` taken for ``colormap``,
    ``scalar_range``; ``smooth_shading`` and the like refused saying why).

    >>> _style_from(None, {"cmap": "viridis", "clim": (0, 1)}).colormap
    'viridis'
    >>> _style_from(None, {"smooth_shading": True})
    Traceback (most recent call last):
    TypeError: smooth_shading does not apply to a spline actor: every pixel is shaded with the surface's exact normal: there are no facets to smooth.
    """
    for pv_name, why in PYVISTA_REFUSED.items():
        if pv_name in style_kwargs:
            raise TypeError(f"{pv_name} does not apply to a spline actor: {why}.")
    for pv_name, ours in PYVISTA_ALIASES.items():
        if pv_name in style_kwargs:
            if ours in style_kwargs:
                raise TypeError(f"give {pv_name} (PyVista's name) or {ours}, not both.")
            style_kwargs = {(ours if k == pv_name else k): v for k, v in style_kwargs.items()}
    names = {f.name for f in fields(Style)}
    unknown = [k for k in style_kwargs if k not in names]
    if unknown:
        hints = []
        for k in unknown:
            close = difflib.get_close_matches(k, names, n=1)
            hints.append(f"{k!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise TypeError(f"unknown effect or style option {', '.join(hints)}; known: {', '.join(sorted(names))}.")
    if style is None:
        return Style(**style_kwargs)
    if not isinstance(style, Style):
        raise TypeError(f"style must be a splinevis.Style, got {type(style).__name__}.")
    return style.replace(**style_kwargs) if style_kwargs else style


def _anti_aliasing_choice(value) -> tuple:
    """``(kind for PyVista's enable_anti_aliasing or None, supersampling factor)`` of ``Plotter(anti_aliasing=)``.

    >>> _anti_aliasing_choice(False), _anti_aliasing_choice(4), _anti_aliasing_choice("ssaa")
    ((None, 1), (None, 4), ('ssaa', 1))
    >>> _anti_aliasing_choice(True)
    Traceback (most recent call last):
    ValueError: anti_aliasing=True is ambiguous: give False, a supersampling factor k >= 2 (k x k samples a pixel, e.g. anti_aliasing=2), or one of PyVista's 'ssaa', 'fxaa', 'msaa'.
    """
    if value is None or value is False:
        return None, 1
    if isinstance(value, str) and value in ("ssaa", "fxaa", "msaa"):
        return value, 1
    if not isinstance(value, bool) and isinstance(value, (int, np.integer)) and 1 <= value <= 8:
        return None, int(value)
    raise ValueError(f"anti_aliasing={value!r} is " + ("ambiguous" if value is True else "not known") + ": give "
                     "False, a supersampling factor k >= 2 (k x k samples a pixel, e.g. anti_aliasing=2), or one of "
                     "PyVista's 'ssaa', 'fxaa', 'msaa'.")


def _check_window_size(window_size) -> None:
    """ValueError unless ``window_size`` is two positive ints ``(width, height)``.

    >>> _check_window_size((0, 0))
    Traceback (most recent call last):
    ValueError: window_size=(0, 0) must be two positive pixel counts (width, height), e.g. window_size=(800, 600); a zero or negative size would silently render a 300 x 300 picture.
    """
    try:
        w, h = window_size
        ok = all(not isinstance(v, bool) and int(v) == v and int(v) > 0 for v in (w, h))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"window_size={window_size!r} must be two positive pixel counts (width, height), e.g. "
                         "window_size=(800, 600); a zero or negative size would silently render a 300 x 300 "
                         "picture.")
