"""The showcase's NURBS figure: zebra stripes and mean curvature of a multi-patch NURBS model, per fragment,
beside what a tessellated mesh gives (interpolated vertex normals; discrete curvature of the mesh)."""

from __future__ import annotations

import numpy as np

from .report import pyplot, save_figure

__all__ = ["nurbs_figure", "DEMO_CAMERA"]

DEMO_CAMERA = [(1.0, -1.75, 1.9), (1.0, 0.45, 0.1), (0.0, 0.0, 1.0)]


def _model():
    from datasets_synthetic.nurbs_models import hood

    from ..nurbs import NurbsModel
    from ..nurbs.operations import bezier_patches

    return NurbsModel([p for p, _ in bezier_patches(hood())], source="hood panel, 25 bicubic Bezier patches")


def nurbs_figure(path, window=(520, 390), mesh_density=2):
    """Write the 2 x 2 figure to ``path``: mesh zebra | per-fragment zebra; mesh curvature | per-fragment
    curvature (same camera, same colour scale: the surface's true |H| maximum)."""
    import pyvista as pv

    from ..gl.mesh_effects import add_mesh_with_reflection_lines
    from ..nurbs.tessellate import tessellate
    from ..plotting import Plotter

    model = _model()
    mesh = tessellate(model, mesh_density)
    scale = float(np.abs(model.curvature_samples(41)["H"]).max())
    zebra = {"reflection_lines": 12, "reflection_axis": (1.0, 0.0, 0.0)}

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
            pl, mesh, 12, color=(0.85, 0.75, 0.6), axis=(1.0, 0.0, 0.0)))),
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
    fig.suptitle(f"NURBS {model.source}: mean curvature colour range +-{scale:.3g} (true |H| maximum)", fontsize=11)
    save_figure(fig, path)
    return path
