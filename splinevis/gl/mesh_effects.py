"""Reflection lines on ordinary meshes, from the same GLSL file the spline programs use.

A marching cubes or other triangle mesh shaded with its interpolated vertex normals shows what users see
today; to compare surface quality with the ray-cast splines side by side, the mesh gets the very same
stripes: ``glsl/lib/effects/reflection_lines.glsl`` evaluated per fragment on the mirrored view ray of the
interpolated (model-space) vertex normal, multiplied into VTK's own lighting. Facets and normal kinks of the
mesh then show as kinks in the stripes.
"""

from __future__ import annotations

import numpy as np
from vtkmodules.vtkCommonCore import VTK_OBJECT

from .assembler import assemble
from .inject import _set_uniform

__all__ = ["add_mesh_with_reflection_lines", "add_mesh_with_effects", "MESH_EFFECTS"]

_VS_DEC = """//VTK::Normal::Dec
out vec3 svMeshPosMC;
out vec3 svMeshNormalMC;
"""
_VS_IMPL = """//VTK::Normal::Impl
  svMeshPosMC = vertexMC.xyz;
  svMeshNormalMC = normalMC;
"""
_FS_DEC = """//VTK::Normal::Dec
in vec3 svMeshPosMC;
in vec3 svMeshNormalMC;
uniform vec3 sv_eye_mc;
"""
_FS_LIGHT = """//VTK::Light::Impl
  {
    vec3 sv_rd = normalize(svMeshPosMC - sv_eye_mc);
    vec3 sv_n = normalize(svMeshNormalMC);
    if (dot(sv_n, sv_rd) > 0.0) sv_n = -sv_n;  // two-sided, as lib/core/shading.glsl
    fragOutput0.rgb *= sv_reflection_lines(reflect(sv_rd, sv_n));
  }
"""


def add_mesh_with_reflection_lines(plotter, mesh, stripes: int, *, color="tan", ambient: float = 0.15,
                                   diffuse: float = 0.85, axis=(1.0, 0.0, 0.0)):
    """Add ``mesh`` (point normals are used, e.g. from marching cubes; computed if absent) to ``plotter``,
    Phong-shaded with VTK's lights, with ``stripes`` reflection lines computed as for the splines
    (``Style(reflection_lines=stripes, reflection_axis=axis)``). The mesh is in world coordinates (no actor
    transform).

    Returns the vtkActor. (A vtkOpenGLPolyDataMapper of our own: pyvista's DataSetMapper renders through
    an internal mapper whose shader events it does not forward.)

    Examples
    --------
    >>> import pyvista as pv
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(48, 48))
    >>> actor = add_mesh_with_reflection_lines(pl, pv.Sphere(), 8)
    >>> image = pl.screenshot()
    >>> actor.GetMapper().GetClassName(), image.shape, int(image.std()) > 10  # striped, not flat
    ('vtkOpenGLPolyDataMapper', (48, 48, 3), True)
    >>> pl.close()
    """
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkCommand
    from vtkmodules.vtkRenderingCore import vtkActor
    from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

    if isinstance(stripes, bool) or not isinstance(stripes, (int, np.integer)) or stripes < 1:
        raise ValueError(f"stripes must be a positive integer, got {stripes!r}.")
    mesh = pv.wrap(mesh).extract_surface(algorithm=None) if not isinstance(mesh, pv.PolyData) else mesh
    if mesh.point_data.get("Normals") is None:
        mesh = mesh.compute_normals(cell_normals=False, split_vertices=False)
    mesh.point_data.active_normals_name = "Normals"
    mapper = vtkOpenGLPolyDataMapper()
    mapper.SetInputData(mesh)
    mapper.ScalarVisibilityOff()
    actor = vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetColor(*pv.Color(color).float_rgb)
    prop.SetInterpolationToPhong()
    prop.SetAmbient(ambient)
    prop.SetDiffuse(diffuse)
    code = assemble('#include "lib/effects/reflection_lines.glsl"\n', {}).text
    sp = actor.GetShaderProperty()
    sp.AddVertexShaderReplacement("//VTK::Normal::Dec", True, _VS_DEC, False)
    sp.AddVertexShaderReplacement("//VTK::Normal::Impl", True, _VS_IMPL, False)
    sp.AddFragmentShaderReplacement("//VTK::Normal::Dec", True, _FS_DEC + code, False)
    sp.AddFragmentShaderReplacement("//VTK::Light::Impl", True, _FS_LIGHT, False)
    renderer = plotter.renderer
    from ..effects import line_frame

    line_b, line_c = line_frame(axis)

    def update(caller, event, program=None):
        if program is None:
            return
        eye = np.array(renderer.GetActiveCamera().GetPosition(), dtype=np.float64)
        _set_uniform(program, "sv_eye_mc", eye)
        _set_uniform(program, "sv_stripes", float(stripes))
        _set_uniform(program, "sv_line_b", np.asarray(line_b))
        _set_uniform(program, "sv_line_c", np.asarray(line_c))

    update.CallDataType = VTK_OBJECT
    mapper.AddObserver(vtkCommand.UpdateShaderEvent, update)
    actor._sv_update = update  # keep the callback alive with the actor
    plotter.add_actor(actor, reset_camera=True)
    return actor


#: Style effects a mesh made by a ``passes`` or ``mesh`` program can show today.
MESH_EFFECTS = frozenset({"lights", "reflection_lines", "transparency"})


def add_mesh_with_effects(plotter, mesh, style, *, name=None):
    """Draw the dataset a ``passes`` or ``mesh`` program made (:mod:`splinevis.gl.contract`) with the scene's
    :class:`~splinevis.Style`: colour, lighting weights and opacity through VTK, reflection lines through the
    same GLSL file as the ray-cast programs (:func:`add_mesh_with_reflection_lines`).

    Effects a mesh cannot show yet (textures, environment maps, isophotes, output modes) raise a
    ``ValueError`` naming them, instead of being dropped silently.

    Examples
    --------
    >>> import pyvista as pv
    >>> from splinevis import Style
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(48, 48))
    >>> actor = add_mesh_with_effects(pl, pv.Sphere(), Style(lights=1, opacity=0.5))
    >>> actor.GetProperty().GetOpacity()
    0.5
    >>> add_mesh_with_effects(pl, pv.Sphere(), Style(output="normals"))
    Traceback (most recent call last):
    ValueError: a mesh-drawing program cannot show the effects normals yet; it shows lights, reflection_lines, transparency. Remove them from the Style.
    >>> pl.close()
    """
    unsupported = sorted(set(style.effect_set()) - MESH_EFFECTS)
    if unsupported:
        raise ValueError(f"a mesh-drawing program cannot show the effects {', '.join(unsupported)} yet; it shows "
                         f"{', '.join(sorted(MESH_EFFECTS))}. Remove them from the Style.")
    if style.reflection_lines:
        actor = add_mesh_with_reflection_lines(plotter, mesh, int(style.reflection_lines), color=style.color,
                                               ambient=style.ambient, diffuse=style.diffuse,
                                               axis=style.reflection_axis)
        actor.GetProperty().SetOpacity(float(style.opacity))
        return actor
    return plotter.add_mesh(mesh, color=style.color, smooth_shading=True, ambient=style.ambient,
                            diffuse=style.diffuse, opacity=float(style.opacity), lighting=style.lights > 0, name=name)
