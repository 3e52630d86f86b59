"""The C1 measure at the four cut vertices of a geometry image, shared by the surface tests
(tests/test_geometry_image_model.py) and the mesh-to-image tests (tests/test_geometry_image_build.py)."""

import numpy as np
from scipy.interpolate import NdBSpline

from splinevis.geometry_image.image import cut_vertices, pad


def cone_measure(G):
    """|det[P_ss, P_st, P_tt]| / (|P_ss| |P_st| |P_tt|) at the four cut vertices of the image G, scipy's
    tensor-product B-spline of the padded image as the reference: 0 when the second-order terms span a plane (a
    tangent plane exists, C1), of order 1 for a cusp (three independent directions)."""
    N = G.shape[0] - 1
    knots = np.arange(-3.0, N + 4.0)
    ref = NdBSpline((knots, knots), pad(G, 1), 3)
    ts = cut_vertices(G.shape[0]).astype(float)  # (row, column) = (t, s)
    a, b, c = ref(ts, nu=(0, 2)), ref(ts, nu=(1, 1)), ref(ts, nu=(2, 0))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    return np.abs(det) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1) * np.linalg.norm(c, axis=1))
