"""ProgramSpec: what a GPU program needs, as plain arrays. No VTK here, so model code can build specs."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["ProgramSpec"]


@dataclass(frozen=True)
class ProgramSpec:
    """Everything a GPU program needs, as plain arrays (no VTK objects).

    Attributes
    ----------
    name : str
        Program name (part of the cache key), e.g. ``"analytic_patch"``.
    entry : str
        GLSL file under ``glsl/`` defining ``sv_surface_hit``.
    points : (N, 3) float64 ndarray
        Proxy vertices in model coordinates (the proxy must enclose the surface).
    triangles : (M, 3) int ndarray
        Proxy triangles, outward oriented.
    defines : dict
        Program-specific compile-time flags (the Style adds the effect flags).
    uniforms : dict
        name -> float, int, tuple of 2..4 floats, or 1-D array (set element-wise as ``name[i]``).
    textures : dict
        name -> (H, W, 4) float32 array, bound as an RGBA32F ``sampler2D`` read with ``texelFetch``.
    attributes : dict
        name -> (N, k <= 4) float array per proxy vertex; declared ``in`` in the vertex shader and
        forwarded to the fragment shader as ``<name>VSOut`` (flat).
    varyings : dict
        name -> (N, k <= 4) float array per proxy vertex, interpolated (perspective-correct) across each
        proxy triangle and read in the fragment shader as ``<name>VSOut``. The isosurface program passes
        cube-local corner coordinates this way, so every fragment knows its position relative to its own
        cube to float32 precision whatever the volume's size.
    frame_uniforms : callable, optional
        ``f(eye_mc, view_dir_mc) -> dict`` of uniforms recomputed every frame.
    cull_front : bool or None
        Whether the actor culls front faces (None: the kind's default, culled for ray-cast proxies drawn from
        their far side; False: neither). ``cull_per_frame``, when given, decides instead, every frame.
    cull_per_frame : callable, optional
        ``f(eye_mc, view_dir_mc, parallel, near) -> "front" | "back" | None`` (``near``: the near clipping
        distance), called before every render of the
        actor's renderer: which faces to cull in this frame (None: none). The terrain's mesh proxy culls back
        faces while the eye is outside the region under its mesh and front faces while it may be inside.
    defines_per_frame : callable, optional
        ``f(eye_mc, view_dir_mc, parallel, near) -> dict`` of compile-time defines added to ``defines`` for this frame,
        called before every render: a program with a rare special case (the eye inside the terrain's mesh
        proxy) compiles it only while it applies, instead of carrying its code in every fragment.
    world_frame : (rotation (3, 3), pivot (3,)) or None
        For a model drawn in a rotated frame (a volume on a rotated orthogonal lattice): the actor maps model
        coordinates into the world by this rotation about ``pivot`` (:meth:`SplineActor.set_frame`).
    glsl_roots : tuple of Path, optional
        Folders searched for GLSL files before the shipped ``glsl/`` (a family outside the package keeps its
        program file there; ``entry`` is then relative to such a folder).
    offset : (3,) float64, optional
        World position of the model frame's origin. Model coordinates (``points``, everything the
        shader sees) are world minus ``offset``; VTK composes the translation in double precision, so
        UTM-sized coordinates never reach float32.

    Examples
    --------
    >>> import numpy as np
    >>> box = ProgramSpec("box", "programs/box.glsl", np.zeros((8, 3)), np.zeros((12, 3), dtype=int),
    ...                   uniforms={"sv_size": 2.0}, offset=(5e5, 5e6, 0.0))
    >>> box.defines, box.uniforms, box.offset
    ({}, {'sv_size': 2.0}, (500000.0, 5000000.0, 0.0))
    """

    name: str
    entry: str
    points: np.ndarray
    triangles: np.ndarray
    defines: dict = field(default_factory=dict)
    uniforms: dict = field(default_factory=dict)
    textures: dict = field(default_factory=dict)
    attributes: dict = field(default_factory=dict)
    varyings: dict = field(default_factory=dict)
    frame_uniforms: Callable | None = None
    offset: tuple = (0.0, 0.0, 0.0)
    glsl_roots: tuple = ()
    world_frame: tuple | None = None
    cull_front: bool | None = None
    cull_per_frame: Callable | None = None
    defines_per_frame: Callable | None = None
