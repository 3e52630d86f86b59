"""The pass runner (splinevis.gl.passes) and the shared moderngl context (splinevis.gl.context)."""

import ctypes
import gc
import weakref

import numpy as np
import pytest

from splinevis.errors import ShaderCompileError
from splinevis.gl import passes as passes_mod
from splinevis.gl.context import current, get_context, max_texture_size
from splinevis.gl.passes import Pass, PassChain, read_rgba32f, run_passes, to_vtk_image, to_vtk_texture

pytestmark = pytest.mark.gl

COPY = "passes/copy.glsl"
# 37 x 53: neither square nor a power of two, so a swapped (rows, columns) shows up as a shape or value error
H, W = 37, 53

ADD_ONE = """uniform sampler2D sv_src;
void main() { sv_frag_out0 = texelFetch(sv_src, ivec2(gl_FragCoord.xy), 0) + 1.0; }
"""
PIXEL_INDEX = """void main() { sv_frag_out0 = vec4(gl_FragCoord.xy, 0.0, 1.0); }
"""
SPLIT = """uniform sampler2D sv_src;
uniform float sv_scale;
void main() {
    vec4 v = texelFetch(sv_src, ivec2(gl_FragCoord.xy), 0);
    sv_frag_out0 = v;
    sv_frag_out1 = sv_scale * v;
}
"""


def _random_rgba(rng, shape=(H, W)):
    # normal float32 values over 60 decades of magnitude, both signs: every bit of the mantissa matters
    x = rng.normal(size=shape + (4,)) * 10.0 ** rng.uniform(-30, 30, size=shape + (4,))
    return x.astype(np.float32)


def test_copy_pass_round_trip_is_bit_exact_on_a_non_square_grid():
    x = _random_rgba(np.random.default_rng(0))
    out = run_passes([Pass(COPY, {"sv_src": "x"})], {"x": x})
    assert out.dtype == np.float32 and out.shape == (H, W, 4)
    assert np.array_equal(out.view(np.uint32), x.view(np.uint32))  # same bits, not just equal values


def test_array_row_j_column_i_is_fragment_i_j():
    # gl_FragCoord of texel (i, j) is (i + 0.5, j + 0.5): column index in x, row index in y, nothing flipped
    out = run_passes([Pass(PIXEL_INDEX, outputs="idx", shape=(H, W))], {})
    jj, ii = np.mgrid[0:H, 0:W]
    assert np.array_equal(out[:, :, 0], ii + 0.5)
    assert np.array_equal(out[:, :, 1], jj + 0.5)


def test_fewer_channels_are_padded_with_zeros():
    x = np.arange(H * W, dtype=np.float32).reshape(H, W)
    out = run_passes([Pass(COPY, {"sv_src": "x"})], {"x": x})
    assert np.array_equal(out[:, :, 0], x)
    assert not out[:, :, 1:].any()


def test_chain_ping_pongs_on_the_gpu(monkeypatch):
    made, reads = [], []
    real_empty, real_read = passes_mod.empty_rgba32f, passes_mod.read_rgba32f
    monkeypatch.setattr(passes_mod, "empty_rgba32f", lambda shape: made.append(shape) or real_empty(shape))
    monkeypatch.setattr(passes_mod, "read_rgba32f", lambda t: reads.append(t) or real_read(t))
    x = np.random.default_rng(1).integers(-1000, 1000, size=(H, W, 4)).astype(np.float32)
    step = Pass(ADD_ONE, {"sv_src": "x"}, "x")
    out = run_passes([step] * 7, {"x": x})
    assert np.array_equal(out, x + 7)  # small integers: every addition is exact
    # the uploaded input becomes the second buffer: one new texture for seven passes, one readback
    assert made == [(H, W)]
    assert len(reads) == 1


def test_result_can_stay_on_the_gpu_and_feed_another_chain():
    x = np.random.default_rng(2).integers(0, 100, size=(H, W, 4)).astype(np.float32)
    tex = run_passes([Pass(ADD_ONE, {"sv_src": "x"}, "y")], {"x": x}, readback=False)
    try:
        assert tex.size == (W, H)  # moderngl sizes are (width, height)
        again = run_passes([Pass(ADD_ONE, {"sv_src": "t"}, "u")], {"t": tex})
        assert np.array_equal(again, x + 2)
        assert np.array_equal(read_rgba32f(tex), x + 1)  # the caller's texture is read, never written
    finally:
        with current():
            tex.release()


def _vtk_window_round_trip():
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - registers the OpenGL classes

    from splinevis.gl.headless import configure

    configure()
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(8, 8)
    win.AddRenderer(vtkRenderer())
    win.Render()
    win.Finalize()


def test_texture_kept_on_the_gpu_across_vtk_rendering_is_refused_not_misread():
    x = np.full((2, 3), 5.0)
    tex = run_passes([Pass(ADD_ONE, {"sv_src": "x"}, "y")], {"x": x}, readback=False)
    _vtk_window_round_trip()  # replaces our context when VTK terminates the EGL display it shares with us
    # Refused, or (where the process's earlier windows left our context alive: the order the test workers ran
    # their tests in decides it) read right: never misread.
    for use in (lambda: run_passes([Pass(COPY, {"sv_src": "t"})], {"t": tex}), lambda: read_rgba32f(tex)):
        try:
            got = use()
        except ValueError as exc:
            assert "context that no longer exists" in str(exc)
        else:
            assert np.all(np.asarray(got)[:, :, 0] == 6.0)
    assert np.all(run_passes([Pass(ADD_ONE, {"sv_src": "x"})], {"x": x})[:, :, 0] == 6.0)


def test_two_attachments_and_named_results():
    x = np.random.default_rng(3).integers(-50, 50, size=(H, W, 4)).astype(np.float32)
    chain = PassChain([
        Pass(SPLIT, {"sv_src": "x"}, ("same", "scaled"), uniforms={"sv_scale": 4.0}),
        Pass(ADD_ONE, {"sv_src": "scaled"}, "plus"),
    ])
    assert chain.inputs == ("x",)
    same, scaled, plus = chain.run({"x": x}, result=("same", "scaled", "plus"))
    assert np.array_equal(same, x)
    assert np.array_equal(scaled, 4 * x)
    assert np.array_equal(plus, 4 * x + 1)


def test_broken_pass_file_reports_its_file_and_line(tmp_path):
    (tmp_path / "passes").mkdir()
    (tmp_path / "passes" / "broken.glsl").write_text(
        "// a pass with a typo\nuniform sampler2D sv_src;\nvoid main() {\n"
        "    sv_frag_out0 = texelFetch(sv_src, ivec2(gl_FragCoord.xy), 0) +* 2.0;\n}\n"
    )
    with pytest.raises(ShaderCompileError, match=r"passes/broken\.glsl:4") as info:
        run_passes([Pass("passes/broken.glsl", {"sv_src": "x"}, root=tmp_path)], {"x": np.zeros((2, 3))})
    err = info.value
    assert err.stage == "fragment"
    assert "+* 2.0;" in str(err)
    assert any(where == "passes/broken.glsl:4" for _, _, where in err.locations)


def test_wiring_mistakes_are_reported_before_drawing():
    x = np.zeros((2, 3), np.float32)
    with pytest.raises(ValueError, match=r"needs the input textures \['x'\]"):
        run_passes([Pass(COPY, {"sv_src": "x"})], {"y": x})
    with pytest.raises(ValueError, match=r"no uniform sv_gain in the shader"):
        run_passes([Pass(COPY, {"sv_src": "x"}, uniforms={"sv_gain": 2.0})], {"x": x})
    with pytest.raises(ValueError, match=r"no uniform sampler2D sv_other"):
        run_passes([Pass(COPY, {"sv_other": "x"})], {"x": x})
    with pytest.raises(ValueError, match=r"samplers \['sv_src'\] get no texture"):
        run_passes([Pass(COPY, outputs="y", shape=(2, 3))], {})
    with pytest.raises(ValueError, match=r"no inputs, so give its output shape"):
        Pass(PIXEL_INDEX)
    with pytest.raises(ValueError, match=r"input 'x' must have shape \(H, W\) or \(H, W, C\).*got \(2, 3, 5\)"):
        run_passes([Pass(COPY, {"sv_src": "x"})], {"x": np.zeros((2, 3, 5))})
    with pytest.raises(ValueError, match=r"result names \['nope'\]"):
        run_passes([Pass(COPY, {"sv_src": "x"})], {"x": x}, result="nope")


def test_texture_larger_than_the_gl_limit_is_refused():
    limit = max_texture_size()
    with pytest.raises(ValueError, match=rf"GL_MAX_TEXTURE_SIZE is {limit}"):
        run_passes([Pass(PIXEL_INDEX, shape=(1, limit + 1))], {})


# --------------------------------------------------------------------------------------------------
# The context
# --------------------------------------------------------------------------------------------------
def _egl_current_context():
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetCurrentContext.restype = ctypes.c_void_p
    return egl.eglGetCurrentContext()


def test_one_context_shared_with_the_harness():
    from splinevis.gl.harness import get_context as harness_get_context

    assert harness_get_context() is get_context()


def test_current_restores_the_callers_context_and_nests():
    import moderngl

    ours = get_context()
    with current():
        our_handle = _egl_current_context()
    theirs = moderngl.create_standalone_context(backend="egl", require=330)  # now current, like a VTK window
    try:
        their_handle = _egl_current_context()
        assert their_handle and their_handle != our_handle
        with current() as ctx:
            assert ctx is ours and _egl_current_context() == our_handle
            with current():
                pass
            assert _egl_current_context() == our_handle  # the inner block does not release it early
            run_passes([Pass(COPY, {"sv_src": "x"})], {"x": np.ones((2, 2))})
            assert _egl_current_context() == our_handle
        assert _egl_current_context() == their_handle
        out = run_passes([Pass(COPY, {"sv_src": "x"})], {"x": np.full((2, 2), 3.0)})
        assert _egl_current_context() == their_handle
        assert np.all(out[:, :, 0] == 3.0)
    finally:
        theirs.release()
    # releasing a context may terminate the EGL display it shares with ours; the next block still works
    out = run_passes([Pass(ADD_ONE, {"sv_src": "x"})], {"x": np.full((2, 2), 3.0)})
    assert np.all(out[:, :, 0] == 4.0)


# --------------------------------------------------------------------------------------------------
# Handing results to VTK
# --------------------------------------------------------------------------------------------------
def test_vtk_image_shares_memory_and_keeps_orientation():
    from vtkmodules.util.numpy_support import vtk_to_numpy

    a = run_passes([Pass(PIXEL_INDEX, outputs="idx", shape=(H, W))], {})
    img = to_vtk_image(a, spacing=(2.0, 3.0), origin=(10.0, 20.0), name="idx")
    assert img.GetDimensions() == (W, H, 1)
    scalars = img.GetPointData().GetScalars()
    assert scalars.GetName() == "idx" and scalars.GetNumberOfComponents() == 4
    assert np.shares_memory(vtk_to_numpy(scalars), a)
    # point i + j*W is a[j, i] and sits at (x0 + i*dx, y0 + j*dy)
    i, j = 7, 30
    pid = i + j * W
    assert scalars.GetTuple4(pid) == (i + 0.5, j + 0.5, 0.0, 1.0)
    assert img.GetPoint(pid) == (10.0 + 2.0 * i, 20.0 + 3.0 * j, 0.0)
    a[j, i, 2] = 123.5  # a write on the numpy side shows in VTK: nothing was copied
    assert scalars.GetTuple4(pid)[2] == 123.5


def test_vtk_image_keeps_the_array_alive():
    from vtkmodules.util.numpy_support import vtk_to_numpy

    a = np.arange(H * W * 4, dtype=np.float32).reshape(H, W, 4).copy()  # a owns its memory
    expected = a.copy()
    alive = weakref.ref(a)
    img = to_vtk_image(a)
    del a
    gc.collect()
    junk = [np.full(H * W * 4, -1.0, np.float32) for _ in range(50)]  # reuse any freed memory
    assert alive() is not None
    assert np.array_equal(vtk_to_numpy(img.GetPointData().GetScalars()).reshape(H, W, 4), expected)
    del img, junk
    gc.collect()
    assert alive() is None  # and released with the VTK array


def test_vtk_image_copies_what_vtk_cannot_share():
    from vtkmodules.util.numpy_support import vtk_to_numpy

    a = np.ones((3, 4), dtype=np.float64)
    img = to_vtk_image(a)
    vals = vtk_to_numpy(img.GetPointData().GetScalars())
    assert vals.dtype == np.float32 and not np.shares_memory(vals, a)
    assert img.GetDimensions() == (4, 3, 1)


def test_vtk_texture_renders_a_pass_result_upright_after_our_context_was_used():
    """End to end: a VTK window draws a texture made by a pass chain; a chain run between two renders
    leaves VTK's context current and VTK's picture intact; chains still run after VTK is finalized."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersSources import vtkPlaneSource
    from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow,
                                             vtkWindowToImageFilter)
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - registers the OpenGL classes

    from splinevis.gl.headless import configure

    configure()
    # R grows with the column (x), G with the row (y): red right, green top when drawn upright
    q = np.zeros((2, 2, 4), np.float32)
    q[:, 1, 0] = 1.0
    q[1, :, 1] = 1.0
    q[:, :, 3] = 1.0
    tex_values = run_passes([Pass(COPY, {"sv_src": "q"})], {"q": q})
    texture = to_vtk_texture(tex_values)
    assert texture.GetInput().GetDimensions() == (2, 2, 1)

    plane = vtkPlaneSource()
    mapper = vtkPolyDataMapper()
    mapper.SetInputConnection(plane.GetOutputPort())
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.SetTexture(texture)
    actor.GetProperty().LightingOff()
    ren = vtkRenderer()
    ren.AddActor(actor)
    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(64, 64)
    win.AddRenderer(ren)
    ren.ResetCamera()
    ren.GetActiveCamera().Zoom(1.4)  # the plane fills the window
    win.Render()
    vtk_handle = _egl_current_context()
    run_passes([Pass(COPY, {"sv_src": "q"})], {"q": q})
    assert _egl_current_context() == vtk_handle
    win.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    rgb = vtk_to_numpy(grab.GetOutput().GetPointData().GetScalars()).reshape(64, 64, 3)  # row 0 = bottom
    for (row, col), (r, g) in {(8, 8): (0, 0), (8, 56): (255, 0), (56, 8): (0, 255), (56, 56): (255, 255)}.items():
        assert tuple(rgb[row, col, :2]) == (r, g), (row, col, rgb[row, col])
    # VTK's window terminates the EGL display it shares with our context when it is finalized
    win.Finalize()
    assert np.array_equal(run_passes([Pass(ADD_ONE, {"sv_src": "q"})], {"q": q}), q + 1)
