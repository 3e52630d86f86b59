"""Headless OpenGL: choose EGL or OSMesa before VTK's first window, and fail loudly when neither works.

VTK's wheels pick their offscreen window class at run time from ``VTK_DEFAULT_OPENGL_WINDOW``. With the
variable unset and no X display, VTK warns about X and falls back to EGL; with no GL library at all it
prints warnings and renders black images, and Python sees no exception. :func:`configure` decides
before the first window, :func:`check_render_window` verifies a live window and raises
:class:`~splinevis.errors.OpenGLUnavailableError` naming the Debian packages to install.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

from ..errors import OpenGLUnavailableError

__all__ = ["configure", "check_render_window", "gl_info", "INSTALL_HINT", "backend_libraries"]

#: What to run on Debian/Ubuntu when no context can be made.
INSTALL_HINT = (
    "apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 libosmesa6 "
    "(or run `make setup` in the splinevis repository)"
)

_WINDOW_CLASS = {"egl": "vtkEGLRenderWindow", "osmesa": "vtkOSOpenGLRenderWindow", "x": "vtkXOpenGLRenderWindow"}
# Shared objects each backend needs to be loadable (the Mesa EGL vendor library or OSMesa itself; GLX and X11).
_LIBRARIES = {"egl": ("libEGL.so.1", "libEGL_mesa.so.0", "libGL.so.1"), "osmesa": ("libOSMesa.so.8",),
              "x": ("libGL.so.1", "libX11.so.6")}


def _loadable(name: str) -> bool:
    try:
        ctypes.CDLL(name)
        return True
    except OSError:
        return False


def backend_libraries() -> dict:
    """Which of each backend's libraries load here, e.g. ``{"egl": {"libEGL.so.1": True, ...}, ...}``.

    Examples
    --------
    >>> libs = backend_libraries()
    >>> sorted(libs), list(libs["osmesa"])
    (['egl', 'osmesa', 'x'], ['libOSMesa.so.8'])
    """
    return {b: {lib: _loadable(lib) for lib in libs} for b, libs in _LIBRARIES.items()}


def _display_opens() -> bool:
    """Whether ``DISPLAY`` is set and an X server accepts a connection there (Xlib's ``XOpenDisplay``)."""
    if not os.environ.get("DISPLAY") or not all(backend_libraries()["x"].values()):
        return False
    try:
        x11 = ctypes.CDLL("libX11.so.6")
        x11.XOpenDisplay.restype = ctypes.c_void_p
        x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
        display = x11.XOpenDisplay(None)
        if not display:
            return False
        x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
        x11.XCloseDisplay(display)
        return True
    except OSError:
        return False


def configure(backend: str | None = None) -> str:
    """Select the headless window class for VTK and return the backend name (``"egl"`` or ``"osmesa"``).

    Order of precedence: the ``backend`` argument, the environment variable ``SPLINEVIS_GL``, an already
    set ``VTK_DEFAULT_OPENGL_WINDOW`` (respected as the user's choice), then ``"x"`` (VTK's X window, so
    ``show()`` opens a window the user can turn with the mouse) when ``DISPLAY`` names an X server that accepts
    a connection, then EGL if its libraries load, then OSMesa. Must run before VTK creates its first render window; :mod:`splinevis.plotting` calls it
    on import.

    Raises
    ------
    OpenGLUnavailableError
        If the requested backend's libraries cannot be loaded, or no backend can.
    ValueError
        For an unknown backend name.

    Examples
    --------
    >>> configure() in ("egl", "osmesa", "x")  # keeps the choice already made (splinevis.plotting made one)
    True
    >>> configure("directx")
    Traceback (most recent call last):
    ValueError: OpenGL backend 'directx' is not known; choose 'egl', 'osmesa' or 'x' (SPLINEVIS_GL).
    """
    requested = backend or os.environ.get("SPLINEVIS_GL") or None
    if requested is None and os.environ.get("VTK_DEFAULT_OPENGL_WINDOW") in _WINDOW_CLASS.values():
        return {v: k for k, v in _WINDOW_CLASS.items()}[os.environ["VTK_DEFAULT_OPENGL_WINDOW"]]
    libs = backend_libraries()
    if requested is not None:
        requested = requested.lower()
        if requested not in _WINDOW_CLASS:
            raise ValueError(f"OpenGL backend {requested!r} is not known; choose 'egl', 'osmesa' or 'x' (SPLINEVIS_GL).")
        candidates = [requested]
    else:
        candidates = (["x"] if _display_opens() else []) + ["egl", "osmesa"]
    for name in candidates:
        if all(libs[name].values()):
            os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = _WINDOW_CLASS[name]
            return name
    missing = {b: [lib for lib, ok in libs[b].items() if not ok] for b in candidates}
    detail = "; ".join(f"{b}: cannot load {', '.join(m)}" for b, m in missing.items())
    raise OpenGLUnavailableError(f"No headless OpenGL backend is usable ({detail}). Install with: {INSTALL_HINT}")


def check_render_window(render_window) -> dict:
    """Verify that ``render_window`` (a rendered vtkRenderWindow) has a real OpenGL context.

    Returns the :func:`gl_info`-style dict. Raises :class:`OpenGLUnavailableError` when the window is not
    a headless class we configured, or when the driver reports no renderer (VTK's silent failure).

    Examples
    --------
    >>> import vtkmodules.vtkRenderingOpenGL2  # registers the OpenGL window classes
    >>> from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
    >>> backend = configure()
    >>> win = vtkRenderWindow()
    >>> win.SetOffScreenRendering(True)
    >>> win.SetSize(1, 1)
    >>> win.AddRenderer(vtkRenderer())
    >>> win.Render()
    >>> info = check_render_window(win)
    >>> info["window_class"] == _WINDOW_CLASS[backend], bool(info["renderer"])
    (True, True)
    >>> win.Finalize()
    """
    info = _parse_capabilities(render_window)
    info["window_class"] = render_window.GetClassName()
    if not info.get("renderer") or not info.get("version"):
        raise OpenGLUnavailableError(
            f"VTK's {info['window_class']} has no working OpenGL context (renderer string is empty), so it "
            f"would render blank images. Install with: {INSTALL_HINT}"
        )
    return info


def _parse_capabilities(render_window) -> dict:
    text = render_window.ReportCapabilities() or ""
    out = {"vendor": "", "renderer": "", "version": ""}
    for line in text.splitlines():
        key, _, value = line.partition(":")
        key = key.strip().lower()
        if key == "opengl vendor string":
            out["vendor"] = value.strip()
        elif key == "opengl renderer string":
            out["renderer"] = value.strip()
        elif key == "opengl version string":
            out["version"] = value.strip()
    return out


def gl_info(backend: str | None = None) -> dict:
    """Make a 1x1 offscreen VTK window and report vendor, renderer, version and window class.

    Raises :class:`OpenGLUnavailableError` when no context can be made.

    Examples
    --------
    >>> from splinevis.gl.headless import gl_info
    >>> info = gl_info()
    >>> sorted(info)
    ['backend', 'renderer', 'vendor', 'version', 'window_class']
    """
    name = configure(backend)
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL window classes)

    win = vtkRenderWindow()
    win.SetOffScreenRendering(True)
    win.SetSize(1, 1)
    win.AddRenderer(vtkRenderer())
    try:
        win.Render()
        info = check_render_window(win)
    finally:
        win.Finalize()
    info["backend"] = name
    if info["window_class"] != _WINDOW_CLASS[name]:
        raise OpenGLUnavailableError(
            f"VTK made a {info['window_class']} although {_WINDOW_CLASS[name]} was requested; this VTK build "
            "may lack headless support (use the vtk wheel from PyPI, which has EGL and OSMesa)."
        )
    return info
