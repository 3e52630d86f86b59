"""PyVista's ``server`` Jupyter backend for splinevis plotters: trame streams pictures rendered by VTK here.

A trame ``VtkRemoteView`` (trame-pyvista's ``PyVistaRemoteView``) renders the plotter's own offscreen VTK window
on the kernel's side and sends the pictures to the browser. Our GLSL runs there like in any render: the
per-frame uniforms (camera, projection) are set by each mapper's ``UpdateShaderEvent`` observer
(:mod:`splinevis.gl.inject`), which fires in every ``Render()`` of the window, whoever calls it; so the view
needs nothing of ours. Two things differ from trame-pyvista's own launch (``trame_pyvista.jupyter``), and are why
this module exists:

* only the widgets a server-rendered view uses are enabled (vtk, vuetify, html). trame-pyvista also enables
  trame-vtklocal's WebAssembly view, whose set-up downloads VTK's WASM bundle from the internet when the server
  starts (and fails offline), and which, like vtk.js, would render in the browser without our GLSL;
* the server starts as a task on the event loop already running in the kernel's main thread (ipykernel's), and
  the cell returns at once: the server is listening by the time the browser loads the frame, and its renders run
  on that thread, the one that made the GL context. trame-pyvista instead blocks until ready through
  ``nest_asyncio2``, a patch of asyncio.

:func:`register` adds the handler to PyVista under the name :data:`BACKEND`; ``splinevis.Plotter.show`` maps
``jupyter_backend='server'`` to it.
"""

from __future__ import annotations

import asyncio
import importlib
import itertools
import os
import socket

__all__ = ["BACKEND", "INSTALL_HINT", "launch", "register", "show_server", "view_url"]

#: The name under which :func:`show_server` is registered with PyVista.
BACKEND = "splinevis-server"

#: What to install when trame is missing.
INSTALL_HINT = ("jupyter_backend='server' needs trame and PyVista's trame views: pip install trame-pyvista "
                "(add jupyter-server-proxy when the notebook runs on a remote Jupyter server)")

_SERVERS = {}  # id of the event loop -> (server, port, start task): one per kernel; a new loop gets a new one
_COUNT = itertools.count()


def _trame():
    try:
        importlib.import_module("trame_pyvista.jupyter")
    except ImportError as err:
        raise ImportError(f"{INSTALL_HINT} ({err})") from err


def _free_port(host: str) -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def launch(port: int | None = None, host: str | None = None):
    """The trame server of the running event loop, started on its first call: ``(server, port)``.

    The server listens on ``host`` (default: ``TRAME_DEFAULT_HOST`` or 127.0.0.1) at ``port`` (default: PyVista's
    ``global_theme.trame.jupyter_server_port``, or a free port when that is 0); its start is a task of the running
    loop, so it listens once the caller yields to the loop (a Jupyter cell returning). ``server.ready`` is the
    future to await where the caller can. Raises ``RuntimeError`` outside a running loop (a plain script).

    >>> async def cell():
    ...     server, port = launch()
    ...     await server.ready  # what a notebook does by returning from the cell
    ...     same = launch()[0] is server
    ...     await server.stop()
    ...     return same and port > 0
    >>> asyncio.run(cell())
    True
    """
    _trame()
    import pyvista as pv
    from trame.widgets import html, vtk, vuetify3
    from trame_pyvista.widgets import get_server

    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        raise RuntimeError("jupyter_backend='server' runs trame on the kernel's event loop: use it in Jupyter "
                           "(a plain script has no running loop; draw with off_screen=True and save screenshots, "
                           "or call pyvista's trame_pyvista.show_trame yourself)") from None
    if id(loop) in _SERVERS and not _SERVERS[id(loop)][2].done():  # a stopped server's task is done
        return _SERVERS[id(loop)][:2]
    host = host or os.environ.get("TRAME_DEFAULT_HOST", "127.0.0.1")
    port = port or pv.global_theme.trame.jupyter_server_port or _free_port(host)
    server = get_server(f"splinevis-{next(_COUNT)}", client_type="vue3")
    for widgets in (html, vtk, vuetify3):
        widgets.initialize(server)
    task = server.start(exec_mode="task", host=host, port=port, open_browser=False, show_connection_info=False,
                        disable_logging=True, timeout=0, backend="aiohttp", thread=True)
    _SERVERS[id(loop)] = (server, port, task)
    return server, port


def view_url(port: int, ui: str, *, host: str = "localhost", protocol: str = "http",
             server_proxy_enabled: bool | None = None, server_proxy_prefix: str | None = None) -> str:
    """The address of the page of ``ui`` (a plotter's layout) on the trame server at ``port``: direct, or through
    jupyter-server-proxy as PyVista's theme says (``global_theme.trame.server_proxy_enabled`` and ``_prefix``).

    >>> view_url(8123, "P_1")
    'http://localhost:8123/index.html?ui=P_1&reconnect=auto'
    >>> view_url(8123, "P_1", server_proxy_enabled=True, server_proxy_prefix="proxy/")
    'proxy/8123/index.html?ui=P_1&reconnect=auto'
    """
    import pyvista as pv

    if server_proxy_enabled is None:
        server_proxy_enabled = pv.global_theme.trame.server_proxy_enabled
    if server_proxy_prefix is None:
        server_proxy_prefix = pv.global_theme.trame.server_proxy_prefix
    page = f"{port}/index.html?ui={ui}&reconnect=auto"
    if server_proxy_enabled:
        return f"{server_proxy_prefix or ''}{page}"
    return f"{protocol}://{host}:{page}"


def show_server(plotter, screenshot=None, *, width=None, height=None, collapse_menu: bool = False,
                add_menu: bool = True, handler=None, **kwargs):
    """PyVista's ``server`` backend for ``plotter``: a trame page of one server-rendered view (no switch to
    client rendering), returned as an ``IPython.display.IFrame`` of ``width`` x ``height`` (default: the window's
    size). ``handler(viewer, src, **kwargs)``, as in PyVista, makes another output from the page's address.
    ``host``, ``protocol``, ``server_proxy_enabled`` and ``server_proxy_prefix`` go to :func:`view_url`; ``port``
    to :func:`launch`. ``screenshot`` (PyVista's argument) is taken by the caller's ``show``.

    >>> from splinevis import Plotter
    >>> async def cell():
    ...     pl = Plotter(off_screen=True, window_size=(64, 48))
    ...     frame = show_server(pl)
    ...     await launch()[0].ready
    ...     await launch()[0].stop()
    ...     pl.close()
    ...     return frame.src.startswith("http://localhost:"), frame.width
    >>> asyncio.run(cell())
    (True, '64px')
    """
    _trame()
    from IPython.display import IFrame
    from trame_pyvista.jupyter import initialize

    url_keys = ("host", "protocol", "server_proxy_enabled", "server_proxy_prefix")
    url_kwargs = {k: kwargs.pop(k) for k in url_keys if k in kwargs}
    server, port = launch(kwargs.pop("port", None))
    viewer = initialize(server, plotter, mode="server", collapse_menu=collapse_menu, add_menu=add_menu)
    src = view_url(port, plotter._id_name, **url_kwargs)
    w, h = plotter.window_size
    width, height = width or f"{w}px", height or f"{h}px"
    if callable(handler):
        return handler(viewer, src, width=width, height=height, **kwargs)
    return IFrame(src, width, height, **kwargs)


def register() -> str:
    """Register :func:`show_server` with PyVista as :data:`BACKEND` (once); returns the name.

    >>> import pyvista as pv
    >>> register() == BACKEND and BACKEND in [b.name for b in pv.registered_jupyter_backends()]
    True
    """
    import pyvista as pv

    if all(b.name != BACKEND for b in pv.registered_jupyter_backends()):
        pv.register_jupyter_backend(BACKEND, show_server)
    return BACKEND
