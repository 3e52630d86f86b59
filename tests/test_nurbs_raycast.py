"""The NURBS float64 ray cast hands its hits' patch and (u, v) on (RayHits.surface): the depth bound at the hits the
reference found uses them instead of casting again, with the same result."""

import numpy as np
import pytest

from splinevis.gl.camera import pixel_rays
from splinevis.nurbs import raycast
from splinevis.nurbs.exact import torus
from splinevis.nurbs.model import NurbsModel


def _camera_matrix():
    from splinevis.plotting import Plotter

    pl = Plotter(off_screen=True, window_size=(64, 48))
    pl.camera_position = [(3.0, -4.0, 2.5), (0.0, 0.0, 0.0), (0, 0, 1)]
    matrix = pl.camera_matrix()
    pl.close()
    return matrix


def test_the_depth_bound_at_the_reference_hits_equals_the_one_cast_again():
    model = NurbsModel([torus()])
    matrix = _camera_matrix()
    o, d = pixel_rays(matrix, 64, 48)
    hits = raycast.reference(model, o, d)  # rays of shape (48, 64): the parameters keep the rays' shape
    assert hits.surface["patch"].shape == (48, 64) and hits.surface["uv"].shape == (48, 64, 2)
    h = hits.hit
    assert h.sum() > 300
    kept = hits.surface_at(h)
    assert (kept["patch"] == 0).all() and np.isfinite(kept["uv"]).all()  # every hit on the one patch, (u, v) known
    assert (hits.surface["patch"][~h] == -1).all()
    # the surface point at the kept (u, v) is the hit point
    S = model.surfaces[0].evaluate(kept["uv"][:, 0], kept["uv"][:, 1])
    assert np.abs(S - hits.points[h]).max() < 1e-9
    bound = raycast.depth_bound(model, matrix, o[h], d[h], hits.t[h], surface=kept)
    again = raycast.depth_bound(model, matrix, o[h], d[h], hits.t[h])  # no parameters: each ray cast again
    # both (u, v) are Newton's fixed points of the same root (to 4 eps of the parameters); the bound is smooth in
    # S_u, S_v and the normal there, so the two agree far below the bound's own size (hundreds of u32)
    assert np.allclose(bound, again, rtol=1e-9, atol=0.0)
    # a hit whose patch is not known (-1) is cast again, the others keep theirs: the same bound
    partial = {"patch": kept["patch"].copy(), "uv": kept["uv"].copy()}
    partial["patch"][::3] = -1
    assert np.allclose(raycast.depth_bound(model, matrix, o[h], d[h], hits.t[h], surface=partial), bound,
                       rtol=1e-9, atol=0.0)
    # parameters of other rays than the ones asked about: refused, not silently paired with the wrong rays
    with pytest.raises(ValueError, match="surface has .* for .* rays"):
        raycast.depth_bound(model, matrix, o[h][:-1], d[h][:-1], hits.t[h][:-1], surface=kept)
