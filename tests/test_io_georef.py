"""Geographic (degree) height grids brought to a metric frame: known answers from PROJ and the ellipsoid."""

import math

import numpy as np
import pytest
from rasterio.warp import transform

from splinevis.io.georef import degree_lengths, is_geographic, local_metric_crs, scale_geographic, to_metric

LINEAR = (100.0, 1000.0, 500.0)  # h = a + b (lon - lon0) + c (lat - lat0), metres


def _linear_grid(lon0, lat0, d=0.005, shape=(31, 41)):
    ny, nx = shape
    lon, lat = np.meshgrid(lon0 + d * np.arange(nx), lat0 + d * np.arange(ny))
    a, b, c = LINEAR
    return a + b * (lon - lon0) + c * (lat - lat0), (d, d), (lon0, lat0)


def _node_lonlat(m):
    ny, nx = m.heights.shape
    X, Y = np.meshgrid(m.origin[0] + m.spacing[0] * np.arange(nx), m.origin[1] + m.spacing[1] * np.arange(ny))
    lon, lat = transform(m.crs, "EPSG:4326", X.ravel(), Y.ravel())
    return np.asarray(lon).reshape(ny, nx), np.asarray(lat).reshape(ny, nx)


@pytest.mark.parametrize("lon0, lat0, zone", [(7.0, 45.0, "EPSG:32632"), (7.0, 60.0, "EPSG:32632"),
                                              (-70.6, -33.4, "EPSG:32719"), (150.2, -80.0, "EPSG:32756")])
def test_bilinear_reprojection_reproduces_a_height_linear_in_degrees(lon0, lat0, zone):
    # bilinear interpolation reproduces a function linear in (lon, lat) exactly: what is left is the
    # round-off of the height (eps * |h|) and of PROJ's inverse (well below 1e-9 degrees, times the slope)
    h, spacing, origin = _linear_grid(lon0, lat0)
    m = to_metric(h, spacing, origin, "EPSG:4326")
    assert m.crs == zone and zone in m.note and "UTM zone of the centre" in m.note
    lon, lat = _node_lonlat(m)
    a, b, c = LINEAR
    want = a + b * (lon - lon0) + c * (lat - lat0)
    tol = 1e-9 * (abs(b) + abs(c)) + 8 * np.finfo(float).eps * np.abs(want).max()
    assert np.abs(m.heights - want).max() <= tol
    # every node lies inside the source's sample rectangle (no extrapolation), and the grid covers most of it
    assert lon.min() >= lon0 - 1e-9 and lon.max() <= lon0 + 40 * spacing[0] + 1e-9
    assert lat.min() >= lat0 - 1e-9 and lat.max() <= lat0 + 30 * spacing[1] + 1e-9
    assert m.heights.size >= 0.5 * h.size


def test_metric_spacing_is_the_degree_length_at_the_centre():
    h, spacing, origin = _linear_grid(7.0, 60.0)
    m = to_metric(h, spacing, origin, "EPSG:4326")
    mx, my = degree_lengths(60.0 + 15 * 0.005)
    assert m.spacing == pytest.approx((0.005 * mx, 0.005 * my), rel=1e-12)
    # a degree of longitude at 60 N is about half one at the equator: the aspect the picture must show
    assert m.spacing[0] / m.spacing[1] == pytest.approx(0.5, abs=0.01)


def test_named_target_crs_and_refusals():
    h, spacing, origin = _linear_grid(7.0, 45.0)
    m = to_metric(h, spacing, origin, "EPSG:4326", target="EPSG:3035")  # ETRS89 LAEA Europe
    assert m.crs == "EPSG:3035" and "as asked" in m.note
    with pytest.raises(ValueError, match=r"crs='EPSG:4258' is geographic .*projected CRS in metres"):
        to_metric(h, spacing, origin, "EPSG:4326", target="EPSG:4258")
    with pytest.raises(ValueError, match="resampling .* must be one of"):
        to_metric(h, spacing, origin, "EPSG:4326", resampling="lanczos")
    h[3, 4] = np.nan
    with pytest.raises(ValueError, match="fill the gaps before reprojecting"):
        to_metric(h, spacing, origin, "EPSG:4326")


def test_cubic_and_nearest_resampling_known_values():
    h, spacing, origin = _linear_grid(7.0, 45.0)
    lin = to_metric(h, spacing, origin, "EPSG:4326")
    cub = to_metric(h, spacing, origin, "EPSG:4326", resampling="cubic")
    near = to_metric(h, spacing, origin, "EPSG:4326", resampling="nearest")
    # the interpolating cubic spline of a linear function is that function (round-off of its prefilter)
    assert np.abs(cub.heights - lin.heights).max() <= 1e-9 * np.abs(h).max()
    # nearest: each value is one of the samples, within half a sample step of the linear value
    assert np.isin(near.heights, h).all()
    step = 0.5 * (LINEAR[1] + LINEAR[2]) * spacing[0]
    assert np.abs(near.heights - lin.heights).max() <= step + 1e-9


def test_zone_rules():
    assert local_metric_crs(0.0, 0.0) == "EPSG:32631"
    assert local_metric_crs(-0.1, 0.0) == "EPSG:32630"
    assert local_metric_crs(-180.0, -1.0) == "EPSG:32701"
    assert local_metric_crs(359.0, 10.0) == "EPSG:32630"  # longitudes wrap: 359 E is 1 W
    assert local_metric_crs(0.0, 84.5) == "EPSG:32661" and local_metric_crs(0.0, -80.5) == "EPSG:32761"
    assert is_geographic("EPSG:4326") and is_geographic("EPSG:4269") and not is_geographic("EPSG:32632")


def test_degree_lengths_on_the_ellipsoid():
    # the meridian degree grows from the equator to the pole (flattening), the parallel degree is N cos(lat)
    equator, pole = degree_lengths(0.0)[1], degree_lengths(90.0)[1]
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    assert equator == pytest.approx(math.pi / 180 * a * (1 - e2), rel=1e-15)
    assert pole == pytest.approx(math.pi / 180 * a / math.sqrt(1 - e2), rel=1e-15)
    # a different ellipsoid (Clarke 1866, NAD27) gives different lengths
    assert degree_lengths(45.0, "EPSG:4267")[0] != pytest.approx(degree_lengths(45.0)[0], rel=1e-7)


def test_keep_geographic_keeps_the_lattice_with_stated_factors():
    h, spacing, origin = _linear_grid(7.0, 60.0)
    m = scale_geographic(h, spacing, origin, "EPSG:4326")
    mx, my = degree_lengths(60.075)
    assert np.array_equal(m.heights, h)  # unresampled
    assert m.origin == (7.0 * mx, 60.0 * my) and m.spacing == (0.005 * mx, 0.005 * my)
    assert f"{mx:.6g} m" in m.note and f"{my:.6g} m" in m.note and "true there only" in m.note


# ---------------------------------------------------------------------------------------------------
# A degree GeoTIFF read and rendered: the picture has the true aspect
# ---------------------------------------------------------------------------------------------------
CONE_LAT, CONE_LON, CONE_RADIUS = 60.0, 10.0, 4000.0  # metres
DEG = 0.003  # the same step in longitude and latitude: 167 m x 334 m at 60 N


def _cone_geotiff(tmp_path):
    from datasets_synthetic.dem_files import write_geotiff

    n = 61
    lon0, lat0 = CONE_LON - 30 * DEG, CONE_LAT - 30 * DEG
    lon, lat = np.meshgrid(lon0 + DEG * np.arange(n), lat0 + DEG * np.arange(n))
    mx, my = degree_lengths(CONE_LAT)
    r = np.hypot((lon - CONE_LON) * mx, (lat - CONE_LAT) * my)  # metres from the apex (local frame)
    heights = 1500.0 * np.clip(1.0 - r / CONE_RADIUS, 0.0, None)
    return write_geotiff(tmp_path / "cone_deg.tif", heights, (DEG, DEG), (lon0, lat0), epsg=4326)


def _footprint_aspect(read_options):
    import splinevis

    pl = splinevis.Plotter(off_screen=True, window_size=(240, 240))
    actor = pl.add_terrain(_cone_geotiff.path, "C1", read_options=read_options, lights=0)
    grid_extent = actor.model.extent if isinstance(actor.model.extent, tuple) else None
    (x0, x1, y0, y1) = grid_extent
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    pl.camera_position = [(cx, cy, 5e4), (cx, cy, 0.0), (0.0, 1.0, 0.0)]
    pl.camera.parallel_projection = True
    pl.camera.parallel_scale = 0.5 * max(x1 - x0, y1 - y0) * 1.05
    pl.camera.clipping_range = (4e4, 6e4)
    pl.screenshot()
    depth = pl.depth_buffer()
    pl.close()
    # parallel projection, eye at z = 5e4, clipping range (4e4, 6e4): window depth = (1e4 - z) / 2e4
    cone = depth < (1e4 - 20.0) / 2e4  # the cone above 20 m of its 1500 m
    rows, cols = np.nonzero(cone)
    return (cols.max() - cols.min() + 1) / (rows.max() - rows.min() + 1), cone.sum(), actor.model


@pytest.mark.parametrize("read_options", [{}, {"keep_geographic": True}], ids=["utm", "kept-degrees"])
def test_a_degree_geotiff_renders_with_its_true_aspect(tmp_path, read_options):
    _cone_geotiff.path = _cone_geotiff(tmp_path)
    aspect, pixels, model = _footprint_aspect(read_options)
    assert pixels > 500  # the cone is a good part of the picture
    # the footprint (a circle of 4 km less the 20 m rim, ~ 95 px across) is round to its pixel edges;
    # drawn in raw degrees it would be 2:1 (a degree of longitude is half a degree of latitude at 60 N)
    assert aspect == pytest.approx(1.0, abs=3.0 / 90)
    src = model.source if hasattr(model, "source") else ""
    assert ("EPSG:32632" in src) if not read_options else ("keep_geographic=True" in src)
