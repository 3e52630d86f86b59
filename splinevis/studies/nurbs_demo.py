"""The showcase's NURBS figure: zebra stripes and mean curvature of the Newell teapot's 32 patches [Crow1987],
per fragment, beside what a tessellated mesh gives (interpolated vertex normals; discrete curvature of the
mesh). Vertical reflection lines cross the teapot's G1 seams (rim to body, upper to lower body): the exact
picture shows the stripes kink there, which is the surface's, not the mesh's."""

from __future__ import annotations

import numpy as np

from .report import pyplot, save_figure

__all__ = ["nurbs_figure", "DEMO_CAMERA"]

DEMO_CAMERA = [(6.0, -7.5, 4.2), (0.2, 0.0, 1.4), (0.0, 0.0, 1.0)]
#: Share of the sampled |H| the colour scale spans: the median, so the body's gentle curvature shows (the
#: knob's neck and the spout's lip curve far more and saturate; the title states the true maximum).
CURVATURE_QUANTILE = 0.5


def _model():
    from datasets_synthetic.teapot import newell_teapot

    return newell_teapot()


def nurbs_figure(path, window=(520, 390), mesh_density=6):
    """Write the 2 x 2 figure to ``path``: mesh zebra | per-fragment zebra; mesh curvature | per-fragment
    curvature (same camera, same colour scale: the median of the surface's true |H|)."""
    import pyvista as pv

    from ..gl.mesh_effects import add_mesh_with_reflection_lines
    from ..nurbs.tessellate import tessellate
    from ..plotting import Plotter

    model = _model()
    mesh = tessellate(model, mesh_density)
    H = np.abs(model.curvature_samples(41)["H"])
    scale, top = float(np.nanquantile(H, CURVATURE_QUANTILE)), float(np.nanmax(H))
    zebra = {"reflection_lines": 14, "reflection_axis": (0.0, 0.0, 1.0)}

    def shot(draw):
        pl = Plotter(off_screen=True, window_size=window)
        pl.set_background("white")
        draw(pl)
        pl.camera_position = DEMO_CAMERA
        pl.reset_camera_clipping_range()
        img = pl.screenshot()
        pl.close()
        return img

    discrete = pv.PolyData(mesh.points, mesh.faces).curvature("mean")
    images = [
        (f"mesh, {mesh.n_cells:,} triangles: zebra", shot(lambda pl: add_mesh_with_reflection_lines(
            pl, mesh, 14, color=(0.85, 0.75, 0.6), axis=(0.0, 0.0, 1.0)))),
        (f"per fragment, {len(model)} patches: zebra", shot(lambda pl: pl.add_spline(model, lights=1, **zebra))),
        ("mesh: discrete mean curvature", shot(lambda pl: pl.add_mesh(
            mesh, scalars=-discrete, cmap="coolwarm", clim=(-scale, scale), show_scalar_bar=False))),
        ("per fragment: mean curvature", shot(lambda pl: pl.add_spline(model, output="curvature", curvature="mean",
                                                                       curvature_scale=scale))),
    ]
    fig, axes = pyplot().subplots(2, 2, figsize=(11, 8.4))
    for ax, (title, img) in zip(axes.ravel(), images):
        ax.imshow(img)
        ax.set_title(title, fontsize=10)
        ax.set_axis_off()
    fig.suptitle(f"NURBS, {model.source}: mean curvature colour range +-{scale:.3g} (median of the true |H|; "
                 f"maximum {top:.3g})", fontsize=11)
    save_figure(fig, path)
    return path
