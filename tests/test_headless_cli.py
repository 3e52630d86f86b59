"""Headless backend choice, clear errors without a context, and the CLI."""

import json
import subprocess
import sys

import pytest

from splinevis import cli
from splinevis.errors import OpenGLUnavailableError
from splinevis.gl import headless


def test_configure_prefers_egl_and_sets_vtk_window(monkeypatch):
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.delenv("SPLINEVIS_GL", raising=False)
    assert headless.configure() == "egl"
    import os

    assert os.environ["VTK_DEFAULT_OPENGL_WINDOW"] == "vtkEGLRenderWindow"


def test_configure_osmesa_on_request(monkeypatch):
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    assert headless.configure("osmesa") == "osmesa"


def test_missing_libraries_give_install_command(monkeypatch):
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.delenv("SPLINEVIS_GL", raising=False)
    monkeypatch.setattr(headless, "_LIBRARIES", {"egl": ("libEGL_missing.so.9",), "osmesa": ("libOSMesa_missing.so.9",)})
    with pytest.raises(OpenGLUnavailableError, match=r"cannot load libEGL_missing.so.9.*apt-get install libegl1"):
        headless.configure()


def test_unknown_backend_is_named():
    with pytest.raises(ValueError, match="'vulkan' is not known; choose 'egl', 'osmesa' or 'x'"):
        headless.configure("vulkan")


class _DeadWindow:
    def ReportCapabilities(self):
        return ""

    def GetClassName(self):
        return "vtkEGLRenderWindow"


def test_window_without_context_raises_instead_of_rendering_blank():
    with pytest.raises(OpenGLUnavailableError, match="renderer string is empty"):
        headless.check_render_window(_DeadWindow())


@pytest.mark.gl
def test_cli_info_reports_llvmpipe_and_window_class():
    out = subprocess.run([sys.executable, "-m", "splinevis.cli", "info"], capture_output=True, text=True, check=True)
    info = json.loads(out.stdout)
    assert info["window_class"] in ("vtkEGLRenderWindow", "vtkOSOpenGLRenderWindow")
    assert info["renderer"] and info["version"].startswith(("3.", "4."))
    assert "GL_RENDERER" in info["moderngl"]


def test_cli_info_exits_nonzero_without_context(monkeypatch, capsys):
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.delenv("SPLINEVIS_GL", raising=False)
    monkeypatch.setattr(headless, "_LIBRARIES", {"egl": ("libEGL_missing.so.9",), "osmesa": ("libOSMesa_missing.so.9",)})
    assert cli.main(["info"]) == 3
    assert "apt-get install" in capsys.readouterr().err


def test_cli_info_with_egl_backend_exits_0_where_egl_loads_else_3(capsys):
    # 0 when EGL's libraries load here (Mesa llvmpipe gives a context: the case on this project's machines);
    # 3 (no OpenGL) with the install command when they do not
    egl_loads = all(headless.backend_libraries()["egl"].values())
    code = cli.main(["info", "--backend", "egl"])
    out = capsys.readouterr()
    if egl_loads:
        assert code == 0, out.err
        info = json.loads(out.out)
        assert info["window_class"] == "vtkEGLRenderWindow" and info["renderer"]
    else:
        assert code == 3 and "apt-get install" in out.err


def test_cli_bad_backend_exits_2(capsys):
    with pytest.raises(SystemExit) as e:
        cli.main(["info", "--backend", "metal"])
    assert e.value.code == 2
