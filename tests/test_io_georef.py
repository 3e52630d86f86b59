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


def _cropped(*args, **kwargs):
    # to_metric without fill=: the largest north-up rectangle inside the footprint, the rest warned about
    with pytest.warns(UserWarning, match=r"keeps \d+\.\d\d % of the file's footprint"):
        return to_metric(*args, **kwargs)


@pytest.mark.parametrize("lon0, lat0, zone", [(7.0, 45.0, "EPSG:32632"), (7.0, 60.0, "EPSG:32632"),
                                              (-70.6, -33.4, "EPSG:32719"), (150.2, -80.0, "EPSG:32756")])
def test_bilinear_reprojection_reproduces_a_height_linear_in_degrees(lon0, lat0, zone):
    # bilinear interpolation reproduces a function linear in (lon, lat) exactly: what is left is the
    # round-off of the height (eps * |h|) and of PROJ's inverse (well below 1e-9 degrees, times the slope)
    h, spacing, origin = _linear_grid(lon0, lat0)
    m = _cropped(h, spacing, origin, "EPSG:4326")
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
    m = _cropped(h, spacing, origin, "EPSG:4326")
    mx, my = degree_lengths(60.0 + 15 * 0.005)
    assert m.spacing == pytest.approx((0.005 * mx, 0.005 * my), rel=1e-12)
    # a degree of longitude at 60 N is about half one at the equator: the aspect the picture must show
    assert m.spacing[0] / m.spacing[1] == pytest.approx(0.5, abs=0.01)


def test_named_target_crs_and_refusals():
    h, spacing, origin = _linear_grid(7.0, 45.0)
    m = _cropped(h, spacing, origin, "EPSG:4326", target="EPSG:3035")  # ETRS89 LAEA Europe
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
    lin = _cropped(h, spacing, origin, "EPSG:4326")
    cub = _cropped(h, spacing, origin, "EPSG:4326", resampling="cubic")
    near = _cropped(h, spacing, origin, "EPSG:4326", resampling="nearest")
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


# ---------------------------------------------------------------------------------------------------
# Grids reaching the polar caps: universal polar stereographic, all of the area kept
# ---------------------------------------------------------------------------------------------------
UPS_NORTH_POLE = (2.0e6, 2.0e6)  # false easting and northing of EPSG:32661 (the pole's position)


def _polar_field(lon, lat, lat0, a=50.0, b=100.0, c=300.0):
    # linear in latitude plus b sin(lon) fading to 0 at the pole (one height there, whatever the longitude)
    return a + c * (lat - lat0) + b * np.sin(np.radians(lon)) * (90.0 - lat) / (90.0 - lat0)


def _bilinear_bound(dlon_deg, b=100.0, scale=1.0):
    # bilinear interpolation in (lon, lat) is exact for the parts linear in lat; sin(lon) interpolated
    # linearly over a step h has error <= h^2 / 8 * max|sin''| = h^2 / 8 (h in radians), times the factor
    # b (90 - lat) / (90 - lat0) <= b; plus round-off (PROJ's inverse to ~1e-9 degree times the slopes)
    return b * math.radians(dlon_deg) ** 2 / 8 + 1e-9 * (300.0 + b) * scale + 1e-9


def _inside_nodes(m, lon_range, lat_range):
    lon, lat = _node_lonlat(m)
    dl = (lon - lon_range[0]) % 360.0
    dl = np.where(dl > 360.0 - 1e-9, dl - 360.0, dl)
    inside = (dl <= lon_range[1] - lon_range[0] + 1e-9) & (lat >= lat_range[0] - 1e-9) & (lat <= lat_range[1] + 1e-9)
    return lon, lat, inside


def _covers(m, lons, lats):
    # every point of the source's footprint (its boundary, densified) lies inside the new grid's extent
    x, y = transform("EPSG:4326", m.crs, list(lons), list(lats))
    x0, y0 = m.origin
    x1, y1 = x0 + (m.heights.shape[1] - 1) * m.spacing[0], y0 + (m.heights.shape[0] - 1) * m.spacing[1]
    return min(x) >= x0 and max(x) <= x1 and min(y) >= y0 and max(y) <= y1


def _ring(lon0, lon1, lat0, lat1, n=400):
    u = np.linspace(0.0, 1.0, n)
    lons = np.concatenate([lon0 + u * (lon1 - lon0), np.full(n, lon1), lon1 - u * (lon1 - lon0), np.full(n, lon0)])
    lats = np.concatenate([np.full(n, lat0), lat0 + u * (lat1 - lat0), np.full(n, lat1), lat1 - u * (lat1 - lat0)])
    return lons, lats


def test_a_whole_polar_cap_goes_to_ups_north_with_all_of_it_kept():
    # 180 x 41 samples: longitudes -180..178 (every 2 degrees, the circle closes between 178 and 180),
    # latitudes 88..90 (the last row at the pole)
    dlon, dlat = 2.0, 0.05
    lon, lat = np.meshgrid(-180.0 + dlon * np.arange(180), 88.0 + dlat * np.arange(41))
    h = _polar_field(lon, lat, 88.0)
    m = to_metric(h, (dlon, dlat), (-180.0, 88.0), "EPSG:4326", fill="nearest")
    assert m.crs == "EPSG:32661" and "EPSG:32661" in m.note and "100.00 % of the footprint kept" in m.note
    assert _covers(m, *_ring(-180.0, 180.0, 88.0, 90.0))
    nlon, nlat, inside = _inside_nodes(m, (-180.0, 180.0), (88.0, 90.0))
    want = _polar_field(nlon, nlat, 88.0)
    assert np.abs(m.heights - want)[inside].max() <= _bilinear_bound(dlon)
    # the cap is a disk of radius r(88) about the pole: the nodes inside it hold pi r^2 up to the cells the
    # circle cuts (at most its length times the cell diagonal)
    xr, yr = transform("EPSG:4326", "EPSG:32661", [0.0], [88.0])
    r = math.hypot(xr[0] - UPS_NORTH_POLE[0], yr[0] - UPS_NORTH_POLE[1])
    dx, dy = m.spacing
    assert abs(inside.sum() * dx * dy - math.pi * r * r) <= 2 * math.pi * r * math.hypot(dx, dy)
    # the square around the disk: pi / 4 of it inside; the corners are filled (nearest), not extrapolated
    assert inside.mean() == pytest.approx(math.pi / 4, abs=4 * math.hypot(dx, dy) / (2 * r))
    assert m.heights.min() >= h.min() and m.heights.max() <= h.max()


def test_a_wedge_at_the_pole_is_not_cropped():
    # the measured case: longitudes 0..10, latitudes 88..90, pixel centres (half a pixel inside the edges);
    # it used to come back as 4 x 195 nodes, 0.3 % of its area, without a word
    dlon, dlat = 0.05, 0.02
    lon0, lat0 = dlon / 2, 88.0 + dlat / 2
    lon, lat = np.meshgrid(lon0 + dlon * np.arange(200), lat0 + dlat * np.arange(100))
    h = _polar_field(lon, lat, lat0)
    with pytest.raises(ValueError, match=r"heights: .*% of the nodes of the EPSG:32661 grid .* outside the "
                                         r"footprint .*fill='nearest'"):
        to_metric(h, (dlon, dlat), (lon0, lat0), "EPSG:4326")
    m = to_metric(h, (dlon, dlat), (lon0, lat0), "EPSG:4326", fill="linear")
    lon1, lat1 = lon0 + 199 * dlon, lat0 + 99 * dlat
    assert m.crs == "EPSG:32661" and _covers(m, *_ring(lon0, lon1, lat0, lat1))
    nlon, nlat, inside = _inside_nodes(m, (lon0, lon1), (lat0, lat1))
    assert np.abs(m.heights - _polar_field(nlon, nlat, lat0))[inside].max() <= _bilinear_bound(dlon)
    # as many samples as the source (same mean cell area over the footprint), within the border cells
    assert inside.sum() == pytest.approx(h.size, rel=0.05)


def test_lat_85_lon_40_50_goes_to_ups_with_the_footprint_kept():
    # a 10 x 1 degree cell at 85 N, rotated 45 degrees in UPS: refused before as "is the CRS right?"
    dlon, dlat = 0.1, 0.01
    lon, lat = np.meshgrid(40.0 + dlon * np.arange(101), 84.5 + dlat * np.arange(101))
    h = _polar_field(lon, lat, 84.5)
    with pytest.raises(ValueError, match=r"outside the footprint"):
        to_metric(h, (dlon, dlat), (40.0, 84.5), "EPSG:4326")
    m = to_metric(h, (dlon, dlat), (40.0, 84.5), "EPSG:4326", fill="nearest")
    assert m.crs == "EPSG:32661" and _covers(m, *_ring(40.0, 50.0, 84.5, 85.5))
    nlon, nlat, inside = _inside_nodes(m, (40.0, 50.0), (84.5, 85.5))
    assert np.abs(m.heights - _polar_field(nlon, nlat, 84.5))[inside].max() <= _bilinear_bound(dlon)


def test_the_south_cap_goes_to_ups_south():
    dlon, dlat = 1.0, 0.1
    lon, lat = np.meshgrid(-20.0 + dlon * np.arange(41), -82.0 + dlat * np.arange(11))
    m = to_metric(3.0 + 0 * lon + 2.0 * lat, (dlon, dlat), (-20.0, -82.0), "EPSG:4326", fill="nearest")
    assert m.crs == "EPSG:32761" and _covers(m, *_ring(-20.0, 20.0, -82.0, -81.0))


def test_the_crop_of_a_utm_tile_is_measured_and_warned():
    # a 1 x 1 degree tile at 60 N, 3 degrees west of its zone's central meridian: the meridian convergence
    # (gamma = 3 sin 60 = 2.6 degrees) turns it, and the largest north-up rectangle inside leaves out about
    # tan(gamma) (w/h + h/w) = 0.045 (0.5 + 2) = 11 % (w = 55.8, h = 111.4 km); the lattice of the source's
    # spacing ends less than a step short of it (at most 1/40 per axis)
    h, spacing, origin = _linear_grid(6.0, 60.0, d=0.025, shape=(41, 41))
    with pytest.warns(UserWarning, match=r"keeps \d\d\.\d\d % of the file's footprint.*fill='nearest'"):
        m = to_metric(h, spacing, origin, "EPSG:4326")
    # the percentage is the lattice's rectangle over the footprint's area (shoelace on a dense ring)
    x, y = transform("EPSG:4326", m.crs, *(list(v) for v in _ring(6.0, 7.0, 60.0, 61.0, 2000)))
    x, y = np.asarray(x), np.asarray(y)
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    ny, nx = m.heights.shape
    kept = 100.0 * (nx - 1) * m.spacing[0] * (ny - 1) * m.spacing[1] / area
    assert f"{kept:.2f} % of the footprint kept" in m.note
    rough = 1 - math.tan(math.radians(3 * math.sin(math.radians(60.5)))) * (0.5 + 2.0)
    assert rough * (1 - 2 / 40) - 0.02 <= kept / 100 <= rough + 0.02  # the estimate is first order in gamma
    # with fill= the whole footprint is kept: the nodes outside it are gaps filled like the file's own
    whole = to_metric(h, spacing, origin, "EPSG:4326", fill="nearest")
    assert _covers(whole, *_ring(6.0, 7.0, 60.0, 61.0)) and "100.00 % of the footprint kept" in whole.note


# ---------------------------------------------------------------------------------------------------
# CRS errors are ours: ValueError naming the source, the CRS, what is wrong and what to do
# ---------------------------------------------------------------------------------------------------
def test_metres_labelled_degrees_say_so():
    h = np.zeros((11, 11))
    with pytest.raises(ValueError, match=r"dem\.tif: coordinates x 500000\.\.510000, y 5e\+06\.\.5\.01e\+06 are "
                                         r"not degrees: the file's CRS label EPSG:4326 looks wrong; pass "
                                         r"crs='EPSG:326zz'"):
        to_metric(h, (1000.0, 1000.0), (5e5, 5e6), "EPSG:4326", source="dem.tif")
    with pytest.raises(ValueError, match=r"dem\.tif: coordinates .* are not degrees"):
        scale_geographic(h, (1000.0, 1000.0), (5e5, 5e6), "EPSG:4326", source="dem.tif")
    # naming the CRS the coordinates are in takes them as they are (the label is the mistake)
    with pytest.warns(UserWarning, match=r"taken as EPSG:32633"):
        m = to_metric(h + 7.0, (1000.0, 1000.0), (5e5, 5e6), "EPSG:4326", target="EPSG:32633", source="dem.tif")
    assert m.crs == "EPSG:32633" and m.origin == (5e5, 5e6) and m.spacing == (1000.0, 1000.0)
    assert np.array_equal(m.heights, h + 7.0)


@pytest.mark.parametrize("bad", ["EPSG:99999", "not a crs"])
def test_an_unknown_target_crs_is_our_error(bad):
    h, spacing, origin = _linear_grid(7.0, 45.0)
    with pytest.raises(ValueError, match=rf"dem\.tif: crs={bad!r} is not a known CRS .*pass an EPSG code or WKT "
                                         r"PROJ knows, e\.g\. 'EPSG:32633'") as info:
        to_metric(h, spacing, origin, "EPSG:4326", target=bad, source="dem.tif")
    assert type(info.value) is ValueError


def test_a_target_crs_that_cannot_hold_the_grid_is_our_error():
    # an orthographic view of the hemisphere about (0, 0) does not see longitude 170: PROJ fails (or, once its
    # transform object has failed, returns inf)
    lon, lat = np.meshgrid(170.0 + 0.1 * np.arange(11), 45.0 + 0.1 * np.arange(11))
    ortho = "+proj=ortho +lat_0=0 +lon_0=0 +datum=WGS84"
    for fill in (None, "nearest"):
        with pytest.raises(ValueError, match=r"dem\.tif: (PROJ cannot take the grid's coordinates from EPSG:4326 to "
                                             r"|)\+proj=ortho.*(cannot hold the grid's footprint|).*another crs="):
            to_metric(lat, (0.1, 0.1), (170.0, 45.0), "EPSG:4326", target=ortho, fill=fill, source="dem.tif")


def _ascii_grid_in_degrees(path, n=30):
    """An ESRI ASCII grid of heights in metres on a lattice of degrees (lon -105.55.., lat 40.09..), no .prj."""
    rows = "\n".join(" ".join(f"{2000.0 + 10.0 * i + j:.1f}" for j in range(n)) for i in range(n))
    path.write_text(f"ncols {n}\nnrows {n}\nxllcorner -105.55\nyllcorner 40.09\ncellsize 0.000833333333\n"
                    f"NODATA_value -9999\n{rows}\n")
    return path


def test_degrees_without_a_crs_are_warned_and_source_crs_places_them(tmp_path):
    from splinevis.io import read_heights

    path = _ascii_grid_in_degrees(tmp_path / "srtm.asc")
    with pytest.warns(UserWarning, match=r"look like degrees .* pass source_crs='EPSG:4326'"):
        plain = read_heights(path)
    assert plain.crs is None and plain.extent[1] - plain.extent[0] < 0.03  # degrees read as metres: a needle
    g = read_heights(path, source_crs="EPSG:4326", fill="nearest")
    assert g.crs == "EPSG:32613"  # UTM zone 13 holds lon -105.5
    # 29 steps of 3 arc-seconds: 2.21 km east-west at lat 40.1 (cos 40.1 * 111.32 km / degree), 2.68 km
    # north-south; the new lattice holds whole steps of its own spacing: within two of them
    x0, x1, y0, y1 = g.extent
    assert abs((x1 - x0) - 29 * 0.000833333333 * 111_320 * np.cos(np.radians(40.1))) < 2 * g.spacing[0]
    assert abs((y1 - y0) - 29 * 0.000833333333 * 111_000) < 2 * g.spacing[1]


def test_source_crs_is_for_grids_that_name_none(tmp_path):
    from datasets_synthetic.dem_files import write_geotiff
    from splinevis.io import read_heights

    tif = tmp_path / "utm.tif"
    write_geotiff(tif, np.zeros((4, 5)), (30.0, 30.0), (500_000.0, 5_000_000.0), epsg=32633)
    with pytest.raises(ValueError, match="source_crs='EPSG:4326' is for grids that name no CRS; this one names"):
        read_heights(tif, source_crs="EPSG:4326")
    with pytest.raises(ValueError, match=r"source_crs='EPSG:99999' is not a known CRS"):
        read_heights(np.zeros((3, 3)), spacing=(1.0, 1.0), origin=(0.0, 0.0), source_crs="EPSG:99999")
