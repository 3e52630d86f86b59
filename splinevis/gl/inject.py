"""The one place that injects splinevis programs into VTK's vtkOpenGLPolyDataMapper.

A spline program is described by a :class:`ProgramSpec` (plain data: a GLSL entry file, a proxy mesh,
uniforms, float textures, vertex attributes). :func:`make_actor` turns it and a :class:`~splinevis.Style`
into a VTK actor whose fragment shader ray-casts the spline:

* vertex shader: passes the model-space position of the proxy vertex (``svPosMC``) and any vertex
  attributes on to the fragment shader;
* fragment shader: declarations + the assembled block (program file, lib files, declared effects) go in
  at ``//VTK::Edges::Dec`` (after VTK's texture samplers); the ray cast, ``discard`` on a miss and ``gl_FragDepth`` replace
  ``//VTK::Depth::Impl``; VTK's lighting at ``//VTK::Light::Impl`` is replaced by ``sv_shade``;
* per frame, an ``UpdateShaderEvent`` observer sets the camera (eye, view direction, projection type),
  the light directions and every uniform of the spec and the style;
* the proxy is drawn with front faces culled, so fragments lie on its far side and the camera may be
  inside it;
* VBO shift/scale is off, so ``vertexMC`` holds real model coordinates.

Facts this relies on (VBO shift/scale, attribute limits, uniform declarations, front-face culling) were
measured on Mesa llvmpipe and are checked by tests/test_inject.py.
"""

from __future__ import annotations

import numpy as np

from ..effects import Style
from .assembler import assemble
from .spec import ProgramSpec
from .textures import _colormap_image, _image_texture
from .vtk_errors import capture_vtk_errors

from pyvista import Actor as _PyVistaActor
from vtkmodules.vtkCommonCore import VTK_OBJECT

__all__ = ["ProgramSpec", "SplineActor", "make_actor", "camera_frame", "capture_vtk_errors"]

_VS_DEC = """//VTK::Normal::Dec
out vec3 svPosMC;
"""
_VS_IMPL = """//VTK::Normal::Impl
  svPosMC = vertexMC.xyz;
"""
# Inserted at the last declaration tag of VTK's template, after VTK has declared the samplers of the
# textures set on the actor property (effects use them).
_FS_DEC_TAG = "//VTK::Edges::Dec"
_FS_DEC = """//VTK::Edges::Dec
in vec3 svPosMC;
uniform mat4 MCDCMatrix;
"""
# With SV_ANTIALIAS a miss is shaded too, flagged, and discarded after: the stripes' filter differentiates across
# the 2 x 2 pixel quad (lib/effects/footprint.glsl).
_FS_MISS = "#ifdef SV_ANTIALIAS\n  sv_footprint_valid = sv_is_hit ? 1.0 : 0.0;\n#else\n  if (!sv_is_hit) discard;\n#endif\n"
_FS_SHADE = "  vec4 sv_out = sv_shade(sv_hit, sv_rd);\n#ifdef SV_ANTIALIAS\n  if (!sv_is_hit) discard;\n#endif\n"
_FS_DEPTH = """
  vec3 sv_ro; vec3 sv_rd; float sv_tmin;
  sv_pixel_ray(svPosMC, sv_ro, sv_rd, sv_tmin);
  SvHit sv_hit;
  bool sv_is_hit = sv_surface_hit(sv_ro, sv_rd, sv_tmin, sv_hit);
""" + _FS_MISS + """  sv_hit.depth = sv_window_depth(MCDCMatrix, sv_ro + sv_hit.t * sv_rd);
  gl_FragDepth = sv_hit.depth;
""" + _FS_SHADE
# The "surface" kind: the rasterized mesh carries surface parameters; the program's sv_surface_eval evaluates
# the surface exactly at this fragment's parameters (no ray search). The view ray of the fragment still
# decides two-sided shading and reflections.
_FS_SURFACE = """
  vec3 sv_ro; vec3 sv_rd; float sv_tmin;
  sv_pixel_ray(svPosMC, sv_ro, sv_rd, sv_tmin);
  SvHit sv_hit;
  bool sv_is_hit = sv_surface_eval(svPosMC, sv_hit);
""" + _FS_MISS + """  sv_hit.depth = sv_window_depth(MCDCMatrix, sv_hit.pos);
  gl_FragDepth = sv_hit.depth;
""" + _FS_SHADE
_FS_LIGHT = """  fragOutput0 = sv_out;
"""
# The debug build with per-fragment counters (SV_DEBUG_COUNTERS, glsl/lib/core/counters.glsl): a miss is not
# discarded (its work is counted too) but written at the far plane, so the depth buffer still holds exactly
# the hits; the colour is the selected counter.
_FS_COUNTERS = """
  vec3 sv_ro; vec3 sv_rd; float sv_tmin;
  sv_pixel_ray(svPosMC, sv_ro, sv_rd, sv_tmin);
  SvHit sv_hit;
  bool sv_is_hit = sv_surface_hit(sv_ro, sv_rd, sv_tmin, sv_hit);
  gl_FragDepth = sv_is_hit ? sv_window_depth(MCDCMatrix, sv_ro + sv_hit.t * sv_rd) : 1.0;
  vec4 sv_out = sv_counters_color(sv_is_hit);
"""
#: Fragment code per program kind (splinevis.gl.contract.KINDS) that becomes a SplineActor.
_FS_IMPL = {"raycast": _FS_DEPTH, "surface": _FS_SURFACE}


def _set_uniform(program, name: str, value) -> None:
    if isinstance(value, (bool, np.bool_)):
        program.SetUniformi(name, int(value))
    elif isinstance(value, (int, np.integer)):
        program.SetUniformi(name, int(value))
    elif isinstance(value, (float, np.floating)):
        program.SetUniformf(name, float(value))
    else:
        if np.asarray(value).dtype.kind in "iu" and name.endswith("[]"):  # int arrays stay exact (offsets > 2^24)
            ints = np.asarray(value, dtype=np.int64).ravel()
            if np.abs(ints).max(initial=0) >= 2**31:
                raise ValueError(f"uniform {name}: values beyond the 32-bit int range.")
            program.SetUniform1iv(name.rstrip("[]"), int(ints.size), [int(v) for v in ints])
            return
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 1 and arr.size in (2, 3, 4) and not name.endswith("[]"):
            getattr(program, f"SetUniform{arr.size}f")(name, tuple(arr.tolist()))
        elif arr.ndim == 1:
            program.SetUniform1fv(name.rstrip("[]"), int(arr.size), arr.astype(np.float32).tolist())
        elif arr.ndim == 2 and arr.shape[1] in (2, 3, 4):
            base = name.rstrip("[]")
            for i, row in enumerate(arr):
                getattr(program, f"SetUniform{arr.shape[1]}f")(f"{base}[{i}]", tuple(row.tolist()))
        else:
            raise ValueError(f"uniform {name}: cannot set a value of shape {arr.shape}.")


def _float_texture(array: np.ndarray, name: str):
    """An RGBA32F table as a VTK texture sharing the array's memory (:func:`splinevis.gl.textures.to_vtk_texture`)."""
    from .textures import to_vtk_texture

    if np.ndim(array) != 3 or np.shape(array)[2] != 4:
        raise ValueError(f"texture {name} must be (H, W, 4) float32, got {np.shape(array)}.")
    return to_vtk_texture(array, name=name)


def camera_frame(renderer, offset, position=None, rotation=None):
    """(eye, view direction, parallel flag, world-from-camera rotation) of ``renderer``'s camera in a model frame:
    world shifted by ``offset`` or, for a rotated model (``rotation`` R, placed at ``position``),
    ``R^T (world - position)``; in double precision (what a spline actor and a mesh drawn relative to its centre
    hand their shaders).

    Examples
    --------
    >>> from vtkmodules.vtkRenderingCore import vtkRenderer
    >>> renderer = vtkRenderer()
    >>> camera = renderer.GetActiveCamera()
    >>> camera.SetPosition(100, 0, 5); camera.SetFocalPoint(100, 0, 0); camera.SetViewUp(0, 1, 0)
    >>> eye, view, parallel, rotation = camera_frame(renderer, np.array([100.0, 0.0, 0.0]))
    >>> eye, view, parallel
    (array([0., 0., 5.]), array([ 0.,  0., -1.]), False)
    """
    offset = np.asarray(offset, dtype=np.float64)
    cam = renderer.GetActiveCamera()
    eye = np.array(cam.GetPosition(), dtype=np.float64) - offset  # model frame (double precision)
    focal = np.array(cam.GetFocalPoint(), dtype=np.float64) - offset
    view = focal - eye
    view /= np.linalg.norm(view)
    m = cam.GetViewTransformMatrix()
    rot = np.array([[m.GetElement(i, j) for j in range(3)] for i in range(3)])  # camera-from-world
    if rotation is not None:  # a rotated model: camera and its frame into the model frame
        R = rotation
        eye = R.T @ (np.array(cam.GetPosition(), dtype=np.float64) - position)
        view = R.T @ view
        return eye, view / np.linalg.norm(view), bool(cam.GetParallelProjection()), R.T @ rot.T
    return eye, view, bool(cam.GetParallelProjection()), rot.T


class SplineActor(_PyVistaActor):
    """A :class:`pyvista.Actor` ray-casting a spline program, and what it knows about its compiled program:
    ``plotter.remove_actor``, ``visibility``, ``prop`` and the rest work as for any PyVista actor.

    Attributes
    ----------
    actor : SplineActor
        The VTK actor: this object itself (older code said ``spline_actor.actor``).
    model, style
        The model drawn (set by :meth:`splinevis.Plotter.add_spline`) and its :class:`~splinevis.Style`.
    assembled : Assembled
        The fragment block handed to VTK (inspect ``.text`` and ``.files``).
    program_sources : dict
        After the first render: ``{"vertex": ..., "fragment": ...}``, the final sources VTK compiled
        (captured from the program object itself).
    program_ids : set of str
        Addresses of the vtkShaderProgram objects used; equal ids mean a shared compiled program.

    Examples
    --------
    Building the actor needs no OpenGL context (the program compiles at the first render):

    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> from splinevis.analytic.program import patch_program
    >>> actor = SplineActor(patch_program(QuarticTrianglePatch.demo()), Style(lights=1))
    >>> actor.kind, actor.poly.GetNumberOfPoints(), actor.poly.GetNumberOfPolys()  # the proxy prism
    ('raycast', 6, 8)
    >>> actor.assembled.files[:2], actor.program_sources
    (('lib/core/raycast.glsl', 'lib/effects/lights.glsl'), {})
    """

    def __init__(self, spec: ProgramSpec, style: Style, renderer=None, *, cull_front: bool | None = None,
                 kind: str = "raycast"):
        from vtkmodules.vtkCommonCore import vtkCommand
        from vtkmodules.vtkCommonDataModel import vtkPolyData
        from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

        self.spec = spec
        self.model = None  # set by Plotter.add_spline
        self.style = style
        self.renderer = renderer
        defines = dict(spec.defines)
        defines.update(style.defines())
        if spec.world_frame is not None:  # world-frame effects (normal colours, environment) need the rotation
            defines["SV_MODEL_ROTATED"] = 1
        entry = "".join(f'#include "{f}"\n' for f in style.include_files())
        entry += '#include "lib/core/shading.glsl"\n' + f'#include "{spec.entry}"\n'
        # Effect functions must precede lib/core/shading.glsl which calls them; lib/core/raycast.glsl (SvHit)
        # must precede everything, so it goes first.
        entry = '#include "lib/core/raycast.glsl"\n' + entry
        self.assembled = assemble(entry, defines, extra_roots=tuple(spec.glsl_roots))
        self._entry, self._defines, self._variant = entry, defines, ()

        poly = vtkPolyData()
        mapper = vtkOpenGLPolyDataMapper()
        mapper.SetInputData(poly)
        mapper.ScalarVisibilityOff()
        mapper.SetVBOShiftScaleMethod(0)  # DISABLE_SHIFT_SCALE: vertexMC must be model coordinates
        vs_dec, vs_impl = _VS_DEC, _VS_IMPL
        fs_dec = _FS_DEC
        for name, values, qualifier in self._per_vertex(spec):
            k = 1 if np.ndim(values) == 1 else np.shape(values)[1]
            vtype = "float" if k == 1 else f"vec{k}"
            mapper.MapDataArrayToVertexAttribute(name, name, 0, -1)
            vs_dec += f"in {vtype} {name};\n{qualifier}out {vtype} {name}VSOut;\n"
            vs_impl += f"  {name}VSOut = {name};\n"
            fs_dec += f"{qualifier}in {vtype} {name}VSOut;\n"
        self.poly = poly
        self.set_geometry(spec.points, spec.triangles, {**spec.attributes, **spec.varyings})
        self.mapper = mapper

        super().__init__(mapper=mapper)  # a pyvista.Actor itself: remove_actor, visibility, ... as for meshes
        actor = self
        self.offset = np.asarray(spec.offset, dtype=np.float64).reshape(3)
        actor.SetPosition(*self.offset.tolist())
        self.rotation = None  # world-from-model rotation (None: the identity; see set_frame)
        self.model_position = self.offset
        if spec.world_frame is not None:  # (rotation, pivot) of a rotated lattice
            self.set_frame(*spec.world_frame)
        prop = actor.GetProperty()
        if kind not in _FS_IMPL:
            raise ValueError(f"a SplineActor draws programs of kind {' or '.join(_FS_IMPL)}, not {kind!r}.")
        self.kind = kind
        # a ray-cast proxy is drawn from its far side (the camera may be inside it); a surface mesh is the
        # surface itself: both sides drawn
        if cull_front is None:
            cull_front = spec.cull_front if spec.cull_front is not None else kind == "raycast"
        if cull_front:
            prop.FrontfaceCullingOn()
        if style.opacity < 1:
            prop.SetOpacity(float(style.opacity))
        sp = actor.GetShaderProperty()
        sp.AddVertexShaderReplacement("//VTK::Normal::Dec", True, vs_dec, False)
        sp.AddVertexShaderReplacement("//VTK::Normal::Impl", True, vs_impl, False)
        sp.AddFragmentShaderReplacement(_FS_DEC_TAG, True, fs_dec + self.assembled.text, False)
        self._fs_dec = fs_dec
        impl = _FS_COUNTERS if kind == "raycast" and defines.get("SV_DEBUG_COUNTERS") else _FS_IMPL[kind]
        sp.AddFragmentShaderReplacement("//VTK::Depth::Impl", True, impl, False)
        sp.AddFragmentShaderReplacement("//VTK::Light::Impl", True, _FS_LIGHT, False)
        self._textures = {}
        for name, arr in spec.textures.items():
            self._textures[name] = _float_texture(arr, name)
        if style.colormap is not None:
            self._textures["sv_colormap_tex"] = _image_texture(_colormap_image(style.colormap), interpolate=True)
        if style.texture is not None:
            self._textures["sv_texture_tex"] = _image_texture(np.asarray(style.texture), interpolate=True)
        if style.environment is not None:
            self._textures["sv_environment_tex"] = _image_texture(np.asarray(style.environment), interpolate=True, repeat=True)
        for name, tex in self._textures.items():
            prop.SetTexture(name, tex)
        self.program_sources: dict = {}
        self.program_ids: set = set()
        self.extra_uniforms: dict = {}
        mapper.AddObserver(vtkCommand.UpdateShaderEvent, self._on_update_shader)
        per_frame = spec.cull_per_frame is not None or spec.defines_per_frame is not None
        if per_frame and renderer is not None:  # before each frame: see ProgramSpec
            renderer.AddObserver(vtkCommand.StartEvent, self._on_render_start)

    # attributes of ours are set after __init__ too (program, model): pyvista's guard against new ones is lifted
    __setattr__ = object.__setattr__

    @property
    def actor(self):
        """This actor: it is the VTK actor (older code said ``spline_actor.actor``).

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> a = SplineActor(patch_program(QuarticTrianglePatch.demo()), Style(lights=1))
        >>> a.actor is a, isinstance(a, __import__("pyvista").Actor)
        (True, True)
        """
        return self

    def _on_render_start(self, caller=None, event=None):
        """Per-frame face culling and build variant of specs that ask for them (``ProgramSpec.cull_per_frame``,
        ``ProgramSpec.defines_per_frame``)."""
        eye, view, parallel, _ = self.camera_frame()
        near = float(self.renderer.GetActiveCamera().GetClippingRange()[0])
        if self.spec.cull_per_frame is not None:
            which = self.spec.cull_per_frame(eye, view, parallel, near)
            prop = self.actor.GetProperty()
            prop.SetFrontfaceCulling(which == "front")
            prop.SetBackfaceCulling(which == "back")
        if self.spec.defines_per_frame is not None:
            self.set_variant(self.spec.defines_per_frame(eye, view, parallel, near) or {})

    def set_variant(self, extra_defines: dict) -> None:
        """Rebuild the fragment code with ``extra_defines`` on top of the program's (a no-op when they are the
        variant already drawn); VTK compiles the new source at the next render and keeps the old program.

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> actor = SplineActor(patch_program(QuarticTrianglePatch.demo()), Style(lights=1))
        >>> actor.set_variant({"SV_EXAMPLE": 2})
        >>> actor._variant, "#define SV_EXAMPLE 2" in actor.assembled.text
        ((('SV_EXAMPLE', 2),), True)
        """
        key = tuple(sorted(extra_defines.items()))
        if key == self._variant:
            return
        self.assembled = assemble(self._entry, {**self._defines, **extra_defines},
                                  extra_roots=tuple(self.spec.glsl_roots))
        sp = self.actor.GetShaderProperty()
        sp.ClearFragmentShaderReplacement(_FS_DEC_TAG, True)
        sp.AddFragmentShaderReplacement(_FS_DEC_TAG, True, self._fs_dec + self.assembled.text, False)
        self._variant = key
        self.program_sources = {}

    @staticmethod
    def _per_vertex(spec):
        out = [(name, values, "flat ") for name, values in spec.attributes.items()]
        return out + [(name, values, "") for name, values in spec.varyings.items()]

    def set_geometry(self, points, triangles, per_vertex: dict) -> None:
        """Replace the proxy geometry and its per-vertex arrays in place (same names and widths as the
        program was built with); the compiled program, textures and uniforms are kept. This is what an
        isovalue change costs (splinevis.volume.program.set_isovalue).

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> spec = patch_program(QuarticTrianglePatch.demo(), coefficients_in="texture")
        >>> actor = make_actor(spec)
        >>> actor.set_geometry(2 * spec.points, spec.triangles, {"sv_patch_id": np.zeros(6)})
        >>> actor.poly.GetBounds()[:4]
        (-2.0, 2.4, -2.0, 2.2)
        """
        from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray

        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        tris = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        pts = vtkPoints()
        pts.SetDataTypeToDouble()
        pts.SetData(numpy_to_vtk(points, deep=True))
        self.poly.SetPoints(pts)
        cells = vtkCellArray()
        offsets = np.arange(0, 3 * len(tris) + 1, 3, dtype=np.int64)
        cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(tris.ravel(), deep=True))
        self.poly.SetPolys(cells)
        pd = self.poly.GetPointData()
        for name, values in per_vertex.items():
            arr = np.asarray(values, dtype=np.float32)
            if arr.ndim == 1:
                arr = arr[:, None]
            if arr.shape[0] != len(points) or not 1 <= arr.shape[1] <= 4:
                raise ValueError(f"vertex attribute {name} must be (N, 1..4) with N = {len(points)} proxy points, got {arr.shape}.")
            vtk_arr = numpy_to_vtk(np.ascontiguousarray(arr), deep=True)
            vtk_arr.SetName(name)
            pd.RemoveArray(name)
            pd.AddArray(vtk_arr)
        self.poly.Modified()

    def set_triangles(self, triangles) -> None:
        """Replace only the proxy triangles (indices into the current points): view-frustum culling.

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> spec = patch_program(QuarticTrianglePatch.demo())
        >>> actor = make_actor(spec)
        >>> actor.set_triangles(spec.triangles[:2])
        >>> actor.poly.GetNumberOfPolys(), actor.poly.GetNumberOfPoints()
        (2, 6)
        """
        from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray
        from vtkmodules.vtkCommonDataModel import vtkCellArray

        tris = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
        cells = vtkCellArray()
        offsets = np.arange(0, 3 * len(tris) + 1, 3, dtype=np.int64)
        cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(tris.ravel(), deep=True))
        self.poly.SetPolys(cells)
        self.poly.Modified()

    def set_texture(self, name: str, array: np.ndarray) -> None:
        """Replace one RGBA32F texture of the program (e.g. a coefficient table after an isovalue change).

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> actor = make_actor(patch_program(QuarticTrianglePatch.demo(), coefficients_in="texture"))
        >>> actor.set_texture("sv_patch_coeffs", np.zeros((1, 4, 4), dtype=np.float32))
        >>> prop = actor.actor.GetProperty()
        >>> prop.GetNumberOfTextures(), prop.GetTexture("sv_patch_coeffs").GetInput().GetDimensions()
        (1, (4, 1, 1))
        """
        tex = _float_texture(array, name)
        self._textures[name] = tex
        prop = self.actor.GetProperty()
        prop.RemoveTexture(name)  # replacing in place makes VTK warn
        prop.SetTexture(name, tex)

    # VTK passes the vtkShaderProgram as call data; the decorator tells the wrapper its type.
    def _on_update_shader(self, caller, event, program=None):
        if program is None:
            return
        self.program_ids.add(program.GetAddressAsString("vtkShaderProgram"))
        if not self.program_sources:
            self.program_sources = {
                "vertex": program.GetVertexShader().GetSource(),
                "fragment": program.GetFragmentShader().GetSource(),
            }
        for name, value in self.frame_uniforms().items():
            _set_uniform(program, name, value)

    _on_update_shader.CallDataType = VTK_OBJECT

    def set_frame(self, rotation, pivot) -> None:
        """Draw the model rotated: world = ``pivot + rotation @ (p - pivot)`` for a model point ``p`` (the
        model frame being the lattice of a rotated volume); ``rotation`` orthonormal (3, 3).

        The actor gets the rigid motion as its user matrix (its position stays the offset); the ray cast keeps
        working in the model frame (:meth:`camera_frame` maps the camera and lights into it) and the
        window depth follows from VTK's ``MCDCMatrix``, which includes the user matrix.

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> actor = make_actor(patch_program(QuarticTrianglePatch.demo()))
        >>> actor.set_frame([[0, -1, 0], [1, 0, 0], [0, 0, 1]], (1.0, 0.0, 0.0))
        >>> actor.actor.GetMatrix().MultiplyPoint((2.0, 0.0, 0.0, 1.0))  # offset 0: model = world frame
        (1.0, 1.0, 0.0, 1.0)
        """
        from vtkmodules.vtkCommonMath import vtkMatrix4x4

        R = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
        if np.abs(R.T @ R - np.eye(3)).max() > 1e-9:
            raise ValueError(f"set_frame needs an orthonormal rotation, got {R.tolist()}.")
        pivot = np.asarray(pivot, dtype=np.float64).reshape(3)
        self.rotation = R
        self.model_position = pivot + R @ (self.offset - pivot)
        shift = pivot - R @ pivot  # VTK applies the user matrix after the position (the offset)
        m = vtkMatrix4x4()
        for i in range(3):
            for j in range(3):
                m.SetElement(i, j, float(R[i, j]))
            m.SetElement(i, 3, float(shift[i]))
        self.actor.SetUserMatrix(m)
        culler = getattr(self, "culler", None)  # a frustum culler attached before keeps up with the frame
        if culler is not None:
            culler.offset, culler.rotation = self.model_position.copy(), R

    def camera_frame(self):
        """(eye, view direction, parallel flag, world-from-camera rotation) of the renderer's camera.

        Examples
        --------
        >>> from vtkmodules.vtkRenderingCore import vtkRenderer
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> renderer = vtkRenderer()
        >>> camera = renderer.GetActiveCamera()
        >>> camera.SetPosition(0, 0, 5); camera.SetFocalPoint(0, 0, 0); camera.SetViewUp(0, 1, 0)
        >>> eye, view, parallel, rotation = make_actor(patch_program(QuarticTrianglePatch.demo()),
        ...                                            renderer=renderer).camera_frame()
        >>> eye, view, parallel
        (array([0., 0., 5.]), array([ 0.,  0., -1.]), False)
        >>> rotation
        array([[1., 0., 0.],
               [0., 1., 0.],
               [0., 0., 1.]])
        """
        return camera_frame(self.renderer, self.offset, self.model_position, self.rotation)

    def _texture_map(self):
        """(scale_u, scale_v, shift_u, shift_v) from the model's parameter domain to the image."""
        ext = self.style.texture_extent
        model_ext = getattr(self.model, "extent", None)
        if ext is None or model_ext is None or not isinstance(model_ext, tuple):
            return (1.0, 1.0, 0.0, 0.0)
        mx0, mx1, my0, my1 = model_ext
        ex0, ex1, ey0, ey1 = (float(v) for v in ext)
        su, sv = (mx1 - mx0) / (ex1 - ex0), (my1 - my0) / (ey1 - ey0)
        return (su, sv, (mx0 - ex0) / (ex1 - ex0), (my0 - ey0) / (ey1 - ey0))

    def _highlight_frame(self) -> dict:
        """The plane of highlight lights in the model frame: world ``m . x = h`` is model
        ``(R^T m) . p = h - m . position``; the default ``h`` lies one bounding-box diagonal above the model."""
        R = np.eye(3) if self.rotation is None else self.rotation
        m = np.asarray(self.style.highlight_plane)
        across = np.cross(m, np.asarray(self.style.highlight_axis))
        x0, x1, y0, y1, z0, z1 = self.poly.GetBounds()
        corners = np.array(np.meshgrid([x0, x1], [y0, y1], [z0, z1])).reshape(3, -1).T  # model frame
        m_model = R.T @ m
        if self.style.highlight_height is None:
            h_model = float((corners @ m_model).max() + np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))
        else:
            h_model = float(self.style.highlight_height - m @ self.model_position)
        return {"sv_highlight_plane": m_model, "sv_highlight_across": R.T @ across, "sv_highlight_height": h_model,
                "sv_highlight_shift": float(across @ self.model_position)}

    def frame_uniforms(self) -> dict:
        """All uniforms for the next frame: camera, lights, spec, style and extras.

        Examples
        --------
        Without a renderer only the spec's and the style's uniforms (no camera, no lights):

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> from splinevis.analytic.program import patch_program
        >>> actor = make_actor(patch_program(QuarticTrianglePatch.demo(), newton_iterations=5))
        >>> u = actor.frame_uniforms()
        >>> u["sv_newton_iterations"], u["sv_color"], "sv_eye_mc" in u
        (5, (0.8235294117647058, 0.7058823529411765, 0.5490196078431373), False)
        """
        u = {}
        if self.renderer is not None:
            eye, view, parallel, world_from_cam = self.camera_frame()
            u["sv_eye_mc"] = eye
            u["sv_view_dir_mc"] = view
            u["sv_parallel"] = int(parallel)
            if "lights" in self.style.effect_set():
                dirs = self.style.light_directions_camera() @ world_from_cam.T
                u["sv_light_dir[]"] = dirs
            if self.spec.frame_uniforms is not None:
                u.update(self.spec.frame_uniforms(eye, view))
        u.update(self.spec.uniforms)
        u.update(self.style.uniforms())
        if self.style.texture is not None:
            u["sv_texture_map"] = self._texture_map()
        if self.style.highlight_lines is not None:
            u.update(self._highlight_frame())
        if self.rotation is not None and self.spec.world_frame is not None:
            u["sv_world_from_model[]"] = self.rotation
        u.update(self.extra_uniforms)
        return u


def make_actor(spec: ProgramSpec, style: Style | None = None, renderer=None) -> SplineActor:
    """Build a :class:`SplineActor` for ``spec`` shaded with ``style`` (default ``Style()``).

    Examples
    --------
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> from splinevis.analytic.program import patch_program
    >>> actor = make_actor(patch_program(QuarticTrianglePatch.demo()))
    >>> actor.style == Style(), bool(actor.actor.GetProperty().GetFrontfaceCulling())  # drawn from the far side
    (True, True)
    """
    return SplineActor(spec, style if style is not None else Style(), renderer)
