"""Scenes where a float32 isosurface ray cast is most likely to part from its float64 twin.

Each is a :class:`~splinevis.gl.contract.HardCase` rendered at 160 x 120 and compared per pixel by the tests
and the self-test (:func:`splinevis.analysis.agreement.depth_agreement`): both schemes with every encoding,
proxy kind and root finder, anisotropic spacing with a UTM-sized origin, huge spacing, the camera inside the
volume, noisy data, prefiltered data (a noisy interpolating cubic) with higher-order padding, integer and float32 data, a plateau exactly at the isovalue and a sheet one voxel thick.
The distance field of a sphere is the common test data (:func:`sphere_grid`).
"""

from __future__ import annotations

import functools

import numpy as np

from ..gl.contract import HardCase
from ..io.volumes import VolumeGrid
from .isosurface import Isosurface
from .model import VolumeSpline

__all__ = ["hard_cases", "sphere_grid", "CAMERA"]

#: The common oblique view of the sphere cases.
CAMERA = [(3.0, 2.0, 2.5), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]


def sphere_grid(n: int = 20, radius: float = 0.7, spacing=None, origin=None, dtype=np.float64,
                noise: float = 0.0) -> VolumeGrid:
    """|x| sampled on n^3 points of [-1, 1]^3 (the isosurface 0.7 is a sphere), centred on ``origin`` (default:
    the grid centred on 0) with ``spacing`` (default 2 / (n - 1)); ``noise`` adds N(0, noise) (seed 0).

    >>> sphere_grid(5).values.shape
    (5, 5, 5)
    """
    x = np.linspace(-1, 1, n)
    z, y, xx = np.meshgrid(x, x, x, indexing="ij")
    v = np.sqrt(xx ** 2 + y ** 2 + z ** 2)
    if noise:
        v = v + np.random.default_rng(0).normal(scale=noise, size=v.shape)
    h = 2.0 / (n - 1)
    sp = np.array(spacing if spacing is not None else (h, h, h), dtype=float)
    org = np.array(origin if origin is not None else -1.0 * sp * (n - 1) / 2)
    return VolumeGrid(v.astype(dtype), spacing=tuple(sp), origin=tuple(org))


@functools.lru_cache(maxsize=8)
def _sphere(scheme="quadratic", n=20, noise=0.0) -> Isosurface:
    return Isosurface(VolumeSpline(sphere_grid(n=n, noise=noise), scheme), 0.5 if n == 24 else 0.7)


def _utm():
    return Isosurface(VolumeSpline(sphere_grid(spacing=(0.05, 0.12, 0.08), origin=(5.0e5, 4.2e6, 1.0e3))), 0.7)


def _centre(model):
    return np.array(model.spline.bounds).reshape(3, 2).mean(axis=1)


def _huge():
    return Isosurface(VolumeSpline(sphere_grid(spacing=(1.0e3, 1.0e3, 1.0e3), origin=(0.0, 0.0, 0.0))), 0.7)


def _prefiltered(scheme, prefilter, padding, noise=0.0):
    # prefiltered data (splinevis.volume.prefilter) overshoot the samples, most for noisy data interpolated by the
    # cubic (the checkerboard frequency is amplified ~n^2 / 1.2); the sphere is cut by the domain's faces, where the
    # spline reads the higher-order padding
    g = sphere_grid(n=16, noise=noise)
    return Isosurface(VolumeSpline(g, scheme, prefilter=prefilter, padding=padding), 1.05)


def _dtype(name):
    dtype = np.dtype(name)
    g = sphere_grid()
    scale = {"uint8": 200.0, "uint16": 40000.0, "int16": 20000.0, "float32": 1.0}[name]
    values = g.values.astype(dtype) if name == "float32" else np.round(g.values * scale).astype(dtype)
    return Isosurface(VolumeSpline(VolumeGrid(values, spacing=g.spacing, origin=g.origin)), 0.7 * scale + 0.5)


def _plateau():
    # data exactly equal to the isovalue on a block (every coefficient there equals it): the first point of
    # the plateau along the ray is a root (s - iso = 0) and both sides agree on it
    v = np.zeros((16, 16, 16))
    v[4:12, 4:12, 4:12] = 1.0
    v[6:10, 6:10, 6:10] = 2.0
    return Isosurface(VolumeSpline(VolumeGrid(v)), 1.0)


def _sheet():
    # a sheet one voxel thick (x = 8): an isosurface on both sides of it, seen from the side
    w = np.zeros((16, 16, 16))
    w[:, :, 8] = 1.0
    return Isosurface(VolumeSpline(VolumeGrid(w)), 0.5)


def hard_cases() -> list:
    """The isosurface program's hard cases (module docstring).

    Examples
    --------
    >>> cases = hard_cases()
    >>> len(cases), cases[0].name, cases[0].window_size, cases[1].program_options
    (23, 'quadratic-sphere-blocks-data-analytic', (160, 120), {'encoding': 'coefficients'})
    """
    quad, cubic = functools.partial(_sphere, "quadratic"), functools.partial(_sphere, "cubic")
    case = functools.partial(HardCase, min_hits=500 / 19200)  # at least 500 pixels of 160 x 120 show the surface
    cases = []
    for name, opts in [("blocks-data-analytic", {}), ("blocks-table", {"encoding": "coefficients"}),
                       ("bracketed", {"roots": "bracketed"}), ("cubes", {"proxy": "cubes"}),
                       ("cubes-table", {"proxy": "cubes", "encoding": "coefficients"}), ("blocks-of-3", {"block_size": 3})]:
        cases.append(case(f"quadratic-sphere-{name}", quad, CAMERA, program_options=opts))
    for name, opts in [("analytic", {}), ("bracketed", {"roots": "bracketed"}), ("cubes", {"proxy": "cubes"}),
                       ("determining-set", {"encoding": "determining"}),
                       ("determining-set-cubes", {"encoding": "determining", "proxy": "cubes"})]:
        cases.append(case(f"cubic-sphere-{name}", cubic, CAMERA, program_options=opts))
    cases += [
        case("anisotropic-utm-origin", _utm, lambda m: [tuple(_centre(m) + [3.0, 2.0, 2.5]), tuple(_centre(m)),
                                                            (0, 0, 1)]),
        case("spacing-1e3", _huge, lambda m: [tuple(_centre(m) + np.array([3.0, 2.0, 2.5]) * 8e3),
                                                  tuple(_centre(m)), (0, 0, 1)]),
        # the eye inside the domain (outside the sphere): proxies around and behind it are clipped by the near
        # plane; back faces still produce the fragments
        HardCase("camera-inside-volume", functools.partial(_sphere, "quadratic", 24),
                 [(0.9, 0.1, 0.2), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)], min_hits=2000 / 19200),
        case("noisy-data", functools.partial(_sphere, "quadratic", 20, 0.02), CAMERA),
        case("quadratic-local-prefilter-quadratic-padding",
             functools.partial(_prefiltered, "quadratic", "local", "quadratic"), CAMERA),
        case("cubic-interpolating-noisy-cubic-padding",
             functools.partial(_prefiltered, "cubic", "interpolate", "cubic", 0.02), CAMERA),
    ]
    cases += [case(f"{name}-data", functools.partial(_dtype, name), CAMERA)
              for name in ("uint8", "uint16", "int16", "float32")]
    cases += [
        HardCase("plateau-at-isovalue", _plateau, [(30.0, 22.0, 26.0), (7.5, 7.5, 7.5), (0, 0, 1)],
                 min_hits=300 / 19200),
        HardCase("one-voxel-sheet", _sheet, [(30.0, 14.0, 10.0), (7.5, 7.5, 7.5), (0, 0, 1)], min_hits=2000 / 19200),
    ]
    return cases
