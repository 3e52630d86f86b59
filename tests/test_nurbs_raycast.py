"""The NURBS float64 ray cast's bookkeeping: the depth bound at the hits the reference just found uses that
cast's patch and (u, v) instead of casting again, with the same result."""

import numpy as np

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
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    hits = raycast.reference(model, o, d)
    h = np.flatnonzero(hits.hit)
    assert h.size > 300
    state = raycast._LAST.state
    # a ray the last cast did not shoot is not found (and gets the bound of a new cast); a lookup forgets the cast
    pid, _ = raycast._LAST.find(model, o[h[:5]] + 1e-3, d[h[:5]], hits.t[h[:5]])
    assert (pid == -1).all() and raycast._LAST.state is None
    raycast._LAST.state = state
    pid, uv = raycast._LAST.find(model, o[h], d[h], hits.t[h])
    assert (pid == 0).all() and np.isfinite(uv).all()  # every hit found again
    raycast._LAST.state = state
    kept = raycast.depth_bound(model, matrix, o[h], d[h], hits.t[h])
    assert raycast._LAST.state is None  # forgotten: the bound below casts again from just before each hit
    again = raycast.depth_bound(model, matrix, o[h], d[h], hits.t[h])
    # both (u, v) are Newton's fixed points of the same root (to 4 eps of the parameters); the bound is smooth in
    # S_u, S_v and the normal there, so the two agree far below the bound's own size (hundreds of u32)
    assert np.allclose(kept, again, rtol=1e-9, atol=0.0)
