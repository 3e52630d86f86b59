"""``splinevis check`` for height data: is the file read right, and how far is the spline from its samples?

* read: :func:`splinevis.io.read_heights`, with ``fill="nearest"`` when the file has nodata (a WARN says how
  much was filled: the filled area is drawn as flat continuations, not data).
* baseline: what terrain users draw today, the grid's samples as a bilinear mesh (``pyvista``'s
  ``warp_by_scalar`` of the image), in the same metric frame.
* accuracy, two figures:

  - *reader against the file*: every valid sample of the file, read independently with rasterio/GDAL (pixel
    centres from its geotransform, values from its band, its nodata mask), compared with the HeightGrid at the
    same position (bilinear interpolation of the grid after a transform into its CRS when the reader
    reprojected degrees to metres). A grid that equals the file's lattice must match it exactly (a sample one
    row off is a FAIL); after reprojection the difference is bounded by what bilinear interpolation can change
    at a sample, the largest height step between the sample and its 8 neighbours
    (``reader_excess`` > 0 is a FAIL).
  - *spline against the samples*: ``|s(x_ij) - z_ij|`` at every grid node, max and RMS, relative to the relief:
    the quartic quasi-interpolant [Reis2008, sec. IV] smooths, it does not interpolate; reported, not judged.

Why our own code: rasterio does the reading; this module only pairs the two readings.
"""

from __future__ import annotations

import numpy as np

from ..check.judge import FamilyJudge, Finding

__all__ = ["JUDGE"]


def _read(path, options, findings):
    from ..io import read_heights

    kw = {k: options[k] for k in ("scalars", "band", "crs", "source_crs") if k in options}
    grid = read_heights(path, fill="nearest", **kw)
    return grid


def _build(grid, options, findings):
    from .model import TerrainSpline

    return TerrainSpline.from_heights(grid, options.get("scheme", "C1"))


def _baseline(grid, model, options, findings):
    import pyvista as pv

    ny, nx = grid.shape
    img = pv.ImageData(dimensions=(nx, ny, 1), spacing=(*grid.spacing, 1.0), origin=(*grid.origin, 0.0))
    img.point_data["height"] = np.ascontiguousarray(grid.heights).ravel()
    warped = img.warp_by_scalar("height", normal=(0.0, 0.0, 1.0))
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return pv.PolyData.from_regular_faces(np.asarray(warped.points), tris)


def _file_samples(path, band: int = 1):
    """(x, y, z, crs) of the file's valid samples (pixel centres), read with rasterio alone; None when GDAL
    cannot open the file."""
    import rasterio

    try:
        ds = rasterio.open(path)
    except rasterio.errors.RasterioIOError:
        return None
    with ds:
        z = ds.read(band, masked=True)
        rows, cols = np.nonzero(~np.ma.getmaskarray(z))
        xs, ys = rasterio.transform.xy(ds.transform, rows, cols, offset="center")
        return (np.asarray(xs, float), np.asarray(ys, float), np.asarray(z[rows, cols], float), ds.crs,
                (z.astype(float).filled(np.nan), rows, cols, ds.transform))


def _window_step(raster, rows, cols, radius):
    """Largest |z - z'| between each sample and the valid samples within ``radius`` = (rows, cols) pixels."""
    from scipy import ndimage

    size = (2 * radius[0] + 1, 2 * radius[1] + 1)
    hi = ndimage.maximum_filter(np.where(np.isnan(raster), -np.inf, raster), size=size, mode="nearest")
    lo = ndimage.minimum_filter(np.where(np.isnan(raster), np.inf, raster), size=size, mode="nearest")
    z = raster[rows, cols]
    return np.maximum(hi[rows, cols] - z, z - lo[rows, cols])


def _grid_lookup(grid, x, y):
    """Bilinear value of the HeightGrid at (x, y), whether (x, y) is a grid node, and whether it is inside."""
    (dx, dy), (x0, y0) = grid.spacing, grid.origin
    h = grid.heights
    ny, nx = h.shape
    u, v = (x - x0) / dx, (y - y0) / dy
    inside = (u >= -1e-9) & (u <= nx - 1 + 1e-9) & (v >= -1e-9) & (v <= ny - 1 + 1e-9)
    i = np.clip(np.floor(u).astype(int), 0, nx - 2)
    j = np.clip(np.floor(v).astype(int), 0, ny - 2)
    a, b = np.clip(u - i, 0, 1), np.clip(v - j, 0, 1)
    val = (h[j, i] * (1 - a) * (1 - b) + h[j, i + 1] * a * (1 - b) + h[j + 1, i] * (1 - a) * b
           + h[j + 1, i + 1] * a * b)
    exact = (np.abs(u - np.round(u)) < 1e-6) & (np.abs(v - np.round(v)) < 1e-6)
    return np.where(inside, val, np.nan), exact, inside


def reader_against_file(path, grid, band: int = 1) -> dict | None:
    """Compare a HeightGrid with the file's own samples read by rasterio (module docstring); None when GDAL
    cannot open the file.

    Returns ``samples`` (valid file samples compared), ``on_lattice`` (True when every file sample falls on a grid
    node), ``max_difference``, ``reader_excess`` (largest difference beyond its bound; 0 when all are within),
    ``worst`` ((x, y), file value, grid value).
    """
    got = _file_samples(path, band)
    if got is None:
        return None
    x, y, z, crs, (raster, rows, cols, affine) = got
    if len(z) == 0:
        return {"samples": 0, "on_lattice": True, "max_difference": 0.0, "reader_excess": 0.0, "worst": None}
    pixel = np.array([abs(affine.a), abs(affine.e)])  # file pixel (x, y) in the grid's units, unless reprojected
    if crs is not None and grid.crs is not None:
        from rasterio.crs import CRS
        from rasterio.errors import CRSError
        from rasterio.warp import transform

        try:
            target = CRS.from_user_input(grid.crs)
        except CRSError:  # a description the reader gave (a DEM header's state plane zone): the file's own units
            target = CRS.from_user_input(crs)
        if CRS.from_user_input(crs) != target:
            k = len(x) // 2  # the file's pixel measured in the grid's CRS at a sample in the middle
            px, py = transform(crs, target, [x[k], x[k] + abs(affine.a), x[k]], [y[k], y[k], y[k] + abs(affine.e)])
            pixel = np.array([np.hypot(px[1] - px[0], py[1] - py[0]), np.hypot(px[2] - px[0], py[2] - py[0])])
            x, y = (np.asarray(c) for c in transform(crs, target, x, y))
    val, exact, inside = _grid_lookup(grid, x, y)
    # a grid node is a bilinear mix of the file samples around it, a value between grid nodes a mix of those:
    # it lies within the range of the file samples within one grid cell plus one file pixel of the sample
    reach = np.max(np.asarray(grid.spacing)) / pixel.min() + 1.0
    radius = (int(np.ceil(reach)),) * 2
    bound = np.where(exact, 0.0, _window_step(raster, rows, cols, radius))
    diff = np.abs(val - z)
    excess = np.where(inside, diff - bound - 1e-9 * np.maximum(np.abs(z), 1.0), 0.0)
    k = int(np.nanargmax(np.where(inside, diff, -1.0)))
    return {"samples": int(inside.sum()), "outside": int((~inside).sum()), "on_lattice": bool((bound[inside] == 0).all()),
            "max_difference": float(np.nanmax(np.where(inside, diff, 0.0))),
            "reader_excess": float(max(0.0, np.nanmax(excess))),
            "worst": [[float(x[k]), float(y[k])], float(z[k]), float(val[k])]}


def _accuracy(path, grid, model, baseline, options, findings):
    relief = float(np.ptp(grid.heights)) or 1.0
    xx, yy = np.meshgrid(grid.x, grid.y)
    err = np.abs(model.evaluate(xx, yy) - grid.heights)
    acc = {"grid": list(grid.shape), "spacing": list(grid.spacing), "crs": grid.crs, "relief": relief,
           "spline_max_error": float(err.max()), "spline_rms_error": float(np.sqrt((err ** 2).mean())),
           "spline_max_error_relief": float(err.max() / relief)}
    x0, x1, y0, y1 = grid.extent
    width = max(x1 - x0, y1 - y0)
    if relief > 100 * width:  # a needle: horizontal units are not the heights' (degrees read as metres)
        findings.append(Finding("FAIL", f"the grid is {width:.4g} wide and {relief:.4g} high (x/y and heights in "
                                        "different units?): degrees without a coordinate system, drawn as a needle; "
                                        "pass the CRS they are in (read_heights(path, source_crs='EPSG:4326')) or "
                                        "put the .prj file beside it"))
    r = reader_against_file(path, grid, options.get("band", 1))
    if r is None:
        findings.append(Finding("WARN", "GDAL cannot open the file: the reader is not checked against an "
                                        "independent reading"))
        return acc
    acc["reader"] = r
    missing = None
    if r["samples"] or r.get("outside"):
        missing = 1.0 - (r["samples"] + r["outside"]) / grid.heights.size if r["on_lattice"] else None
    if missing:
        findings.append(Finding("WARN", f"{100 * missing:.1f} % of the grid is nodata, filled with the nearest "
                                        "sample (drawn, but not data)"))
    if r["reader_excess"] > 0:
        (wx, wy), fz, gz = r["worst"]
        findings.append(Finding("FAIL", f"the reader disagrees with the file (GDAL): at ({wx:.6g}, {wy:.6g}) the file "
                                        f"says {fz:.6g}, the grid {gz:.6g} "
                                        f"({'same lattice: must be equal' if r['on_lattice'] else 'beyond the bilinear bound'})"))
    elif r["outside"]:
        findings.append(Finding("WARN", f"{r['outside']} file samples lie outside the grid read"))
    else:
        findings.append(Finding("PASS", f"reader matches GDAL at all {r['samples']} valid samples"
                                        f"{' exactly' if r['on_lattice'] else ' within the bilinear bound'}"))
    return acc


def _add(plotter, model, options):
    return plotter.add_spline(model, **options.get("style", {}))


JUDGE = FamilyJudge("terrain", "warp_by_scalar mesh", _read, _build, _baseline, _accuracy, _add,
                    description="height grids (GeoTIFF, USGS DEM, SRTM .hgt, ESRI ASCII, VTK)")
