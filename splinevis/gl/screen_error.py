"""Screen-space size of world errors: how many pixels a displacement of a point can move its image, for a
camera given as a :class:`View` (what :mod:`splinevis.choice` compares renderers by).

A world displacement of length e at a point p moves its projection by at most

* perspective: e * H / (2 tan(fov/2)) * (r + e) / (Z - e)^2, with Z the depth of p along the view
  direction and r its distance to the eye. Derivation: the projection is (X/Z, Y/Z) scaled by
  H / (2 tan(fov/2)) pixels; its Jacobian has singular values 1/Z and r/Z^2, so the larger one, r/Z^2,
  bounds the move per unit of displacement, taken at the worst point of the segment (depth >= Z - e,
  distance <= r + e). The usual footprint 2 d tan(fov/2) / H with d = the distance is *not* conservative
  off the view axis (it is low by (r/Z)^2 in the corners of a wide view); this is.
* parallel: e * H / (2 * parallel_scale) (exact for every point).

Every rasterized point is also snapped to the sub-pixel grid: :data:`SNAP_PX` = sqrt(2) 2^-8 pixels
(:data:`splinevis.gl.error_bounds.SUBPIXEL` per axis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .error_bounds import SUBPIXEL

__all__ = ["View", "SNAP_PX"]

#: Sub-pixel snapping of any rasterized point (both axes), in pixels.
SNAP_PX = math.sqrt(2.0) * SUBPIXEL


@dataclass(frozen=True)
class View:
    """A camera as the error conversion needs it: eye ``position``, ``focal_point``, ``view_up``, vertical
    ``view_angle`` (degrees) or ``parallel_scale`` (half the window height in world units, with
    ``parallel=True``), the window in pixels and the clipping range.

    Examples
    --------
    Looking down -z from (0, 0, 10) with a 90 degree view in a 200 pixel high window: at depth 10 a world
    unit is 200 / (2 tan 45 deg * 10) = 10 pixels; a displacement of 0.1 on the axis moves at most
    0.1 * 100 * 10.1 / 9.9^2 = 1.0305 pixels (the worst point of the segment):

    >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
    >>> round(float(v.point_pixels([[0.0, 0.0, 0.0]], 0.1)[0]), 4)
    1.0305
    >>> round(float(View((0, 0, 10), (0, 0, 0), (0, 1, 0), parallel=True, parallel_scale=5.0, height=200)
    ...             .point_pixels([[3.0, 0.0, 0.0]], 0.1)[0]), 6)  # 0.1 * 200 / (2 * 5)
    2.0
    """

    position: tuple
    focal_point: tuple
    view_up: tuple = (0.0, 0.0, 1.0)
    view_angle: float = 30.0
    parallel: bool = False
    parallel_scale: float = 1.0
    width: int = 800
    height: int = 600
    clipping_range: tuple = (0.01, 1000.0)

    @classmethod
    def from_renderer(cls, renderer, window_size) -> "View":
        """The view of ``renderer``'s active camera in a window of ``window_size`` (width, height).

        >>> import pyvista as pv
        >>> pl = pv.Plotter(off_screen=True, window_size=(64, 48))
        >>> pl.camera_position = [(0.0, 0.0, 5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)]
        >>> View.from_renderer(pl.renderer, pl.window_size).position, pl.close()
        ((0.0, 0.0, 5.0), None)
        """
        cam = renderer.GetActiveCamera()
        w, h = (int(v) for v in window_size)
        angle = float(cam.GetViewAngle())
        if cam.GetUseHorizontalViewAngle():  # the equivalent vertical angle
            angle = math.degrees(2.0 * math.atan(math.tan(math.radians(angle) / 2.0) * h / w))
        return cls(tuple(cam.GetPosition()), tuple(cam.GetFocalPoint()), tuple(cam.GetViewUp()), angle,
                   bool(cam.GetParallelProjection()), float(cam.GetParallelScale()), w, h,
                   tuple(cam.GetClippingRange()))

    def _frame(self):
        eye = np.asarray(self.position, dtype=np.float64)
        d = np.asarray(self.focal_point, dtype=np.float64) - eye
        d /= np.linalg.norm(d)
        up = np.asarray(self.view_up, dtype=np.float64)
        right = np.cross(d, up)
        right /= np.linalg.norm(right)
        return eye, d, np.cross(right, d), right

    def _tans(self):
        ty = math.tan(math.radians(self.view_angle) / 2.0)
        return ty * self.width / self.height, ty

    def matrix(self) -> np.ndarray:
        """(4, 4) world -> normalized device coordinates (VTK's composite projection at this aspect ratio).

        >>> m = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200).matrix()
        >>> p = m @ [1.0, 0.0, 0.0, 1.0]
        >>> round(float(p[0] / p[3]), 12)  # x = 1 at depth 10, tan 45 deg = 1: a tenth of the half width
        0.1
        """
        from vtkmodules.vtkRenderingCore import vtkCamera

        cam = vtkCamera()
        cam.SetPosition(*self.position)
        cam.SetFocalPoint(*self.focal_point)
        cam.SetViewUp(*self.view_up)
        cam.SetViewAngle(self.view_angle)
        cam.SetParallelProjection(self.parallel)
        cam.SetParallelScale(self.parallel_scale)
        cam.SetClippingRange(*self.clipping_range)
        m = cam.GetCompositeProjectionTransformMatrix(self.width / self.height, -1, 1)
        return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])

    def pixel_distance(self, a, b) -> np.ndarray:
        """Distance in pixels between the projections of the world points ``a`` and ``b`` (n, 3 each): the
        screen-space error measured where ``a`` is drawn for ``b``; NaN where either is outside the view
        frustum (behind the eye, beyond the clipping range or the window's sides).

        >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
        >>> v.pixel_distance([[0.0, 0, 0], [0, 0, 0]], [[0.1, 0, 0], [0, 0, 20]]).round(6)  # 10 px per unit at depth 10
        array([ 1., nan])
        """
        m = self.matrix()
        out = []
        for p in (a, b):
            p = np.asarray(p, dtype=np.float64).reshape(-1, 3)
            h = p @ m[:, :3].T + m[:, 3]
            with np.errstate(divide="ignore", invalid="ignore"):
                ndc = h[:, :3] / h[:, 3:4]
            inside = (h[:, 3] > 0) & (np.abs(ndc) <= 1.0).all(axis=1)
            xy = np.column_stack([(ndc[:, 0] + 1.0) * 0.5 * self.width, (ndc[:, 1] + 1.0) * 0.5 * self.height])
            out.append(np.where(inside[:, None], xy, np.nan))
        return np.linalg.norm(out[0] - out[1], axis=1)

    def box_area_pixels(self, lo, hi) -> float:
        """Pixels of the window covered by the screen rectangle around the projection of the box ``lo..hi``:
        an upper bound of the pixels the box's contents can cover (the whole window if the box reaches behind
        the eye plane; 0 if it is outside the view).

        >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
        >>> round(v.box_area_pixels([-1, -1, 0], [1, 1, 0]), 6), v.box_area_pixels([-1, -1, 0], [1, 1, 11])
        (400.0, 40000.0)
        """
        m = self.matrix()
        lo, hi = np.asarray(lo, dtype=np.float64).reshape(3), np.asarray(hi, dtype=np.float64).reshape(3)
        corners = np.array([[(hi if (c >> a) & 1 else lo)[a] for a in range(3)] for c in range(8)])
        h = corners @ m[:, :3].T + m[:, 3]
        if (h[:, 3] <= 0).any():
            return float(self.width * self.height)
        ndc = np.clip(h[:, :2] / h[:, 3:4], -1.0, 1.0)
        w = (ndc[:, 0].max() - ndc[:, 0].min()) * 0.5 * self.width
        t = (ndc[:, 1].max() - ndc[:, 1].min()) * 0.5 * self.height
        return float(w * t)

    def point_pixels(self, points, err) -> np.ndarray:
        """Pixels a world displacement of length ``err`` at ``points`` (n, 3) can move their projection by
        (module docstring); inf for visible points within ``err`` of the eye plane, 0 behind the eye.

        >>> View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, height=200).point_pixels([[0, 0, 9.95], [0, 0, 20]], 0.1)
        array([inf,  0.])
        """
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return self.box_pixels(p, p, err)

    def box_pixels(self, lo, hi, err) -> np.ndarray:
        """Pixels a world displacement of length ``err`` (scalar or one per box) anywhere in the boxes
        ``lo..hi`` (n, 3) can move the projection by: the bound at the box's largest distance and smallest
        depth (perspective); 0 for boxes outside the view frustum's side planes or wholly behind the eye;
        inf for visible boxes reaching within ``err`` of the eye plane.

        The first box's worst point: distance sqrt(102) + 0.1, depth 10 - 0.1 (100 pixels per unit of X/Z):

        >>> v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200)
        >>> v.box_pixels([[-1, -1, 0], [50, 0, 0], [-1, -1, 9.95]], [[1, 1, 0], [51, 1, 0], [1, 1, 11]], 0.1).round(4)
        array([1.0407, 0.    ,    inf])
        """
        lo = np.asarray(lo, dtype=np.float64).reshape(-1, 3)
        hi = np.asarray(hi, dtype=np.float64).reshape(-1, 3)
        err = np.broadcast_to(np.asarray(err, dtype=np.float64), (len(lo),))
        corners = np.stack([np.where(np.array([(c >> a) & 1 for a in range(3)], bool), hi, lo) for c in range(8)], axis=1)
        eye, d, up, right = self._frame()
        rel = corners - eye
        Z, X, Y = rel @ d, rel @ right, rel @ up
        tx, ty = self._tans()
        if self.parallel:
            sx, sy = self.parallel_scale * self.width / self.height, self.parallel_scale
            outside = ((X > sx).all(1) | (X < -sx).all(1) | (Y > sy).all(1) | (Y < -sy).all(1) | (Z <= 0).all(1))
            return np.where(outside, 0.0, err * self.height / (2.0 * self.parallel_scale))
        outside = ((X > Z * tx).all(1) | (X < -Z * tx).all(1) | (Y > Z * ty).all(1) | (Y < -Z * ty).all(1)
                   | (Z <= 0).all(1))
        zmin = Z.min(axis=1) - err
        r = np.linalg.norm(rel, axis=2).max(axis=1) + err
        with np.errstate(divide="ignore", invalid="ignore"):
            px = np.where(zmin > 0, err * self.height / (2.0 * ty) * r / np.maximum(zmin, 1e-300) ** 2, np.inf)
        return np.where(outside, 0.0, px)
