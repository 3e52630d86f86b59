"""OpenCASCADE shapes built by hand for the IGES and STEP reader tests (OCP is imported inside, as the readers
import it only when used)."""

import numpy as np


def occ_bspline_surface(dz: float = 0.0):
    """A rational bicubic x quadratic B-spline surface with an interior knot (OCP Geom_BSplineSurface), lifted by
    ``dz``."""
    from OCP.collections import Array1_double, Array1_int, Array2_double, Array2_gp_Pnt
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt

    nu, nv = 5, 3
    poles, weights = Array2_gp_Pnt(1, nu, 1, nv), Array2_double(1, nu, 1, nv)
    for i in range(nu):
        for j in range(nv):
            poles.SetValue(i + 1, j + 1, gp_Pnt(float(i), float(j), dz + round(float(np.sin(i + 2 * j)), 4)))
            weights.SetValue(i + 1, j + 1, 1.0 + 0.25 * ((i + j) % 3))
    uk, um, vk, vm = Array1_double(1, 3), Array1_int(1, 3), Array1_double(1, 2), Array1_int(1, 2)
    for a, (k, m) in enumerate([(0.0, 4), (0.375, 1), (1.0, 4)]):
        uk.SetValue(a + 1, k)
        um.SetValue(a + 1, m)
    for a, (k, m) in enumerate([(0.0, 3), (2.0, 3)]):
        vk.SetValue(a + 1, k)
        vm.SetValue(a + 1, m)
    return Geom_BSplineSurface(poles, weights, uk, vk, um, vm, 3, 2)
