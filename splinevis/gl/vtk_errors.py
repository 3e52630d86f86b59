"""VTK's reports turned into Python: the text VTK sends to its output window collected
(:class:`capture_vtk_errors`), and a shader compile or link failure in it raised as
:class:`~splinevis.errors.ShaderCompileError` with the log, the source and the GLSL file and line each error
comes from (:func:`raise_for_shader_errors`). VTK prints a failed compile and carries on rendering a blank
picture; these make it an exception."""

from __future__ import annotations

import re

from ..errors import ShaderCompileError
from .assembler import Assembled

__all__ = ["capture_vtk_errors", "raise_for_shader_errors"]


class capture_vtk_errors:
    """Context manager collecting the text VTK sends to its output window (errors and warnings).

    VTK reports a failed shader compile on its output window and carries on rendering; this is how we
    turn that into a Python exception.

    Examples
    --------
    >>> from vtkmodules.vtkCommonCore import vtkOutputWindow
    >>> with capture_vtk_errors() as captured:
    ...     vtkOutputWindow.GetInstance().DisplayErrorText("shader failed")
    >>> captured.text
    'shader failed\\n'
    """

    def __enter__(self):
        from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow

        self._window = vtkStringOutputWindow()
        self._previous = vtkOutputWindow.GetInstance()
        vtkOutputWindow.SetInstance(self._window)
        return self

    def __exit__(self, *exc):
        from vtkmodules.vtkCommonCore import vtkOutputWindow

        vtkOutputWindow.SetInstance(self._previous)
        self.text = self._window.GetOutput() or ""
        return False


_NUMBERED = re.compile(r"^(\d+): ?(.*)$")


def raise_for_shader_errors(text: str, assembled: Assembled | None = None) -> None:
    """Raise :class:`ShaderCompileError` if ``text`` (VTK's output) reports a shader compile/link failure.

    >>> raise_for_shader_errors("vtkOpenGLRenderer: nothing went wrong")  # no shader error: nothing raised
    >>> raise_for_shader_errors("ERROR: In vtkShaderProgram.cxx, line 453\\nvtkShaderProgram (0x1): 0:3(1): error: bad")
    Traceback (most recent call last):
    splinevis.errors.ShaderCompileError: ...
    """
    if "vtkShaderProgram" not in text or not re.search(r"error", text, re.IGNORECASE):
        return
    source_lines, log_lines = [], []
    for raw in text.splitlines():
        body = raw.split("): ", 1)[1] if "vtkShaderProgram (" in raw and "): " in raw else raw
        m = _NUMBERED.match(body)
        if m and not re.match(r"^\d+:\d+\(\d+\)", body):
            source_lines.append(m.group(2))
        elif re.search(r"In vtk\w+\.cxx, line", body):
            continue
        elif re.search(r"\d+:\d+\(\d+\):|error|ERROR", body):
            log_lines.append(body.strip())
    source = "\n".join(source_lines)
    stage = "fragment" if "fragOutput0" in source else ("vertex" if "gl_Position" in source else "unknown")
    origin = assembled.origin_in(source) if assembled is not None and source else None
    raise ShaderCompileError("\n".join(log_lines), source, stage, origin)
