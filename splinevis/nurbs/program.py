"""The NURBS GPU program [Kanai2007]: a coarse tessellation carrying (u, v) and the patch id is rasterized, and
every fragment evaluates the rational surface exactly at parameters refined by Newton on its pixel ray
(``glsl/programs/nurbs.glsl``, ``glsl/lib/nurbs/basis.glsl``).

Tables (RGBA32F, :func:`splinevis.gl.proxies.pack_rgba32f`):

* ``sv_nurbs_header``: 4 texels per patch: ``(p, q, nu, nv)``; the knot offsets of U and V split as
  ``(hi, lo)`` with ``offset = 4096 hi + lo`` (both parts exact in float32, so offsets stay exact far beyond
  2^24); the control-point offset ``(hi, lo)`` and the closed-in-u / closed-in-v flags; the patch magnitude M
  and the largest |knot| (the shader's float32 tolerance, :func:`splinevis.nurbs.raycast.residual_tolerance`)
  and the collapsed edges (poles) as bits u=lo, u=hi, v=lo, v=hi (1, 2, 4, 8), plus ``16 << edge`` where that
  pole has an antipode table (no half-turn symmetry: :mod:`splinevis.nurbs.poles`);
* ``sv_nurbs_knots``: all knot vectors, one float each; after a patch's V knots, its pole tables (lower edge
  first, :func:`splinevis.nurbs.poles.pole_table`: the pole normal and POLE_TABLE + 1 antipode offsets);
* ``sv_nurbs_cps``: homogeneous control points ``(w (P - offset), w)``, one texel each (model frame: world
  minus the box centre, so coordinates around 1e6 never reach float32).
"""

from __future__ import annotations

import os

import numpy as np

from ..gl.contract import SplineProgram
from ..gl.proxies import pack_rgba32f
from ..gl.spec import ProgramSpec
from .model import NurbsModel
from .raycast import depth_bound, reference
from .renderers import RENDERERS
from .shell import model_offset, patch_facts, tessellate
from .surface import NurbsSurface

__all__ = ["nurbs_tables", "nurbs_program", "model_from", "PROGRAM"]

_SPLIT = 4096
#: SV_NURBS_MAX_DEGREE of lib/nurbs/basis.glsl when the program does not define it.
_GLSL_DEGREE = 7


def nurbs_tables(model: NurbsModel) -> dict:
    """The three tables of the shader (module docstring) as float arrays (before packing).

    >>> from splinevis.nurbs.exact import sphere, saddle
    >>> t = nurbs_tables(NurbsModel([sphere(), saddle()]))
    >>> t["header"].reshape(2, 4, 4)[1, :3].tolist()  # patch 1: degrees, counts; knot offsets; cp offset
    [[2.0, 2.0, 3.0, 3.0], [0.0, 20.0, 0.0, 26.0], [0.0, 45.0, 0.0, 0.0]]
    >>> t["knots"].size, t["cps"].shape
    (32, (54, 4))
    """
    off = model_offset(model)
    facts = patch_facts(model)
    header, knots, cps = [], [], []
    nk = ncp = 0
    for s, f in zip(model.surfaces, facts):
        (p, q), (U, V) = s.degree, s.knots
        nu, nv = s.shape
        ku, kv = nk, nk + len(U)
        tables = [t for t in f["pole_tables"] if t is not None]
        bits = sum(b << i for i, b in enumerate(f["poles"])) + sum(16 << i for i, t in enumerate(f["pole_tables"])
                                                                   if t is not None)
        header += [p, q, nu, nv, ku // _SPLIT, ku % _SPLIT, kv // _SPLIT, kv % _SPLIT,
                   ncp // _SPLIT, ncp % _SPLIT, float(f["closed"][0]), float(f["closed"][1]),
                   f["magnitude"], f["knot_max"], float(bits), 0.0]
        knots += [U, V, *tables]
        nk += len(U) + len(V) + sum(len(t) for t in tables)
        w = np.ones(s.shape) if s.weights is None else s.weights
        cps.append(np.concatenate([(s.control_points - off) * w[..., None], w[..., None]], axis=-1).reshape(-1, 4))
        ncp += nu * nv
    return {"header": np.asarray(header, dtype=np.float64), "knots": np.concatenate(knots), "cps": np.concatenate(cps)}


def nurbs_program(model, style=None, *, newton_iterations: int = 12, subdivisions: int = 8) -> ProgramSpec:
    """The ProgramSpec of a NURBS model (or one NurbsSurface).

    Parameters
    ----------
    newton_iterations : int, 1..16
        Largest number of Newton steps on the pixel ray per fragment (a fragment stops one step after its
        residual is accepted; 12: grazing rays near silhouettes converge only linearly).
    subdivisions : int
        Tessellation cells per knot span and direction for a span that turns 90 degrees, fewer for flatter
        spans (:func:`splinevis.nurbs.shell.shell_grid`).

    >>> from splinevis.nurbs.exact import torus
    >>> spec = nurbs_program(torus(), subdivisions=2)
    >>> spec.points.shape, sorted(spec.textures), spec.uniforms["sv_newton_iterations"]
    ((162, 3), ['sv_nurbs_cps', 'sv_nurbs_header', 'sv_nurbs_knots'], 12)
    """
    model = model_from(model)
    if not 1 <= int(newton_iterations) <= 16:
        raise ValueError(f"newton_iterations must be 1..16, got {newton_iterations!r}.")
    if int(subdivisions) < 1:
        raise ValueError(f"subdivisions must be >= 1, got {subdivisions!r}.")
    t = nurbs_tables(model)
    points, triangles, uv, patch = tessellate(model, int(subdivisions), adaptive=True)
    zr = np.asarray(model.bounds()[4:]) - model_offset(model)[2]
    trim = _trim_spec(model)
    defines = dict(trim.get("defines", {}))
    degree = max(max(s.degree) for s in model.surfaces)
    if degree > _GLSL_DEGREE:
        # the shader's local basis arrays are sized by SV_NURBS_MAX_DEGREE (lib/nurbs/basis.glsl, 7 by default):
        # raised only for a model that needs it, so the common low-degree program keeps its cost
        defines["SV_NURBS_MAX_DEGREE"] = int(degree)
    if any(t is not None for f in patch_facts(model) for t in f["pole_tables"]):
        # the antipode rule over asymmetric poles (lib/nurbs/poles.glsl) is compiled in only for models that have
        # one: inside the Newton loop it doubles llvmpipe's time per fragment even where it never runs
        defines["SV_NURBS_POLE_TABLES"] = True
    return ProgramSpec(
        name="nurbs", entry="programs/nurbs.glsl", points=points, triangles=triangles,
        uniforms={"sv_newton_iterations": int(newton_iterations), "sv_scalar_range": (float(zr[0]), float(zr[1]))},
        textures={"sv_nurbs_header": pack_rgba32f(t["header"], name="NURBS header"),
                  "sv_nurbs_knots": pack_rgba32f(t["knots"], name="NURBS knots"),
                  "sv_nurbs_cps": pack_rgba32f(t["cps"], name="NURBS control points"), **trim.get("textures", {})},
        defines=defines,
        attributes={"sv_nurbs_patch": patch}, varyings={"sv_nurbs_uv": uv},
        offset=tuple(model_offset(model).tolist()))


def _trim_spec(model) -> dict:
    """Defines and tables of per-fragment trimming (``lib/nurbs/trim.glsl``), for a model with trim loops: the
    pieces of all loops, and per patch ``(first // 4096, first % 4096, count, 0)``; nothing when untrimmed.

    >>> from splinevis.nurbs.exact import saddle
    >>> _trim_spec(NurbsModel([saddle()]))
    {}
    """
    if all(t is None for t in model.trims):
        return {}
    from .trim import trim_pieces

    pieces = trim_pieces(model.trims)
    index = np.column_stack([pieces.start // _SPLIT, pieces.start % _SPLIT, pieces.count, np.zeros(len(pieces.count))])
    table = pieces.table() if len(pieces.degree) else np.zeros((1, 32))
    return {"defines": {"SV_NURBS_TRIM": True},
            "textures": {"sv_trim_table": pack_rgba32f(table, name="trim pieces"),
                               "sv_trim_index": pack_rgba32f(index, name="trim index")}}


def model_from(data, *args, **kwargs) -> NurbsModel:
    """A NurbsModel from a NurbsModel, a NurbsSurface, a list of surfaces or a file name
    (:func:`splinevis.io.read_nurbs`).

    >>> from splinevis.nurbs.exact import saddle
    >>> model_from(saddle()).names
    ('saddle',)
    """
    if isinstance(data, NurbsModel):
        return data
    if isinstance(data, NurbsSurface):
        return NurbsModel([data], source=data.name)
    if isinstance(data, (str, os.PathLike)):
        from ..io.nurbs_files import read_nurbs

        return read_nurbs(data)
    return NurbsModel(list(data), *args, **kwargs)


def _hard_cases():
    from .hard_cases import hard_cases

    return hard_cases()


def _build(model, style, *, newton_iterations, subdivisions=8):
    return nurbs_program(model, style, newton_iterations=newton_iterations, subdivisions=subdivisions)


PROGRAM = SplineProgram(
    name="nurbs", kind="surface", model_type=NurbsModel, build=_build, reference=reference, depth_bound=depth_bound,
    hard_cases=_hard_cases, model_from=model_from, root_methods=("newton",), newton_iterations=12,
    options=("subdivisions",), description="NURBS patches evaluated per fragment, Newton on the pixel ray [Kanai2007]",
    converts=(NurbsSurface,), renderers=RENDERERS)
