"""Two toy spline families defined outside the package, as a contributor would write them
(docs/architecture.md, "How to add a family"): a ray-cast sphere with its own GLSL file, float64 twin, derived
depth bound and hard cases, and a CPU-tessellated ("mesh" kind) sphere. The ray-cast sphere declares its own
renderers for the choice by accuracy (``renderers.py``: a tessellation with a proven bound, and the exact ray
cast); the others declare none. Registering them touches no package file."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from splinevis.gl.contract import HardCase, RayHits, SplineProgram
from splinevis.gl.error_bounds import U32, depth_error, model_frame_matrix, root_shift
from splinevis.gl.proxies import boxes
from splinevis.gl.spec import ProgramSpec

from .renderers import RENDERERS

GLSL = Path(__file__).parent / "glsl"


class ToySphere:
    """The sphere of ``radius`` around ``center`` (world coordinates)."""

    def __init__(self, radius=1.0, center=(0.0, 0.0, 0.0)):
        self.radius = float(radius)
        self.center = np.asarray(center, dtype=np.float64)

    @property
    def bounds(self):
        """(xmin, xmax, ymin, ymax, zmin, zmax), what a camera is fitted to."""
        lo, hi = self.center - self.radius, self.center + self.radius
        return (lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])


def build(model, style, *, newton_iterations):
    r = model.radius * (1 + 1e-6)
    points, triangles = boxes((-r, -r, -r), (r, r, r))
    return ProgramSpec(name="toy_sphere", entry="toy_sphere.glsl", points=points, triangles=triangles,
                       uniforms={"sv_toy_radius": model.radius, "sv_scalar_range": (-model.radius, model.radius)},
                       offset=tuple(model.center), glsl_roots=(GLSL,))


def reference(model, origins, directions, tmin=0.0, *, method="reference", iterations=None):
    o = np.asarray(origins, dtype=np.float64) - model.center
    d = np.asarray(directions, dtype=np.float64)
    a = np.einsum("...i,...i", d, d)
    b = np.einsum("...i,...i", o, d)
    c = np.einsum("...i,...i", o, o) - model.radius ** 2
    disc = b * b - a * c
    with np.errstate(invalid="ignore", divide="ignore"):
        q = -(b + np.copysign(np.sqrt(disc), b))
        t0, t1 = np.minimum(q / a, c / q), np.maximum(q / a, c / q)
    t = np.where(t0 >= tmin, t0, np.where(t1 >= tmin, t1, np.nan))
    t = np.where(disc >= 0, t, np.nan)
    p = np.asarray(origins) + t[..., None] * d
    return RayHits(t, p, p - model.center)


def depth_bound(model, matrix, origins, directions, t, *, surface=None):
    # g(t) = |ro + t rd|^2 - r^2 in float32 from a proxy point ro (|ro| <= sqrt(3) r) with |rd| = 1: the dot
    # products and the square root round a few times on terms of size (|ro| + |t|)^2 <= (2 sqrt(3) r)^2, and
    # the ray itself is rounded (8 u P sideways over P = 2 sqrt(3) r, moving g by 2 |p| 8 u P):
    # eps = 16 u (12 r^2) + 16 u r P; g' = 2 p.rd at the hit, g'' = 2.
    d = np.asarray(directions, dtype=np.float64)
    unit = d / np.linalg.norm(d, axis=-1, keepdims=True)
    p = np.asarray(origins) + np.asarray(t)[..., None] * d - model.center
    r = model.radius
    P = 2 * np.sqrt(3) * r
    eps = 16 * U32 * 12 * r * r + 16 * U32 * r * P
    dt_unit = root_shift(eps, np.abs(2 * np.einsum("...i,...i", p, unit)), 2.0)
    dt = dt_unit / np.linalg.norm(d, axis=-1)
    o = np.asarray(origins) - model.center
    return depth_error(model_frame_matrix(matrix, model.center), o, d, np.asarray(t), 1e-6 * np.maximum(1, np.abs(t)), dt)


def hard_cases():
    far = lambda: ToySphere(2.0, (5.0e5, 4.2e6, 100.0))  # noqa: E731 - UTM-sized centre
    return [
        HardCase("front", ToySphere, [(3.0, -4.0, 2.0), (0.0, 0.0, 0.0), (0, 0, 1)], (200, 150)),
        HardCase("camera-inside-proxy", ToySphere, [(0.0, -1.2, 0.3), (0.0, 1.0, 0.0), (0, 0, 1)], (200, 150),
                 clipping_range=(1e-3, 10.0)),
        HardCase("utm-centre", far, [(5.0e5 + 6, 4.2e6 - 8, 104.0), (5.0e5, 4.2e6, 100.0), (0, 0, 1)], (200, 150)),
    ]


RAYCAST = SplineProgram(name="toy_sphere", kind="raycast", model_type=ToySphere, build=build, reference=reference,
                        depth_bound=depth_bound, hard_cases=hard_cases, description="a sphere, ray-cast",
                        renderers=RENDERERS)


class ToyMeshSphere(ToySphere):
    """The same sphere, drawn by CPU tessellation."""


def tessellate(model, style, *, newton_iterations, resolution=32):
    import pyvista as pv

    return pv.Sphere(radius=model.radius, center=model.center, theta_resolution=resolution,
                     phi_resolution=resolution)


MESH = SplineProgram(name="toy_mesh_sphere", kind="mesh", model_type=ToyMeshSphere, build=tessellate,
                     options=("resolution",), description="a sphere, tessellated on the CPU")


class ToyPlane:
    """The parallelogram ``p0 + u e1 + v e2``, (u, v) in [0, 1]^2: a "surface"-kind toy."""

    def __init__(self, p0=(-1.0, -1.0, 0.0), e1=(2.0, 0.0, 0.5), e2=(0.0, 2.0, 0.25)):
        self.p0, self.e1, self.e2 = (np.asarray(v, dtype=np.float64) for v in (p0, e1, e2))


def build_plane(model, style, *, newton_iterations):
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    points = model.p0 + uv[:, :1] * model.e1 + uv[:, 1:] * model.e2
    return ProgramSpec(name="toy_plane", entry="toy_plane.glsl", points=points, triangles=np.array([[0, 1, 2], [0, 2, 3]]),
                       uniforms={"sv_toy_p0": tuple(model.p0), "sv_toy_e1": tuple(model.e1),
                                 "sv_toy_e2": tuple(model.e2), "sv_scalar_range": (-1.0, 1.0)},
                       varyings={"sv_uv": uv}, glsl_roots=(GLSL,))


SURFACE = SplineProgram(name="toy_plane", kind="surface", model_type=ToyPlane, build=build_plane,
                        description="a parallelogram evaluated per fragment")
