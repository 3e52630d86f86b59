"""Choice of renderer by accuracy (splinevis.choice): the terrain mesh's chord bound holds on hard terrains and
is attained by a paraboloid, the isosurface mesh's value error stays within its proven part, the pixel
conversion matches a hand-derived camera, the choice moves from coarse to fine meshes to the ray cast as
the request shrinks, bad requests raise, and each choice renders a picture."""

import math

import numpy as np
import pytest

import splinevis
from datasets_synthetic.dem_files import fractal_terrain
from splinevis.choice import choose
from splinevis.gl.screen_error import SNAP_PX, View
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.sampled_mesh import chord_bounds, sampled_mesh
from splinevis.volume.model import VolumeSpline
from splinevis.volume import sampled_mesh as vsm

N = 25


def _crater():
    y, x = np.mgrid[-1:1:N * 1j, -1:1:N * 1j]
    r = np.hypot(x, y)
    return np.exp(-((r - 0.5) / 0.12) ** 2) - 0.7 * np.exp(-(r / 0.3) ** 2)


def _cliff():
    y, x = np.mgrid[0:N, 0:N].astype(float)
    return (x + 0.3 * y > 12.0).astype(float)


TERRAINS = {"crater": _crater, "cliff": _cliff, "fractal": lambda: fractal_terrain(N, seed=3)}


def _mesh_height(t, k, x, y):
    """The sampled mesh's height at (x, y): linear on the sub-triangle (split along u = v)."""
    mesh = sampled_mesh(t, k)
    ncy, ncx = t.shape
    z = mesh.points[:, 2].reshape(k * ncy + 1, k * ncx + 1)
    u, v = t.to_index(x, y)
    a = np.minimum(np.floor(u * k).astype(int), k * ncx - 1)
    b = np.minimum(np.floor(v * k).astype(int), k * ncy - 1)
    lu, lv = u * k - a, v * k - b
    z00, z10, z11, z01 = z[b, a], z[b, a + 1], z[b + 1, a + 1], z[b + 1, a]
    lower = z00 + lu * (z10 - z00) + lv * (z11 - z10)  # triangle (00, 10, 11)
    upper = z00 + lv * (z01 - z00) + lu * (z11 - z01)  # triangle (00, 11, 01)
    return np.where(lv > lu, upper, lower)


@pytest.mark.parametrize("name", sorted(TERRAINS))
@pytest.mark.parametrize("scheme", ["C1", "C2", "C0"])
def test_terrain_mesh_chord_bound_holds(name, scheme):
    t = TerrainSpline.from_heights(TERRAINS[name](), scheme, spacing=(0.1, 0.1))
    rng = np.random.default_rng(7)
    x0, x1, y0, y1 = t.extent
    x, y = rng.uniform(x0, x1, 20_000), rng.uniform(y0, y1, 20_000)
    u, v = t.to_index(x, y)
    cell = (np.minimum(v.astype(int), t.shape[0] - 1), np.minimum(u.astype(int), t.shape[1] - 1))
    span = float(np.ptp(t.coefficients))
    for k in (1, 2, 3):
        err = np.abs(_mesh_height(t, k, x, y) - t.evaluate(x, y))
        bound = chord_bounds(t, k)[cell]
        # float64 evaluation of both sides: a few roundings of the coefficients' size
        assert (err <= bound + 1e-12 * span).all(), (name, scheme, k, float((err - bound).max()))
        assert err.max() > 0.0


def test_chord_bound_is_attained_by_a_paraboloid():
    # f = u^2 + v^2 (reproduced by C1): L - f = R^2 - |x - centre|^2 on each sub-triangle, largest (h^2 / 2
    # times M / 2 = M h^2 / 4 with M = 2) at the hypotenuse's midpoint
    y, x = np.mgrid[0:6, 0:6].astype(float)
    t = TerrainSpline.from_heights(x * x + y * y, "C1")
    k = 2
    px, py = 2.25, 1.25  # midpoint of the sub-square's diagonal (2, 1) - (2.5, 1.5)
    err = float(_mesh_height(t, k, np.array([px]), np.array([py]))[0] - t.evaluate(px, py))
    assert err == pytest.approx(2.0 / (4 * k * k), rel=1e-9)
    assert float(chord_bounds(t, k)[1, 2]) == pytest.approx(2.0 / (4 * k * k), rel=1e-9)


def _torus(n=20):
    z, y, x = np.mgrid[-1:1:n * 1j, -1:1:n * 1j, -0.5:0.5:(n // 2) * 1j]
    return np.hypot(np.hypot(z, y) - 0.6, x), (2 / (n - 1), 2 / (n - 1), 1 / (n // 2 - 1))


def test_isosurface_mesh_value_error_within_its_proven_part():
    values, spacing = _torus()
    s = VolumeSpline(values, "quadratic", order="xyz", spacing=spacing, origin=(-1.0, -1.0, -0.5))  # x the thin axis
    iso = 0.25
    rel = s.relevant(iso)
    M = vsm.hessian_bounds(s, rel.cubes).max()
    rng = np.random.default_rng(1)
    for k in (1, 2):
        mesh = vsm.sampled_mesh(s, iso, k, rel)
        tri = mesh.faces.reshape(-1, 4)[:, 1:]
        lam = rng.dirichlet(np.ones(3), len(tri))
        pts = np.einsum("ti,tij->tj", lam, mesh.points[tri])
        h = s.spacing / k
        delta = M * (h.max() ** 2 / 8 + (h ** 2).sum() / 2)
        assert np.abs(s.evaluate(pts) - iso).max() <= delta
        # the distance estimate delta / g against the first-order distance |s - iso| / |grad s|
        _, grad = s.evaluate(pts, gradient=True)
        g = vsm.gradient_floor(s, vsm.sampled_mesh(s, iso, 1, rel))
        assert (np.abs(s.evaluate(pts) - iso) / np.linalg.norm(grad, axis=1)).max() <= delta / g


def test_pixel_conversion_against_a_hand_derived_camera():
    v = View((0, 0, 10), (0, 0, 0), (0, 1, 0), 90.0, width=200, height=200, clipping_range=(1, 100))
    m = v.matrix()

    def project(p):
        c = m @ np.append(p, 1.0)
        return (c[:2] / c[3] + 1.0) * 100.0  # 200 pixels across 2 NDC units

    # on the axis at depth 10, tan 45 deg = 1: 100 pixels per unit of X / Z, a 0.1 step sideways is 1 pixel
    moved = np.linalg.norm(project([0.1, 0.0, 0.0]) - project([0.0, 0.0, 0.0]))
    assert moved == pytest.approx(1.0, rel=1e-12)
    assert v.point_pixels([[0, 0, 0]], 0.1)[0] == pytest.approx(0.1 * 100 * 10.1 / 9.9 ** 2, rel=1e-12)
    # off the axis the bound holds for every direction of the displacement (r / Z^2, not 1 / Z)
    rng = np.random.default_rng(0)
    for p in ([6.0, 6.0, 1.0], [-3.0, 8.0, -20.0]):
        dirs = rng.normal(size=(500, 3))
        dirs *= 0.05 / np.linalg.norm(dirs, axis=1, keepdims=True)
        worst = max(np.linalg.norm(project(np.add(p, d)) - project(p)) for d in dirs)
        bound = v.point_pixels([p], 0.05)[0]
        assert worst <= bound
        rel = np.subtract(p, v.position)
        z, r = -rel[2], np.linalg.norm(rel)
        assert worst > 0.95 * 0.05 * 100 * r / z ** 2  # the sampled directions come close to the largest stretch
    # parallel: 2 * parallel_scale world units span the window height
    par = View((0, 0, 10), (0, 0, 0), (0, 1, 0), parallel=True, parallel_scale=4.0, height=300)
    assert par.point_pixels([[3.0, -2.0, 5.0]], 0.2)[0] == pytest.approx(0.2 * 300 / 8.0, rel=1e-12)


def _franke_like():
    y, x = np.mgrid[0:17, 0:17] / 16.0
    return TerrainSpline.from_heights(0.3 * np.sin(4 * x) * np.cos(3 * y), "C1", spacing=(1 / 16, 1 / 16))


def test_choice_refines_the_mesh_then_switches_to_the_box_ray_cast():
    t = _franke_like()
    v = View((0.5, -1.5, 1.5), (0.5, 0.5, 0.0), (0, 0, 1), 30.0, width=320, height=240, clipping_range=(0.5, 5))
    cache = {}
    picks = [choose(t, v, e, triangle_cap=50_000, cache=cache) for e in (4.0, 1.0, 0.3, 0.1, 0.03, 0.02)]
    ks = [c.level for c in picks if c.renderer == "mesh"]
    assert [c.renderer for c in picks] == ["mesh"] * 5 + ["raycast"]
    assert ks == sorted(ks) and ks[0] == 1 and ks[-1] > ks[0]
    for c in picks:
        assert c.meets and c.error_px <= c.max_error_px
        assert c.renderer in c.message and "considered" in c.message
        # the chosen mesh is the smallest k meeting the request: the one before it does not
        earlier = [o for o in c.options if o.name == "mesh" and o.level is not None and not o.reason]
        assert all(o.error_px > c.max_error_px for o in earlier if o is not c.chosen)
    # the chord bound scales as 1 / k^2: the mesh errors less the fixed float32 / snapping terms
    mesh = {o.level: o.error_px - SNAP_PX for o in picks[-1].options if o.name == "mesh" and not o.reason}
    assert mesh[2] / mesh[4] == pytest.approx(4.0, rel=0.05)
    # nothing meets a request below the sub-pixel snapping: the cheapest exact ray cast is drawn and the choice
    # says so
    c = choose(t, v, 1e-4, triangle_cap=50_000, cache=cache)
    assert not c.meets and c.renderer == "raycast" and "nothing meets" in c.message


@pytest.mark.parametrize("bad", [0, -1.0, math.nan, math.inf, "0.5", True])
def test_bad_max_error_raises(bad):
    pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
    with pytest.raises(ValueError, match="max_error_px must be a positive finite number"):
        pl.add_terrain(np.zeros((5, 5)), max_error_px=bad)
    with pytest.raises(ValueError, match="max_error_px must be a positive finite number"):
        pl.add_isosurface(np.random.default_rng(0).random((6, 6, 6)), 0.5, max_error_px=bad)
    pl.close()


def _foreground(image):
    return (np.abs(image.astype(int) - image[0, 0].astype(int)).sum(axis=2) > 30).mean()


@pytest.mark.parametrize("case, expected", [
    ("terrain mesh", "mesh"), ("terrain colormap", "raycast"), ("sphere mesh", "mesh"), ("sphere fine", "raycast")])
def test_each_choice_renders(case, expected):
    pl = splinevis.Plotter(off_screen=True, window_size=(160, 120))
    if case.startswith("terrain"):
        z = np.add.outer(np.sin(np.linspace(0, 3, 17)), np.cos(np.linspace(0, 3, 17)))
        extra = {"colormap": "terrain"} if "colormap" in case else {"reflection_lines": 8}
        actor = pl.add_terrain(z, "C1", read_options={"spacing": (0.2, 0.2)}, max_error_px=0.5, **extra)
    else:
        z, y, x = np.mgrid[-1:1:20j, -1:1:20j, -1:1:20j]
        actor = pl.add_isosurface(np.sqrt(x ** 2 + y ** 2 + z ** 2), 0.7, read_options={"spacing": (2 / 19,) * 3},
                                  max_error_px=1.0 if "mesh" in case else 0.01)
    choice = actor.renderer_choice
    assert choice.renderer == expected and choice.meets, choice.message
    image = pl.screenshot()
    assert 0.05 < _foreground(image) < 0.9 and image.std() > 10
    pl.close()


def test_ray_cast_options_exclude_the_mesh():
    pl = splinevis.Plotter(off_screen=True, window_size=(64, 48))
    z = np.add.outer(np.sin(np.linspace(0, 3, 9)), np.cos(np.linspace(0, 3, 9)))
    actor = pl.add_terrain(z, "C1", max_error_px=5.0, program_options={"roots": "paper"})
    choice = actor.renderer_choice
    assert choice.renderer == "raycast" and "program_options given" in choice.message
    assert actor.spec.defines["SV_ROOTS_PAPER"]
    pl.close()


def test_choice_module_knows_no_family():
    # The renderers are part of each family's contract (SplineProgram.renderers, declared in the family's
    # folder): splinevis/choice.py imports no family module, even lazily, and its table is gone.
    import ast
    from pathlib import Path

    import splinevis.choice as choice
    from splinevis import programs

    families = {m.split(".")[1] for m in programs.BUILTIN}
    tree = ast.parse(Path(choice.__file__).read_text())
    modules = set()  # choice.py sits in the package's top level: ".x" is "splinevis.x"
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            modules.add(("splinevis." if node.level == 1 else "") + (node.module or ""))
        elif isinstance(node, ast.Import):
            modules.update(a.name for a in node.names)
    imported = {m.split(".")[1] for m in modules if m.startswith("splinevis.")}
    assert "gl" in imported and "programs" in imported  # the walk sees the lazy imports too
    assert families & imported == set() and not hasattr(choice, "RENDERERS")
    assert [r.name for r in programs.get("terrain").renderers] == ["mesh", "mesh_guided", "raycast"]
    assert [r.name for r in programs.get("isosurface").renderers] == ["mesh", "raycast"]
