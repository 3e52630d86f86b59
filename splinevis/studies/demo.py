"""The showcase figures (``splinevis demo --out DIR``), rendered offscreen.

* ``composite.png`` -- the ray-cast quartic patch and an ordinary PyVista sphere cutting through it: the
  sphere is in front of the patch in some pixels and behind it in others, so occlusion must be right both
  ways round (the surface writes ``gl_FragDepth``).
* ``effects.png`` -- the same patch under each effect set; every panel compiled only its own effects.
* ``composite_check.png`` -- which surface is in front per pixel, GPU against the float64 reference.
* ``volume.png`` -- Marschner-Lobb 41^3, close-up: marching cubes (flying edges), VTK's GPU isosurface ray
  caster, the quadratic and the cubic spline ray-cast per pixel; second row with reflection lines.
* ``terrain.png`` -- a synthetic DEM (UTM-sized origin) as a C1 quartic spline: colour by height with
  reflection lines, beside the same data as a linear mesh and as the C2 box spline.
* ``nurbs.png`` -- NURBS surfaces per fragment with zebra stripes beside tessellated meshes.
* ``geometry_image.png`` -- a closed mesh (a bent blob, not star-shaped), its spherical parametrization, the
  unfolded octahedron, its geometry image, the smooth surface subdivided by GPU passes and its reflection
  lines [Losasso2003].
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .report import progress_bar, pyplot, save_figure

__all__ = ["render_showcase", "composite_scene", "EFFECT_PANELS"]

CAMERA = [(2.5, -3.3, 2.4), (0.05, -0.1, 0.05), (0.0, 0.0, 1.0)]
SPHERE = dict(center=(0.05, -0.15, 0.22), radius=0.3)


def _checker(n=256, k=8):
    i, j = np.indices((n, n)) // (n // k)
    img = np.where(((i + j) % 2)[..., None] == 0, [235, 225, 200], [60, 90, 140]).astype(np.uint8)
    return img


def _sky(h=128, w=256):
    v = np.linspace(0.0, 1.0, h)[:, None, None]
    u = np.linspace(0.0, 1.0, w)[None, :, None]
    top = np.array([70, 110, 190])
    bottom = np.array([210, 180, 140])
    img = top * (1 - v) + bottom * v
    img = img + 40 * (np.sin(u * 12 * np.pi) > 0.9)
    return np.clip(img, 0, 255).astype(np.uint8)


def _effect_panels():
    """The panels of ``effects.png``: ``(title, style)`` per panel, ``style`` the keywords of
    :meth:`splinevis.Plotter.add_spline` (public as :data:`EFFECT_PANELS`; a function, because the texture
    and environment panels make their images on each call).

    Examples
    --------
    >>> from splinevis.studies.demo import EFFECT_PANELS
    >>> [title for title, _ in EFFECT_PANELS()]  # doctest: +NORMALIZE_WHITESPACE
    ['unlit colour', '1 light', '3 lights + specular', 'colormap (height)', 'texture', 'environment map',
     'reflection lines', 'isophotes', 'normals', 'mean curvature']
    >>> dict(EFFECT_PANELS())["3 lights + specular"]
    {'lights': 3, 'specular': True}
    """
    return [
        ("unlit colour", dict(lights=0)),
        ("1 light", dict(lights=1)),
        ("3 lights + specular", dict(lights=3, specular=True)),
        ("colormap (height)", dict(colormap="viridis")),
        ("texture", dict(texture=_checker())),
        ("environment map", dict(environment=_sky(), specular=True)),
        ("reflection lines", dict(reflection_lines=10)),
        ("isophotes", dict(isophotes=8)),
        ("normals", dict(output="normals")),
        ("mean curvature", dict(output="curvature", curvature_scale=2.0)),
    ]


EFFECT_PANELS = _effect_panels


def composite_scene(window_size=(640, 480), style=None, sphere=True):
    """A Plotter with the demo patch (and the sphere mesh) at the showcase camera.

    Returns
    -------
    (Plotter, QuarticTrianglePatch, SplineActor)
        The offscreen plotter (the caller closes it), the patch and its actor.

    Examples
    --------
    >>> from splinevis.studies.demo import composite_scene
    >>> pl, patch, actor = composite_scene((64, 48))
    >>> type(patch).__name__, actor.program.name, len(pl.renderer.actors)  # the patch and the sphere
    ('QuarticTrianglePatch', 'analytic_patch', 2)
    >>> bool((pl.depth_buffer() < 1.0).any())  # something was drawn
    True
    >>> pl.close()
    """
    import pyvista as pv

    from ..analytic import QuarticTrianglePatch
    from ..plotting import Plotter

    patch = QuarticTrianglePatch.demo()
    pl = Plotter(off_screen=True, window_size=window_size)
    pl.set_background("white")
    actor = pl.add_spline(patch, **(style or dict(lights=2, specular=True, color="tan")))
    if sphere:
        pl.add_mesh(pv.Sphere(theta_resolution=96, phi_resolution=96, **SPHERE), color="steelblue",
                    smooth_shading=True)
    pl.camera_position = CAMERA
    pl.reset_camera_clipping_range()
    return pl, patch, actor


def render_showcase(out_dir, *, progress=True, scale: float = 1.0) -> dict:
    """Render every showcase figure into ``out_dir``; returns {name: path}. ``scale`` multiplies the window
    sizes of the two figures whose float64 twins cost most (the composite check and the NURBS zebra): the same
    code at a quarter of the pixels (the test suite's run)."""
    from ..analysis.composite import UNLIT, front_surface_agreement

    plt = pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    panels = _effect_panels()
    steps = progress_bar(total=6 + len(panels), desc="showcase", enabled=progress, unit="fig")
    written = {}

    pl, patch, _ = composite_scene()
    pl.add_text("ray-cast quartic patch (exact per pixel) + PyVista sphere mesh", font_size=10, color="black")
    path = out / "composite.png"
    pl.screenshot(str(path))
    pl.close()
    written["composite"] = path
    steps.update()

    result = front_surface_agreement(*composite_scene(_scaled((640, 480), scale), style=UNLIT)[:2])
    from matplotlib.colors import ListedColormap

    classes = ListedColormap(["white", "firebrick", "royalblue"])  # background, patch, sphere
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    axes[0].imshow(result["gpu_front"], cmap=classes, vmin=0, vmax=2, interpolation="nearest")
    axes[0].set_title("GPU: front surface (red = patch, blue = sphere)")
    axes[1].imshow(result["reference_front"], cmap=classes, vmin=0, vmax=2, interpolation="nearest")
    axes[1].set_title("float64 reference")
    axes[2].imshow(result["disagree"], cmap="gray_r", interpolation="nearest")
    axes[2].set_title(f"disagreement: {result['disagree_count']} of {result['compared']} px "
                      f"({100 * result['agreement']:.3f}% agree)")
    for ax in axes:
        ax.set_axis_off()
    written["composite_check"] = save_figure(fig, out / "composite_check.png", dpi=110)
    steps.update()

    images = []
    for title, style in panels:
        pl, _, _ = composite_scene(window_size=(360, 270), style=style, sphere=False)
        images.append((title, pl.screenshot()))
        pl.close()
        steps.update()
    cols = 5
    rows = (len(images) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.6 * rows))
    for ax, (title, img) in zip(axes.ravel(), images):
        ax.imshow(img)
        ax.set_title(title, fontsize=10)
    for ax in axes.ravel():
        ax.set_axis_off()
    written["effects"] = save_figure(fig, out / "effects.png", dpi=110)
    path = out / "terrain.png"
    _terrain_figure(path)
    written["terrain"] = path
    steps.update()
    from .volume_figures import side_by_side_figure

    path = out / "volume.png"
    side_by_side_figure(path)
    written["volume"] = path
    steps.update()
    from .nurbs_demo import nurbs_figure

    written["nurbs"] = nurbs_figure(out / "nurbs.png", window=_scaled((520, 390), scale))
    steps.update()
    from .geometry_image_figures import pipeline_figure

    written["geometry_image"] = pipeline_figure(out / "geometry_image.png")
    steps.update()
    steps.close()
    return written


def _scaled(window, scale):
    return tuple(max(int(round(scale * w)), 16) for w in window)


def _terrain_figure(path):
    from scipy.ndimage import gaussian_filter

    from datasets_synthetic.dem_files import fractal_terrain
    from ..io import read_heights
    from ..plotting import Plotter

    heights = 400.0 + 300.0 * gaussian_filter(fractal_terrain(65, seed=7, hurst=0.9), 1.5, mode="wrap")
    grid = read_heights(heights, spacing=(60.0, 60.0), origin=(500_010.0, 5_100_020.0))
    fig, axes = pyplot().subplots(1, 3, figsize=(15, 4.6))
    for ax, scheme in zip(axes, ("linear", "C2", "C1")):
        pl = Plotter(off_screen=True, window_size=(600, 440))
        pl.set_background("white")
        actor = pl.add_terrain(grid, scheme, colormap="terrain", lights=2, reflection_lines=30)
        x0, x1, y0, y1 = actor.model.extent
        zlo, zhi = actor.model.zrange
        cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        pl.camera_position = [(cx - 0.5 * (x1 - x0), cy - 1.1 * (y1 - y0), zhi + 0.9 * (x1 - x0)), (cx, cy, zlo),
                              (0, 0, 1)]
        pl.reset_camera_clipping_range()
        ax.imshow(pl.screenshot())
        pl.close()
        ax.set_title(f"{scheme}: {actor.model.num_patches:,} patches, reflection lines", fontsize=10)
        ax.set_axis_off()
    fig.suptitle("65x65 DEM at UTM (500010, 5100020), every pixel ray-cast on the spline", fontsize=11)
    save_figure(fig, path)
