"""Numeric harness: run GLSL functions on many inputs in one full-screen fragment pass and read back
exact float32 results.

Each input row (``k`` floats) goes to one pixel of a ``W x H`` grid. The ``k`` floats are packed into
``ceil(k / 4)`` RGBA32F textures that the fragment shader reads with ``texelFetch`` (no filtering, no
conversion: the shader sees the exact float32 values). Results are written to ``ceil(outputs / 4)`` RGBA32F
color attachments and read back as float32. The shader is wrapped as ``#version 150`` -- the version VTK
emits -- so a library file that passes here also compiles inside VTK's programs.

The context is a moderngl standalone context on EGL (headless; Mesa llvmpipe is enough), created once per
process. Compile and link failures raise :class:`splinevis.errors.ShaderCompileError` with the driver log
mapped back to ``glsl/`` file and line.
"""

from __future__ import annotations

import functools
import math
import re
from pathlib import Path

import numpy as np

from ..errors import OpenGLUnavailableError, ShaderCompileError
from .assembler import assemble

__all__ = ["get_context", "run_glsl", "GLSL_VERSION"]

#: The version line of the harness programs (VTK's vtkOpenGLPolyDataMapper emits ``#version 150``).
GLSL_VERSION = "#version 150"

_MAX_OUTPUTS = 16  # 4 color attachments; enough for every function we test

_VERTEX = """#version 150
void main() {
    // one triangle covering the viewport: (-1,-1), (3,-1), (-1,3)
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
"""

_ctx = None


def get_context():
    """The process-wide moderngl standalone context (EGL backend, OpenGL >= 3.3 core).

    Raises
    ------
    OpenGLUnavailableError
        When no context can be created; the message names the Debian packages that provide EGL and
        Mesa's software rasterizer.
    """
    global _ctx
    if _ctx is None:
        try:
            import moderngl
        except ImportError as exc:  # pragma: no cover - moderngl is a dependency
            raise OpenGLUnavailableError(f"moderngl is not installed ({exc}); pip install moderngl.") from None
        try:
            _ctx = moderngl.create_standalone_context(backend="egl", require=330)
        except Exception as exc:
            raise OpenGLUnavailableError(
                "Could not create a headless OpenGL 3.3 context with EGL "
                f"({type(exc).__name__}: {exc}). On Debian/Ubuntu install the packages "
                "libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 (Mesa's llvmpipe software renderer is enough)."
            ) from None
    return _ctx


def _fragment_source(n_in_tex: int, n_in: int, n_out_att: int, n_out: int) -> tuple[str, str]:
    """(header, wrapper-of-main-with-{body}) for the fragment shader."""
    head = [GLSL_VERSION]
    for i in range(n_in_tex):
        head.append(f"uniform sampler2D sv_tex_in{i};")
    for j in range(n_out_att):
        head.append(f"out vec4 sv_frag_out{j};")
    head_text = "\n".join(head) + "\n"
    main = ["void main() {", "    ivec2 sv_px = ivec2(gl_FragCoord.xy);", f"    float sv_in[{4 * n_in_tex}];"]
    for i in range(n_in_tex):
        main.append(f"    {{ vec4 v = texelFetch(sv_tex_in{i}, sv_px, 0);")
        main.append(f"      sv_in[{4 * i}] = v.x; sv_in[{4 * i + 1}] = v.y; sv_in[{4 * i + 2}] = v.z; sv_in[{4 * i + 3}] = v.w; }}")
    main.append(f"    float sv_out[{4 * n_out_att}];")
    main.append(f"    for (int q = 0; q < {4 * n_out_att}; ++q) sv_out[q] = 0.0;")
    main.append("    // --- body")
    main.append("{body}")
    main.append("    // --- end of body")
    for j in range(n_out_att):
        main.append(f"    sv_frag_out{j} = vec4(sv_out[{4 * j}], sv_out[{4 * j + 1}], sv_out[{4 * j + 2}], sv_out[{4 * j + 3}]);")
    main.append("}")
    return head_text, "\n".join(main) + "\n"


def _stage_of(message: str) -> str:
    low = message.lower()
    if "fragment_shader" in low or "fragment shader" in low:
        return "fragment"
    if "vertex_shader" in low or "vertex shader" in low:
        return "vertex"
    if "link" in low:
        return "link"
    return "unknown"


@functools.lru_cache(maxsize=64)
def _program(frag_source: str, n_out_att: int):
    ctx = get_context()
    import moderngl

    try:
        prog = ctx.program(
            vertex_shader=_VERTEX,
            fragment_shader=frag_source,
            fragment_outputs={f"sv_frag_out{j}": j for j in range(n_out_att)},
        )
    except moderngl.Error as exc:
        return exc  # cached failure; the caller raises with the origin mapping
    return prog


def run_glsl(functions: str, body: str, inputs, outputs: int, *, defines=None, root: Path | None = None) -> np.ndarray:
    """Evaluate GLSL code on every row of ``inputs`` in one draw call.

    Parameters
    ----------
    functions : str
        GLSL text defining the functions to test, typically ``'#include "lib/roots.glsl"\\n'``; includes
        are resolved by :func:`splinevis.gl.assembler.assemble` against ``root``.
    body : str
        Statements of ``main`` that read the row from ``float sv_in[...]`` (``sv_in[i]`` is column ``i``)
        and write results to ``float sv_out[...]`` (``sv_out[j]`` becomes column ``j``), e.g.
        ``"sv_out[0] = sv_bernstein_eval(float[5](sv_in[0], sv_in[1], 0.0, 0.0, 0.0), 1, sv_in[2]);"``.
    inputs : (M, k) array_like
        Converted to float32 (the values the shader sees are exactly ``inputs.astype(float32)``).
    outputs : int
        Number of result columns, 1..16.
    defines : mapping, optional
        Compile-time flags for :func:`assemble`.
    root : Path, optional
        Another GLSL root (tests use a temporary one).

    Returns
    -------
    (M, outputs) float32 ndarray

    Raises
    ------
    ShaderCompileError
        If the program does not compile or link; the message lists each log line with its
        ``file:line`` origin in ``glsl/`` and the offending source text.
    OpenGLUnavailableError
        If no OpenGL context can be created.
    """
    x = np.asarray(inputs)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2 or x.shape[0] == 0 or x.shape[1] == 0:
        raise ValueError(f"inputs must have shape (M, k) with M, k >= 1; got {np.shape(inputs)}.")
    if isinstance(outputs, bool) or not isinstance(outputs, (int, np.integer)) or not 1 <= outputs <= _MAX_OUTPUTS:
        raise ValueError(f"outputs must be an integer in 1..{_MAX_OUTPUTS}; got {outputs!r}.")
    x = np.ascontiguousarray(x, dtype=np.float32)
    ctx = get_context()
    # Make the harness context current for the whole pass and restore the caller's afterwards: another GL
    # user in the process (a VTK render window) may have left its own context current, and then the
    # driver refuses to create programs ("cannot create program").
    with ctx:
        return _run(ctx, x, functions, body, outputs, defines, root)


def _run(ctx, x, functions, body, outputs, defines, root):
    m, k = x.shape
    n_tex = math.ceil(k / 4)
    n_att = math.ceil(outputs / 4)
    max_size = int(ctx.info.get("GL_MAX_TEXTURE_SIZE", 8192))
    width = max(1, math.ceil(math.sqrt(m)))
    if width > max_size:
        raise ValueError(f"inputs has {m} rows; at most {max_size ** 2} fit one pass on this GL implementation.")
    height = math.ceil(m / width)

    head, main = _fragment_source(n_tex, k, n_att, outputs)
    text = functions if functions.endswith("\n") else functions + "\n"
    block = assemble(text + main.replace("{body}", body), defines, root=root)
    source = head + block.text
    prog = _program(source, n_att)
    if isinstance(prog, Exception):
        message = str(prog)
        raise ShaderCompileError(_log_from(message), source, _stage_of(message), origin=block.origin_in(source))

    # pack inputs: texture i holds columns 4i..4i+3, pixel (r % W, r // W) holds row r
    padded = np.zeros((width * height, 4 * n_tex), dtype=np.float32)
    padded[:m, :k] = x
    textures = []
    fbo = None
    try:
        for i in range(n_tex):
            data = np.ascontiguousarray(padded[:, 4 * i:4 * i + 4]).reshape(height, width, 4)
            tex = ctx.texture((width, height), 4, data.tobytes(), dtype="f4")
            tex.filter = (ctx.NEAREST, ctx.NEAREST) if hasattr(ctx, "NEAREST") else tex.filter
            tex.use(location=i)
            textures.append(tex)
            name = f"sv_tex_in{i}"
            if name in prog:
                prog[name].value = i
        targets = [ctx.texture((width, height), 4, dtype="f4") for _ in range(n_att)]
        textures.extend(targets)
        fbo = ctx.framebuffer(color_attachments=targets)
        fbo.use()
        ctx.viewport = (0, 0, width, height)
        vao = ctx.vertex_array(prog, [])
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        cols = []
        for j in range(n_att):
            raw = fbo.read(components=4, attachment=j, dtype="f4")
            cols.append(np.frombuffer(raw, dtype=np.float32).reshape(height * width, 4))
        vao.release()
    finally:
        if fbo is not None:
            fbo.release()
        for tex in textures:
            tex.release()
    out = np.concatenate(cols, axis=1)[:m, :outputs]
    return np.array(out, dtype=np.float32)


_HEADER = re.compile(r"^(GLSL Compiler failed|GLSL Linker failed|=+|vertex_shader|fragment_shader|geometry_shader)\s*$")


def _log_from(message: str) -> str:
    """Strip moderngl's headers from its error message, keeping the driver's info log."""
    lines = [ln for ln in message.splitlines() if not _HEADER.match(ln.strip())]
    return "\n".join(lines).strip()
