"""GLSL program assembly: ``#include`` resolution, compile-time flags, a cache, and line origins.

Shader code lives in small files under ``glsl/`` (shipped as ``splinevis.glsl``). A file pulls in another
with ``#include "lib/core/bernstein.glsl"`` (path relative to the ``glsl/`` root). Each file is included at
most once per program, so files can include what they use without guards. Compile-time flags become
``#define`` lines at the top; effects and program variants are selected with ``#ifdef`` in the files,
so code of an effect that a scene does not declare never reaches the driver. The assembler itself
resolves conditionals on ``SV_`` flags (``#ifdef SV_X``, ``#ifndef``, ``#if defined(SV_X) && ...``,
``#elif``, ``#else``, ``#endif``): disabled branches are dropped from the text, so the source handed to
the driver -- and kept for inspection -- holds no code of an undeclared effect. Conditionals on other
names pass through to the GLSL preprocessor untouched.

The same assembled text serves VTK (spliced into vtkOpenGLPolyDataMapper's template by
:mod:`splinevis.gl.inject`) and moderngl (:mod:`splinevis.gl.harness`); both wrap it with their own
``#version`` line. Every output line remembers the file and line it came from, so a compile error can be
reported against ``glsl/lib/core/roots.glsl:42`` rather than line 731 of VTK's expanded program.
"""

from __future__ import annotations

import functools
import importlib.resources
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from ..errors import ShaderIncludeError

__all__ = ["Assembled", "assemble", "glsl_root", "BEGIN_MARKER"]

_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"\s*(//.*)?$')
_DEFINE_NAME = re.compile(r"^[A-Z_][A-Z0-9_]*$")
#: First line of every assembled block; lets us find our code inside VTK's expanded program.
BEGIN_MARKER = "// splinevis:begin "


def glsl_root() -> Path:
    """The directory holding the shipped GLSL sources (``glsl/`` in the repository).

    Examples
    --------
    >>> (glsl_root() / "lib" / "core" / "roots.glsl").is_file()
    True
    """
    return Path(str(importlib.resources.files("splinevis.glsl")))


@dataclass(frozen=True)
class Assembled:
    """An assembled GLSL block.

    Attributes
    ----------
    name : str
        The entry file (or ``"<string>"``).
    defines : tuple of (str, str)
        The compile-time flags, sorted; part of the cache key.
    text : str
        The source: marker line, ``#define`` lines, then the files in include order.
    origins : tuple of (str, int)
        For each line of ``text``, the ``glsl/``-relative file and 1-based line it came from
        (``("<defines>", 0)`` for generated lines).
    files : tuple of str
        The files that were included, in order (what a test inspects to prove an effect was left out).

    Examples
    --------
    >>> block = assemble('#include "lib/core/bernstein.glsl"\\n', {"SV_X": 4})
    >>> block.name, block.defines, block.files
    ('<string>', (('SV_X', 4),), ('lib/core/bernstein.glsl',))
    >>> block.text.splitlines()[:2], block.origins[:2]
    (['// splinevis:begin <string>', '#define SV_X 4'], (('<marker>', 0), ('<defines>', 0)))
    """

    name: str
    defines: tuple
    text: str
    origins: tuple
    files: tuple

    def origin_in(self, full_source: str):
        """Return a function mapping a 1-based line of ``full_source`` (which contains ``text``) to
        ``"file:line"`` or None for lines outside our block.

        Examples
        --------
        >>> block = assemble('#include "lib/core/bernstein.glsl"\\n')
        >>> origin = block.origin_in("#version 330\\n" + block.text)  # one line before the block
        >>> origin(1), origin(5)
        (None, 'lib/core/bernstein.glsl:2')
        """
        lines = full_source.splitlines()
        marker = self.text.splitlines()[0]
        try:
            start = lines.index(marker)
        except ValueError:
            start = None

        def origin(lineno: int):
            if start is None:
                return None
            k = lineno - 1 - start
            if 0 <= k < len(self.origins):
                f, ln = self.origins[k]
                return f"{f}:{ln}"
            return None

        return origin


def _format_define(name: str, value) -> str:
    if not isinstance(name, str) or not _DEFINE_NAME.match(name):
        raise ValueError(
            f"GLSL flag name {name!r} is not valid: use upper-case letters, digits and '_' "
            "(e.g. 'SV_NUM_LIGHTS')."
        )
    if value is True or value is None:
        return f"#define {name} 1"
    if value is False:
        return ""  # a false flag is simply absent, so #ifdef sees it as off
    if isinstance(value, int):
        return f"#define {name} {value}"
    if isinstance(value, float):
        return f"#define {name} {value!r}"
    raise TypeError(f"GLSL flag {name} must be bool, int or float, got {type(value).__name__} {value!r}.")


_COND = re.compile(r"^\s*#\s*(ifdef|ifndef|if|elif|else|endif)\b\s*(.*?)\s*(//.*)?$")
_SV_EXPR = re.compile(r"^(?:\s|!|&&|\|\||\(|\)|defined\s*\(\s*SV_[A-Z0-9_]*\s*\)|defined\s+SV_[A-Z0-9_]*)*$")


def _eval_condition(kind: str, expr: str, defined: set):
    """True/False for a condition on SV_ flags only, None when it involves anything else."""
    if kind in ("ifdef", "ifndef"):
        name = expr.strip()
        if not name.startswith("SV_"):
            return None
        return (name in defined) == (kind == "ifdef")
    if not expr or not _SV_EXPR.match(expr):
        return None
    py = re.sub(r"defined\s*\(\s*(SV_[A-Z0-9_]*)\s*\)|defined\s+(SV_[A-Z0-9_]*)",
                lambda m: str((m.group(1) or m.group(2)) in defined), expr)
    py = py.replace("&&", " and ").replace("||", " or ").replace("!", " not ")
    return bool(eval(py, {"__builtins__": {}}, {}))  # noqa: S307 - only True/False/and/or/not/parens remain


def _strip_sv_conditionals(lines, origins, defined: set, name: str):
    """Drop branches of SV_ conditionals that are off; keep everything else (and other conditionals)."""
    out, out_origins = [], []
    stack = []  # entries: [ours, active_now, taken_before, parent_active]
    active = True
    for line, origin in zip(lines, origins):
        m = _COND.match(line)
        if m:
            kind, expr = m.group(1), m.group(2)
            if kind in ("ifdef", "ifndef", "if"):
                value = _eval_condition(kind, expr, defined)
                if value is None:
                    stack.append([False, active, False, active])
                else:
                    stack.append([True, active and value, value, active])
                    active = active and value
                    continue
            elif kind in ("elif", "else", "endif"):
                if not stack:
                    raise ValueError(f"GLSL #{kind} without #if in {origin[0]}:{origin[1]} ({name})")
                top = stack[-1]
                if top[0]:
                    if kind == "endif":
                        stack.pop()
                        active = top[3]
                        continue
                    value = True if kind == "else" else _eval_condition("if", expr, defined)
                    if value is None:
                        raise ValueError(
                            f"GLSL #elif {expr} at {origin[0]}:{origin[1]} mixes SV_ flags with other names "
                            "after an #if on SV_ flags; split the conditional."
                        )
                    take = value and not top[2]
                    top[2] = top[2] or value
                    active = top[3] and take
                    continue
                if kind == "endif":
                    stack.pop()
        if active:
            out.append(line)
            out_origins.append(origin)
    if stack:
        raise ValueError(f"GLSL conditional not closed with #endif in {name}")
    return out, out_origins


def _read(roots: tuple, rel: str, chain: tuple) -> list[str]:
    for root in roots:
        path = root / rel
        if path.is_file():
            return path.read_text().splitlines()
    where = f" (included from {chain[-1]})" if chain else ""
    under = " or ".join(str(r) for r in roots)
    raise ShaderIncludeError(
        f"GLSL file {rel!r}{where} not found under {under}. Include paths are relative to the glsl/ "
        "folder, e.g. #include \"lib/core/bernstein.glsl\"."
    )


def assemble(entry: str, defines: Mapping[str, object] | None = None, *, root: Path | None = None,
             extra_roots: tuple = ()) -> Assembled:
    """Assemble a GLSL block from ``entry`` with compile-time ``defines``.

    Parameters
    ----------
    entry : str
        A path under ``glsl/`` such as ``"programs/analytic_patch.frag.glsl"``, or GLSL source text
        (anything containing a newline is taken as text; its includes are resolved the same way).
    defines : mapping of str to bool, int or float, optional
        Compile-time flags. ``True`` and ints become ``#define NAME value``; ``False`` leaves the flag
        undefined.
    root : Path, optional
        Another GLSL root (tests use a temporary one). Defaults to :func:`glsl_root`.
    extra_roots : tuple of Path, optional
        Folders searched before ``root``: a spline family outside the package ships its own GLSL files
        there and includes the shipped library as usual.

    Returns
    -------
    Assembled
        Cached: the same ``(entry, defines, root)`` returns the same object.

    Examples
    --------
    >>> from splinevis.gl.assembler import assemble
    >>> block = assemble('#include "lib/core/bernstein.glsl"\\n', {"SV_DEGREE": 4})
    >>> "lib/core/bernstein.glsl" in block.files
    True
    >>> "#define SV_DEGREE 4" in block.text
    True
    """
    key = tuple(sorted((defines or {}).items()))
    for name, value in key:
        _format_define(name, value)  # validate before the cache so bad flags always raise
    extra = tuple(str(r) for r in extra_roots)
    return _assemble_cached(entry, key, str(root) if root is not None else None, extra)


@functools.lru_cache(maxsize=256)
def _assemble_cached(entry: str, key: tuple, root_str: str | None, extra: tuple = ()) -> Assembled:
    roots = tuple(Path(r) for r in extra) + (Path(root_str) if root_str is not None else glsl_root(),)
    is_text = "\n" in entry
    name = "<string>" if is_text else entry
    out: list[str] = [BEGIN_MARKER + name]
    origins: list[tuple] = [("<marker>", 0)]
    for n, v in key:
        line = _format_define(n, v)
        if line:
            out.append(line)
            origins.append(("<defines>", 0))
    seen: list[str] = []

    defined = {n for n, v in key if v is not False}

    def expand(lines: list[str], rel: str, chain: tuple):
        # Resolve this file's SV_ conditionals first, so an #include in a disabled branch is never read:
        # a scheme or effect that is not declared pulls in none of its files.
        kept, where = _strip_sv_conditionals(list(lines), [(rel, i) for i in range(1, len(lines) + 1)], defined, rel)
        for line, (_, i) in zip(kept, where):
            m = _INCLUDE.match(line)
            if not m:
                out.append(line)
                origins.append((rel, i))
                continue
            target = m.group(1)
            if target in chain:
                cycle = " -> ".join(chain + (target,))
                raise ShaderIncludeError(f"GLSL include cycle: {cycle}. Remove one of these #include lines.")
            if target in seen:
                continue
            seen.append(target)
            out.append(f"// --- {target}")
            origins.append((target, 0))
            expand(_read(roots, target, chain + (rel,)), target, chain + (target,))

    if is_text:
        expand(entry.splitlines(), "<string>", ())
    else:
        seen.append(entry)
        expand(_read(roots, entry, ()), entry, (entry,))
    out, origins = _strip_sv_conditionals(out, origins, defined, name)
    return Assembled(name=name, defines=key, text="\n".join(out) + "\n", origins=tuple(origins), files=tuple(seen))
