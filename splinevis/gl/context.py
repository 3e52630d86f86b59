"""The one process-wide moderngl context, and a way to use it without disturbing anybody else's.

Every moderngl user in splinevis (the numeric harness :mod:`splinevis.gl.harness` and the pass runner
:mod:`splinevis.gl.passes`) draws with the same standalone EGL context: creating one costs tens of
milliseconds, and textures made by one user (a pass chain's result kept on the GPU) must be usable by the
next.

A process may hold other OpenGL contexts, typically the one of a VTK render window. OpenGL calls go to
whichever context is current on the thread, so moderngl work has to run inside :func:`current`, which
makes our context current and afterwards makes the caller's EGL context current again. This is done
with EGL directly rather than with moderngl's ``with ctx:``, for two reasons measured with VTK 9.7 and
glcontext 3.0 on Mesa:

* moderngl's exit leaves *no* context current instead of the caller's, and a nested ``with ctx:``
  releases the context at the inner exit;
* creating a VTK EGL render window, and finalizing one, destroys our context (VTK shares the EGL
  display with us and apparently terminates it); moderngl's enter then fails *silently* and every
  following GL call lands in VTK's context, which turned VTK's next picture black;

So :func:`current` checks that our context really became current, and when it was destroyed it makes a
new one (objects of the old one -- textures kept on the GPU by a caller -- are gone with it; the pass
runner refuses them with a clear error).
"""

from __future__ import annotations

import contextlib
import ctypes
import threading

from ..errors import OpenGLUnavailableError

__all__ = ["get_context", "current", "max_texture_size"]

_INSTALL_HINT = ("On Debian/Ubuntu install the packages libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 "
                 "(Mesa's llvmpipe software renderer is enough).")

_ctx = None  # the moderngl context
_own = None  # its (display, context) EGL handles
# One thread at a time may have the context current; the lock is re-entrant so helpers that enter
# current() can call other helpers that enter it again.
_lock = threading.RLock()
_depth = 0
_saved = None


def get_context():
    """The process-wide moderngl standalone context (EGL backend, OpenGL >= 3.3 core).

    Created on the first call, without changing which context is current for the caller. Issue GL
    calls with it only inside :func:`current` (``ctx.info`` is read at creation and may be used
    anywhere).

    Returns
    -------
    moderngl.Context

    Raises
    ------
    OpenGLUnavailableError
        When no context can be created; the message names the Debian packages that provide EGL and
        Mesa's software rasterizer.

    Examples
    --------
    >>> from splinevis.gl.context import get_context
    >>> ctx = get_context()
    >>> ctx is get_context()  # one context per process
    True
    >>> ctx.version_code >= 330
    True
    """
    global _ctx, _own
    with _lock:
        if _ctx is None:
            try:
                import moderngl
            except ImportError as exc:  # pragma: no cover - moderngl is a dependency
                raise OpenGLUnavailableError(f"moderngl is not installed ({exc}); pip install moderngl.") from None
            saved = _egl_current()
            try:
                ctx = moderngl.create_standalone_context(backend="egl", require=330)
                state = _egl_current()  # glcontext leaves the new context current: these are its handles
                ctx.info  # noqa: B018 - cached by moderngl; read now, while the context is current
            except Exception as exc:
                raise OpenGLUnavailableError(
                    "Could not create a headless OpenGL 3.3 context with EGL "
                    f"({type(exc).__name__}: {exc}). {_INSTALL_HINT}"
                ) from None
            finally:
                _egl_restore(saved, _egl_current())
            if state is None:  # pragma: no cover - glcontext always makes its new context current
                raise OpenGLUnavailableError("The new EGL context was not current after creation; "
                                             "cannot tell its handles. " + _INSTALL_HINT)
            _ctx, _own = ctx, (state[0], state[3])
        return _ctx


@contextlib.contextmanager
def current():
    """Make the process-wide context current for the block, then restore the caller's EGL context.

    Re-entrant: nested blocks (on the same thread) leave the context current until the outermost one
    ends. Other threads wait until the outermost block ends, because one context can be current on one
    thread only. If another EGL user destroyed our context since the last block (a VTK window
    terminating the shared display), a new context is made.

    Yields
    ------
    moderngl.Context

    Raises
    ------
    OpenGLUnavailableError
        When no context can be created or made current.

    Examples
    --------
    >>> from splinevis.gl.context import current
    >>> with current() as ctx:
    ...     tex = ctx.texture((2, 2), 4, dtype="f4")
    ...     tex.release()
    """
    global _depth, _saved, _ctx
    with _lock:
        if _depth == 0:
            saved = _egl_current()
            get_context()
            if not _make_own_current():
                _ctx = None  # destroyed under us: its objects are gone, make a fresh context
                get_context()
                if not _make_own_current():
                    _egl_restore(saved, None)
                    raise OpenGLUnavailableError("Could not make the moderngl EGL context current. " + _INSTALL_HINT)
            _saved = saved
        _depth += 1
        try:
            yield _ctx
        finally:
            _depth -= 1
            if _depth == 0:
                _egl_restore(_saved, _egl_current())
                _saved = None


def max_texture_size() -> int:
    """``GL_MAX_TEXTURE_SIZE`` of the process-wide context: the largest width or height of a texture.

    Returns
    -------
    int

    Examples
    --------
    >>> from splinevis.gl.context import max_texture_size
    >>> max_texture_size() >= 8192  # Mesa llvmpipe: 16384
    True
    """
    return int(get_context().info.get("GL_MAX_TEXTURE_SIZE", 8192))


# --------------------------------------------------------------------------------------------------
# EGL through ctypes. glcontext (moderngl's EGL backend) loads libEGL, so it is in the process whenever
# a context exists; loading it again returns the same library.
# --------------------------------------------------------------------------------------------------
_egl = None
_EGL_DRAW = 0x3059
_EGL_READ = 0x305A


def _egl_lib():
    global _egl
    if _egl is None:
        try:
            lib = ctypes.CDLL("libEGL.so.1")
        except OSError:
            _egl = False
            return None
        for name in ("eglGetCurrentDisplay", "eglGetCurrentContext"):
            getattr(lib, name).restype = ctypes.c_void_p
            getattr(lib, name).argtypes = []
        lib.eglGetCurrentSurface.restype = ctypes.c_void_p
        lib.eglGetCurrentSurface.argtypes = [ctypes.c_int32]
        lib.eglMakeCurrent.restype = ctypes.c_uint32
        lib.eglMakeCurrent.argtypes = [ctypes.c_void_p] * 4
        _egl = lib
    return _egl or None


def _egl_current():
    """(display, draw, read, context) current on this thread, or None when no EGL context is current."""
    lib = _egl_lib()
    if lib is None or not lib.eglGetCurrentContext():
        return None
    return (lib.eglGetCurrentDisplay(), lib.eglGetCurrentSurface(_EGL_DRAW), lib.eglGetCurrentSurface(_EGL_READ),
            lib.eglGetCurrentContext())


def _make_own_current() -> bool:
    """Make our context current (surfaceless, as glcontext made it) and check that it is."""
    lib = _egl_lib()
    display, context = _own
    return bool(lib.eglMakeCurrent(display, None, None, context)) and lib.eglGetCurrentContext() == context


def _egl_restore(saved, now) -> None:
    """Make ``saved`` current again, or release ``now`` when nothing was current before."""
    lib = _egl_lib()
    if lib is None:
        return
    if saved is not None:
        if saved != now:
            lib.eglMakeCurrent(*saved)
    elif now is not None:
        lib.eglMakeCurrent(now[0], None, None, None)
