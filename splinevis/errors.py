"""Exceptions raised by splinevis.

Each subclasses a built-in so callers can catch broadly, and each message says what went wrong, where,
and what to do about it.
"""

from __future__ import annotations

import re

__all__ = [
    "SplinevisError",
    "OpenGLUnavailableError",
    "ShaderIncludeError",
    "ShaderCompileError",
    "MeshTopologyError",
]


class SplinevisError(Exception):
    """Base class of all splinevis errors.

    Examples
    --------
    >>> issubclass(ShaderCompileError, SplinevisError), issubclass(ShaderCompileError, RuntimeError)
    (True, True)
    """


class OpenGLUnavailableError(SplinevisError, RuntimeError):
    """No OpenGL context could be made (VTK would otherwise render blank images silently).

    Examples
    --------
    >>> try:
    ...     raise OpenGLUnavailableError("no EGL display")
    ... except RuntimeError as exc:  # caught as a RuntimeError too
    ...     print(type(exc).__name__, exc)
    OpenGLUnavailableError no EGL display
    """


class ShaderIncludeError(SplinevisError, FileNotFoundError):
    """A ``#include`` in a GLSL file names a file that does not exist, or includes form a cycle.

    Examples
    --------
    >>> from splinevis.gl.assembler import assemble
    >>> assemble('#include "lib/no_such_file.glsl"\\nvoid main() {}')
    Traceback (most recent call last):
    splinevis.errors.ShaderIncludeError: ...no_such_file.glsl...
    >>> issubclass(ShaderIncludeError, FileNotFoundError)
    True
    """


# Mesa/llvmpipe logs look like "0:12(5): error: ..." ; NVIDIA like "0(12) : error C0000: ...";
# Intel/ANGLE like "ERROR: 0:12: ...". The first number after the source-string index is the line.
_LOG_LINE_PATTERNS = (
    re.compile(r"^\s*\d+:(\d+)\(\d+\):\s*(.*)$"),  # Mesa
    re.compile(r"^\s*\d+\((\d+)\)\s*:\s*(.*)$"),  # NVIDIA
    re.compile(r"^\s*(?:ERROR|WARNING):\s*\d+:(\d+):\s*(.*)$"),  # Intel, ANGLE
)


def parse_glsl_log(log: str) -> list[tuple[int, str]]:
    """Return ``(line_number, message)`` for each line of a GLSL info log that names a source line.

    Line numbers are 1-based as the driver prints them.
    """
    found = []
    for raw in log.splitlines():
        for pattern in _LOG_LINE_PATTERNS:
            m = pattern.match(raw)
            if m:
                found.append((int(m.group(1)), m.group(2).strip()))
                break
    return found


class ShaderCompileError(SplinevisError, RuntimeError):
    """A GLSL program failed to compile or link.

    Attributes
    ----------
    log : str
        The driver's info log, verbatim.
    source : str
        The full source handed to the driver (after include resolution and, for VTK, after VTK's own
        template substitution).
    stage : str
        ``"vertex"``, ``"fragment"``, ``"link"`` or ``"unknown"``.
    locations : list of (int, str, str | None)
        For each log line that names a source line: the line number, the message and, when the
        source came from :func:`splinevis.gl.assembler.assemble`, ``"file:line"`` in ``glsl/``.

    Examples
    --------
    >>> err = ShaderCompileError("0:2(5): error: `x' undeclared", "void main() {\\n  x = 1;\\n}", "fragment")
    >>> err.locations
    [(2, "error: `x' undeclared", None)]
    >>> print(str(err).splitlines()[-2:])
    ["line 2: error: `x' undeclared", '    x = 1;']
    """

    def __init__(self, log: str, source: str, stage: str = "unknown", origin=None):
        self.log = log
        self.source = source
        self.stage = stage
        lines = source.splitlines()
        self.locations = []
        parts = [f"GLSL {stage} shader failed to compile.", "Driver log:", log.strip(), ""]
        for lineno, message in parse_glsl_log(log):
            where = origin(lineno) if origin is not None else None
            self.locations.append((lineno, message, where))
            text = lines[lineno - 1] if 0 < lineno <= len(lines) else "<line not in source>"
            head = f"line {lineno}" + (f" ({where})" if where else "")
            parts.append(f"{head}: {message}\n    {text.strip()}")
        if not self.locations:
            parts.append("(the log names no source line; the full source is in .source)")
        super().__init__("\n".join(parts))


class MeshTopologyError(SplinevisError, ValueError):
    """A mesh is not what an algorithm needs (closed, manifold, connected, genus 0, outward); ``check`` names the
    test that failed, the message says where and what to do.

    Examples
    --------
    >>> e = MeshTopologyError("genus 0", "bunny has genus 1")
    >>> e.check, str(e), isinstance(e, ValueError)
    ('genus 0', 'genus 0: bunny has genus 1', True)
    """

    def __init__(self, check: str, message: str):
        self.check = check
        super().__init__(f"{check}: {message}")
