"""The walkthrough pipeline: visibility ``V``, mesh builder ``T`` and renderer ``P`` as threads that hand over
their results without locks [Kumar1997, sec. 5].

**Stages.** Each frame the renderer ``P`` (the caller's thread) moves the camera, publishes it and draws the
newest mesh it has. The visibility worker ``V`` takes the newest published camera and picks a level per
super-surface (:func:`.select.select_levels`: frustum culling, back-patch culling, screen-space error). The
mesh builder ``T`` takes the newest selection and assembles one crack-free mesh of it
(:func:`.levels.assemble`), into arrays and a ``vtkCellArray`` it allocates anew. With ``dynamic=True`` the
super-surfaces whose level 0 projects to more than ``pixel_error`` pixels are tessellated finer by ``T``
(:class:`.dynamic.Refiner`: ``delta_0 / ratio**j`` with the ``j`` the selection asks, cached, assembled without
cracks beside any static level) [Kumar1997, sec. 2.2, 4.4]. For a new selection ``T`` first publishes the mesh
with the refined meshes it has cached (at once), then tessellates one bounded batch (the nearest needs first)
and publishes again; while some are pending it goes on without waiting for a new camera (incremental
refinement: the paper's "denser triangulation computed incrementally" as the user zooms in, sec. 6).

**Hand-over** [Kumar1997, sec. 5.2]. Every result is an immutable record written into *new* memory and
published by rebinding one attribute (``self._camera``, ``self._selection``, ``self._mesh``); a rebinding is
atomic in Python, and a reader that took the old reference keeps a consistent record (the old arrays are
not touched). So ``P`` never waits: it draws whichever mesh is newest, possibly built for a camera ``k``
frames earlier (the *mesh age*; the paper's ``T`` lags 2-3 frames). ``V`` and ``T`` sleep on an event when
there is nothing new (the paper's busy-wait would hold the interpreter lock); setting an event does not block.
``T`` skips the assembly when the new selection equals the one it last built (frame-to-frame coherence) and
republishes the same cells for the newer camera.

**Interactive window.** :meth:`Walkthrough.interact` opens the plotter's window; the user flies with the mouse
(VTK's interactor) and a repeating interactor timer calls :meth:`Walkthrough.tick` on the renderer's thread: it
publishes the user's camera to ``V`` when it moved and swaps in ``T``'s newest mesh. Closing the window stops the
workers. :meth:`Walkthrough.tick` works off screen too (the tests move the camera and call it).

**Sequential baseline.** ``threaded=False`` runs V, T and P one after the other in every frame (the same
code and the same skipping), the paper's "sequential implementation" [Kumar1997, sec. 6].

**Threads on this machine.** Python threads overlap only where the interpreter lock is released: numpy's
array kernels and VTK's rendering (measured: a pure-Python thread keeps running at about half speed during
``vtkRenderWindow.Render`` on two cores, so the lock is released there). Whether this pays is measured by the
walkthrough study (:mod:`splinevis.studies.walkthrough`), not assumed: the software rasterizer (Mesa
llvmpipe) itself renders on every core, so ``V`` and ``T`` compete with ``P``'s rasterizer threads for the
same two cores, and ``V`` (about 1 ms) and ``T`` (a few ms when the levels change) are small beside ``P``'s
rendering (tens of ms). Processes would avoid the interpreter lock but must copy (or share through shared
memory) each mesh of up to millions of indices per hand-over, for stages this small; threads share it for free.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np

from .select import select_levels

__all__ = ["Walkthrough", "camera_path", "view_proj_matrix"]


def view_proj_matrix(plotter) -> np.ndarray:
    """The 4x4 world-to-clip matrix (OpenGL depth range, column vectors) of a PyVista plotter's active camera
    at its window's aspect ratio (``vtkCamera.GetCompositeProjectionTransformMatrix``).

    Examples
    --------
    >>> import pyvista as pv
    >>> pl = pv.Plotter(off_screen=True, window_size=(40, 30))
    >>> pl.camera_position = [(0, 0, 5), (0, 0, 0), (0, 1, 0)]
    >>> M = view_proj_matrix(pl)
    >>> c = M @ [0.0, 0.0, 0.0, 1.0]  # the focal point projects to the centre of the view
    >>> M.shape, bool(abs(c[0]) < 1e-12 and abs(c[1]) < 1e-12 and c[3] > 0)
    ((4, 4), True)
    >>> pl.close()
    """
    w, h = plotter.window_size
    cam = plotter.renderer.GetActiveCamera()
    m = cam.GetCompositeProjectionTransformMatrix(float(w) / float(h), -1.0, 1.0)
    return np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)], dtype=np.float64)


def _smooth(t):
    return t * t * (3.0 - 2.0 * t)


def camera_path(bounds, frames: int, target=None) -> list:
    """A fly-through of ``frames`` camera positions ``[eye, focal point, view up]`` (z up) for a model with
    ``bounds`` (xmin, xmax, ymin, ymax, zmin, zmax): the first 60 % a low pass along x, 10 % of the diagonal
    above the model, looking ahead and down at its middle; then a close approach to ``target`` (default: the
    top of the model's centre), ending 3 % of the diagonal from it.

    Examples
    --------
    >>> path = camera_path((0, 10, 0, 10, 0, 1), 10)
    >>> len(path), path[0][2]
    (10, (0.0, 0.0, 1.0))
    >>> eye, focal, _ = path[-1]
    >>> round(float(np.linalg.norm(np.subtract(eye, focal))), 3)  # 3 % of the diagonal 14.177
    0.425
    """
    b = np.asarray(bounds, dtype=np.float64).reshape(6)
    lo, hi = b[0::2], b[1::2]
    D = float(np.linalg.norm(hi - lo))
    c = 0.5 * (lo + hi)
    frames = int(frames)
    if frames < 1:
        raise ValueError(f"frames must be >= 1, got {frames!r}.")
    n_pass = max(1, int(round(0.6 * frames)))
    path = []
    y_eye = lo[1] + 0.3 * (hi[1] - lo[1])
    z_eye = hi[2] + 0.1 * D
    for k in range(n_pass):
        t = k / max(n_pass - 1, 1)
        x = lo[0] - 0.1 * D + t * (hi[0] - lo[0] - 0.15 * D)
        eye = np.array([x, y_eye, z_eye])
        focal = np.array([x + 0.25 * D, c[1], lo[2] + 0.3 * (hi[2] - lo[2])])
        path.append((eye, focal))
    start_eye, start_focal = path[-1]
    target = np.array([c[0], c[1], hi[2]]) if target is None else np.asarray(target, dtype=np.float64).reshape(3)
    end_eye = target + 0.03 * D * np.array([-1.0, -1.0, 1.0]) / np.sqrt(3.0)
    n_close = frames - n_pass
    for k in range(1, n_close + 1):
        t = _smooth(k / n_close)
        path.append((start_eye + t * (end_eye - start_eye), start_focal + t * (target - start_focal)))
    return [(tuple(map(float, e)), tuple(map(float, f)), (0.0, 0.0, 1.0)) for e, f in path]


def _cells(triangles):
    """A new vtkCellArray of triangles (T, 3) sharing a new int64 copy."""
    import pyvista as pv

    tri = np.array(triangles, dtype=np.int64, copy=True).reshape(-1, 3)
    return pv.CellArray.from_regular_cells(tri), tri


def _clipping_range(boxes, eye):
    """Near and far distances that hold every super-surface box from ``eye``."""
    lo, hi = boxes[:, 0::2].min(axis=0), boxes[:, 1::2].max(axis=0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    far = float(np.linalg.norm(corners - eye, axis=1).max()) * 1.01
    gap = np.maximum(np.maximum(lo - eye, eye - hi), 0.0)
    near = max(0.99 * float(np.linalg.norm(gap)), 1e-4 * far)
    return near, far


class Walkthrough:
    """Fly a camera through a :class:`~splinevis.nurbs.lod.levels.LodModel` with the pipeline of the module
    docstring, drawing one mesh actor in ``plotter`` [Kumar1997, sec. 5].

    Parameters
    ----------
    lod : LodModel
    plotter : pyvista.Plotter
        Off-screen is fine; its window size gives the viewport height.
    threaded : bool
        Run ``V`` and ``T`` in their own threads (False: all stages in sequence each frame).
    pixel_error : float or None
        Screen-space error bound; None: no levels of detail (level 0 everywhere drawn).
    cull_frustum, cull_back : bool
        The two culling tests of :func:`.select.select_levels`.
    assemble : callable, optional
        ``assemble(lod, levels) -> (points, triangles, info)`` (default :func:`.levels.assemble`).
    color : str
        The mesh colour (shaded with the surface's exact vertex normals, ``LodModel.normals``).
    dynamic : bool or Refiner
        Dynamic tessellation finer than level 0 where the view needs it (:mod:`.dynamic`); a
        :class:`.dynamic.Refiner` sets its caps. Off by default: on this machine's two shared cores ``T``'s
        tessellation takes CPU from the software rasterizer while refinements are pending (measured in the
        example: 6.3 fps against 18.5 on 64 teapots at 1 px), so the static pipeline's numbers stay as they were
        unless it is asked for.
    closeup : CloseUp, optional
        Super-surfaces that fill the screen drawn exactly by the per-fragment program (:mod:`.closeup`), their
        mesh kept as a backstop; its ``update`` runs on the renderer's thread each frame and its statistics join
        the frame log. Off by default: an exact close-up costs about a second a frame on this CPU renderer.
    max_normal_error_deg : float or None
        Largest angle in degrees between the normals drawn and the surface's: each super-surface is drawn no coarser
        than its levels' proven normal bounds allow (``LodModel.normal_bounds``, :func:`.select.select_levels`; the
        frames count the super-surfaces drawn finer for it, ``normal_limited``, and those no level meets,
        ``normal_unmet``); not with ``dynamic`` (its finer tessellations bound positions only).

    Examples
    --------
    The torus at two levels, three frames of a still camera, in sequence and threaded: the same triangles.

    >>> import pyvista as pv
    >>> from splinevis.nurbs.exact import torus
    >>> from splinevis.nurbs.lod.levels import build_lod
    >>> lod = build_lod(torus(), 0.05, levels=2, progress=False)
    >>> path = [[(0.0, -4.0, 3.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]] * 3
    >>> drawn = []
    >>> for threaded in (False, True):
    ...     pl = pv.Plotter(off_screen=True, window_size=(64, 48))
    ...     frames = Walkthrough(lod, pl, threaded=threaded).fly(path, progress=False)
    ...     drawn.append([f["triangles"] for f in frames])
    ...     pl.close()
    >>> drawn[0] == drawn[1], drawn[0][0] > 0
    (True, True)
    """

    def __init__(self, lod, plotter, threaded: bool = True, pixel_error=1.0, *, cull_frustum: bool = True,
                 cull_back: bool = True, assemble=None, color: str = "tan", dynamic=False, closeup=None,
                 max_normal_error_deg=None):
        import pyvista as pv

        from .dynamic import Refiner

        if max_normal_error_deg is not None and (dynamic is not False or getattr(lod, "normal_bounds", None) is None):
            raise ValueError("max_normal_error_deg needs levels with proven normal bounds (build_lod's) and no dynamic "
                             "tessellation (its finer tessellations bound positions only).")
        if dynamic is not False and dynamic is not True and not isinstance(dynamic, Refiner):
            raise TypeError(f"dynamic must be a bool or a Refiner, got {type(dynamic).__name__}.")
        if dynamic is not False and assemble is not None:
            raise ValueError("dynamic tessellation draws with its own assembly: give assemble or dynamic, not both.")
        if dynamic is not False and pixel_error is None:
            raise ValueError("dynamic tessellation needs a pixel_error (None draws level 0 everywhere).")
        self.refiner = (dynamic if isinstance(dynamic, Refiner) else Refiner(lod)) if dynamic is not False else None
        if assemble is None:
            from .levels import assemble
        self.lod = lod
        self.plotter = plotter
        self.threaded = bool(threaded)
        self.pixel_error = pixel_error
        self.max_normal_error_deg = max_normal_error_deg
        self.cull_frustum = bool(cull_frustum)
        self.cull_back = bool(cull_back)
        self._assemble = assemble
        self._boxes = np.asarray(lod.boxes, dtype=np.float64)
        self.mesh = pv.PolyData(np.zeros((1, 3)))  # replaced by the first mesh (pyvista refuses empty ones)
        self.actor = plotter.add_mesh(self.mesh, color=color, reset_camera=False)
        if getattr(lod, "normals", None) is not None:  # the surface's exact vertex normals: smooth shading
            self.actor.prop.interpolation = "phong"
        self.closeup = closeup
        if closeup is not None:
            closeup.attach(plotter, lod, self.actor)
        self._points = None  # the points array the actor shows
        self._shown_cells = None
        self._camera = None  # (frame, eye, view_proj, height)
        self._selection = None  # (frame, levels, stats, select_ms, eye)
        # (frame, cells, triangles, points, levels, selection stats, select_ms, assemble_ms, normals, dynamic info)
        self._mesh = None
        self._workers = []
        self._tessellated = 0.0  # ms T spent tessellating, in all
        self._frame = -1  # the interactive mode's camera counter
        self._view = None  # the interactive mode's last camera position
        self._error = None
        self._stop = False
        self._wake_v = threading.Event()
        self._wake_t = threading.Event()

    # ---------------------------------------------------------------- the stages
    def _select(self, camera):
        frame, eye, M, H = camera
        t0 = time.perf_counter()
        extra = {} if self.refiner is None else {"finer_ratio": self.refiner.ratio,
                                                  "max_finer": self.refiner.max_steps}
        levels, stats = select_levels(self.lod, eye, M, H, self.pixel_error, self.cull_back,
                                      cull_frustum=self.cull_frustum, max_normal_deg=self.max_normal_error_deg, **extra)
        return frame, levels, stats, 1e3 * (time.perf_counter() - t0), eye

    def _build(self, selection, last, budget=None):
        """The mesh record for ``selection``; reuses ``last``'s cells when the levels (and finer steps) are
        unchanged and no refinement is pending."""
        frame, levels, stats, select_ms, eye = selection
        steps = stats.get("finer_steps") if self.refiner is not None else None
        if (last is not None and np.array_equal(last[4], levels) and not last[9]["pending"]
                and (steps is None or np.array_equal(last[9]["steps"], steps))):
            return (frame, last[1], last[2], last[3], levels, stats, select_ms, 0.0, last[8],
                    dict(last[9], tessellate_ms=0.0))
        t0 = time.perf_counter()
        if self.refiner is not None:
            points, normals, triangles, info = self.refiner.build(levels, steps, eye=eye, budget=budget)
        else:
            points, triangles, info = self._assemble(self.lod, levels)
            normals = getattr(self.lod, "normals", None)
        self._tessellated += float(info.get("tessellate_ms", 0.0))  # only T (or P in sequence) writes it
        if normals is not None and len(normals) != len(points):
            normals = None
        cells, tri = _cells(triangles)
        dyn = {"steps": steps, "refined": int(info.get("refined", 0)),
               "refined_triangles": int(info.get("refined_triangles", 0)),
               "tessellate_ms": float(info.get("tessellate_ms", 0.0)), "pending": int(info.get("pending", 0)),
               "capped": int(info.get("capped", 0)) + int(stats.get("finer_capped", 0))}
        return (frame, cells, tri.shape[0], points, levels, stats, select_ms, 1e3 * (time.perf_counter() - t0),
                normals, dyn)

    def _visibility_loop(self):
        done = -1
        try:
            while not self._stop:
                self._wake_v.wait()
                self._wake_v.clear()
                camera = self._camera
                if self._stop or camera is None or camera[0] == done:
                    continue
                self._selection = self._select(camera)
                done = camera[0]
                self._wake_t.set()
        except BaseException as exc:  # noqa: BLE001 - re-raised on the renderer's thread
            self._error = exc

    def _builder_loop(self):
        done = -1
        try:
            while not self._stop:
                self._wake_t.wait()
                self._wake_t.clear()
                selection, last = self._selection, self._mesh
                pending = last is not None and last[9]["pending"] > 0
                if self._stop or selection is None or (selection[0] == done and not pending):
                    continue
                if self.refiner is not None and selection[0] != done:
                    # the newest view at once with the meshes cached, then one batch of tessellation
                    last = self._mesh = self._build(selection, last, budget=0)
                self._mesh = self._build(selection, last)
                done = selection[0]
                if self._mesh[9]["pending"]:  # refine on without waiting for a new camera
                    self._wake_t.set()
        except BaseException as exc:  # noqa: BLE001
            self._error = exc

    # ---------------------------------------------------------------- the renderer P
    def _camera_for(self, frame, position):
        pl = self.plotter
        pl.camera_position = [tuple(position[0]), tuple(position[1]), tuple(position[2])]
        eye = np.asarray(position[0], dtype=np.float64)
        pl.camera.clipping_range = _clipping_range(self._boxes, eye)
        return frame, eye, view_proj_matrix(pl), int(pl.window_size[1])

    def _show(self, record):
        """Point the actor at ``record``'s mesh (no copy: new memory each time)."""
        if record is None or record[1] is self._shown_cells:
            return False
        if record[3] is not self._points:
            self.mesh.points = record[3]
            if record[8] is not None:
                self.mesh.point_data.active_normals = record[8]  # exact surface normals: smooth shading
            self._points = record[3]
        self.mesh.SetPolys(record[1])
        self.mesh.Modified()
        self._shown_cells = record[1]
        return True

    def _render(self):
        pl = self.plotter
        if hasattr(pl, "render_now"):
            pl.render_now()
            return
        if pl.render_window is None or getattr(pl, "_first_time", False):
            pl.show(auto_close=False)
        pl.render_window.Render()

    def fly(self, camera_path, frames_dir=None, progress: bool = True) -> list:
        """Render one frame per camera position ``[eye, focal point, view up]``; returns a dict per frame:
        ``frame``, ``time_ms`` (the renderer's whole frame), ``triangles``, ``visible`` and ``needs_finer``
        (super-surfaces of the mesh drawn, and those whose finest level exceeds the pixel error there),
        ``mesh_age`` (frames between the camera the drawn mesh was selected for and this one), ``new_mesh``,
        ``select_ms`` and ``assemble_ms`` (of the stages that made the drawn mesh; 0 assembly when the levels
        had not changed; the assembly includes the dynamic tessellation), ``upload_ms`` and ``render_ms``; of the
        dynamic tessellation (0 without): ``refined`` and ``refined_triangles`` (super-surfaces drawn finer than
        level 0 and their triangles), ``tessellate_ms`` (``T``'s time tessellating since the previous frame),
        ``finer_pending`` (drawn coarser than asked, being made) and ``finer_capped`` (where a cap binds);
        ``normal_limited`` and ``normal_unmet`` (super-surfaces drawn finer for ``max_normal_error_deg``, and met
        by no level: :func:`.select.select_levels`).
        ``frames_dir``: write ``frame_0000.png`` ... there.

        Before the first frame the mesh for the first camera is built and drawn once (not timed), in both
        modes, so that frame 0 shows the model and both modes start from the same state.

        Examples
        --------
        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import sphere
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(sphere(), 0.05, levels=2, progress=False)
        >>> pl = pv.Plotter(off_screen=True, window_size=(48, 36))
        >>> path = camera_path((-1, 1, -1, 1, -1, 1), 4)
        >>> frames = Walkthrough(lod, pl, threaded=False, dynamic=True).fly(path, progress=False)
        >>> [f["frame"] for f in frames], sorted(frames[0])[:4]
        ([0, 1, 2, 3], ['assemble_ms', 'finer_capped', 'finer_pending', 'frame'])
        >>> frames[-1]["refined"] > 0  # the close approach: finer than level 0 near the eye
        True
        >>> pl.close()
        """
        from tqdm.auto import tqdm

        path = list(camera_path)
        if not path:
            return []
        if frames_dir is not None:
            Path(frames_dir).mkdir(parents=True, exist_ok=True)
        self._prime(path[0])
        self._start()
        out = []
        tessellated = self._tessellated
        try:
            for i, position in enumerate(tqdm(path, desc="walkthrough", disable=not progress, unit="frame")):
                t0 = time.perf_counter()
                camera = self._camera_for(i, position)
                self._camera = camera
                if self.threaded:
                    if self._error is not None:
                        raise self._error
                    self._wake_v.set()
                else:
                    self._selection = self._select(camera)
                    self._mesh = self._build(self._selection, self._mesh)
                record = self._mesh
                t1 = time.perf_counter()
                new = self._show(record)
                cu = self.closeup.update(camera, record[4]) if self.closeup is not None else {}
                t2 = time.perf_counter()
                self._render()
                t3 = time.perf_counter()
                if frames_dir is not None:
                    self.plotter.screenshot(str(Path(frames_dir) / f"frame_{i:04d}.png"))
                dyn, t_ms, tessellated = record[9], self._tessellated - tessellated, self._tessellated
                out.append({"frame": i, "time_ms": 1e3 * (t3 - t0), "triangles": int(record[2]),
                            "visible": int(record[5]["visible"]), "needs_finer": int(record[5]["needs_finer"]),
                            "mesh_age": i - int(record[0]), "new_mesh": bool(new),
                            "select_ms": float(record[6]), "assemble_ms": float(record[7]),
                            "upload_ms": 1e3 * (t2 - t1), "render_ms": 1e3 * (t3 - t2),
                            "refined": dyn["refined"], "refined_triangles": dyn["refined_triangles"],
                            "tessellate_ms": t_ms, "finer_pending": dyn["pending"],
                            "finer_capped": dyn["capped"], "normal_limited": int(record[5].get("normal_limited", 0)),
                            "normal_unmet": int(record[5].get("normal_unmet", 0)), **cu})
        finally:
            self._halt()
        if self._error is not None:
            raise self._error
        return out

    # ---------------------------------------------------------------- workers and the interactive mode
    def _prime(self, position, frame=0, render=True):
        """Build and show the mesh of the first camera (in this thread, before any worker starts)."""
        first = self._camera_for(frame, position)
        self._camera = first
        self._selection = self._select(first)
        self._mesh = self._build(self._selection, None)
        self._show(self._mesh)
        if render:
            self._render()

    def _start(self):
        if not self.threaded or self._workers:
            return
        self._stop, self._error = False, None
        self._workers = [threading.Thread(target=self._visibility_loop, name="lod-V", daemon=True),
                         threading.Thread(target=self._builder_loop, name="lod-T", daemon=True)]
        for w in self._workers:
            w.start()
        if self._mesh is not None and self._mesh[9]["pending"]:
            self._wake_t.set()  # the first mesh left refinements pending: T goes on with them

    def _halt(self):
        self._stop = True
        self._wake_v.set()
        self._wake_t.set()
        for w in self._workers:
            w.join(timeout=60.0)
        self._workers = []
        self._wake_v.clear()
        self._wake_t.clear()

    def tick(self) -> bool:
        """One step of the interactive mode, on the renderer's thread: when the plotter's camera moved since the
        last tick, publish it to ``V`` (threaded; in sequence: select and build here), then show ``T``'s newest
        mesh and render if it is new. Returns whether a new mesh was shown. The first tick starts the workers
        (threaded) after building the first mesh; :meth:`close` stops them.

        Examples
        --------
        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import torus
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> lod = build_lod(torus(), 0.05, levels=2, progress=False)
        >>> pl = pv.Plotter(off_screen=True, window_size=(64, 48))
        >>> w = Walkthrough(lod, pl, threaded=False)
        >>> pl.camera_position = [(0.0, -6.0, 1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
        >>> w.tick(), w.tick()  # a new mesh for the first camera, then nothing new: the camera did not move
        (True, False)
        >>> w.visible()  # the whole torus
        16
        >>> pl.camera_position = [(2.0, -0.6, 0.1), (2.0, 1.0, 0.0), (0.0, 0.0, 1.0)]  # close to the tube
        >>> w.tick(), w.visible() < 16  # a new mesh: the super-surfaces out of view culled
        (True, True)
        >>> w.close(); pl.close()
        """
        pl = self.plotter
        view = tuple(tuple(float(x) for x in v) for v in pl.camera_position)
        if self._mesh is None:
            self._frame, self._view = 0, view
            self._prime(view, 0)
            self._start()
            return True
        if view != self._view:
            self._view = view
            self._frame += 1
            self._camera = self._camera_for(self._frame, view)
            if self.threaded:
                self._wake_v.set()
            else:
                self._selection = self._select(self._camera)
        if not self.threaded and self._selection is not None:
            self._mesh = self._build(self._selection, self._mesh)  # reused when nothing changed
        if self._error is not None:
            raise self._error
        new = self._show(self._mesh)
        if self.closeup is not None and self._camera is not None:
            new = self.closeup.update(self._camera, self._mesh[4])["closeup_switch"] or new
        if new:
            self._render()
        return new

    def visible(self) -> int:
        """Super-surfaces in the mesh shown now (culling and levels of the camera it was built for).

        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import sphere
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> pl = pv.Plotter(off_screen=True, window_size=(48, 36))
        >>> w = Walkthrough(build_lod(sphere(), 0.05, levels=1, progress=False), pl, threaded=False)
        >>> w.visible()  # nothing shown yet
        0
        >>> pl.close()
        """
        record = self._mesh
        return 0 if record is None or record[1] is not self._shown_cells else int(record[5]["visible"])

    def close(self):
        """Stop the worker threads (the interactive mode's; :meth:`fly` stops its own).

        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import sphere
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> pl = pv.Plotter(off_screen=True, window_size=(48, 36))
        >>> Walkthrough(build_lod(sphere(), 0.05, levels=1, progress=False), pl).close()
        >>> pl.close()
        """
        self._halt()
        if self.closeup is not None:
            self.closeup.detach()
        if self._error is not None:
            error, self._error = self._error, None
            raise error

    def interact(self, interval_ms: int = 30):
        """Open the plotter's window and let the user fly with the mouse; every ``interval_ms`` a repeating
        interactor timer calls :meth:`tick` (the camera to ``V``, ``T``'s newest mesh shown). Returns when the
        window is closed, the workers stopped. Needs an on-screen plotter (a display): ``RuntimeError`` otherwise.

        >>> import pyvista as pv
        >>> from splinevis.nurbs.exact import sphere
        >>> from splinevis.nurbs.lod.levels import build_lod
        >>> pl = pv.Plotter(off_screen=True, window_size=(48, 36))
        >>> try:
        ...     Walkthrough(build_lod(sphere(), 0.05, levels=1, progress=False), pl).interact()
        ... except RuntimeError as e:
        ...     print(str(e)[:38])
        interact needs an on-screen plotter (a
        >>> pl.close()
        """
        pl = self.plotter
        if pl.off_screen:
            raise RuntimeError("interact needs an on-screen plotter (a display); off screen, call tick() after each "
                               "camera move or fly() a path.")
        failure = []

        def on_timer(*_):
            if failure:
                return
            try:
                self.tick()
            except BaseException as exc:  # noqa: BLE001 - VTK would print and go on: stop and re-raise after
                failure.append(exc)
                pl.iren.interactor.TerminateApp()

        if not pl.camera_set:  # the start of the fly-through's path
            b = self._boxes
            bounds = np.ravel([[b[:, 2 * a].min(), b[:, 2 * a + 1].max()] for a in range(3)])
            pl.camera_position = camera_path(bounds, 2)[0]
        self._view = tuple(tuple(float(x) for x in v) for v in pl.camera_position)
        self._frame = 0
        self._prime(self._view, 0, render=False)  # the window's first render shows it
        self._start()
        pl.iren.add_observer("TimerEvent", on_timer)
        pl.iren.create_timer(int(interval_ms), repeating=True)
        try:
            pl.show(auto_close=False)
        finally:
            self._halt()
        if failure:
            raise failure[0]
        if self._error is not None:
            raise self._error
