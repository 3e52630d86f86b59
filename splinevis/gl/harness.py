"""Numeric harness: run GLSL functions on many inputs in one full-screen fragment pass and read back
exact float32 results.

Each input row (``k`` floats) goes to one pixel of a ``W x H`` grid. The ``k`` floats are packed into
``ceil(k / 4)`` RGBA32F textures that the fragment shader reads with ``texelFetch`` (no filtering, no
conversion: the shader sees the exact float32 values). Results are written to ``ceil(outputs / 4)`` RGBA32F
color attachments and read back as float32. The shader is wrapped as ``#version 150`` -- the version VTK
emits -- so a library file that passes here also compiles inside VTK's programs.

The evaluation is one pass of :mod:`splinevis.gl.passes` on the process-wide moderngl context of
:mod:`splinevis.gl.context` (EGL, headless; Mesa llvmpipe is enough), so programs, textures and error
reporting are the product's own: compile and link failures raise
:class:`splinevis.errors.ShaderCompileError` with the driver log mapped back to ``glsl/`` file and line.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .context import get_context, max_texture_size
from .passes import GLSL_VERSION, Pass, run_passes

__all__ = ["get_context", "run_glsl", "GLSL_VERSION"]

_MAX_OUTPUTS = 16  # 4 color attachments; enough for every function we test


def _harness_text(n_in_tex: int, n_out_att: int, functions: str, body: str) -> str:
    """GLSL of the harness pass: samplers, the functions under test, and ``main`` around ``body``."""
    lines = [f"uniform sampler2D sv_tex_in{i};" for i in range(n_in_tex)]
    lines.append(functions.rstrip("\n"))
    lines += ["void main() {", "    ivec2 sv_px = ivec2(gl_FragCoord.xy);", f"    float sv_in[{4 * n_in_tex}];"]
    for i in range(n_in_tex):
        lines.append(f"    {{ vec4 v = texelFetch(sv_tex_in{i}, sv_px, 0);")
        lines.append(f"      sv_in[{4 * i}] = v.x; sv_in[{4 * i + 1}] = v.y; sv_in[{4 * i + 2}] = v.z; sv_in[{4 * i + 3}] = v.w; }}")
    lines.append(f"    float sv_out[{4 * n_out_att}];")
    lines.append(f"    for (int q = 0; q < {4 * n_out_att}; ++q) sv_out[q] = 0.0;")
    lines.append("    // --- body")
    lines.append(body)
    lines.append("    // --- end of body")
    for j in range(n_out_att):
        lines.append(f"    sv_frag_out{j} = vec4(sv_out[{4 * j}], sv_out[{4 * j + 1}], sv_out[{4 * j + 2}], sv_out[{4 * j + 3}]);")
    lines.append("}")
    return "\n".join(lines) + "\n"


def run_glsl(functions: str, body: str, inputs, outputs: int, *, defines=None, root: Path | None = None,
             tables=None) -> np.ndarray:
    """Evaluate GLSL code on every row of ``inputs`` in one draw call.

    Parameters
    ----------
    functions : str
        GLSL text defining the functions to test, typically ``'#include "lib/core/roots.glsl"\\n'``; includes
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
    tables : mapping of str to (H, W, 4) float32 array, optional
        Table textures the functions read (``uniform sampler2D <name>``, declared by the functions), e.g.
        a program's coefficient table from :func:`splinevis.gl.proxies.pack_rgba32f`.

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

    Examples
    --------
    Value and derivative of the quadratics with Bernstein coefficients ``(0, 1, 0)`` at ``t = 1/2`` and
    ``(1, 2, 4)`` at ``t = 1/4``, one row each (columns: three coefficients, then ``t``):

    >>> from splinevis.gl.harness import run_glsl
    >>> body = '''
    ...     float c[5] = float[5](sv_in[0], sv_in[1], sv_in[2], 0.0, 0.0);
    ...     sv_out[0] = sv_bernstein_eval(c, 2, sv_in[3]);
    ...     sv_out[1] = sv_bernstein_deriv(c, 2, sv_in[3]);'''
    >>> run_glsl('#include "lib/core/bernstein.glsl"\\n', body, [[0, 1, 0, 0.5], [1, 2, 4, 0.25]], 2)
    array([[0.5   , 0.    ],
           [1.5625, 2.5   ]], dtype=float32)
    """
    x = np.asarray(inputs)
    if x.ndim == 1:
        x = x[:, None]
    if x.ndim != 2 or x.shape[0] == 0 or x.shape[1] == 0:
        raise ValueError(f"inputs must have shape (M, k) with M, k >= 1; got {np.shape(inputs)}.")
    if isinstance(outputs, bool) or not isinstance(outputs, (int, np.integer)) or not 1 <= outputs <= _MAX_OUTPUTS:
        raise ValueError(f"outputs must be an integer in 1..{_MAX_OUTPUTS}; got {outputs!r}.")
    x = np.ascontiguousarray(x, dtype=np.float32)
    m, k = x.shape
    n_tex = math.ceil(k / 4)
    n_att = math.ceil(outputs / 4)
    max_size = max_texture_size()
    width = max(1, math.ceil(math.sqrt(m)))
    if width > max_size:
        raise ValueError(f"inputs has {m} rows; at most {max_size ** 2} fit one pass on this GL implementation.")
    height = math.ceil(m / width)

    # pack inputs: texture i holds columns 4i..4i+3, pixel (r % W, r // W) holds row r
    padded = np.zeros((width * height, 4 * n_tex), dtype=np.float32)
    padded[:m, :k] = x
    textures = {f"in{i}": padded[:, 4 * i:4 * i + 4].reshape(height, width, 4) for i in range(n_tex)}
    tables = dict(tables or {})
    textures.update({f"table_{name}": np.ascontiguousarray(t, dtype=np.float32) for name, t in tables.items()})
    step = Pass(
        _harness_text(n_tex, n_att, functions, body),
        inputs={**{f"sv_tex_in{i}": f"in{i}" for i in range(n_tex)}, **{name: f"table_{name}" for name in tables}},
        outputs=tuple(f"out{j}" for j in range(n_att)),
        shape=(height, width),
        defines=defines,
        root=root,
    )
    # run_passes makes the shared context current and restores the caller's (a VTK render window's) after
    results = run_passes([step], textures, result=step.outputs)
    cols = [r.reshape(height * width, 4) for r in results]
    return np.array(np.concatenate(cols, axis=1)[:m, :outputs], dtype=np.float32)
