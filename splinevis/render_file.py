"""One call from a user's file to a picture: ``splinevis render FILE`` and :func:`render_file`.

The file's family is found from its content (:func:`splinevis.check.detect.detect_family`), read and built as
``splinevis check`` does (the family's reader and defaults: a volume's isovalue from its histogram, a mesh's
geometry image size from its detail), drawn exact per pixel with an effect, and saved as a PNG. The camera is
PyVista's default for the drawn model (seen obliquely from above), moved in until the model fills most of the
picture.
"""

from __future__ import annotations

import time
from pathlib import Path

__all__ = ["render_file", "EFFECT_STYLES"]

#: ``--effect`` choices and the style each draws (curvature's full-colour value is set from the model's size).
EFFECT_STYLES = {
    "shaded": {"lights": 2, "specular": True},
    "zebra": {"lights": 1, "reflection_lines": 16},
    "isophotes": {"lights": 1, "isophotes": 10},
    "curvature": {"output": "curvature", "curvature": "mean"},
}


def render_file(path, out=None, *, effect: str = "shaded", isovalue: float | None = None, window=(1024, 768),
                family: str = "auto", supersample: int = 1) -> dict:
    """Render the file ``path`` with ``effect`` into ``out`` (default: ``<file name>.png`` in the current folder).

    Parameters
    ----------
    path : str or Path
        A terrain (GeoTIFF, USGS DEM, SRTM, ASCII grid, ...), a volume (VTK, MetaImage, NRRD, NIfTI, cube), a CAD
        file (3DM, IGES, STEP) or a closed triangle mesh (OBJ, OFF, PLY, STL).
    out : str or Path, optional
        The PNG to write.
    effect : {"shaded", "zebra", "isophotes", "curvature"}
        Two lights with a highlight, reflection lines, isophotes, or the mean curvature (blue-white-red, full
        colour at a radius of a twentieth of the model's diagonal).
    isovalue : float, optional
        The isosurface of a volume (default: the check's, from the histogram).
    window : (int, int)
        Picture size in pixels.
    family : {"auto", "terrain", "volume", "nurbs", "mesh"}
        Skip the detection.
    supersample : int
        ``k x k`` samples a pixel (``Plotter(anti_aliasing=k)``): smooth silhouettes, ``k^2`` times the time.

    Returns
    -------
    dict
        ``{"file", "family", "effect", "out", "seconds": {"read", "build", "draw"}}``.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> z = np.add.outer(np.linspace(0, 40, 12), np.linspace(0, 30, 16) ** 1.5 / 10)
    >>> _ = (d / "ramp.asc").write_text("ncols 16\\nnrows 12\\nxllcorner 0\\nyllcorner 0\\ncellsize 5\\n"
    ...                                 + "\\n".join(" ".join(f"{v:.2f}" for v in row) for row in z))
    >>> r = render_file(d / "ramp.asc", d / "ramp.png", effect="zebra", window=(160, 120))
    >>> r["family"], pathlib.Path(r["out"]).stat().st_size > 1000
    ('terrain', True)
    """
    import numpy as np

    from .check.run import get_judge
    from .read_any import family_of
    from .plotting import Plotter

    path = Path(path)
    if effect not in EFFECT_STYLES:
        raise ValueError(f"effect {effect!r} is not known; choose one of {', '.join(EFFECT_STYLES)}.")
    family = family_of(path, family)
    judge = get_judge(family)
    options = {} if isovalue is None else {"isovalue": float(isovalue)}
    seconds, findings = {}, []
    t = time.perf_counter()
    data = judge.read(path, options, findings)
    seconds["read"] = time.perf_counter() - t
    t = time.perf_counter()
    model = judge.build(data, options, findings)
    seconds["build"] = time.perf_counter() - t
    style = dict(EFFECT_STYLES[effect])
    if effect == "curvature":  # full colour at a radius of a twentieth of the diagonal
        probe = Plotter(off_screen=True, window_size=(8, 8))
        judge.add(probe, model, options)
        lo, hi = np.asarray(probe.bounds).reshape(3, 2).T
        probe.close()
        style["curvature_scale"] = 20.0 / max(float(np.linalg.norm(hi - lo)), 1e-300)
    t = time.perf_counter()
    pl = Plotter(off_screen=True, window_size=tuple(int(v) for v in window), anti_aliasing=int(supersample))
    pl.set_background((0.82, 0.82, 0.84) if effect == "curvature" else "white")  # flat (white) parts show
    judge.add(pl, model, dict(options, style=style))
    pl.reset_camera()
    pl.camera.zoom(1.4)  # PyVista's reset leaves a wide margin: the model fills most of the picture
    pl.reset_camera_clipping_range()
    out = Path(out) if out is not None else Path.cwd() / f"{path.name}.png"
    pl.screenshot(str(out))
    pl.close()
    seconds["draw"] = time.perf_counter() - t
    return {"file": str(path), "family": family, "effect": effect, "out": str(out), "seconds": seconds,
            "notes": [f.reason for f in findings]}
