"""splinevis.io.read_heights: every reader round-trips exact reference values; bad input fails clearly."""

import warnings

import numpy as np
import pytest
import pyvista as pv
import rasterio

from datasets_synthetic.dem_files import DEM_VOID, fractal_terrain, write_usgs_ascii_dem
from splinevis.io import HeightGrid, read_heights
from splinevis.io.dem import looks_like_usgs_dem, read_dem_records

UTM = (5e5, 5.1e6)


def plane(nx, ny, dx=1.0, dy=1.0, x0=0.0, y0=0.0):
    """Heights 3 + 2x - 0.5y (in local coordinates) on the grid; rows south to north."""
    x = np.arange(nx) * dx
    y = np.arange(ny) * dy
    return 3.0 + 2.0 * x[None, :] - 0.5 * y[:, None]


# ---- numpy -----------------------------------------------------------------------------------------
def test_numpy_defaults_and_geometry():
    h = np.arange(12.0).reshape(3, 4)
    g = read_heights(h)
    assert g.spacing == (1.0, 1.0) and g.origin == (0.0, 0.0) and g.source == "numpy array"
    assert g.shape == (3, 4) and g.extent == (0.0, 3.0, 0.0, 2.0) and g.height_range == (0.0, 11.0)
    assert np.array_equal(g.heights, h) and not g.heights.flags.writeable
    h[0, 0] = 99  # the grid holds a copy
    assert g.heights[0, 0] == 0


def test_numpy_anisotropic_utm_kept_exactly_and_points():
    h = np.arange(6, dtype=np.int16).reshape(2, 3)
    g = read_heights(h, spacing=(0.5, 2.0), origin=UTM)
    assert g.heights.dtype == np.float64
    assert g.spacing == (0.5, 2.0) and g.origin == (500000.0, 5100000.0)
    assert np.array_equal(g.x, [500000.0, 500000.5, 500001.0]) and np.array_equal(g.y, [5100000.0, 5100002.0])
    p = g.points()
    assert p.shape == (6, 3)
    assert np.array_equal(p[4], [500000.5, 5100002.0, 4.0])  # x fastest: index 4 is (i=1, j=1)


@pytest.mark.parametrize(
    "value, kwargs, exc, match",
    [
        (np.zeros(5), {}, ValueError, r"2-D array \(ny, nx\), got shape \(5,\)"),
        (np.zeros((2, 3, 4)), {}, ValueError, r"got shape \(2, 3, 4\)\. Squeeze"),
        (np.zeros((0, 3)), {}, ValueError, r"at least 2 x 2 samples, got shape \(0, 3\)"),
        (np.array([["a", "b"], ["c", "d"]]), {}, TypeError, r"real numbers, got dtype <U1 \(strings\)"),
        (np.zeros((2, 2)), {"spacing": (1.0, 0.0)}, ValueError, r"spacing must be > 0 in x and y, got \(1.0, 0.0\)"),
        (np.zeros((2, 2)), {"spacing": (1.0, -2.0)}, ValueError, r"spacing must be > 0"),
        (np.zeros((2, 2)), {"spacing": "1,1"}, TypeError, r"spacing must be two real numbers, got the string"),
        (np.zeros((2, 2)), {"origin": (np.nan, 0.0)}, ValueError, r"origin must be finite, got \(nan, 0.0\)"),
        (np.zeros((2, 2)), {"origin": (1.0, 2.0, 3.0)}, ValueError, r"origin must be two numbers \(x, y\)"),
        (np.zeros((2, 2)), {"fill": "cubic"}, ValueError, r"fill 'cubic' is not known; choose one of: 'linear', 'nearest'"),
        (np.zeros((2, 2)), {"resample": "spline"}, ValueError, r"resample 'spline' is not known"),
        (np.zeros((2, 2)), {"scalars": "z"}, ValueError, r"a numpy array has none"),
        ({"h": 1}, {}, TypeError, r"source of type dict is not supported; pass a 2-D numpy array"),
    ],
)
def test_bad_inputs(value, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        read_heights(value, **kwargs)


def test_heightgrid_validates_itself():
    with pytest.raises(ValueError, match=r"heights must have finite values; found 1 non-finite"):
        HeightGrid(np.array([[0.0, np.nan], [1.0, 2.0]]), (1, 1), (0, 0))


# ---- missing samples ---------------------------------------------------------------------------------
def test_nan_error_names_source_count_position_coordinate_and_fix():
    h = plane(5, 4)
    h[2, 3] = np.nan
    h[3, 0] = -9999.0
    with pytest.raises(ValueError, match=r"numpy array: 2 of 20 samples are missing .*\(row, col\) = \(2, 3\) "
                                         r"\[array index \[row, col\]\], \(x, y\) = \(10.5, 104.0\).*"
                                         r"Pass fill='nearest' or fill='linear'"):
        read_heights(h, nodata=-9999, spacing=(2.5, 2.0), origin=(3.0, 100.0))


def test_all_missing_is_an_error():
    with pytest.raises(ValueError, match=r"all 4 samples are missing"):
        read_heights(np.full((2, 2), -1.0), nodata=-1, fill="nearest")


def test_linear_fill_reproduces_a_plane_and_nearest_uses_world_distance():
    dx, dy = 1.0, 10.0
    h = plane(6, 5, dx, dy)
    holes = h.copy()
    holes[2, 2:4] = np.nan  # interior gap
    holes[0, 0] = np.nan  # corner: outside the convex hull of the valid samples -> nearest
    lin = read_heights(holes, spacing=(dx, dy), fill="linear")
    inside = np.ones(h.shape, bool)
    inside[0, 0] = False
    np.testing.assert_allclose(lin.heights[inside], h[inside], rtol=0, atol=1e-12)
    assert lin.heights[0, 0] == h[0, 1]
    near = read_heights(holes, spacing=(dx, dy), fill="nearest")
    # (2, 2): neighbour in x is 1 away, in y 10 away -> takes (2, 1); (2, 3) takes (2, 4)
    assert near.heights[2, 2] == h[2, 1] and near.heights[2, 3] == h[2, 4]
    assert near.heights[0, 0] == h[0, 1]


# ---- pyvista ImageData ---------------------------------------------------------------------------------
def image(nx=4, ny=3, spacing=(0.5, 2.0, 1.0), origin=(5e5, 5.1e6, 0.0)):
    img = pv.ImageData(dimensions=(nx, ny, 1), spacing=spacing, origin=origin)
    h = np.arange(nx * ny, dtype=np.float64).reshape(ny, nx) ** 1.5
    img.point_data["elev"] = h.ravel()
    return img, h


def test_imagedata_anisotropic_utm_exact():
    img, h = image()
    g = read_heights(img)
    assert g.spacing == (0.5, 2.0) and g.origin == (500000.0, 5100000.0)
    assert np.array_equal(g.heights, h) and g.source == "pyvista.ImageData"
    # the raw vtk object works too
    assert np.array_equal(read_heights(img.copy()).heights, h)


def test_imagedata_named_scalars_and_errors():
    img, h = image()
    img.point_data["other"] = np.zeros(img.n_points)
    img.set_active_scalars("other")
    assert np.array_equal(read_heights(img, scalars="elev").heights, h)
    with pytest.raises(ValueError, match=r"no point array named 'height'; point arrays: \['elev', 'other'\]"):
        read_heights(img, scalars="height")
    with pytest.raises(ValueError, match=r"carries its own spacing and origin; spacing= would override"):
        read_heights(img, spacing=(1, 1))
    empty = pv.ImageData(dimensions=(3, 3, 1))
    with pytest.raises(ValueError, match=r"no active point scalars; pass scalars="):
        read_heights(empty)
    vol = pv.ImageData(dimensions=(3, 4, 5))
    vol.point_data["h"] = np.zeros(vol.n_points)
    with pytest.raises(ValueError, match=r"one x-y slice, dims \(nx, ny, 1\); got dims \(3, 4, 5\)"):
        read_heights(vol)
    rot = pv.ImageData(dimensions=(3, 3, 1), direction_matrix=[[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    rot.point_data["h"] = np.zeros(9)
    with pytest.raises(ValueError, match=r"direction matrix .* is not the identity; only axis-aligned"):
        read_heights(rot)


def test_vti_file_round_trip(tmp_path):
    img, h = image()
    path = tmp_path / "terrain.vti"
    img.save(path)
    g = read_heights(path)
    assert g.spacing == (0.5, 2.0) and g.origin == UTM and np.array_equal(g.heights, h)
    assert g.source == str(path)


# ---- RectilinearGrid / StructuredGrid ------------------------------------------------------------------
def test_rectilinear_uniform_and_decreasing():
    x = 1000.0 + np.arange(5) * 2.0
    y = 2000.0 + np.arange(4) * 0.5
    h = np.arange(20.0).reshape(4, 5)
    grid = pv.RectilinearGrid(x, y, [0.0])
    grid.point_data["h"] = h.ravel()
    g = read_heights(grid)
    assert g.spacing == (2.0, 0.5) and g.origin == (1000.0, 2000.0) and np.array_equal(g.heights, h)
    rev = pv.RectilinearGrid(x[::-1], y, [0.0])  # x runs east to west
    rev.point_data["h"] = h.ravel()
    g2 = read_heights(rev)
    assert g2.origin == (1000.0, 2000.0) and np.array_equal(g2.heights, h[:, ::-1])


def test_float32_utm_coordinates_count_as_uniform_and_other_types_are_refused(tmp_path):
    x = (5e5 + np.arange(6) * 1.0).astype(np.float32) + np.float32([0, 0, 0.03125, 0, 0, 0])  # float32 rounding
    y = (5.1e6 + np.arange(3) * 2.0).astype(np.float32)
    grid = pv.RectilinearGrid(x, y, np.zeros(1, np.float32))
    grid.point_data["h"] = np.arange(18.0)
    g = read_heights(grid)
    assert g.spacing == (1.0, 2.0) and g.origin == UTM
    with pytest.raises(TypeError, match=r"pyvista.PolyData is not supported; heights come from ImageData"):
        read_heights(pv.Sphere())
    pv.Sphere().save(tmp_path / "s.vtk")
    with pytest.raises(TypeError, match=r"s\.vtk is not supported"):
        read_heights(tmp_path / "s.vtk")


def test_rectilinear_non_uniform_errors_then_resamples():
    x = np.array([0.0, 1.0, 2.0, 4.0, 6.0])  # steps 1, 1, 2, 2 -> mean 1.5, worst deviation 1/3
    y = np.array([10.0, 11.0, 12.0])
    grid = pv.RectilinearGrid(x, y, [0.0])
    grid.point_data["h"] = (3.0 + 2.0 * x[None, :] - 0.5 * (y[:, None] - 10.0)).ravel()
    with pytest.raises(ValueError, match=r"x coordinates are not uniformly spaced \(largest relative deviation "
                                         r"of a step from the mean step: 0.333\).*Pass resample=True"):
        read_heights(grid)
    g = read_heights(grid, resample=True)
    # smallest step 1 -> 6 steps over [0, 6]
    assert g.shape == (3, 7) and g.spacing == (1.0, 1.0) and g.origin == (0.0, 10.0)
    np.testing.assert_allclose(g.heights, plane(7, 3), atol=1e-12)


def test_structured_grid_surface_and_flat_with_scalars():
    x, y = np.meshgrid(300.0 + np.arange(4) * 3.0, 50.0 + np.arange(3) * 1.5)
    z = x * 0.1 + y
    surf = pv.StructuredGrid(x, y, z)
    g = read_heights(surf)
    assert g.spacing == (3.0, 1.5) and g.origin == (300.0, 50.0)
    np.testing.assert_array_equal(g.heights, z)
    flat = pv.StructuredGrid(x, y, np.zeros_like(x))
    flat.point_data["elev"] = z.ravel(order="F")  # pyvista orders points like x.ravel(order="F")
    np.testing.assert_array_equal(read_heights(flat).heights, z)
    # VTK's i axis along x (arrays shaped (nx, ny) as pyvista expects): same result
    ij = pv.StructuredGrid(x.T, y.T, z.T)
    assert ij.dimensions == (4, 3, 1)
    g2 = read_heights(ij)
    assert g2.spacing == (3.0, 1.5) and g2.origin == (300.0, 50.0)
    np.testing.assert_array_equal(g2.heights, z)
    surf.point_data["elev"] = z.ravel()
    with pytest.raises(ValueError, match=r"scalars='elev' given but the points' z varies"):
        read_heights(surf, scalars="elev")
    c, s = np.cos(0.3), np.sin(0.3)
    rot = pv.StructuredGrid(c * x - s * y, s * x + c * y, z)
    with pytest.raises(ValueError, match=r"not an axis-aligned lattice"):
        read_heights(rot)


# ---- files: common errors --------------------------------------------------------------------------------
def test_missing_file_and_unknown_extension(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"height file not found: .*nothere\.dem"):
        read_heights(tmp_path / "nothere.dem")
    (tmp_path / "h.csv").write_text("1,2\n3,4\n")
    with pytest.raises(ValueError, match=r"h\.csv: extension '\.csv' is not supported; supported: \.vti .*\.tiff"):
        read_heights(str(tmp_path / "h.csv"))
    (tmp_path / "bad.dem").write_text("too short")
    with pytest.raises(ValueError, match=r"bad\.dem: too short for a USGS ASCII DEM \(9 bytes"):
        read_heights(tmp_path / "bad.dem")


# ---- USGS ASCII DEM ---------------------------------------------------------------------------------------
# Precision of the format: corners D24.15 (16 significant digits), spacing E12.6 (7 significant
# digits), elevations integers times z_resolution (0.01 m here): heights within z_resolution / 2.
@pytest.mark.parametrize("nx", [6, 100])  # both parsed by our reader (vtkDEMReader is no longer used)
def test_usgs_dem_round_trip(tmp_path, nx):
    ny = 7
    h = 250.0 + 0.123 * plane(nx, ny, 30.0, 10.0) + 17.0 * np.sin(np.arange(nx))[None, :]
    path = write_usgs_ascii_dem(tmp_path / "t.dem", h, (30.0, 10.0), UTM, z_resolution=0.01)
    g = read_heights(path)
    assert g.shape == (ny, nx) and g.spacing == (30.0, 10.0) and g.origin == UTM
    assert g.crs == "EPSG:32633" and g.units == "m"  # UTM zone 33 on the WGS 84 datum the header names
    assert np.abs(g.heights - h).max() <= 0.005 + 1e-9
    # exactly the stored integers times the resolution
    np.testing.assert_array_equal(g.heights, np.rint(h / 0.01) * 0.01)


def test_usgs_dem_void_is_reported_with_file_position(tmp_path):
    h = plane(100, 3, 30.0, 10.0) + 100.0
    h[1, 7] = np.nan
    path = write_usgs_ascii_dem(tmp_path / "v.dem", h, (30.0, 10.0), UTM)
    with pytest.raises(ValueError, match=r"v\.dem: 1 of 300 samples are missing.*\(row, col\) = \(1, 7\) \[row counted "
                                         r"from the south, column = profile\], \(x, y\) = \(500210.0, 5100010.0\)"):
        read_heights(path)
    g = read_heights(path, fill="linear")
    np.testing.assert_allclose(g.heights[1, 7], 100.0 + plane(100, 3, 30.0, 10.0)[1, 7], atol=0.002)
    assert DEM_VOID == -32767


def test_usgs_dem_clipped_profiles_land_at_their_own_northing(tmp_path):
    # A 7.5-minute-style DEM: every profile starts at its own northing and has its own length; the
    # quadrangle corners lie off the sample lattice. vtkDEMReader put such profiles rows too far south
    # and filled the uncovered nodes with the file minimum; each sample must land at its true (x, y)
    # and uncovered nodes must be missing.
    nx, ny, dx, dy = 120, 40, 30.0, 30.0
    jj, ii = np.mgrid[0:ny, 0:nx]
    h = 1000.0 + 3.0 * ii + 7.0 * jj  # a plane: the true height at node (i, j) is known
    first = (ii[0] * 13) % 9  # first row of each profile (0..8)
    last = ny - 1 - (ii[0] * 7) % 11  # last row (29..39)
    first[0] = 3  # the westmost profile starts north of the south-west node
    first[5] = 0  # another starts on row 0, so the south-west node is (x0, y0)
    inside = (jj >= first[None, :]) & (jj <= last[None, :])
    h[~inside] = np.nan
    x0, y0 = 500010.0, 5100020.0
    corners = ((x0 - 6.0, y0 - 19.0), (x0 - 6.0, y0 + 1200.0), (x0 + 3600.0, y0 + 1200.0), (x0 + 3600.0, y0 - 19.0))
    path = write_usgs_ascii_dem(tmp_path / "clip.dem", h, (dx, dy), (x0, y0), z_resolution=0.01,
                                clip_profiles=True, corners=corners)
    with pytest.raises(ValueError, match=r"clip\.dem: .* samples are missing"):
        read_heights(path)  # uncovered nodes are reported, never silently filled
    g = read_heights(path, fill="nearest")
    assert g.shape == (ny, nx) and g.origin == (x0, y0) and g.spacing == (dx, dy)
    true = 1000.0 + 3.0 * (g.x[None, :] - x0) / dx + 7.0 * (g.y[:, None] - y0) / dy
    np.testing.assert_allclose(g.heights[inside], true[inside], atol=0.005)
    assert g.height_range[0] >= 1000.0 - 0.005  # no node filled with a value from outside the data


def test_usgs_dem_truncated_mid_profile_is_a_clear_error(tmp_path):
    h = 100.0 + plane(120, 200, 30.0, 30.0)
    path = write_usgs_ascii_dem(tmp_path / "full.dem", h, (30.0, 30.0), UTM)
    np.testing.assert_allclose(read_heights(path).heights, h, atol=0.005)  # multi-block profiles read whole
    data = path.read_bytes()
    cut = tmp_path / "cut.dem"
    cut.write_bytes(data[:len(data) * 2 // 3 + 500])  # cut inside a profile
    with pytest.raises(ValueError, match=r"cut\.dem: truncated or malformed .*profile \d+ .*file ends after"):
        read_heights(cut)
    whole = tmp_path / "whole_profiles.dem"  # cut exactly after a complete profile record
    per = (len(data) - 1024) // 120
    whole.write_bytes(data[:1024 + 80 * per])
    with pytest.raises(ValueError, match=r"whole_profiles\.dem: header says 120 profiles but the file holds 80"):
        read_heights(whole)


def test_usgs_dem_where_gdal_fails_our_parser_gives_the_known_answer(tmp_path):
    # GDAL 3.10's USGSDEM driver (measured, see splinevis/io/dem.py): it snaps the raster to multiples
    # of the spacing, so samples starting at a northing that is not a multiple of 30 m are read 10 m
    # off; and it cannot read six-digit elevation fields that touch (1000 m at z resolution 0.01 is
    # 100000). Our parser must put every sample at its true (x, y) with its true height in both cases.
    nx, ny, d = 7, 5, 30.0
    x0, y0 = 500010.0, 5100020.0  # x a multiple of 30, y not
    for base, zres in ((100.0, 0.1), (1000.0, 0.01)):  # 4-5 digit fields, then touching 6-digit ones
        h = base + 3.0 * np.arange(nx)[None, :] + 7.0 * np.arange(ny)[:, None]
        path = write_usgs_ascii_dem(tmp_path / f"g{base:.0f}.dem", h, d, (x0, y0), z_resolution=zres)
        if base == 1000.0:
            assert "100000100700" in path.read_text()  # the fields touch (first profile, rows 0 and 1)
        g = read_heights(path)
        np.testing.assert_array_equal(g.x, x0 + d * np.arange(nx))
        np.testing.assert_array_equal(g.y, y0 + d * np.arange(ny))
        np.testing.assert_allclose(g.heights, h, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(g.heights, np.rint(h / zres) * zres)  # float64, stored integers * zres


def test_dem_writer_refuses_float32_inexact_geometry(tmp_path):
    with pytest.raises(ValueError, match=r"vtkDEMReader would count .* samples in x"):
        write_usgs_ascii_dem(tmp_path / "x.dem", np.zeros((3, 200)), (0.1, 1.0), (5e5 + 0.05, 5.1e6))


@pytest.mark.parametrize("line_breaks", [False, True])
def test_usgs_dem_type_c_record_and_line_breaks(tmp_path, line_breaks):
    # A DEM that ends with a type C (accuracy) record, whose type A record says so (accuracy code 1): the
    # record is read, not taken for one more profile; some distributions end every 1024-character block
    # with a line break: same values.
    h = 300.0 + plane(150, 160, 10.0, 10.0)  # 160 elevations: two blocks per profile
    acc = (1, 2, 3, 4, 28, 1, 0, 0, 7, 30)
    path = write_usgs_ascii_dem(tmp_path / "c.dem", h, 10.0, UTM, z_resolution=0.01, accuracy=acc,
                                line_breaks=line_breaks)
    assert (b"\n" in path.read_bytes()) == line_breaks
    g = read_heights(path)
    np.testing.assert_array_equal(g.heights, np.rint(h / 0.01) * 0.01)
    assert g.origin == UTM and g.crs == "EPSG:32633"
    dem = read_dem_records(path)
    assert dem.header["accuracy_code"] == 1 and tuple(dem.accuracy.values()) == acc
    assert dem.accuracy["dem_rmse_z"] == 7 and dem.header["vertical_datum"] == 3


def test_usgs_dem_more_profiles_than_the_header_is_an_error(tmp_path):
    # What follows the announced profiles must be a type C record; a 4th profile after a header announcing
    # 3 means the header or the file is wrong: said, never dropped or taken for accuracy figures.
    path = write_usgs_ascii_dem(tmp_path / "four.dem", 100.0 + plane(4, 5), 1.0, (0.0, 0.0))
    data = bytearray(path.read_bytes())
    data[858:864] = b"     3"  # the number of profiles, columns 859-864 of the type A record
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"four\.dem: after the profiles the header announces, the file holds "
                                         r"[\d,]+ more characters that are not a type C"):
        read_heights(path)


@pytest.mark.parametrize("field", [b"  1x2 ", b" 12 34", b"-  123", b"   12-", b"  +-12", b"      "])
def test_usgs_dem_malformed_elevation_names_profile_and_byte(tmp_path, field):
    path = write_usgs_ascii_dem(tmp_path / "bad.dem", 100.0 + plane(4, 5), 1.0, (0.0, 0.0), z_resolution=1.0)
    data = bytearray(path.read_bytes())
    at = 1024 + 2 * 1024 + 144 + 6 * 2  # profile 3, its third elevation
    data[at:at + 6] = field
    path.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=rf"bad\.dem: malformed type B .*field '{field.decode().replace('+', '[+]')}' "
                                         rf"of profile 3 at byte {at}"):
        read_heights(path)


def test_usgs_dem_signed_and_padded_fields(tmp_path):
    # right-justified I6 with a sign, and -99999 (the most negative five digits): exact stored integers
    h = np.array([[-99999.0, -5.0, 0.0], [7.0, -32766.0, 999999.0]])
    path = write_usgs_ascii_dem(tmp_path / "s.dem", h, 1.0, (0.0, 0.0), z_resolution=1.0)
    assert b"-99999     7" in path.read_bytes() and b"    -5-32766" in path.read_bytes()  # profiles are columns
    np.testing.assert_array_equal(read_dem_records(path).elevations, h.astype(int))


def test_usgs_dem_named_tif_is_read_by_content(tmp_path):
    # A DEM named .tif went to GDAL's USGSDEM driver, which snaps the origin to multiples of the spacing
    # (10 m off here) and invents a row; by content it reaches our parser: every sample at its place.
    h = 200.0 + plane(8, 6, 30.0, 30.0)
    x0, y0 = 500010.0, 5100020.0
    dem = write_usgs_ascii_dem(tmp_path / "a.dem", h, 30.0, (x0, y0), z_resolution=0.01)
    tif = tmp_path / "really_a_dem.tif"
    tif.write_bytes(dem.read_bytes())
    g = read_heights(tif)
    assert g.shape == (6, 8) and g.origin == (x0, y0) and g.crs == "EPSG:32633"
    np.testing.assert_array_equal(g.heights, read_heights(dem).heights)
    assert not looks_like_usgs_dem(write_usgs_ascii_dem.__code__.co_filename)  # a Python file is not a DEM


@pytest.mark.parametrize("datum, epsg", [(1, 4267), (3, 4326), (4, 4269), (None, None)])
def test_usgs_dem_geographic_in_arc_seconds(tmp_path, datum, epsg):
    # USGS 1-degree DEMs: planimetric system 0, x and y in arc-seconds (3 arc-seconds apart); read in degrees
    # with the geographic CRS of the header's horizontal datum (NAD 27, WGS 84, NAD 83).
    lon0, lat0 = -113.0 * 3600, 37.0 * 3600
    h = 1500.0 + plane(5, 4, 3.0, 3.0)
    path = write_usgs_ascii_dem(tmp_path / "geo.dem", h, 3.0, (lon0, lat0), z_resolution=1.0, geographic=True,
                                horizontal_datum=datum)
    if datum is None:  # no datum code: NAD 27 as GDAL assumes it, and said
        with pytest.warns(UserWarning, match=r"geo\.dem: the type A record names no horizontal datum .* NAD 27 "
                                             r"assumed \(EPSG:4267\)"):
            dem = read_dem_records(path)
        epsg = 4267
    else:
        dem = read_dem_records(path)
    assert dem.origin == (-113.0, 37.0) and dem.spacing == (3.0 / 3600, 3.0 / 3600)
    assert dem.crs == f"EPSG:{epsg}"
    with rasterio.open(path) as ds:  # GDAL's USGSDEM driver: same CRS
        assert ds.crs.to_epsg() == epsg
    np.testing.assert_array_equal(dem.elevations, np.rint(h).astype(int))


def test_usgs_dem_utm_crs_from_datum(tmp_path):
    h = 100.0 + plane(3, 3)
    for datum, zone, crs in ((1, 12, "EPSG:26712"), (4, 17, "EPSG:26917"), (3, -19, "EPSG:32719"),
                             (2, 5, "EPSG:32205"), (None, 12, "EPSG:26712")):
        path = write_usgs_ascii_dem(tmp_path / "u.dem", h, 1.0, UTM, utm_zone=zone, horizontal_datum=datum)
        with warnings.catch_warnings(record=True):
            warnings.simplefilter("always")
            assert read_dem_records(path).crs == crs, (datum, zone)
        with rasterio.open(path) as ds:  # GDAL's USGSDEM driver reads the same datum and zone
            assert ds.crs.to_epsg() == int(crs[5:]), (datum, zone)
    path = write_usgs_ascii_dem(tmp_path / "sp.dem", h, 1.0, UTM, utm_zone=12)
    data = bytearray(path.read_bytes())
    data[156:162] = b"     2"  # state plane: no EPSG from the header alone, a description
    path.write_bytes(bytes(data))
    assert read_dem_records(path).crs == "state plane zone 12, WGS 84 (x, y in m)"


# GeoTIFF and the other rasters read through rasterio/GDAL: tests/test_io_raster.py


# ---- synthetic terrain -------------------------------------------------------------------------------------
def test_fractal_terrain_reproducible_and_scaled():
    z = fractal_terrain(32, seed=3, amplitude=100.0)
    assert z.shape == (32, 32) and z.min() == 0.0 and z.max() == pytest.approx(100.0, rel=1e-12)
    assert np.array_equal(z, fractal_terrain(32, seed=3, amplitude=100.0))
    with pytest.raises(ValueError, match=r"n must be an integer >= 2, got 1"):
        fractal_terrain(1)


@pytest.mark.parametrize("keep", [0, 0.5])
def test_empty_or_truncated_vti_says_so(tmp_path, keep):
    import pyvista as pv

    src = tmp_path / "ok.vti"
    g = pv.ImageData(dimensions=(8, 6, 1))
    g.point_data["h"] = np.arange(48.0)
    g.save(src)
    bad = tmp_path / "bad.vti"
    data = src.read_bytes()
    bad.write_bytes(data[: int(len(data) * keep)])
    with pytest.raises(ValueError, match=r"bad\.vti: .*(empty or truncated|could not read)"):
        read_heights(bad)
