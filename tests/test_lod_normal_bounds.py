"""Proven normal bounds of the levels of detail (splinevis.nurbs.normal_bounds.lod_normal_bounds, stored as
LodModel.normal_bounds): at random points inside every drawn triangle of every level the normalized barycentric
combination of the stored vertex normals is within the bound of the float64 surface's normal at the interpolated
parameter (a torus, a sphere with poles, a C0 crease whose bound is infinite), and the walkthrough's normal
request draws finer levels where the position request alone would not."""

import numpy as np
import pytest

import splinevis.nurbs.normal_bounds as nb
from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.hard_cases import crease
from splinevis.nurbs.lod.bezier import evaluate
from splinevis.nurbs.lod.levels import build_lod
from splinevis.nurbs.lod.select import select_levels
from splinevis.nurbs.model import NurbsModel


def _build(model, delta, levels, monkeypatch):
    """The LodModel and the per-level triangle records build_lod bounds: (s, l, triangles, patch, local uv, fans)."""
    got, orig = {}, nb.lod_normal_bounds

    def grab(*args, **kwargs):
        got["records"] = args[6]
        return orig(*args, **kwargs)

    monkeypatch.setattr(nb, "lod_normal_bounds", grab)
    lod = build_lod(model, delta, levels=levels, progress=False, workers=1)
    return lod, got["records"]


def _measured(lod, records, n=3000, seed=0):
    """(S, L): the largest angle between the shading normal and the exact normal at sampled points."""
    rng = np.random.default_rng(seed)
    out = np.zeros(lod.normal_bounds.shape)
    for s, l, tri, patch, uv, _ in records:
        t = rng.integers(0, len(tri), n)
        lam = rng.dirichlet(np.ones(3), n)
        shade = np.einsum("nk,nkc->nc", lam, lod.normals[tri[t]])
        shade /= np.linalg.norm(shade, axis=1, keepdims=True)
        q = np.einsum("nk,nkc->nc", lam, uv[t])
        _, su, sv = evaluate(lod.bezier, patch[t], q[:, 0], q[:, 1], derivatives=True)
        g = np.cross(su, sv)
        ok = np.linalg.norm(g, axis=1) > 1e-9 * np.linalg.norm(su, axis=1) * np.linalg.norm(sv, axis=1)  # no pole
        g = g[ok] / np.linalg.norm(g[ok], axis=1, keepdims=True)
        out[s, l] = np.arctan2(np.linalg.norm(np.cross(shade[ok], g), axis=1), np.einsum("ij,ij->i", shade[ok], g)).max()
    return out


@pytest.mark.parametrize("name", ["torus", "sphere-poles"])
def test_the_bound_holds_against_the_float64_surface(name, monkeypatch):
    model = {"torus": torus, "sphere-poles": sphere}[name]()
    lod, records = _build(model, 0.01, 3, monkeypatch)
    bound, angle = lod.normal_bounds, _measured(lod, records)
    assert len(records) == bound.size  # every level of every super-surface bounded
    # both sides are float64 evaluations of unit normals: the test's barycentric sums and the evaluation at the
    # sample add a few eps (radians)
    assert (angle <= bound + 1e-12).all(), float(np.degrees(angle - bound).max())
    assert angle.min() > 0.0  # points inside the triangles: not vacuous
    # G1 seams, poles covered by cones: finite at every level, larger the coarser
    assert np.isfinite(bound).all() and (np.diff(bound.max(axis=0)) > 0).all()


def test_a_crease_has_no_bound_and_the_mesh_is_really_that_far_off(monkeypatch):
    # a u knot of multiplicity p: the ridge's vertices carry one side's normal, 90 degrees off the other side's
    lod, records = _build(NurbsModel([crease()]), 0.01, 2, monkeypatch)
    bound, angle = lod.normal_bounds, _measured(lod, records)
    assert np.isinf(bound).any() and np.degrees(angle[np.isinf(bound)].max()) > 80.0
    assert (angle <= bound + 1e-12).all()


def _view():
    from splinevis.nurbs.lod.pipeline import view_proj_matrix
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=(160, 120))
    pl.camera_position = [(0.0, -6.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
    M = view_proj_matrix(pl)
    pl.close()
    return np.array([0.0, -6.0, 3.0]), M


def test_a_normal_request_draws_finer_levels(monkeypatch):
    lod, _ = _build(torus(), 0.01, 3, monkeypatch)
    eye, M = _view()
    plain, _ = select_levels(lod, eye, M, 120, pixel_error=2.0)
    request = float(np.degrees(lod.normal_bounds[:, 0].max())) + 0.01  # level 0 meets it everywhere
    finer, stats = select_levels(lod, eye, M, 120, pixel_error=2.0, max_normal_deg=request)
    drawn = plain >= 0
    assert (finer[drawn] <= plain[drawn]).all() and (finer[drawn] < plain[drawn]).any()
    assert (np.degrees(lod.normal_bounds[drawn, finer[drawn]]) <= request).all()
    assert stats["normal_limited"] == int((finer < plain).sum()) and stats["normal_unmet"] == 0
    # a request no level meets: level 0, counted
    _, stats = select_levels(lod, eye, M, 120, pixel_error=2.0, max_normal_deg=1e-3)
    assert stats["normal_unmet"] == int(drawn.sum())


def test_the_walkthrough_flies_with_a_normal_request(tmp_path):
    import pyvista as pv
    from PIL import Image

    from splinevis.nurbs.lod.pipeline import Walkthrough

    lod = build_lod(torus(), 0.01, levels=3, progress=False)
    path = [[(0.0, -6.0 + k, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)] for k in range(3)]
    tri = {}
    for request in (None, 10.0):
        pl = pv.Plotter(off_screen=True, window_size=(96, 72))
        frames = Walkthrough(lod, pl, threaded=False, pixel_error=2.0, max_normal_error_deg=request).fly(
            path, frames_dir=tmp_path / str(request), progress=False)
        pl.close()
        tri[request] = [f["triangles"] for f in frames]
        assert all(f["normal_unmet"] == 0 for f in frames)
    assert all(a <= b for a, b in zip(tri[None], tri[10.0])) and tri[None] != tri[10.0]
    img = np.asarray(Image.open(tmp_path / "10.0" / "frame_0002.png").convert("L"), dtype=float)
    assert img.std() > 10.0  # the torus, shaded, on the background: not a blank frame
    with pytest.raises(ValueError, match="dynamic"):
        Walkthrough(lod, pv.Plotter(off_screen=True), dynamic=True, max_normal_error_deg=1.0)
