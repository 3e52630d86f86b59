"""Figures of the geometry-image study (:mod:`splinevis.studies.geometry_image`) and of the showcase: the
pipeline from a mesh to a smooth surface [Losasso2003, Fig. 1 and 3], error against triangles, fairness, levels
of detail. Every render is offscreen (Mesa llvmpipe)."""

from __future__ import annotations

import numpy as np

from .report import pyplot, save_figure

__all__ = ["pipeline_figure", "accuracy_figure", "fairness_figure", "lod_figure", "reflection_row_figure", "render"]

CAMERA = [(5.0, -6.5, 4.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]


def render(add, camera=CAMERA, size=(360, 300)) -> np.ndarray:
    """An offscreen screenshot of the scene ``add(plotter)`` builds, seen from ``camera`` (zoomed to fit).

    >>> import pyvista as pv
    >>> render(lambda pl: pl.add_mesh(pv.Sphere()), size=(40, 30)).shape
    (30, 40, 3)
    """
    import splinevis

    pl = splinevis.Plotter(off_screen=True, window_size=size)
    pl.set_background("white")
    add(pl)
    pl.camera_position = camera
    pl.reset_camera()
    pl.camera.zoom(1.15)
    image = pl.screenshot()
    pl.close()
    return image


def _mesh(points, faces):
    import pyvista as pv

    return pv.PolyData(np.asarray(points, dtype=np.float64), faces=pv.CellArray.from_regular_cells(np.asarray(faces)))


def pipeline_figure(path, *, quick: bool = False, n: int = 65, stripes: int = 12):
    """Mesh -> sphere -> octahedron -> geometry image -> smooth surface -> reflection lines, for the bent blob (not
    star-shaped: central projection would fold it)."""
    from datasets_synthetic.closed_meshes import bent_blob

    from ..geometry_image.build import FOLD_LEVEL, geometry_image_from_mesh
    from ..geometry_image.image import image_uv, octahedral_to_sphere, sphere_to_octahedral
    from ..geometry_image.program import surface_mesh
    from ..geometry_image.sphere import spherical_parametrization, surface_points

    mesh = bent_blob(level=3 if quick else 4)
    smap = spherical_parametrization(mesh, name="bent blob")
    import warnings

    with warnings.catch_warnings():  # the folded fraction is in the title
        warnings.simplefilter("ignore")
        image, report = geometry_image_from_mesh(mesh, n, name="bent blob", sphere_map=smap)
    height = np.asarray(mesh.points)[:, 2]
    panels = []
    panels.append(("1. input mesh, %s triangles" % f"{mesh.n_cells:,}",
                   render(lambda pl: pl.add_mesh(mesh, color="tan", show_edges=True, edge_color="gray"))))
    R = report.orientation  # the sphere as the image samples it: rotated under the octahedron
    sphere = _mesh(smap.sphere @ R.T, smap.faces)
    sphere.point_data["z"] = height
    panels.append((f"2. on the sphere (stretch {report.stretch['l2']:.2f}, 0 flipped)",
                   render(lambda pl: pl.add_mesh(sphere, scalars="z", cmap="viridis", show_edges=True,
                                                 edge_color="gray", show_scalar_bar=False))))
    uv = sphere_to_octahedral(smap.sphere @ R.T)
    edges = np.unique(np.sort(np.concatenate([smap.faces[:, [0, 1]], smap.faces[:, [1, 2]], smap.faces[:, [2, 0]]]),
                              axis=1), axis=0)
    short = np.abs(uv[edges[:, 0]] - uv[edges[:, 1]]).max(axis=1) < 0.25  # not across the X-cut's borders
    M = 257
    heights = surface_points(smap, octahedral_to_sphere(image_uv(M)).reshape(-1, 3) @ R)[:, 2].reshape(M, M)
    panels.append(("3. octahedron unfolded (X-cut), mesh edges", ("domain", heights, uv, edges[short])))
    G = image.control
    lo, hi = G.reshape(-1, 3).min(axis=0), G.reshape(-1, 3).max(axis=0)
    panels.append((f"4. geometry image {n}x{n} (xyz as RGB)", ("image", (G - lo) / (hi - lo))))
    smooth = surface_mesh(image, 3)
    panels.append((f"5. smooth surface, level 3 ({smooth.n_cells:,} triangles)",
                   render(lambda pl: pl.add_geometry_image(image, level=3, lights=2))))
    panels.append(("6. reflection lines (exact normals)",
                   render(lambda pl: pl.add_geometry_image(image, level=3, reflection_lines=stripes))))
    plt = pyplot()
    fig, axes = plt.subplots(1, 6, figsize=(21, 4.2))
    for ax, (title, what) in zip(axes, panels):
        if isinstance(what, tuple) and what[0] == "domain":
            from matplotlib.collections import LineCollection

            _, h, uv_, e = what
            ax.imshow(h, origin="lower", extent=(-1, 1, -1, 1), cmap="viridis", interpolation="bilinear")
            ax.add_collection(LineCollection(uv_[e], colors="white", linewidths=0.2, alpha=0.6))
            ax.plot([-1, 0, 1, 0, -1], [0, 1, 0, -1, 0], color="k", lw=0.8)
            ax.set_xlim(-1, 1)
            ax.set_ylim(-1, 1)
            ax.set_aspect("equal")
        elif isinstance(what, tuple):
            ax.imshow(what[1], origin="lower", interpolation="nearest")
        else:
            ax.imshow(what)
        ax.set_title(title, fontsize=10)
        ax.set_xticks([])
        ax.set_yticks([])
    folds = report.folds or {}
    fold_text = ("no limit triangle folds over" if folds.get("folded", 1) == 0 else
                 "%.2g%% of the limit triangles fold over" % (100 * folds.get("fraction", report.folded)))
    fig.suptitle("Smooth geometry image of a bent blob [Losasso2003]: Hausdorff distance %.1e of the diagonal; %s "
                 "(level %d, the check's count; fairness %g)" % (report.distance["hausdorff"], fold_text,
                                                                  FOLD_LEVEL, report.fairness), fontsize=11)
    return save_figure(fig, path, dpi=90)


def accuracy_figure(path, rows):
    """Distance to the exact surface and normal error against triangles, one line per method (section b).

    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = [{"method": m, "triangles": t, "distance_max": 1.0 / t, "normal_rms_deg": 100.0 / t}
    ...         for m in ("input mesh", "geometry image 9x9") for t in (128, 512)]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     accuracy_figure(Path(d) / "a.png", rows).stat().st_size > 0
    True
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    for m in methods:
        rs = sorted((r for r in rows if r["method"] == m), key=lambda r: r["triangles"])
        t = [r["triangles"] for r in rs]
        style = "o-" if m.startswith("geometry image") else ("s--" if m != "input mesh" else "k*")
        axes[0].loglog(t, [r["distance_max"] for r in rs], style, label=m)
        axes[1].semilogx(t, [r["normal_rms_deg"] for r in rs], style, label=m)
    axes[0].set_ylabel("max distance to the exact surface (diagonals)")
    axes[1].set_ylabel("RMS normal error (degrees)")
    for ax in axes:
        ax.set_xlabel("triangles drawn")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=8)
    fig.suptitle("Star blob from a mesh: geometry image against subdivision of the mesh, measured where drawn")
    return save_figure(fig, path, dpi=100)


def fairness_figure(path, rows):
    """Distance to the input and normal error against the fairness weight (section d).

    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = [{"fairness": f, "hausdorff": 1e-3 * (1 + f), "normal_rms_deg": 1.0 / (1 + f)} for f in (0.0, 0.1, 1.0)]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     fairness_figure(Path(d) / "f.png", rows).stat().st_size > 0
    True
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    lam = [max(r["fairness"], 1e-4) for r in rows]
    ax.semilogx(lam, [r["hausdorff"] for r in rows], "o-", color="C0", label="Hausdorff to the input mesh")
    ax.set_xlabel("fairness weight (0 drawn at 1e-4)")
    ax.set_ylabel("Hausdorff distance (diagonals)", color="C0")
    ax2 = ax.twinx()
    ax2.semilogx(lam, [r["normal_rms_deg"] for r in rows], "s--", color="C3", label="RMS normal error")
    ax2.set_ylabel("RMS normal error (degrees)", color="C3")
    ax.set_title("Fairness trades distance for smooth normals")
    return save_figure(fig, path, dpi=100)


def lod_figure(path, image, rows, levels=None):
    """Renders at continuous levels from the octahedron up, with edges, and the distance against level.

    >>> import tempfile
    >>> from pathlib import Path
    >>> from splinevis.geometry_image.image import image_uv, octahedral_to_sphere
    >>> from splinevis.geometry_image.model import GeometryImage
    >>> gi = GeometryImage(octahedral_to_sphere(image_uv(9)), constrain=True)
    >>> rows = [{"level": -2.0, "distance_max": 0.1}, {"level": 0.0, "distance_max": 0.01}]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     lod_figure(Path(d) / "l.png", gi, rows, levels=[-2.0, 0.0]).stat().st_size > 0
    True
    """
    from ..geometry_image.program import min_level, surface_mesh

    lo = min_level(image.n)
    levels = levels or [lo, lo + 1.5, -1.0, 0.0, 0.5, 2.0]
    shots = []
    for lv in levels:
        m = surface_mesh(image, lv, backend="numpy")
        shots.append((lv, m.n_cells, render(lambda pl, m=m: pl.add_mesh(m, color="tan", show_edges=m.n_cells < 20000,
                                                                          edge_color="gray", smooth_shading=True),
                                            size=(300, 260))))
    plt = pyplot()
    fig = plt.figure(figsize=(19, 6.5))
    for i, (lv, cells, shot) in enumerate(shots):
        ax = fig.add_subplot(2, len(shots), i + 1)
        ax.imshow(shot)
        ax.set_title(f"level {lv:g}: {cells:,} triangles", fontsize=9)
        ax.axis("off")
    ax = fig.add_subplot(2, 1, 2)
    ax.semilogy([r["level"] for r in rows], [r["distance_max"] for r in rows], ".-")
    ax.set_xlabel("continuous level (negative: subsampled towards the octahedron)")
    ax.set_ylabel("max distance to the exact blob")
    ax.grid(True, which="both", alpha=0.3)
    return save_figure(fig, path, dpi=90)


def reflection_row_figure(path, shots, title: str):
    """One row of renders ``shots`` (``(title, image)`` pairs, the same camera for all) under ``title``: the real
    meshes of section (g), each surface with the same reflection lines.

    >>> import tempfile
    >>> from pathlib import Path
    >>> shots = [(f"panel {i}", np.full((20, 20, 3), 60 * i, np.uint8)) for i in range(3)]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     reflection_row_figure(Path(d) / "r.png", shots, "three panels").stat().st_size > 0
    True
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, len(shots), figsize=(4.6 * len(shots), 5.0), squeeze=False)
    for ax, (label, image) in zip(axes[0], shots):
        ax.imshow(image)
        ax.set_title(label, fontsize=10)
        ax.axis("off")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.94))  # room for the title above the panels' own
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
