"""Chains of full-screen fragment passes on RGBA32F textures: the "passes" kind of GPU program.

Some computations are images in, images out: a pre-filter of a height grid, one subdivision step of a
geometry image. Each step is a *pass*: a fragment shader from ``glsl/`` drawn over a full-screen
triangle into one or more RGBA32F color attachments, reading its inputs with ``texelFetch`` (no
filtering, no conversion: the shader sees exact float32 values). :class:`PassChain` runs a list of
passes, keeping every intermediate texture on the GPU and reusing dead textures as the targets of later
passes (ping-pong), and returns the named results read back as exact float32 arrays or kept on the GPU
as moderngl textures; :mod:`splinevis.gl.textures` hands a read-back result to VTK without copying it.

Conventions
-----------
* An array ``a`` of shape ``(H, W, 4)`` is a texture of width ``W`` and height ``H``; ``a[j, i]`` is the
  texel at ``ivec2(i, j)`` -- what a pass sees as ``ivec2(gl_FragCoord.xy)``. Shapes in this module are
  numpy's ``(rows, columns)``; nothing is flipped on the way in or out.
* A pass file is GLSL without ``#version``: the runner prepends ``#version 150`` (the version VTK emits,
  so library files shared with VTK programs compile here unchanged) and declares one
  ``out vec4 sv_frag_out<j>`` per output of the pass. The file declares its own samplers and uniforms;
  ``#include`` works as everywhere (:func:`splinevis.gl.assembler.assemble`).
* All GL work runs inside :func:`splinevis.gl.context.current`; a texture returned with
  ``readback=False`` belongs to the caller, who uses it inside ``current()`` and releases it. It lives
  only as long as the context: creating or finalizing a VTK EGL window replaces the context (see
  :mod:`splinevis.gl.context`), and a stale texture is refused with a ValueError.

Compile and link failures raise :class:`splinevis.errors.ShaderCompileError` with the driver log mapped
back to ``glsl/`` file and line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..errors import ShaderCompileError
from .assembler import Assembled, assemble
from .context import current
from .textures import _alive, _check_size, as_rgba32f, empty_rgba32f, read_rgba32f, upload_rgba32f  # noqa: F401
from .textures import to_vtk_image, to_vtk_texture  # noqa: F401 (re-exported: the results' way to VTK)

__all__ = [
    "GLSL_VERSION",
    "FULLSCREEN_VERTEX",
    "Pass",
    "PassChain",
    "run_passes",
    "program_for",
    "as_rgba32f",
    "upload_rgba32f",
    "empty_rgba32f",
    "read_rgba32f",
    "to_vtk_image",
    "to_vtk_texture",
]

#: The version line of pass and harness programs (VTK's vtkOpenGLPolyDataMapper emits ``#version 150``).
GLSL_VERSION = "#version 150"

#: One triangle covering the viewport, (-1,-1), (3,-1), (-1,3): every pixel gets exactly one fragment and
#: no vertex buffer is needed.
FULLSCREEN_VERTEX = """#version 150
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
"""

_OUT = "sv_frag_out"
_MAX_PROGRAMS = 64  # compiled programs kept per context
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_UNIFORM_DECL = re.compile(r"\buniform\s+(?:(?:lowp|mediump|highp)\s+)?\w+\s+(\w+)")
# GL_SAMPLER_2D, GL_INT_SAMPLER_2D, GL_UNSIGNED_INT_SAMPLER_2D: the sampler kinds a pass can be fed
_SAMPLER_TYPES = {0x8B5E, 0x8DCA, 0x8DD2}


# --------------------------------------------------------------------------------------------------
# Programs
# --------------------------------------------------------------------------------------------------
def program_for(block: Assembled, outputs: int):
    """Compile ``block`` as a fragment shader behind the full-screen-triangle vertex shader.

    Parameters
    ----------
    block : Assembled
        From :func:`splinevis.gl.assembler.assemble`; its ``origins`` map driver log lines back to
        ``glsl/`` files.
    outputs : int
        Number of color outputs; ``out vec4 sv_frag_out0 .. sv_frag_out<outputs-1>`` are declared ahead
        of ``block`` and bound to color attachments ``0 .. outputs-1``.

    Returns
    -------
    moderngl.Program
        Cached per context: the same source compiles once (again only if the context was replaced).

    Raises
    ------
    ShaderCompileError
        With each driver log line mapped to its ``glsl/`` file and line.

    Examples
    --------
    >>> from splinevis.gl.assembler import assemble
    >>> from splinevis.gl.passes import program_for
    >>> prog = program_for(assemble("passes/copy.glsl"), 1)
    >>> "sv_src" in prog, prog is program_for(assemble("passes/copy.glsl"), 1)
    (True, True)

    A compile error names the line of the GLSL it came from (here line 1 of the text given):

    >>> program_for(assemble("void main() { sv_frag_out0 = vec4(undefined_name); }\\n"), 1)
    Traceback (most recent call last):
    ...
    splinevis.errors.ShaderCompileError: GLSL fragment shader failed to compile.
    ...
    line 4 (<string>:1): ...undefined_name...
    ...
    """
    head = [GLSL_VERSION, *(f"out vec4 {_OUT}{j};" for j in range(outputs))]
    source = "\n".join(head) + "\n" + block.text
    prog = _compiled(source, outputs)
    if isinstance(prog, Exception):
        message = str(prog)
        raise ShaderCompileError(_log_from(message), source, _stage_of(message), origin=block.origin_in(source))
    return prog


def _compiled(source: str, outputs: int):
    """The program of ``source``, or the moderngl error it raised, cached per context (programs die
    with the context that made them, and :func:`splinevis.gl.context.current` may replace it)."""
    import moderngl

    with current() as ctx:
        if not isinstance(ctx.extra, dict):
            ctx.extra = {}
        cache = ctx.extra.setdefault("splinevis.programs", {})
        key = (source, outputs)
        if key not in cache:
            try:
                cache[key] = ctx.program(
                    vertex_shader=FULLSCREEN_VERTEX,
                    fragment_shader=source,
                    fragment_outputs={f"{_OUT}{j}": j for j in range(outputs)},
                )
            except moderngl.Error as exc:
                cache[key] = exc  # cached failure; program_for raises it with the origin mapping
            while len(cache) > _MAX_PROGRAMS:  # oldest first (dicts keep insertion order)
                old = cache.pop(next(iter(cache)))
                if not isinstance(old, Exception):
                    old.release()
        return cache[key]


def _stage_of(message: str) -> str:
    low = message.lower()
    if "fragment_shader" in low or "fragment shader" in low:
        return "fragment"
    if "vertex_shader" in low or "vertex shader" in low:
        return "vertex"
    if "link" in low:
        return "link"
    return "unknown"


_HEADER = re.compile(r"^(GLSL Compiler failed|GLSL Linker failed|=+|vertex_shader|fragment_shader|geometry_shader)\s*$")


def _log_from(message: str) -> str:
    """Strip moderngl's headers from its error message, keeping the driver's info log."""
    lines = [ln for ln in message.splitlines() if not _HEADER.match(ln.strip())]
    return "\n".join(lines).strip()


# --------------------------------------------------------------------------------------------------
# Passes
# --------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Pass:
    """One full-screen fragment pass.

    Parameters
    ----------
    shader : str
        A file under ``glsl/`` such as ``"passes/binomial3.glsl"``, or GLSL text (anything with a newline).
        It writes ``sv_frag_out0``, ``sv_frag_out1``, ... (declared by the runner, one per output).
    inputs : mapping of str to str, or sequence of str
        Which texture each sampler reads: ``{"sv_src": "heights"}`` binds the chain's texture named
        ``heights`` to ``uniform sampler2D sv_src``. A sequence of names means sampler name == texture
        name.
    outputs : str or sequence of str
        Names of the textures the pass writes, one per color attachment (``sv_frag_out<j>`` becomes
        ``outputs[j]``). A name may be written again by a later pass; readers see the newest version.
    shape : (H, W), optional
        Size of the outputs; defaults to the shape of the first input.
    uniforms : mapping, optional
        Values of the shader's other uniforms (float, int or tuples for vectors).
    defines : mapping, optional
        Compile-time flags for :func:`splinevis.gl.assembler.assemble`.
    root : Path, optional
        Another GLSL root (tests use a temporary one).

    Examples
    --------
    >>> from splinevis.gl.passes import Pass
    >>> p = Pass("passes/binomial3.glsl", {"sv_src": "heights"}, "smooth", uniforms={"sv_axis": (1, 0)})
    >>> p.inputs, p.outputs
    ((('sv_src', 'heights'),), ('smooth',))
    >>> Pass("passes/copy.glsl", ["sv_src"]).inputs  # a sequence: sampler name == texture name
    (('sv_src', 'sv_src'),)
    >>> Pass("void main() { sv_frag_out0 = vec4(1.0); }\\n")
    Traceback (most recent call last):
    ...
    ValueError: Pass '<string>' has no inputs, so give its output shape=(H, W).
    """

    shader: str
    inputs: Mapping[str, str] | Sequence[str] = ()
    outputs: str | Sequence[str] = "out"
    shape: tuple | None = None
    uniforms: Mapping[str, object] = field(default_factory=dict)
    defines: Mapping[str, object] | None = None
    root: Path | None = None

    def __post_init__(self):
        if not isinstance(self.shader, str) or not self.shader.strip():
            raise ValueError(f"Pass shader must be a glsl/ file path or GLSL text; got {self.shader!r}.")
        pairs = tuple(self.inputs.items()) if isinstance(self.inputs, Mapping) else tuple((n, n) for n in self.inputs)
        outs = (self.outputs,) if isinstance(self.outputs, str) else tuple(self.outputs)
        for sampler, tex in pairs:
            for what, n in (("sampler", sampler), ("input texture", tex)):
                if not isinstance(n, str) or not _NAME.match(n):
                    raise ValueError(f"Pass {self.label!r}: {what} name {n!r} is not an identifier.")
        if not outs:
            raise ValueError(f"Pass {self.label!r}: give at least one output name.")
        for n in outs:
            if not isinstance(n, str) or not _NAME.match(n):
                raise ValueError(f"Pass {self.label!r}: output name {n!r} is not an identifier.")
        if len(set(outs)) != len(outs):
            raise ValueError(f"Pass {self.label!r}: output names repeat: {outs}.")
        shape = self.shape
        if shape is not None:
            if (len(shape) != 2 or any(isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 1
                                       for s in shape)):
                raise ValueError(f"Pass {self.label!r}: shape must be (H, W) with integers >= 1; got {shape!r}.")
            shape = (int(shape[0]), int(shape[1]))
        elif not pairs:
            raise ValueError(f"Pass {self.label!r} has no inputs, so give its output shape=(H, W).")
        object.__setattr__(self, "inputs", pairs)
        object.__setattr__(self, "outputs", outs)
        object.__setattr__(self, "shape", shape)
        object.__setattr__(self, "uniforms", dict(self.uniforms))

    @property
    def label(self) -> str:
        """The shader file, or ``"<string>"`` for GLSL text (for messages).

        Examples
        --------
        >>> from splinevis.gl.passes import Pass
        >>> Pass("passes/copy.glsl", {"sv_src": "x"}).label
        'passes/copy.glsl'
        >>> Pass("void main() { sv_frag_out0 = vec4(1.0); }\\n", shape=(1, 1)).label
        '<string>'
        """
        return "<string>" if "\n" in self.shader else self.shader

    def program(self):
        """The compiled program (cached); raises :class:`ShaderCompileError` mapped to ``glsl/`` lines.

        Examples
        --------
        >>> from splinevis.gl.passes import Pass
        >>> prog = Pass("passes/binomial3.glsl", {"sv_src": "x"}, uniforms={"sv_axis": (1, 0)}).program()
        >>> "sv_src" in prog, "sv_axis" in prog
        (True, True)
        >>> prog is Pass("passes/binomial3.glsl", {"sv_src": "y"}).program()  # same source: compiled once
        True
        """
        return program_for(assemble(self.shader, self.defines, root=self.root), len(self.outputs))


class PassChain:
    """A list of passes wired by texture names, run with every intermediate texture kept on the GPU.

    Parameters
    ----------
    passes : sequence of Pass

    Attributes
    ----------
    passes : tuple of Pass
    inputs : tuple of str
        Texture names the chain reads before any of its passes writes them: what :meth:`run` needs.

    Examples
    --------
    Separable binomial smoothing, along x and then along y:

    >>> from splinevis.gl.passes import Pass, PassChain
    >>> chain = PassChain([
    ...     Pass("passes/binomial3.glsl", {"sv_src": "h"}, "hx", uniforms={"sv_axis": (1, 0)}),
    ...     Pass("passes/binomial3.glsl", {"sv_src": "hx"}, "hxy", uniforms={"sv_axis": (0, 1)})])
    >>> chain
    PassChain(['passes/binomial3.glsl', 'passes/binomial3.glsl'], inputs=['h'])
    >>> chain.inputs  # "hx" is written by the first pass
    ('h',)
    """

    def __init__(self, passes: Sequence[Pass]):
        self.passes = tuple(passes)
        if not self.passes:
            raise ValueError("PassChain needs at least one Pass.")
        for p in self.passes:
            if not isinstance(p, Pass):
                raise TypeError(f"PassChain takes Pass objects; got {type(p).__name__}.")
        needed, written = [], set()
        for p in self.passes:
            for _, name in p.inputs:
                if name not in written and name not in needed:
                    needed.append(name)
            written.update(p.outputs)
        self.inputs = tuple(needed)
        self._written = written

    def __repr__(self) -> str:
        return f"PassChain({[p.label for p in self.passes]}, inputs={list(self.inputs)})"

    def _needed_after(self, i: int, name: str, keep: set) -> bool:
        """Whether the current version of ``name`` is read after pass ``i`` (or returned at the end)."""
        for p in self.passes[i + 1:]:
            if any(n == name for _, n in p.inputs):
                return True
            if name in p.outputs:
                return False
        return name in keep

    def run(self, inputs: Mapping[str, object], *, result=None, readback: bool = True):
        """Run the passes in order.

        Parameters
        ----------
        inputs : mapping of str to array_like or moderngl.Texture
            One entry per name in :attr:`inputs`. Arrays, ``(H, W)`` or ``(H, W, C)`` with C in 1..4, are
            uploaded as float32 (see :func:`as_rgba32f`); textures are read as they are and never written
            or released.
        result : str or sequence of str, optional
            Names of the textures to return; defaults to the outputs of the last pass.
        readback : bool
            True: return float32 ``(H, W, 4)`` arrays (exact texel values). False: return the moderngl
            textures; they belong to the caller.

        Returns
        -------
        ndarray or moderngl.Texture, or a tuple of them when ``result`` is a sequence (or the last pass
        has several outputs and ``result`` is not given).

        Examples
        --------
        The separable binomial smoothing of a spike (``[1, 2, 1] / 4`` along x, then along y):

        >>> import numpy as np
        >>> from splinevis.gl.passes import Pass, PassChain
        >>> chain = PassChain([
        ...     Pass("passes/binomial3.glsl", {"sv_src": "h"}, "hx", uniforms={"sv_axis": (1, 0)}),
        ...     Pass("passes/binomial3.glsl", {"sv_src": "hx"}, "hxy", uniforms={"sv_axis": (0, 1)})])
        >>> h = np.zeros((3, 3), dtype=np.float32)
        >>> h[1, 1] = 16.0
        >>> chain.run({"h": h})[:, :, 0]  # float32 (H, W, 4); channel 0 holds the heights
        array([[1., 2., 1.],
               [2., 4., 2.],
               [1., 2., 1.]], dtype=float32)
        >>> hx, hxy = chain.run({"h": h}, result=("hx", "hxy"))  # an intermediate texture too
        >>> hx[:, :, 0]
        array([[0., 0., 0.],
               [4., 8., 4.],
               [0., 0., 0.]], dtype=float32)

        With ``readback=False`` the result stays on the GPU; the caller uses and releases it inside
        :func:`splinevis.gl.context.current`:

        >>> from splinevis.gl.context import current
        >>> with current():
        ...     tex = chain.run({"h": h}, readback=False)
        ...     size = tex.size
        ...     tex.release()
        >>> size
        (3, 3)
        """
        if result is None:
            outs = self.passes[-1].outputs
            names, single = outs, len(outs) == 1
        elif isinstance(result, str):
            names, single = (result,), True
        else:
            names, single = tuple(result), False
        missing = [n for n in self.inputs if n not in inputs]
        if missing:
            raise ValueError(f"PassChain needs the input textures {missing}; got {sorted(inputs)}.")
        unknown = [n for n in names if n not in self._written and n not in inputs]
        if unknown:
            raise ValueError(f"result names {unknown} are neither written by a pass nor given as inputs.")
        keep = set(names)
        with current() as ctx:
            store, handed = _Store(), []
            try:
                env = {}
                for n in self.inputs + tuple(n for n in names if n in inputs and n not in self._written):
                    v = inputs[n]
                    env[n] = _alive(v, ctx, f"input {n!r}") if _is_texture(v) else store.upload(v, f"input {n!r}")
                for i, p in enumerate(self.passes):
                    before = dict(env)
                    for n, tex in zip(p.outputs, self._draw(ctx, p, env, store)):
                        env[n] = tex
                    # a texture whose last reader was this pass becomes a target of a later pass
                    for n in dict.fromkeys(n for _, n in p.inputs):
                        if n in p.outputs:
                            store.recycle(before[n])
                        elif not self._needed_after(i, n, keep):
                            store.recycle(env.pop(n))
                    for n in p.outputs:  # an output nobody reads (an unused attachment)
                        if not self._needed_after(i, n, keep):
                            store.recycle(env.pop(n))
                found = [env[n] for n in names]
                if readback:
                    out = [read_rgba32f(t) for t in found]
                else:
                    out = handed = found  # now the caller's to release
            finally:
                store.release_all(keep=handed)
        return out[0] if single else tuple(out)

    def _draw(self, ctx, p: Pass, env: dict, store: "_Store") -> list:
        prog = p.program()
        textures = {s: env[n] for s, n in p.inputs}
        shape = p.shape or _shape_of(textures[p.inputs[0][0]])
        _check_size(shape, f"output of pass {p.label!r}")
        limit = int(ctx.info.get("GL_MAX_DRAW_BUFFERS", 8))
        if len(p.outputs) > limit:
            raise ValueError(f"pass {p.label!r} has {len(p.outputs)} outputs; this OpenGL implementation "
                             f"draws at most {limit}.")
        declared = set(_UNIFORM_DECL.findall(_source_of(p)))
        for s in textures:
            if s not in declared:
                raise ValueError(f"pass {p.label!r}: no uniform sampler2D {s} in the shader; "
                                 f"it declares {sorted(declared)}.")
        for name in p.uniforms:
            if name not in declared:
                raise ValueError(f"pass {p.label!r}: no uniform {name} in the shader; it declares {sorted(declared)}.")
        unbound = [n for n in prog if getattr(prog[n], "gl_type", None) in _SAMPLER_TYPES and n not in textures]
        if unbound:
            raise ValueError(f"pass {p.label!r}: samplers {unbound} get no texture; add them to the pass inputs.")
        targets = [store.take(shape) for _ in p.outputs]
        for unit, (s, tex) in enumerate(textures.items()):
            if s in prog:  # the driver drops samplers the shader never reads
                tex.use(location=unit)
                prog[s].value = unit
        for name, value in p.uniforms.items():
            if name in prog:
                prog[name].value = value
        fbo = ctx.framebuffer(color_attachments=targets)
        vao = ctx.vertex_array(prog, [])
        try:
            fbo.use()
            ctx.viewport = (0, 0, shape[1], shape[0])
            vao.render(mode=ctx.TRIANGLES, vertices=3)
        finally:
            vao.release()
            fbo.release()
        return targets


def run_passes(passes: Sequence[Pass], inputs: Mapping[str, object], *, result=None, readback: bool = True):
    """Run ``passes`` as a :class:`PassChain`; see :meth:`PassChain.run` for the arguments.

    Examples
    --------
    >>> import numpy as np
    >>> from splinevis.gl.passes import Pass, run_passes
    >>> x = np.arange(6, dtype=np.float32).reshape(2, 3)
    >>> out = run_passes([Pass("passes/copy.glsl", {"sv_src": "x"})], {"x": x})
    >>> out.shape, bool((out[:, :, 0] == x).all())
    ((2, 3, 4), True)
    """
    return PassChain(passes).run(inputs, result=result, readback=readback)


def _is_texture(v) -> bool:
    return hasattr(v, "size") and hasattr(v, "read_into") and not isinstance(v, np.ndarray)


def _shape_of(tex) -> tuple:
    w, h = tex.size
    return (h, w)


class _Store:
    """The textures one run creates: reused as targets once dead, all released at the end but those
    handed to the caller. The caller's own textures never enter it, so they are never written."""

    def __init__(self):
        self.created, self.free = [], []

    def upload(self, values, name):
        tex = upload_rgba32f(values, name)
        self.created.append(tex)
        return tex

    def take(self, shape):
        for k, tex in enumerate(self.free):
            if _shape_of(tex) == tuple(shape):
                return self.free.pop(k)
        tex = empty_rgba32f(shape)
        self.created.append(tex)
        return tex

    def recycle(self, tex) -> None:
        if any(tex is t for t in self.created) and not any(tex is t for t in self.free):
            self.free.append(tex)

    def release_all(self, keep) -> None:
        for tex in self.created:
            if not any(tex is k for k in keep):
                tex.release()


def _source_of(p: Pass) -> str:
    return assemble(p.shader, p.defines, root=p.root).text
