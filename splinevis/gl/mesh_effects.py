"""Style effects on ordinary meshes, from the same GLSL files the spline programs use.

A marching cubes mesh, or the dataset a ``passes`` / ``mesh`` program made (limit points and exact normals of
a subdivision, NURBS levels of detail), is shaded by VTK with its interpolated vertex normals. To compare it
with the ray-cast splines like with like, the effects that look at the surface's differential geometry are
evaluated per fragment by the very same functions:

* ``reflection_lines`` -- ``glsl/lib/effects/reflection_lines.glsl`` on the mirrored view ray of the
  interpolated (model-space) vertex normal, multiplied into VTK's lighting;
* ``isophotes`` -- ``glsl/lib/effects/isophotes.glsl``: bands of ``dot(n, L)`` for the Style's first light,
  turned into model coordinates every frame as for the ray-cast programs, multiplied into VTK's lighting;
* ``curvature`` -- an output mode: the fragment's colour is ``sv_curvature_color`` of
  ``glsl/lib/effects/curvature.glsl`` (unlit, as the spline programs show it) of the mesh's point-data array
  ``"curvature"`` (mean H, Gaussian K per vertex), passed to the shader as a vertex attribute.

Facets and normal kinks of the mesh then show as kinks in the stripes and bands. One function,
:func:`_add_shaded_mesh`, assembles the shader replacements from the declared effects; only the declared
effects' GLSL is compiled in.
"""

from __future__ import annotations


import numpy as np
import pyvista as pv
from vtkmodules.vtkCommonCore import VTK_OBJECT

from ..effects import EFFECTS, Style
from .assembler import assemble
from .inject import _set_uniform, camera_frame

__all__ = ["add_mesh_with_reflection_lines", "add_mesh_with_effects", "MeshActor", "MESH_EFFECTS", "CURVATURE_ARRAY"]

#: Style effects a mesh made by a ``passes`` or ``mesh`` program can show.
MESH_EFFECTS = frozenset({"lights", "reflection_lines", "isophotes", "antialias", "transparency", "curvature"})
#: Point-data array of (mean H, Gaussian K) per vertex that ``output="curvature"`` shows on a mesh.
CURVATURE_ARRAY = "curvature"
# The effects drawn by fragment code of ours (the others are VTK's lighting and opacity), in the order
# lib/core/shading.glsl applies them.
_SHADER_EFFECTS = ("reflection_lines", "isophotes", "curvature")

_VS_DEC = """//VTK::Normal::Dec
in vec3 svMeshNormal;
out vec3 svMeshPosMC;
out vec3 svMeshNormalMC;
"""
_VS_IMPL = """//VTK::Normal::Impl
  svMeshPosMC = vertexMC.xyz;
  svMeshNormalMC = svMeshNormal;
"""
_FS_DEC = """//VTK::Normal::Dec
in vec3 svMeshPosMC;
in vec3 svMeshNormalMC;
uniform vec3 sv_eye_mc;       // camera position, model coordinates (perspective views)
uniform vec3 sv_view_dir_mc;  // unit view direction, model coordinates (parallel views)
uniform int sv_parallel;      // 1 for a parallel projection
"""
# Declared by lib/core/raycast.glsl for the ray-cast programs; lib/effects/lights.glsl refers to them.
_FS_LIGHT_WEIGHTS = """uniform float sv_ambient;
uniform float sv_diffuse;
"""
_CURVATURE_VS_DEC = "in vec2 svMeshCurvature;\nout vec2 svMeshCurvatureVS;\n"
_CURVATURE_VS_IMPL = "  svMeshCurvatureVS = svMeshCurvature;\n"
_CURVATURE_FS_DEC = "in vec2 svMeshCurvatureVS;\n"
_FS_RAY = """    vec3 sv_rd = sv_parallel == 1 ? sv_view_dir_mc : normalize(svMeshPosMC - sv_eye_mc);
    vec3 sv_n = normalize(svMeshNormalMC);
    if (dot(sv_n, sv_rd) > 0.0) sv_n = -sv_n;  // two-sided, as lib/core/shading.glsl
"""
_FS_EFFECT = {
    "reflection_lines": "    fragOutput0.rgb *= sv_reflection_lines(reflect(sv_rd, sv_n));\n",
    "isophotes": "    fragOutput0.rgb *= sv_isophotes(sv_n);\n",
    # an output mode replaces shading, unlit and opaque as in lib/core/shading.glsl
    "curvature": "    fragOutput0 = vec4(sv_curvature_color(svMeshCurvatureVS), 1.0);\n",
}


class MeshActor(pv.Actor):
    """A ``pyvista.Actor`` drawing a mesh with a :class:`~splinevis.Style` (``.style``; ``.model`` and ``.program``
    when a program made the mesh), so a mesh-drawing program's actor is used as the ray-cast ones are.

    >>> from splinevis import Style
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(32, 24))
    >>> a = add_mesh_with_effects(pl, pv.Sphere(), Style(reflection_lines=4))
    >>> isinstance(a, pv.Actor), a.style.reflection_lines, pl.remove_actor(a)
    (True, 4, True)
    >>> pl.close()
    """

    __setattr__ = object.__setattr__  # .style, .model, ... are set after construction
    model = program = None


def _replacements(effects) -> list[tuple[str, str, str]]:
    """(stage, VTK tag, replacement) for the declared ``effects`` (those of :data:`_SHADER_EFFECTS`); the
    GLSL of an effect that is not declared is not in them."""
    shown = [name for name in _SHADER_EFFECTS if name in effects]
    files, defines = [], {}
    if "isophotes" in shown:  # the bands use the first light's direction, sv_light_dir[0]
        files.append(EFFECTS["lights"][1])
        defines["SV_NUM_LIGHTS"] = 1
    for name in shown:
        files.append(EFFECTS[name][1])
        defines[EFFECTS[name][0]] = True
    if "antialias" in effects and shown:  # the stripes averaged over the pixel, as on the spline programs
        defines[EFFECTS["antialias"][0]] = True
    code = assemble("".join(f'#include "{f}"\n' for f in files), defines).text if files else ""
    vs_dec, vs_impl, fs_dec = _VS_DEC, _VS_IMPL, _FS_DEC
    if "isophotes" in shown:
        fs_dec += _FS_LIGHT_WEIGHTS
    if "curvature" in shown:
        vs_dec, vs_impl, fs_dec = vs_dec + _CURVATURE_VS_DEC, vs_impl + _CURVATURE_VS_IMPL, fs_dec + _CURVATURE_FS_DEC
    light = "//VTK::Light::Impl\n  {\n" + _FS_RAY + "".join(_FS_EFFECT[name] for name in shown) + "  }\n"
    return [("vertex", "//VTK::Normal::Dec", vs_dec), ("vertex", "//VTK::Normal::Impl", vs_impl),
            ("fragment", "//VTK::Normal::Dec", fs_dec + code), ("fragment", "//VTK::Light::Impl", light)]


def _surface_with_normals(mesh):
    """A shallow copy of ``mesh`` as PolyData with active point normals (its own if it has them, e.g. exact
    normals of a program; else computed from the triangles) and the normals array's name."""
    import pyvista as pv

    mesh = pv.wrap(mesh)
    mesh = mesh.extract_surface(algorithm=None) if not isinstance(mesh, pv.PolyData) else mesh.copy(deep=False)
    active = mesh.GetPointData().GetNormals()
    if active is not None and active.GetName():
        return mesh, active.GetName()
    if mesh.point_data.get("Normals") is None:
        mesh = mesh.compute_normals(cell_normals=False, split_vertices=False)
    mesh.point_data.active_normals_name = "Normals"
    return mesh, "Normals"


def _check_curvature(mesh) -> None:
    how = (f"Add it from the surface the mesh samples, or estimate it from the mesh: mesh.point_data["
           f"'{CURVATURE_ARRAY}'] = np.column_stack([mesh.curvature('mean'), mesh.curvature('gaussian')]).")
    values = mesh.point_data.get(CURVATURE_ARRAY)
    if values is None:
        where = " (it is cell data; it must be point data)" if CURVATURE_ARRAY in mesh.cell_data else ""
        raise ValueError(f"Style(output='curvature') on a mesh shows its point-data array '{CURVATURE_ARRAY}' of "
                         f"(mean H, Gaussian K) per vertex; this mesh has none{where}. {how}")
    values = np.asarray(values)
    if values.shape != (mesh.n_points, 2) or not np.isfinite(values).all():
        raise ValueError(f"the mesh's point-data array '{CURVATURE_ARRAY}' must be ({mesh.n_points}, 2) finite "
                         f"(mean H, Gaussian K) per vertex, got {values.dtype} {values.shape}"
                         f"{'' if values.shape != (mesh.n_points, 2) else ' with non-finite values'}. {how}")


def _add_shaded_mesh(plotter, mesh, style: Style, name=None):
    """Add ``mesh`` with ``style``'s effects as a vtkOpenGLPolyDataMapper of our own (pyvista's DataSetMapper
    renders through an internal mapper whose shader events it does not forward); returns the vtkActor, whose
    ``program_sources`` hold the compiled vertex and fragment shaders after the first render."""
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkCommand
    from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

    effects = style.effect_set()
    mesh, normals = _surface_with_normals(mesh)
    # Model coordinates relative to the mesh's centre, the actor placed there: VTK's shift-scale of the vertex
    # buffer is off (vertexMC must match the eye), so far from the origin (UTM-sized coordinates) float32 vertices
    # would otherwise lose their digits; the eye goes into the same frame in double precision (camera_frame).
    centre = np.asarray(mesh.center, dtype=np.float64) if mesh.n_points else np.zeros(3)
    mesh = mesh.copy(deep=False)  # new vtkPoints on the copy: the caller's mesh keeps its own points
    mesh.SetPoints(pv.vtk_points(np.asarray(mesh.points, dtype=np.float64) - centre))
    mapper = vtkOpenGLPolyDataMapper()
    mapper.SetInputData(mesh)
    mapper.ScalarVisibilityOff()
    mapper.SetVBOShiftScaleMethod(0)  # DISABLE_SHIFT_SCALE: vertexMC must be model coordinates, like the eye
    # our own attributes: VTK declares normalMC only when lighting is on, and knows nothing of curvature
    mapper.MapDataArrayToVertexAttribute("svMeshNormal", normals, 0, -1)
    if "curvature" in effects:
        _check_curvature(mesh)
        mapper.MapDataArrayToVertexAttribute("svMeshCurvature", CURVATURE_ARRAY, 0, -1)
    actor = MeshActor(mapper=mapper)
    actor.style = style
    actor.SetPosition(*centre)
    prop = actor.GetProperty()
    prop.SetColor(*style.color)
    prop.SetInterpolationToPhong()
    prop.SetAmbient(float(style.ambient))
    prop.SetDiffuse(float(style.diffuse))
    if "lights" not in effects:  # unlit (lights=0, or an output mode): the base colour, as the spline programs
        prop.LightingOff()
    if "transparency" in effects:
        prop.SetOpacity(float(style.opacity))
    sp = actor.GetShaderProperty()
    for stage, tag, text in _replacements(effects):
        add = sp.AddVertexShaderReplacement if stage == "vertex" else sp.AddFragmentShaderReplacement
        add(tag, True, text, False)
    renderer = plotter.renderer
    style_uniforms = style.uniforms()
    actor.program_sources = {}

    def update(caller, event, program=None):
        if program is None:
            return
        if not actor.program_sources:
            actor.program_sources = {"vertex": program.GetVertexShader().GetSource(),
                                     "fragment": program.GetFragmentShader().GetSource()}
        # the model frame: world shifted by the mesh's centre, as a spline actor with that offset and no rotation
        eye, view, parallel, world_from_cam = camera_frame(renderer, centre)
        uniforms = {"sv_eye_mc": eye, "sv_view_dir_mc": view, "sv_parallel": int(parallel)}
        if "isophotes" in effects:
            uniforms["sv_light_dir[]"] = style.light_directions_camera()[:1] @ world_from_cam.T
        uniforms.update(style_uniforms)
        for key, value in uniforms.items():
            _set_uniform(program, key, value)

    update.CallDataType = VTK_OBJECT
    mapper.AddObserver(vtkCommand.UpdateShaderEvent, update)
    actor._sv_update = update  # keep the callback alive with the actor
    plotter.add_actor(actor, reset_camera=True, name=name)
    return actor


def add_mesh_with_reflection_lines(plotter, mesh, stripes: int, *, color="tan", ambient: float = 0.15,
                                   diffuse: float = 0.85, axis=(1.0, 0.0, 0.0), antialias: bool = True):
    """Add ``mesh`` (point normals are used, e.g. from marching cubes; computed if absent) to ``plotter``,
    Phong-shaded with VTK's lights, with ``stripes`` reflection lines computed as for the splines
    (``Style(reflection_lines=stripes, reflection_axis=axis, antialias=antialias)``: filtered over the pixel
    unless ``antialias`` is False). The mesh is in world coordinates (no actor transform).

    Returns the vtkActor. (A vtkOpenGLPolyDataMapper of our own: pyvista's DataSetMapper renders through
    an internal mapper whose shader events it does not forward.) This is :func:`add_mesh_with_effects` with
    ``Style(lights=1, reflection_lines=stripes, ...)``.

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

    if isinstance(stripes, bool) or not isinstance(stripes, (int, np.integer)) or stripes < 1:
        raise ValueError(f"stripes must be a positive integer, got {stripes!r}.")
    style = Style(lights=1, color=pv.Color(color).float_rgb, reflection_lines=int(stripes), reflection_axis=axis,
                  ambient=ambient, diffuse=diffuse, antialias=antialias)
    return _add_shaded_mesh(plotter, mesh, style)


def add_mesh_with_effects(plotter, mesh, style, *, name=None):
    """Draw the dataset a ``passes`` or ``mesh`` program made (:mod:`splinevis.gl.contract`) with the scene's
    :class:`~splinevis.Style`: colour, lighting weights and opacity through VTK; reflection lines, isophotes
    and the curvature output through the same GLSL files as the ray-cast programs.

    The mesh's point normals are used (e.g. a program's exact normals; computed from the triangles if absent).
    ``output="curvature"`` shows the point-data array ``"curvature"`` of (mean H, Gaussian K) per vertex, which
    the program computes from its surface; a mesh without it raises a ``ValueError`` saying how to add one.
    Effects a mesh cannot show yet (textures, environment maps, other output modes) raise a ``ValueError``
    naming them, instead of being dropped silently.

    Returns a :class:`MeshActor` (a ``pyvista.Actor``: ``remove_actor`` and the rest work) with ``.style``; with
    effects drawn by our shader code its ``program_sources`` hold the compiled shaders after the first render.

    Examples
    --------
    >>> import numpy as np
    >>> import pyvista as pv
    >>> from splinevis import Style
    >>> from splinevis.plotting import Plotter
    >>> pl = Plotter(off_screen=True, window_size=(48, 48))
    >>> actor = add_mesh_with_effects(pl, pv.Sphere(), Style(lights=1, opacity=0.5))
    >>> actor.GetProperty().GetOpacity()
    0.5
    >>> sphere = pv.Sphere(radius=2.0)
    >>> sphere.point_data["curvature"] = np.tile([0.5, 0.25], (sphere.n_points, 1))  # (H, K) = (1/r, 1/r^2)
    >>> actor = add_mesh_with_effects(pl, sphere, Style(output="curvature", curvature_scale=1.0), name="sphere")
    >>> image = pl.screenshot()
    >>> image[24, 24].tolist()  # mean curvature 0.5 at scale 1: halfway from white to red, unlit
    [218, 130, 147]
    >>> "sv_curvature_color" in actor.program_sources["fragment"], "sv_isophotes" in actor.program_sources["fragment"]
    (True, False)
    >>> add_mesh_with_effects(pl, pv.Sphere(), Style(output="curvature"))
    Traceback (most recent call last):
    ValueError: Style(output='curvature') on a mesh shows its point-data array 'curvature' of (mean H, Gaussian K) per vertex; this mesh has none. Add it from the surface the mesh samples, or estimate it from the mesh: mesh.point_data['curvature'] = np.column_stack([mesh.curvature('mean'), mesh.curvature('gaussian')]).
    >>> add_mesh_with_effects(pl, pv.Sphere(), Style(output="normals"))
    Traceback (most recent call last):
    ValueError: a mesh-drawing program cannot show the effects normals yet; it shows antialias, curvature, isophotes, lights, reflection_lines, transparency. Remove them from the Style.
    >>> pl.close()
    """
    effects = style.effect_set()
    unsupported = sorted(set(effects) - MESH_EFFECTS)
    if unsupported:
        raise ValueError(f"a mesh-drawing program cannot show the effects {', '.join(unsupported)} yet; it shows "
                         f"{', '.join(sorted(MESH_EFFECTS))}. Remove them from the Style.")
    if effects & set(_SHADER_EFFECTS):
        return _add_shaded_mesh(plotter, mesh, style, name=name)
    plain = plotter.add_mesh(mesh, color=style.color, smooth_shading=True, ambient=style.ambient,
                             diffuse=style.diffuse, opacity=float(style.opacity), lighting=style.lights > 0, name=name)
    actor = MeshActor(mapper=plain.GetMapper(), prop=plain.GetProperty())  # the same drawing, with .style
    actor.style, actor.program_sources = style, {}
    plotter.remove_actor(plain, reset_camera=False)
    plotter.add_actor(actor, reset_camera=True, name=name)
    return actor
