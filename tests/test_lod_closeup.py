"""Close-ups drawn exactly (splinevis.nurbs.lod.closeup): the rule follows the camera (far: no close-up, near:
some), the switch re-uses the compiled per-fragment program, and where a switched super-surface meets its mesh
neighbours no gap opens: from inside a closed model no background pixel shows, and every pixel the exact
program draws alone is drawn the same (colour and depth) with the meshes around it."""

import numpy as np
import pytest
import pyvista as pv
from scipy.ndimage import binary_dilation

import splinevis
from splinevis.gl.camera import pixel_rays
from splinevis.nurbs.exact import sphere, torus
from splinevis.nurbs.lod.closeup import CloseUp, closeup_candidates, push_distances, screen_coverage
from splinevis.nurbs.lod.levels import assemble, build_lod
from splinevis.nurbs.model import NurbsModel

from _camera import look_at, perspective

H = 150
ASPECT = 4.0 / 3.0


@pytest.fixture(scope="module")
def lods():
    # delta 0.05 on a unit sphere / a torus of tube radius 0.5: a chord's gap is several pixels up close
    return {"sphere": build_lod(sphere(), 0.05, levels=2, progress=False),
            "torus": build_lod(torus(), 0.05, levels=2, progress=False)}


def _record(eye, focal, fov=60.0, near=1e-3, far=100.0):
    M = perspective(np.radians(fov), ASPECT, near, far) @ look_at(eye, focal)
    return (0, np.asarray(eye, dtype=float), M, H)


def test_coverage_is_the_projected_rectangle():
    _, _, M, _ = _record((0.0, -5.0, 0.0), (0.0, 0.0, 0.0))
    # a unit square at distance 5: the view is 2 tan(30 deg) 5 = 5.774 high and 4/3 of that wide
    box = np.array([[-0.5, 0.5, 0.0, 0.0, -0.5, 0.5]])
    expected = (1.0 / (2 * np.tan(np.radians(30.0)) * 5.0 * ASPECT)) * (1.0 / (2 * np.tan(np.radians(30.0)) * 5.0))
    assert screen_coverage(box, M)[0] == pytest.approx(expected, rel=1e-12)
    assert screen_coverage(np.array([[-1, 1, -6, -4, -1, 1.0]]), M)[0] == 1.0  # reaches behind the eye


def test_candidates_follow_the_camera(lods):
    lod = lods["sphere"]
    drawn = np.zeros(len(lod.supers.members), dtype=int)
    far_ids, far_info = closeup_candidates(lod, *_record((0.0, -200.0, 0.0), (0, 0, 0))[1:], drawn)
    assert far_ids.size == 0 and far_info["candidates"] == 0
    rec = _record((0.0, -1.3, 0.0), (0.0, 0.0, 0.0))
    near_ids, info = closeup_candidates(lod, *rec[1:], drawn)
    assert 0 < near_ids.size <= 4 and info["coverage"] >= 0.25
    # the chosen ones face the camera: their boxes reach to y < 0
    assert (lod.boxes[near_ids, 2] < 0).all()
    # caps: one super-surface, or patches too few for any
    assert closeup_candidates(lod, *rec[1:], drawn, max_supers=1)[0].size == 1
    assert closeup_candidates(lod, *rec[1:], drawn, max_patches=0)[0].size == 0
    # a super-surface not in the drawn mesh has no backstop: never chosen
    hidden = drawn.copy()
    hidden[near_ids] = -1
    assert not np.isin(closeup_candidates(lod, *rec[1:], hidden)[0], near_ids).any()
    # needs-finer alone: a middle distance where no box covers a quarter but level 0 exceeds 1 pixel
    mid = _record((0.0, -6.0, 0.0), (0.0, 0.0, 0.0))
    ids_cov, _ = closeup_candidates(lod, *mid[1:], drawn, pixel_error=None)
    ids_fin, info_fin = closeup_candidates(lod, *mid[1:], drawn, pixel_error=1.0)
    assert ids_cov.size == 0 and ids_fin.size > 0 and info_fin["needs_finer"] > 0


def test_shown_super_surfaces_stay_until_half_the_threshold_and_rank_higher(lods):
    lod = lods["sphere"]
    drawn = np.zeros(len(lod.supers.members), dtype=int)
    rec = _record((0.0, -1.3, 0.0), (0.0, 0.0, 0.0))
    cov = screen_coverage(lod.boxes, rec[2])
    s = int(np.argmax(cov))
    # a threshold just above its coverage: dropped when new, kept (hysteresis) when shown
    kw = dict(pixel_error=None, coverage=min(1.0, cov[s] * 1.5))
    assert s not in closeup_candidates(lod, *rec[1:], drawn, **kw)[0]
    assert s in closeup_candidates(lod, *rec[1:], drawn, current=[s], **kw)[0]
    # one slot: the largest wins, unless a shown one covers more than keep (1/2) of it
    rec = _record((0.3, -2.0, 0.5), (0.0, 0.0, 0.0))
    cov = screen_coverage(lod.boxes, rec[2])
    first, second = np.argsort(cov)[::-1][:2]
    weak = int(np.flatnonzero((cov >= 0.1) & (cov < 0.5 * cov[first]))[0])
    kw = dict(pixel_error=None, coverage=0.2, max_supers=1)
    assert closeup_candidates(lod, *rec[1:], drawn, **kw)[0].tolist() == [first]
    assert cov[second] > 0.5 * cov[first]
    assert closeup_candidates(lod, *rec[1:], drawn, current=[second], **kw)[0].tolist() == [second]
    assert closeup_candidates(lod, *rec[1:], drawn, current=[weak], **kw)[0].tolist() == [first]


def test_push_distances_cover_the_switched_mesh(lods):
    lod = lods["torus"]
    levels = np.array([0, 1] * (len(lod.supers.members) // 2))
    d = push_distances(lod, levels, [1], depth_margin=3.0)
    tri, _fans = lod.meshes[1][1]
    assert (d[np.unique(tri)] == np.float32(3.0 * lod.tolerance[1])).all()
    for e in lod.super_edges[1]:  # the finer chains of its shared edges (fans may use them) too
        assert (d[lod.edge_ids[e]] > 0).all()
    assert (d > 0).sum() < d.size / 2


def test_bad_input_is_refused(lods):
    lod = lods["sphere"]
    drawn = np.zeros(len(lod.supers.members), dtype=int)
    rec = _record((0.0, -1.3, 0.0), (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="coverage must be"):
        closeup_candidates(lod, *rec[1:], drawn, coverage=0.0)
    with pytest.raises(ValueError, match="one level per super-surface"):
        closeup_candidates(lod, *rec[1:], drawn[:3])
    with pytest.raises(ValueError, match="not drawn"):
        push_distances(lod, np.full(len(drawn), -1), [0])
    with pytest.raises(ValueError, match="depth_margin"):
        CloseUp(depth_margin=0.5)
    with pytest.raises(RuntimeError, match="before attach"):
        CloseUp().update(rec, drawn)
    pl = pv.Plotter(off_screen=True, window_size=(40, 30))
    cu = CloseUp()
    cu.attach(pl, lod)
    with pytest.raises(ValueError, match="ids must be in"):
        cu.show([99], drawn)
    with pytest.raises(RuntimeError, match="attached already"):
        cu.attach(pl, lod)
    cu.detach()
    pl.close()


def _scene(lod, level, eye, focal, size=(200, H)):
    """A splinevis.Plotter with the assembled mesh of ``level`` (white, unlit) and the camera set."""
    pl = splinevis.Plotter(off_screen=True, window_size=size)
    pl.set_background("black")
    points, tri, _ = assemble(lod, level)
    actor = pl.add_mesh(pv.PolyData(points, np.column_stack([np.full(len(tri), 3), tri]).ravel()), color="white",
                        lighting=False, reset_camera=False)
    pl.camera_position = [eye, focal, (0.0, 0.0, 1.0)]
    pl.camera.view_angle = 60.0
    pl.camera.clipping_range = (1e-3, 10.0)
    pl.render_now()  # the mesh actor's inner poly mapper exists from the first render on
    return pl, actor


@pytest.mark.gl
def test_switch_shows_hides_and_keeps_the_compiled_program(lods):
    lod = lods["torus"]
    level = np.zeros(len(lod.supers.members), dtype=int)
    pl, actor = _scene(lod, level, (0.0, -4.0, 3.0), (0.0, 0.0, 0.0))
    cu = CloseUp(color="red")
    cu.attach(pl, lod, actor)
    first = cu.show([0, 1], level)
    pl.render_now()
    spline, programs = cu.actor, set(cu.actor.program_ids)
    assert first["closeup_switch"] and first["closeup"] == 2 and spline.actor.GetVisibility()
    assert spline.model.names == tuple(lod.bezier.surface(int(i)).name for s in (0, 1) for i in lod.supers.members[s])
    again = cu.show([0, 1], level)
    assert not again["closeup_switch"] and again["closeup_build_ms"] == 0.0
    other = cu.show([5], level)
    pl.render_now()
    assert other["closeup_switch"] and cu.actor is spline  # one actor: new shell and tables ...
    assert cu.actor.program_ids == programs  # ... the same compiled program
    assert spline.model.names == tuple(lod.bezier.surface(int(i)).name for i in lod.supers.members[5])
    assert cu.show([], level)["closeup"] == 0 and not spline.actor.GetVisibility()
    n_actors = pl.renderer.GetActors().GetNumberOfItems()
    cu.detach()
    assert pl.renderer.GetActors().GetNumberOfItems() == n_actors - 1
    assert actor.GetShaderProperty().GetNumberOfShaderReplacements() == 0
    pl.close()


def _exact_alone(lod, supers, eye, focal, style, options, size=(200, H)):
    """The per-fragment program's own picture of the patches of ``supers`` (``add_spline``): colours,
    depth, and the unit normal and unit ray per pixel (from a second picture with ``output="normals"``)."""
    model = NurbsModel([lod.bezier.surface(int(i)) for s in supers for i in lod.supers.members[s]])
    out = []
    for st in (style, style.replace(output="normals")):
        pl = splinevis.Plotter(off_screen=True, window_size=size)
        pl.set_background("black")
        pl.add_spline(model, st, program_options={"subdivisions": options["subdivisions"]},
                      newton_iterations=options["newton_iterations"])
        pl.camera_position = [eye, focal, (0.0, 0.0, 1.0)]
        pl.camera.view_angle = 60.0
        pl.camera.clipping_range = (1e-3, 10.0)
        out.append((pl.screenshot(), pl.depth_buffer(), pl.camera_matrix()))
        pl.close()
    (img, depth, _), (nimg, _, matrix) = out
    normal = nimg[..., :3].astype(float) / 255.0 * 2.0 - 1.0
    _, ray = pixel_rays(matrix, size[0], size[1])
    unit = lambda v: v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)  # noqa: E731
    return img, depth, np.abs(np.sum(unit(normal) * unit(ray), axis=-1))


@pytest.mark.gl
@pytest.mark.parametrize("name, eye, focal", [("sphere", (0.3, 0.1, 0.1), (1.0, 0.3, 0.2)),
                                               ("sphere", (-0.4, 0.3, -0.2), (-1.0, -0.2, 0.4)),
                                               ("torus", (2.0, 0.0, 0.0), (2.0, 1.0, 0.1)),
                                               ("torus", (0.0, -2.1, 0.1), (1.0, -1.5, 0.0))])
def test_no_gap_at_the_seams_and_exact_pixels_as_drawn_alone(lods, name, eye, focal):
    lod = lods[name]
    S = len(lod.supers.members)
    level = np.arange(S) % lod.levels  # mixed levels: fans on the finer side's neighbours
    rec = _record(eye, focal)
    cu = CloseUp(color="red", lights=1, max_supers=3, coverage=0.05)
    ids, _ = closeup_candidates(lod, *rec[1:], level, current=(), **cu.rule)
    assert ids.size > 0
    # without the backstop (the switched super-surfaces left out of the mesh) the chords leave gaps: the test
    # sees them in each of these views
    bare = level.copy()
    bare[ids] = -1
    pl, _ = _scene(lod, bare, eye, focal)
    bare_depth = pl.depth_buffer()  # the other super-surfaces' mesh alone
    gap = CloseUp(cu.style, **cu.options)
    gap.attach(pl, lod)
    gap.show(ids, level)
    pl.render_now()
    assert (pl.depth_buffer() == 1.0).sum() > 0
    pl.close()
    # with it: every pixel hits the model
    pl, actor = _scene(lod, level, eye, focal)
    cu.attach(pl, lod, actor)
    cu.show(ids, level)
    pl.render_now()  # (a screenshot alone would show the last rendered frame)
    img, depth = pl.screenshot(), pl.depth_buffer()
    cu.detach()
    pl.close()
    assert (depth == 1.0).sum() == 0
    # every pixel the exact program draws alone is drawn the same here (same program and uniforms: the same
    # bits, colour and depth), except where (a) another super-surface's mesh lies in front of it (a true
    # occlusion: from inside the torus' tube its far side is seen through its near wall's bend) or (b) the
    # ray meets the surface at cos(theta) < 1 / depth_margin, where the pushed mesh (within tol / cos(theta)
    # along the ray) may stay in front (module docstring); within one pixel of it, as the normal turns fast there
    ref_img, ref_depth, cos = _exact_alone(lod, ids, eye, focal, cu.style, cu.options)
    hit = ref_depth < 1.0
    assert hit.sum() > 0.05 * hit.size
    differs = hit & ((img != ref_img).any(axis=-1) | (depth != ref_depth))
    in_front = bare_depth < ref_depth
    grazing = binary_dilation(hit & (cos < 1.0 / cu.depth_margin), iterations=1)
    assert not (differs & ~in_front & ~grazing).any()
    # ... and every other pixel is the white mesh
    assert (img[~hit] == 255).all()


def _pixel_rect(points, matrix, size):
    """The pixel rectangle (x0, x1, y0, y1), row 0 at the top, holding the projections of ``points``."""
    clip = points @ matrix[:, :3].T + matrix[:, 3]
    assert (clip[:, 3] > 0).all()  # all in front of the eye
    ndc = clip[:, :2] / clip[:, 3:]
    x = (ndc[:, 0] + 1.0) * 0.5 * size[0]
    y = (1.0 - ndc[:, 1]) * 0.5 * size[1]
    return (max(int(np.floor(x.min())) - 1, 0), int(np.ceil(x.max())) + 1,
            max(int(np.floor(y.min())) - 1, 0), int(np.ceil(y.max())) + 1)


@pytest.mark.gl
def test_teapot_close_up_is_exact_near_and_mesh_far(tmp_path):
    from datasets_synthetic.large_models import teapot_field
    from splinevis.nurbs.lod.pipeline import _clipping_range, view_proj_matrix
    from splinevis.nurbs.lod.select import select_levels

    lod = build_lod(teapot_field(4), 0.05, levels=2, progress=False)
    size = (320, 240)
    pl = splinevis.Plotter(off_screen=True, window_size=size)
    pl.set_background("white")
    mesh = pv.PolyData(np.zeros((1, 3)))
    actor = pl.add_mesh(mesh, color="tan", reset_camera=False)  # the walkthrough's mesh actor
    actor.prop.interpolation = "phong"
    cu = CloseUp(reflection_lines=10, lights=2)
    cu.attach(pl, lod, actor)
    box = lod.bezier.bbox[:32]  # teapot 0
    lo, hi = box[:, 0::2].min(axis=0), box[:, 1::2].max(axis=0)
    centre = 0.5 * (lo + hi)
    pictures, stats = {}, {}
    for where, distance in (("far", 60.0), ("near", 6.5)):
        eye = centre + distance * np.array([-2.5, -3.0, 1.5]) / np.linalg.norm([-2.5, -3.0, 1.5])
        pl.camera_position = [tuple(eye), tuple(centre), (0.0, 0.0, 1.0)]
        pl.camera.clipping_range = _clipping_range(lod.boxes, eye)
        record = (0, eye, view_proj_matrix(pl), size[1])
        levels, _ = select_levels(lod, eye, record[2], size[1], 1.0)
        points, tri, _ = assemble(lod, levels)
        mesh.points = points
        mesh.point_data.active_normals = lod.normals
        mesh.SetPolys(pv.CellArray.from_regular_cells(tri))
        mesh.Modified()
        cu.show([], levels)  # the mesh alone ...
        pl.render_now()
        plain = pl.screenshot()
        stats[where] = cu.update(record, levels)  # ... then with the close-up the rule picks
        pl.render_now()
        pictures[where] = (plain, pl.screenshot(), pl.camera_matrix(), levels, tri)
    shown = cu.shown.copy()
    cu.detach()
    pl.close()
    assert stats["far"]["closeup"] == 0 and not stats["far"]["closeup_switch"]
    assert (pictures["far"][0] == pictures["far"][1]).all()
    near = stats["near"]
    assert near["closeup_switch"] and 0 < near["closeup"] <= 4 and near["closeup_patches"] <= 64
    plain, exact, matrix, levels, tri = pictures["near"]
    import imageio

    imageio.imwrite(tmp_path / "teapot_closeup.png", np.concatenate([plain, exact], axis=1))
    white = (plain == 255).all(axis=-1)
    assert not ((exact == 255).all(axis=-1) & ~white).any()  # no hole opened: the backstop covers as before
    changed = (plain != exact).any(axis=-1)
    assert changed.mean() > 0.05  # the exact patches are drawn with their reflection lines ...
    assert (exact[changed].max(axis=-1) < 40).mean() > 0.1  # ... dark stripes on the tan
    # the exact patches lie in their boxes; the pushed vertices move the triangles that use them
    pushed = push_distances(lod, levels, shown) > 0
    moved = lod.vertices[np.unique(tri[pushed[tri].any(axis=1)])]
    corners = lod.boxes[shown][:, [[i, j, k] for i in (0, 1) for j in (2, 3) for k in (4, 5)]].reshape(-1, 3)
    x0, x1, y0, y1 = _pixel_rect(np.concatenate([moved, corners]), matrix, size)
    outside = np.ones(changed.shape, dtype=bool)
    outside[y0:y1, x0:x1] = False
    assert outside.mean() > 0.1 and not (changed & outside).any()  # elsewhere: the mesh picture, unchanged


@pytest.mark.gl
def test_vertices_made_after_the_model_are_pushed_inside_the_switched_boxes(lods):
    # a mesh whose switched super-surfaces use vertices numbered after lod.vertices (as a finer mesh made on
    # the fly does): the same positions, so the same picture as with the model's own vertices
    lod = lods["sphere"]
    eye, focal = (0.3, 0.1, 0.1), (1.0, 0.3, 0.2)
    level = np.zeros(len(lod.supers.members), dtype=int)
    cu = CloseUp(color="red", lights=1, max_supers=3, coverage=0.05)
    ids, _ = closeup_candidates(lod, *_record(eye, focal)[1:], level, **cu.rule)
    points, tri, _ = assemble(lod, level)
    # one level everywhere: no fans, the rows of super-surface s are its level-0 triangles, in the order of s
    start = np.concatenate([[0], np.cumsum(lod.triangles[:, 0])])
    rows = np.concatenate([np.arange(start[s], start[s + 1]) for s in ids])
    copies = np.unique(tri[rows])
    renumber = np.full(len(points), -1)
    renumber[copies] = len(points) + np.arange(copies.size)
    tri = tri.copy()
    tri[rows] = renumber[tri[rows]]
    points = np.concatenate([points, points[copies]])
    pictures = []
    for pts, tr in ((points, tri), (None, None)):
        pl, actor = _scene(lod, level, eye, focal)
        if pts is not None:
            actor.mapper.dataset.points = pts
            actor.mapper.dataset.faces = np.column_stack([np.full(len(tr), 3), tr]).ravel()
        cu.attach(pl, lod, actor)
        cu.show(ids, level)
        pl.render_now()
        pictures.append((pl.screenshot(), pl.depth_buffer()))
        cu.detach()
        pl.close()
    (img, depth), (img0, depth0) = pictures
    assert (depth == 1.0).sum() == 0
    assert (img == img0).all() and (depth == depth0).all()
    assert (img == (255, 0, 0)).all(axis=-1).sum() == 0 and (img[..., 0] > img[..., 1]).mean() > 0.3  # red shows


@pytest.mark.gl
def test_the_push_follows_the_camera_between_updates(lods):
    # an interactor renders as the user drags, before the next update: the push must point away from the eye of
    # each render (set when the shader is updated), or the backstop would be drawn pushed along other rays. A
    # per-vertex push keeps the mesh watertight whatever its direction (the vertices stay shared), so the
    # witness is the picture: the same colours and depths as a close-up set up at that camera
    lod = lods["sphere"]
    level = np.zeros(len(lod.supers.members), dtype=int)
    views = (((0.3, 0.1, 0.1), (1.0, 0.3, 0.2)), ((-0.5, 0.2, -0.3), (0.5, -0.2, 0.2)),
             ((0.0, -0.6, 0.5), (0.0, 1.0, -0.5)))
    pl, actor = _scene(lod, level, *views[0])
    cu = CloseUp(depth_margin=8.0)
    cu.attach(pl, lod, actor)
    cu.show([0, 1, 2, 3], level)  # half the sphere exact, its mesh pushed far (8 tol)
    for eye, focal in views[1:]:
        pl.camera_position = [eye, focal, (0.0, 0.0, 1.0)]
        pl.camera.clipping_range = (1e-3, 10.0)  # as _scene's
        pl.render_now()
        moved = (pl.screenshot(), pl.depth_buffer())
        fresh_pl, fresh_actor = _scene(lod, level, eye, focal)
        fresh = CloseUp(depth_margin=8.0)
        fresh.attach(fresh_pl, lod, fresh_actor)
        fresh.show([0, 1, 2, 3], level)
        fresh_pl.render_now()
        assert (moved[1] < 1.0).all()
        assert (moved[0] == fresh_pl.screenshot()).all() and (moved[1] == fresh_pl.depth_buffer()).all()
        fresh.detach()
        fresh_pl.close()
    cu.detach()
    pl.close()


@pytest.mark.gl
def test_a_close_up_keeps_the_trims():
    """The exact patches carry their surface's trim loops (in each patch's domain): a hole cut in the LOD mesh
    stays a hole drawn exactly, and patches trimmed away are not drawn."""
    from datasets_synthetic.large_models import ellipse_loop, rectangle_loop
    from splinevis.nurbs.surface import NurbsSurface

    g = np.linspace(0.0, 1.0, 6)
    X, Y = np.meshgrid(g, g, indexing="ij")
    knots = [0, 0, 0, 0, 1 / 3, 2 / 3, 1, 1, 1, 1]
    s = NurbsSurface((3, 3), (knots, knots), np.stack([X, Y, 0.05 * np.sin(3 * X + 2 * Y)], axis=-1), None, "plate")
    border = rectangle_loop(0.0, 1.0, 0.0, 1.0)
    square = rectangle_loop(1 / 3, 2 / 3, 1 / 3, 2 / 3)  # the centre patch, whole
    hole = ellipse_loop(0.2, 0.25, 0.1, 0.1)  # across the knot line v = 1/3
    lod = build_lod(NurbsModel([s], trims=[[border, square, hole]]), 0.005, levels=2, progress=False)
    assert (lod.status == -1).sum() == 1
    pl = pv.Plotter(off_screen=True, window_size=(200, 200))
    pl.set_background("black")
    pl.camera_position = [(0.5, 0.5, 3.0), (0.5, 0.5, 0.0), (0.0, 1.0, 0.0)]
    pl.camera.view_angle = 22.0
    cu = CloseUp(max_supers=len(lod.supers.members), max_patches=len(lod.bezier))
    cu.attach(pl, lod)
    cu.show(np.arange(len(lod.supers.members)), np.zeros(len(lod.supers.members), dtype=int))
    img = pl.screenshot()
    cu.detach()
    pl.close()
    lit = img.sum(axis=-1) > 0

    def pixel(u, v):  # the view: 3 units away, 22 degrees: 1.166 units over 200 pixels, v up
        scale = 200 / (2 * 3.0 * np.tan(np.radians(11.0)))
        return int(round(100 - (v - 0.5) * scale)), int(round(100 + (u - 0.5) * scale))

    for (u, v), drawn in [((0.2, 0.25), False), ((0.5, 0.5), False), ((0.8, 0.8), True), ((0.2, 0.6), True),
                          ((0.2, 0.39), True), ((0.12, 0.25), True), ((0.2, 0.3), False)]:
        r, c = pixel(u, v)
        assert lit[r, c] == drawn, (u, v)
