"""OpenGL camera matrices built by hand for the culling and level-selection tests (the reference the product's
matrices from PyVista cameras are compared against): gluLookAt and gluPerspective/glOrtho conventions."""

import math

import numpy as np


def look_at(eye, focal, up=(0.0, 0.0, 1.0)):
    """The 4x4 view matrix of a camera at ``eye`` looking at ``focal``."""
    eye, focal, up = (np.asarray(v, dtype=np.float64) for v in (eye, focal, up))
    f = focal - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    V = np.eye(4)
    V[0, :3], V[1, :3], V[2, :3] = s, u, -f
    V[:3, 3] = -V[:3, :3] @ eye
    return V


def perspective(fov_y, aspect, near, far):
    """The 4x4 perspective projection (vertical field of view ``fov_y`` in radians)."""
    t = 1.0 / math.tan(0.5 * fov_y)
    P = np.zeros((4, 4))
    P[0, 0], P[1, 1] = t / aspect, t
    P[2, 2], P[2, 3] = -(far + near) / (far - near), -2.0 * far * near / (far - near)
    P[3, 2] = -1.0
    return P


def background_from_inside(points, tri, eye, focus, view_angle=60.0, far=10.0, size=(200, 150)) -> int:
    """How many pixels of background a camera at ``eye`` looking at ``focus`` (z up) sees around the mesh
    ``points, tri`` (drawn white and unlit on black): from inside a closed mesh, every pixel is a crack."""
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=size)
    pl.set_background("black")
    pl.add_mesh(pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel()), color="white",
                lighting=False)
    pl.camera_position = [tuple(eye), tuple(focus), (0.0, 0.0, 1.0)]
    pl.camera.view_angle = view_angle
    pl.camera.clipping_range = (1e-3, far)
    img = pl.screenshot()
    pl.close()
    return int((img.sum(axis=-1) == 0).sum())
