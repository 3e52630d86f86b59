"""splinevis.Plotter: a pyvista.Plotter that also takes spline models, ray-cast per pixel.

Importing this module selects the headless OpenGL backend (:func:`splinevis.gl.headless.configure`)
before VTK makes its first window.
"""

from __future__ import annotations

import os

import numpy as np

from .effects import Style
from .gl import headless
from .plotting_options import _anti_aliasing_choice, _check_window_size, _style_from, split_read_options

headless.configure()

import pyvista as pv  # noqa: E402  (after configure: VTK reads the window class at first window)

from .gl.inject import SplineActor  # noqa: E402
from .gl.vtk_errors import capture_vtk_errors, raise_for_shader_errors  # noqa: E402

__all__ = ["Plotter", "companion_polydata"]

# Jupyter backends whose page renders with vtk.js (no GLSL of ours): why each is refused.
_BROWSER_BACKENDS = {"client": "renders in the browser with vtk.js", "html": "exports the scene to vtk.js in the browser",
                     "trame": "has a switch to rendering in the browser with vtk.js"}


def _can_serve() -> bool:
    """trame-pyvista is installed and an event loop runs in this thread (a Jupyter kernel's) to serve from."""
    import asyncio
    import importlib.util

    try:
        asyncio.get_running_loop()
    except RuntimeError:
        return False
    return importlib.util.find_spec("trame_pyvista") is not None


def companion_polydata(points, cells) -> pv.PolyData:
    """A :class:`pyvista.PolyData` of companion geometry: ``cells`` (m, 3) triangles, (m, 2) line segments or
    (m, 1) vertices of ``points`` (see :meth:`splinevis.nurbs.NurbsModel.companion_meshes`).

    >>> companion_polydata(np.eye(3), [[0, 1], [1, 2]]).n_lines
    2
    """
    cells = np.asarray(cells, dtype=np.int64)
    key = {3: "faces", 2: "lines", 1: "verts"}[cells.shape[1]]
    return pv.PolyData(np.asarray(points, dtype=np.float64), **{key: pv.CellArray.from_regular_cells(cells)})


def _scalar_bar_mapper(style: Style, program_range):
    """A mapper holding the colours ``style`` maps values to (its colormap over its ``scalar_range`` or the
    program's, or the curvature output's blue-white-red over +-``curvature_scale``), for PyVista's
    ``add_scalar_bar``; None when the style maps no value to a colour."""
    if style.output == "curvature":
        t = np.linspace(-1.0, 1.0, 256)[:, None]
        blue, red, white = np.array([0.23, 0.30, 0.75]), np.array([0.71, 0.02, 0.15]), np.ones(3)
        rgb = np.where(t < 0, white + (blue - white) * -t, white + (red - white) * t)  # glsl/lib/effects/curvature.glsl
        lut = pv.LookupTable()
        lut.values = np.column_stack([np.rint(255 * rgb), np.full(256, 255)]).astype(np.uint8)
        lo, hi = -style.curvature_scale, style.curvature_scale
    elif style.colormap is not None and style.output is None:
        lut = pv.LookupTable(cmap=style.colormap, n_values=256)
        lo, hi = style.scalar_range if style.scalar_range is not None else (program_range or (0.0, 1.0))
    else:
        return None
    mapper = pv.DataSetMapper()
    mapper.lookup_table = lut
    mapper.scalar_range = (float(lo), float(hi))
    return mapper


class Plotter(pv.Plotter):
    """A :class:`pyvista.Plotter` with :meth:`add_spline`; everything else is PyVista's.

    Parameters
    ----------
    anti_aliasing : False, int or {"ssaa", "fxaa", "msaa"}, default False
        How silhouettes are smoothed, for spline actors and meshes alike (the stripes of reflection lines,
        isophotes and highlight lines are filtered in the shader whatever this is, ``Style.antialias``):

        * ``False`` -- one sample per pixel: exact readback (depth, colours) and timings need single-sample
          buffers.
        * an int ``k >= 2`` -- supersampling: :meth:`screenshot` renders the whole scene (every actor, depth
          compositing intact) at ``k`` times the window's width and height and averages each ``k x k`` block,
          ``k^2`` samples a pixel at ``k^2`` times the fragments.
        * ``"ssaa"``, ``"fxaa"``, ``"msaa"`` -- PyVista's :meth:`~pyvista.Plotter.enable_anti_aliasing` (VTK's
          render passes; on the OSMesa/EGL builds of VTK, PyVista draws ``"fxaa"`` as ``"ssaa"``).

    Examples
    --------
    >>> import pyvista as pv
    >>> import splinevis
    >>> from splinevis.analytic import QuarticTrianglePatch
    >>> pl = splinevis.Plotter(off_screen=True, window_size=(320, 240))
    >>> actor = pl.add_spline(QuarticTrianglePatch.demo(), reflection_lines=10)
    >>> _ = pl.add_mesh(pv.Sphere(radius=0.3, center=(0, 0, 0.1)), color="steelblue")
    >>> image = pl.screenshot()
    >>> image.shape
    (240, 320, 3)

    Supersampled 2 x 2: the same picture size, smooth silhouettes.

    >>> pl = splinevis.Plotter(off_screen=True, window_size=(160, 120), anti_aliasing=2)
    >>> actor = pl.add_spline(QuarticTrianglePatch.demo(), reflection_lines=10)
    >>> pl.screenshot().shape
    (120, 160, 3)
    """

    _gl_checked = False
    _spline_actors: tuple = ()
    _supersample = 1

    def __init__(self, *args, anti_aliasing=False, **kwargs):
        if kwargs.get("window_size") is not None:
            _check_window_size(kwargs["window_size"])
        kind, factor = _anti_aliasing_choice(anti_aliasing)
        super().__init__(*args, **kwargs)
        self._supersample = factor
        if kind is None:
            self.disable_anti_aliasing()
            self.render_window.SetMultiSamples(0)  # before the first render: single-sample buffers
        else:
            self.enable_anti_aliasing(kind)
        self._spline_actors: list[SplineActor] = []
        self._gl_checked = False

    def screenshot(self, filename=None, transparent_background=None, return_img=True, window_size=None,
                   scale=None):
        """PyVista's :meth:`~pyvista.Plotter.screenshot`; with ``anti_aliasing=k`` the scene is rendered at
        ``k`` times the size and each ``k x k`` block averaged (rounded to the nearest 8-bit level).

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> pl = Plotter(off_screen=True, window_size=(40, 30), anti_aliasing=3)
        >>> _ = pl.add_spline(QuarticTrianglePatch.demo())
        >>> pl.screenshot().shape
        (30, 40, 3)
        """
        k = self._supersample
        if k == 1:
            return super().screenshot(filename, transparent_background=transparent_background, return_img=return_img,
                                      window_size=window_size, scale=scale)
        w, h = (int(v) for v in (window_size if window_size is not None else self.window_size))
        big = np.asarray(super().screenshot(None, transparent_background=transparent_background, return_img=True,
                                            window_size=(w * k, h * k), scale=scale))
        s = int(scale or 1)
        blocks = big.reshape(h * s, k, w * s, k, big.shape[-1]).astype(np.float64)
        img = pv.pyvista_ndarray(np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8))
        if filename:
            from PIL import Image

            Image.fromarray(np.asarray(img)).save(filename)
        return img if return_img else None

    def __del__(self):
        if "_initialized" not in self.__dict__:  # __init__ refused its arguments before pyvista set up
            return
        super().__del__()

    def add_spline(self, model, style: Style | None = None, *, name: str | None = None,
                   newton_iterations: int | None = None, program_options: dict | None = None,
                   program: str | None = None, max_error_px: float | None = None,
                   max_normal_error_deg: float | None = None, **style_options) -> SplineActor:
        """Add a spline model, drawn exactly per pixel by its program, beside any ordinary meshes.

        The model's program is found in the registry (:func:`splinevis.programs.program_for`).

        Parameters
        ----------
        model
            A spline model of any registered family (e.g. :class:`splinevis.analytic.QuarticTrianglePatch`).
        style : Style, optional
            Effects and their parameters; keyword options (``lights=2``, ``reflection_lines=12``, …)
            build or amend it. Only the declared effects are compiled in.
        name : str, optional
            Actor name (as in :meth:`pyvista.Plotter.add_actor`).
        newton_iterations : int, optional
            Fixed iteration count of the root finder, 1..8 (default: the program's own).
        program_options : dict, optional
            Options of the model's program (``splinevis.programs.program_for(model).options``, e.g.
            ``{"coefficients_in": "texture"}`` for the analytic patch).
        program : str, optional
            A registered program by name where several draw the model's type (``"nurbs_lod"``: levels of
            detail as one mesh, instead of the per-fragment ``"nurbs"``); default: the model's program.
        max_error_px : float, optional
            Draw it the cheapest way its program declares whose screen-space error stays below that many
            pixels for the current camera (:mod:`splinevis.choice`); the actor's ``choice`` says which. The
            choice is made again when the camera moves (:func:`splinevis.choice.add_model_by_accuracy`).
        max_normal_error_deg : float, optional
            With or without ``max_error_px``: the normals it is shaded with (reflection lines, isophotes) stay
            within that many degrees of the spline's exact normals (a mesh whose normal error is proven that
            small, or an exact renderer).

        Returns
        -------
        SplineActor
            Holds the VTK actor (``.actor``), the assembled GLSL (``.assembled``) and, after the first
            render, the compiled sources (``.program_sources``).

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> actor = pl.add_spline(QuarticTrianglePatch.demo(), lights=2, reflection_lines=8,
        ...                       program_options={"roots": "paper"})
        >>> actor.program.name, sorted(actor.style.effect_set()), actor.spec.defines["SV_ROOTS_PAPER"]
        ('analytic_patch', ['antialias', 'lights', 'reflection_lines'], True)
        >>> pl.add_spline(QuarticTrianglePatch.demo(), reflection_line=8)
        Traceback (most recent call last):
        TypeError: unknown effect or style option 'reflection_line' (did you mean 'reflection_lines'?); known: ...
        >>> pl.close()
        """
        from .programs import get, program_for

        st = _style_from(style, style_options)
        if max_error_px is not None or max_normal_error_deg is not None:
            from .choice import add_model_by_accuracy

            return add_model_by_accuracy(self, model, st, max_error_px, name=name, newton_iterations=newton_iterations,
                                         program_options=program_options, program=program,
                                         max_normal_error_deg=max_normal_error_deg)
        program = program_for(model) if program is None else get(program)
        if not isinstance(model, (program.model_type, str, os.PathLike) + tuple(program.converts)):
            raise TypeError(f"program {program.name!r} draws {program.model_type.__name__}, not {type(model).__name__}.")
        if not isinstance(model, program.model_type):  # a type the program converts (SplineProgram.converts)
            model = program.model_from(model)
        built = program.make(model, st, newton_iterations=newton_iterations, **(program_options or {}))
        if program.kind in ("passes", "mesh"):  # the program made an ordinary dataset: a mesh with the effects
            from .gl.mesh_effects import add_mesh_with_effects

            actor = add_mesh_with_effects(self, built, st, name=name)
            actor.model, actor.program = model, program
            return actor
        spline = SplineActor(built, st, self.renderer, kind=program.kind)
        spline.model = model
        spline.program = program
        self.add_actor(spline.actor, name=name, reset_camera=True)
        bar = _scalar_bar_mapper(st, built.uniforms.get("sv_scalar_range"))
        if bar is not None:
            self.mapper = bar  # add_scalar_bar() with no mapper shows this actor's colours, as after add_mesh
        self._spline_actors.append(spline)
        spline.companions = self._add_companions(model, st, name)
        return spline

    def _add_companions(self, model, style, name) -> list:
        """Draw a model's plain geometry (``model.companion_meshes()``: a CAD file's mesh objects, curves and
        points) as ordinary smooth-shaded meshes in the style's colour, and dark lines and points; returns their
        actors (``SplineActor.companions``)."""
        actors = []
        for k, (label, points, cells) in enumerate(getattr(model, "companion_meshes", lambda: ())()):
            surface = np.shape(cells)[1] == 3  # curves and points dark and unlit, as CAD programs draw them
            actors.append(self.add_mesh(companion_polydata(points, cells), reset_camera=True,
                                        color=style.color if surface else "#202020", smooth_shading=surface,
                                        lighting=surface, line_width=2, point_size=5,
                                        name=None if name is None else f"{name} mesh {k} ({label})"))
        return actors

    def add_terrain(self, heights, scheme: str = "C1", style: Style | None = None, *, read_options: dict | None = None,
                    presmooth: int = 0, max_error_px: float | None = None, max_normal_error_deg: float | None = None,
                    **options):
        """Build a terrain spline from height data and add it (see :meth:`add_spline` for ``options``).

        ``max_error_px``: draw it the cheapest way whose screen-space error stays below that many pixels for
        the current camera (set before the call; else the camera fitted to the terrain): a mesh of the spline
        sampled k x k per cell (smallest k with a proven bound below it) or the exact ray cast
        (:mod:`splinevis.choice`, ``docs/terrain-schemes.md``). The actor's ``renderer_choice`` says which, with
        the error and the alternatives; a nonpositive or non-finite value raises ValueError.

        ``presmooth`` > 0 smooths noisy heights first with that many GPU passes of a binomial filter
        (:func:`splinevis.terrain.prefilter.smooth_heights`).

        ``heights`` is anything :func:`splinevis.io.read_heights` reads (2-D array, pyvista grid, VTK
        file, USGS DEM, GeoTIFF) or a :class:`~splinevis.io.HeightGrid`; ``scheme`` one of
        ``linear, C0, C1, C2, C2-cubic``. ``spacing=`` and ``origin=`` go to the reader given plainly (as
        ``pv.wrap`` takes them) or in ``read_options``, with or without ``max_error_px``; ``order=`` is a
        volume's and raises TypeError saying the array's one reading (``heights[j, i]``, rows along y). Returns
        the :class:`SplineActor`; its ``model`` attribute is the :class:`~splinevis.terrain.TerrainSpline`.

        Examples
        --------
        >>> import numpy as np
        >>> import splinevis
        >>> z = np.add.outer(np.sin(np.linspace(0, 3, 33)), np.cos(np.linspace(0, 3, 33)))
        >>> pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
        >>> actor = pl.add_terrain(z, "C2", read_options={"spacing": (0.1, 0.1)}, colormap="terrain")
        >>> actor.model.num_patches
        2048
        """
        read_options, options = split_read_options("terrain", read_options, options)
        if max_error_px is not None or max_normal_error_deg is not None:
            from .choice import add_by_accuracy

            return add_by_accuracy(self, "terrain", (heights, scheme, presmooth), read_options, style, options,
                                   max_error_px, style_from=_style_from, max_normal_error_deg=max_normal_error_deg)
        return self._add_from("terrain", (heights, scheme, presmooth), read_options, style, options)

    def add_terrain_store(self, store, box=None, **options):
        """Add the tiles of a terrain store (:mod:`splinevis.outofcore`) that the camera (or ``box``) sees, at
        the finest level that fits (:func:`splinevis.outofcore.render.add_terrain_store`: ``max_cells``,
        ``level`` and the options of :meth:`add_spline`). ``actor.store_view`` tells the level drawn.

        Examples
        --------
        >>> import tempfile
        >>> import numpy as np
        >>> from splinevis.outofcore import write_terrain_store
        >>> s = write_terrain_store(tempfile.mkdtemp() + "/t.zarr", np.eye(33), "C1", chunks=8, progress=False)
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> pl.add_terrain_store(s, (0.0, 10.0, 0.0, 10.0, -1.0, 2.0)).store_view.tiles.tolist()
        [[0, 0], [0, 1], [1, 0], [1, 1]]
        >>> pl.close()
        """
        from .outofcore.render import add_terrain_store

        return add_terrain_store(self, store, box, **options)

    def add_isosurface_store(self, store, isovalue, box=None, **options):
        """Add the isosurface ``s = isovalue`` of the bricks of a volume store (:mod:`splinevis.outofcore`) that
        hold it and that the camera (or ``box``) sees, at the finest level that fits
        (:func:`splinevis.outofcore.render_volume.add_volume_store`: ``max_cubes``, ``level`` and the options
        of :meth:`add_spline`). ``actor.store_view`` tells the level and bricks drawn.

        Examples
        --------
        >>> import tempfile
        >>> import numpy as np
        >>> from splinevis.outofcore import write_volume_store
        >>> z, y, x = np.mgrid[0:16, 0:16, 0:16].astype(float)
        >>> s = write_volume_store(tempfile.mkdtemp() + "/v.zarr", x, chunks=8, progress=False)
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> pl.add_isosurface_store(s, 4.5, (0.0, 15.0, 0.0, 5.0, 0.0, 15.0)).store_view.bricks.tolist()
        [[0, 0, 0], [1, 0, 0]]
        >>> pl.close()
        """
        from .outofcore.render_volume import add_volume_store

        return add_volume_store(self, store, isovalue, box, **options)

    def add_isosurface(self, volume, isovalue: float, scheme: str = "quadratic", style: Style | None = None, *,
                       read_options: dict | None = None, newton_iterations: int = 6, culling: bool = True,
                       max_error_px: float | None = None, max_normal_error_deg: float | None = None,
                       prefilter: str = "none", padding: str = "linear",
                       **options):
        """Ray-cast the isosurface ``s = isovalue`` of a trivariate spline of volume data [Kalbe2008].

        ``max_error_px``: draw it the cheapest way whose screen-space error stays below that many pixels for
        the current camera (set before the call; else the camera fitted to the volume): marching cubes of the
        spline sampled k times per cube (smallest k whose estimated error is below it) or the ray cast
        (:mod:`splinevis.choice`); the actor's ``renderer_choice`` says which. Nonpositive or non-finite
        values raise ValueError.

        ``volume`` is a :class:`~splinevis.volume.VolumeSpline`, a :class:`~splinevis.io.VolumeGrid`, or
        anything :func:`splinevis.io.read_volume` reads (3-D array, pyvista ImageData, .vti/.nrrd/.mha/...
        file); ``scheme`` ``"quadratic"`` or ``"cubic"``, ``prefilter`` ``"none"`` (the paper's quasi-interpolant),
        ``"local"`` (reproduces quadratics: values of order 3) or ``"interpolate"`` (cubic: the spline
        interpolates the samples) and ``padding`` ``"linear"``, ``"quadratic"`` or ``"cubic"`` (order 2 gradients up
        to the boundary) choose the spline (:class:`~splinevis.volume.VolumeSpline`; all ignored for a
        VolumeSpline). ``culling``: hierarchical
        view-frustum culling of the proxies by the octree before every frame (``actor.culler``). Program options
        (``encoding``, ``roots``) go in ``program_options``; ``order``, ``spacing`` and ``origin`` go to the
        reader, given plainly or in ``read_options``, with or without ``max_error_px``; other keywords are
        effects (see :meth:`add_spline`). An isovalue outside the data's range (an empty isosurface) raises ValueError
        giving the range. A volume on a rotated orthogonal lattice (``VolumeGrid.direction``, e.g. a Gaussian
        cube file) is drawn in its true frame (the actor's user matrix; culled in its lattice frame). Returns the
        :class:`SplineActor`; its ``model`` is the :class:`~splinevis.volume.isosurface.Isosurface`.

        Examples
        --------
        >>> import numpy as np
        >>> import splinevis
        >>> z, y, x = np.mgrid[-1:1:24j, -1:1:24j, -1:1:24j]
        >>> pl = splinevis.Plotter(off_screen=True, window_size=(200, 150))
        >>> actor = pl.add_isosurface(np.sqrt(x**2 + y**2 + z**2), 0.7, read_options={"spacing": (2 / 23,) * 3})
        >>> len(actor.model.relevant.cubes) > 0
        True
        """
        read_options, options = split_read_options("isosurface", read_options, options)
        if max_error_px is not None or max_normal_error_deg is not None:
            from .choice import add_by_accuracy

            return add_by_accuracy(self, "isosurface", (volume, isovalue, scheme, prefilter, padding), read_options, style,
                                   dict(options, newton_iterations=newton_iterations), max_error_px,
                                   style_from=_style_from, add_options={"culling": culling},
                                   max_normal_error_deg=max_normal_error_deg)
        return self._add_from("isosurface", (volume, isovalue, scheme, prefilter, padding), read_options, style,
                              dict(options, newton_iterations=newton_iterations), {"culling": culling})

    def _add_from(self, program_name, args, read_options, style, options, add_options=None):
        """Build a model of the registered program ``program_name`` from user data, add it, run its hook."""
        from .programs import get

        program = get(program_name)
        actor = self.add_spline(program.model_from(*args, **(read_options or {})), style, **options)
        if program.on_add is not None:
            program.on_add(actor, self, **(add_options or {}))
        return actor

    def add_nurbs(self, model, style: Style | None = None, **options):
        """Draw a NURBS model evaluated per fragment [Kanai2007] (see :meth:`add_spline` for ``options``).

        ``model`` is a :class:`~splinevis.nurbs.NurbsModel`, a :class:`~splinevis.nurbs.NurbsSurface`, a list
        of surfaces or a file :func:`splinevis.io.read_nurbs` reads (.3dm, .igs, .stp, .g2, .json, .bpt).
        Returns the :class:`SplineActor`; its ``model`` is the NurbsModel.

        Examples
        --------
        >>> from splinevis.nurbs.exact import torus
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> actor = pl.add_nurbs(torus(), reflection_lines=8)
        >>> actor.model.names, bool(pl.screenshot().std() > 10)
        (('torus',), True)
        >>> pl.close()
        """
        return self._add_from("nurbs", (model,), None, style, options)

    def add_geometry_image(self, surface, style: Style | None = None, *, n="auto", level: float = 3.0, fairness="auto",
                           displacement=None, backend="gpu", max_error_px=None, max_normal_error_deg=None, **options):
        """Draw a closed genus-0 surface as a smooth geometry image [Losasso2003]: one bicubic B-spline on an
        octahedral image, subdivided by GPU passes to the continuous ``level`` of detail, with exact normals.

        ``surface`` is a :class:`~splinevis.geometry_image.GeometryImage`, or a closed genus-0 triangle mesh (pyvista
        PolyData or any file pyvista reads), parametrized on the sphere and fitted with an ``n x n`` image
        (``n="auto"``: the smallest of 33, 65, 129, 257 within 0.5 % of the diagonal, measured, or, where it folds,
        one twice as fine from a map nearer conformal; warnings of folds and lost detail reach the caller) with ``fairness`` ("auto": 0.1, stronger while the
        surface folds, :func:`splinevis.geometry_image.build.geometry_image_from_mesh`) first (a mesh that is not
        closed, manifold, connected and of genus 0 raises :class:`splinevis.errors.MeshTopologyError` saying which
        check failed and where). ``displacement``: a scalar map on the output grid
        (:func:`splinevis.geometry_image.program.displacement_map`); ``backend="numpy"`` subdivides with the float64
        twin. Other keywords are effects (see :meth:`add_spline`); reflection lines, isophotes and curvature use the
        surface's exact normals and curvature. ``max_error_px``, ``max_normal_error_deg``: the level is chosen
        (:func:`.geometry_image.renderers.add_by_accuracy`). Returns the vtkActor of the mesh.

        Examples
        --------
        >>> from datasets_synthetic.closed_meshes import star_blob
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> actor = pl.add_geometry_image(star_blob(level=2), n=17, level=1, reflection_lines=8)
        >>> actor.GetMapper().GetInput().GetNumberOfPoints(), bool(pl.screenshot().std() > 10)
        (1089, True)
        >>> pl.close()
        """
        from .geometry_image.renderers import add_by_accuracy
        from .programs import get
        model = get("geometry_image").model_from(surface, n, fairness=fairness)
        if max_error_px is not None or max_normal_error_deg is not None:
            return add_by_accuracy(self, model, style, options, max_error_px, max_normal_error_deg, displacement, backend)
        return self.add_spline(model, style, program_options={"level": level, "displacement": displacement,
                                                              "backend": backend}, **options)

    def add_walkthrough(self, model, max_error_px: float = 1.0, *, delta: float | None = None, levels: int = 4,
                        threaded: bool = False, progress: bool = False, **options):
        """Levels of detail of a large NURBS model within ``max_error_px`` pixels of the surface, chosen per
        super-surface every frame [Kumar1997]: returns the :class:`~splinevis.nurbs.lod.pipeline.Walkthrough`,
        whose ``fly(camera_path)`` renders a path, ``interact()`` opens the window. ``model``: a NurbsModel (or
        surface), levels built with bounds ``delta * 4**l`` (default ``delta``: a thousandth of the model's size),
        or a ``LodModel``; ``options`` go to the Walkthrough (``dynamic``, ``closeup``, ``color``, ...).

        >>> from splinevis.nurbs.exact import torus
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> walk = pl.add_walkthrough(torus(), levels=2)
        >>> frames = walk.fly([[(0.0, -4.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]] * 2, progress=False)
        >>> frames[-1]["triangles"] > 0
        True
        >>> pl.close()
        """
        from .nurbs.lod.bezier import bezier_set
        from .nurbs.lod.levels import LodModel, build_lod
        from .nurbs.lod.pipeline import Walkthrough

        if not isinstance(model, LodModel):
            step = 1e-3 * bezier_set(model).size if delta is None else float(delta)
            model = build_lod(model, step, levels=levels, progress=progress)
        return Walkthrough(model, self, threaded=threaded, pixel_error=max_error_px, **options)

    def show(self, *args, jupyter_backend=None, **kwargs):
        """PyVista's :meth:`~pyvista.Plotter.show`. In Jupyter our programs render on the server: the ``static``
        backend (a picture) and ``server`` (trame streams the pictures VTK renders here:
        :mod:`splinevis.gl.trame_view`; the default in a Jupyter kernel when trame-pyvista is installed) show them.
        ``client`` and ``html`` hand the scene to vtk.js in the browser, which knows nothing of our GLSL and would
        draw the proxies, and ``trame`` offers a switch to it, so they are refused (a spline-free scene may still
        use them: draw it with ``pyvista.Plotter``).

        >>> pl = Plotter(off_screen=True, window_size=(32, 24))
        >>> pl.show(jupyter_backend="client")
        Traceback (most recent call last):
        ValueError: jupyter_backend='client' renders in the browser with vtk.js, which drops splinevis's GLSL (the splines would show as their proxy boxes); use jupyter_backend='static' (a picture rendered here) or 'server' (trame, rendered here and streamed).
        """
        backend = jupyter_backend if jupyter_backend is not None else pv.global_theme.jupyter_backend
        backend = backend.lower() if isinstance(backend, str) else backend
        if backend in _BROWSER_BACKENDS:
            raise ValueError(f"jupyter_backend={backend!r} {_BROWSER_BACKENDS[backend]}, which drops splinevis's GLSL "
                             "(the splines would show as their proxy boxes); use jupyter_backend='static' (a picture "
                             "rendered here) or 'server' (trame, rendered here and streamed).")
        if self.notebook and (backend == "server" or (backend is None and _can_serve())):
            from .gl import trame_view

            jupyter_backend = trame_view.register()
        return super().show(*args, jupyter_backend=jupyter_backend, **kwargs)

    def render(self) -> None:
        """Render; a GLSL compile or link error raises :class:`splinevis.errors.ShaderCompileError`.

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> actor = pl.add_spline(QuarticTrianglePatch.demo())
        >>> actor.program_sources
        {}
        >>> pl.show(auto_close=False)  # the first frame; later ones: pl.render()
        >>> pl.render()
        >>> sorted(actor.program_sources), len(actor.program_ids)  # compiled once
        (['fragment', 'vertex'], 1)
        >>> pl.close()
        """
        with capture_vtk_errors() as cap:
            super().render()
        self._after_render(cap.text)

    def render_now(self) -> None:
        """Render the window immediately and wait for the GL pipeline (what benchmarks time).

        Examples
        --------
        No :meth:`show` is needed first: the first call opens the window and compiles the programs.

        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> actor = pl.add_spline(QuarticTrianglePatch.demo())
        >>> pl.render_now()
        >>> "sv_surface_hit" in actor.program_sources["fragment"]
        True
        >>> pl.close()
        """
        if self._first_time:
            self.show(auto_close=False)
        with capture_vtk_errors() as cap:
            self.render_window.Render()
            self.render_window.WaitForCompletion()
        self._after_render(cap.text)

    def _after_render(self, text: str) -> None:
        if "vtkShaderProgram" in text:
            # Map line numbers back to glsl/ files through the actor whose block is in the failed source.
            owner = next((s.assembled for s in self._spline_actors if s.assembled.text.splitlines()[0] in text), None)
            raise_for_shader_errors(text, owner)
        if not self._gl_checked and self.render_window is not None and not self._first_time:
            headless.check_render_window(self.render_window)
            self._gl_checked = True

    def depth_buffer(self) -> np.ndarray:
        """Window depth in [0, 1] per pixel, (H, W), row 0 at the top like :meth:`screenshot`.

        Read straight from the framebuffer (pyvista's ``get_image_depth`` would reset the clipping range); a
        window that was never rendered is rendered first (its framebuffer would hold garbage).

        Examples
        --------
        >>> from splinevis.analytic import QuarticTrianglePatch
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> _ = pl.add_spline(QuarticTrianglePatch.demo())
        >>> _ = pl.screenshot()
        >>> depth = pl.depth_buffer()
        >>> depth.shape, float(depth[0, 0]), bool(depth.min() < 1.0)  # background 1, the patch nearer
        ((48, 64), 1.0, True)
        >>> pl.close()
        """
        if self._first_time:
            self.render_now()
        w, h = self.window_size
        from vtkmodules.vtkCommonCore import vtkFloatArray

        arr = vtkFloatArray()
        self.render_window.GetZbufferData(0, 0, w - 1, h - 1, arr)
        from vtkmodules.util.numpy_support import vtk_to_numpy

        return vtk_to_numpy(arr).reshape(h, w)[::-1].astype(np.float64)

    def camera_matrix(self) -> np.ndarray:
        """(4, 4) float64 world -> normalized device coordinates of the active camera at this window's
        aspect ratio (the matrix VTK's shaders use, in double precision).

        Examples
        --------
        >>> pl = Plotter(off_screen=True, window_size=(64, 48))
        >>> pl.camera_position = [(0.0, 0.0, 5.0), (1.0, 2.0, 0.0), (0.0, 1.0, 0.0)]
        >>> m = pl.camera_matrix()
        >>> clip = m @ [1.0, 2.0, 0.0, 1.0]  # the focal point projects to the centre of the window
        >>> m.shape, (clip[:2] / clip[3]).round(12) + 0.0
        ((4, 4), array([0., 0.]))
        >>> pl.close()
        """
        w, h = self.window_size
        cam = self.renderer.GetActiveCamera()
        m = cam.GetCompositeProjectionTransformMatrix(w / h, -1, 1)
        return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
