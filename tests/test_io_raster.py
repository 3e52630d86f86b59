"""splinevis.io.raster (rasterio/GDAL): every sample lands at its known (x, y) with its known height, for
GeoTIFF (PixelIsArea and PixelIsPoint), COG, SRTM .hgt, ESRI ASCII grids (xllcorner and xllcenter) and
Erdas .img; bad rasters fail with a message naming the file and what to do."""

import warnings

import numpy as np
import pytest
import rasterio
import rasterio.shutil
import tifffile
from affine import Affine
from rasterio.crs import CRS

from datasets_synthetic.dem_files import write_geotiff
from splinevis.io import SUPPORTED_EXTENSIONS, read_heights
from splinevis.io.georef import degree_lengths
from splinevis.io.raster import read_raster

UTM = (5e5, 5.1e6)


def plane_at(x, y):
    """The known height at world (x, y): a tilted plane with distinct values everywhere."""
    return 3.0 + 0.02 * (x - UTM[0]) - 0.005 * (y - UTM[1])


def write(path, data, transform, *, driver="GTiff", crs="EPSG:32633", nodata=None, tags=None, count=None):
    data = np.asarray(data)
    bands = data if data.ndim == 3 else data[None]
    with rasterio.open(path, "w", driver=driver, width=bands.shape[2], height=bands.shape[1], count=count or
                       bands.shape[0], dtype=bands.dtype, crs=crs, transform=transform, nodata=nodata) as ds:
        if tags:
            ds.update_tags(**tags)
        ds.write(bands)
    return path


def check_every_sample(g, xs, ys, heights, *, atol=0.0):
    """``g`` (HeightGrid) holds ``heights[j, i]`` at (xs[i], ys[j]), exactly (or within atol)."""
    assert g.shape == heights.shape
    np.testing.assert_array_equal(g.x, xs)
    np.testing.assert_array_equal(g.y, ys)
    np.testing.assert_allclose(g.heights, heights, rtol=0, atol=atol)
    pts = g.points()
    xx, yy = np.meshgrid(xs, ys)
    np.testing.assert_allclose(pts, np.column_stack([xx.ravel(), yy.ravel(), heights.ravel()]), rtol=0, atol=atol)


# ---- GeoTIFF -------------------------------------------------------------------------------------------
def test_geotiff_north_up_float32_nodata_every_sample(tmp_path):
    nx, ny, dx, dy = 5, 4, 30.0, 10.0
    xs, ys = UTM[0] + dx * np.arange(nx), UTM[1] + dy * np.arange(ny)
    known = plane_at(xs[None, :], ys[:, None]).astype(np.float32)
    stored = known[::-1].copy()  # north row first
    stored[0, 2] = -9999.0  # north row, column 2 -> (xs[2], ys[-1])
    path = write(tmp_path / "n.tif", stored, Affine(dx, 0, UTM[0] - dx / 2, 0, -dy, ys[-1] + dy / 2), nodata=-9999.0)
    s = read_raster(path)
    assert s.flip_rows and not s.flip_cols and s.values.dtype == np.float32
    assert s.origin == UTM and s.spacing == (dx, dy) and s.crs == "EPSG:32633"
    assert s.missing.sum() == 1 and s.missing[0, 2] and s.xy_of(0, 2) == (xs[2], ys[-1])
    with pytest.raises(ValueError, match=r"n\.tif: 1 of 20 samples are missing.*\(row, col\) = \(0, 2\) \[\(row, col\) as "
                                         r"stored, row 0 = north\], \(x, y\) = \(500060.0, 5100030.0\), value -9999.0"):
        read_heights(path)
    g = read_heights(path, fill="linear")
    assert g.crs == "EPSG:32633" and g.source == str(path)
    check_every_sample(g, xs, ys, known.astype(np.float64), atol=2e-6)
    assert CRS.from_user_input(g.crs).is_projected


def test_geotiff_written_by_datasets_writer_round_trips_exactly(tmp_path):
    ny, nx = 5, 3
    h = np.repeat(np.arange(ny, dtype=np.float64)[:, None] * 10.0, nx, axis=1)  # increases to the north
    path = write_geotiff(tmp_path / "r.tif", h, (2.0, 3.0), UTM, epsg=32633)
    with rasterio.open(path) as ds:
        assert ds.read(1)[0, 0] == 40.0  # the file stores the northern row first
    g = read_heights(path)
    assert np.all(np.diff(g.heights[:, 0]) > 0)  # increasing with j = northwards
    assert np.array_equal(g.heights, h) and g.spacing == (2.0, 3.0) and g.origin == UTM and g.crs == "EPSG:32633"
    h2 = h.copy()
    h2[0, 1] = np.nan  # south row -> stored row 4
    n = write_geotiff(tmp_path / "n.tif", h2, (2.0, 3.0), UTM, nodata=-9999.0, dtype=np.float32)
    with pytest.raises(ValueError, match=r"n\.tif: 1 of 15 samples are missing.*\(row, col\) = \(4, 1\) .*"
                                         r"\(x, y\) = \(500002.0, 5100000.0\), value -9999.0"):
        read_heights(n)
    assert read_heights(n, nodata=-1.0, fill="nearest").heights[0, 1] == -9999.0  # nodata= replaces the file's


def test_pixel_is_point_and_area_both_put_samples_at_their_positions(tmp_path):
    data = np.arange(6, dtype=np.float32).reshape(3, 2)  # row 0 north
    # a raw GeoTIFF written without GDAL: tiepoint (1000, 2000), 10 x 20 pixels, GTRasterTypeGeoKey 1 or 2
    for raster_type, origin in ((1, (1005.0, 1950.0)), (2, (1000.0, 1960.0))):
        path = tmp_path / f"raw{raster_type}.tif"
        tags = [(34735, "H", 8, (1, 1, 0, 1, 1025, 0, 1, raster_type), False),
                (33550, "d", 3, (10.0, 20.0, 0.0), False), (33922, "d", 6, (0, 0, 0, 1000.0, 2000.0, 0), False)]
        tifffile.imwrite(path, data, extratags=tags, metadata=None)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # no CRS in the raw file
            g = read_heights(path)
        # PixelIsArea: centre of the SW pixel is half a pixel inside the corner; PixelIsPoint: on the tiepoint
        check_every_sample(g, origin[0] + 10.0 * np.arange(2), origin[1] + 20.0 * np.arange(3), data[::-1])
    # the datasets writer: PixelIsPoint keeps the tiepoint on the north-west sample
    h = plane_at(1005.0 + 10.0 * np.arange(2)[None, :], 1950.0 + 20.0 * np.arange(3)[:, None])
    path = write_geotiff(tmp_path / "pt.tif", h, (10.0, 20.0), (1005.0, 1950.0), pixel_is_area=False, epsg=32633)
    with tifffile.TiffFile(path) as tif:
        assert tif.pages[0].tags[33922].value == (0.0, 0.0, 0.0, 1005.0, 1990.0, 0.0)
    check_every_sample(read_heights(path), [1005.0, 1015.0], [1950.0, 1970.0, 1990.0], h)
    area = write_geotiff(tmp_path / "ar.tif", h, (10.0, 20.0), (1005.0, 1950.0))
    with tifffile.TiffFile(area) as tif:
        assert tif.pages[0].tags[33922].value == (0.0, 0.0, 0.0, 1000.0, 2000.0, 0.0)
    check_every_sample(read_heights(area), [1005.0, 1015.0], [1950.0, 1970.0, 1990.0], h)


def test_cog_and_south_up_and_east_to_west(tmp_path):
    nx, ny, d = 6, 5, 25.0
    xs, ys = UTM[0] + d * np.arange(nx), UTM[1] + d * np.arange(ny)
    h = plane_at(xs[None, :], ys[:, None])
    cog = write_geotiff(tmp_path / "c.tif", h, d, UTM, epsg=32633, driver="COG")
    with rasterio.open(cog) as ds:
        assert ds.tags(ns="IMAGE_STRUCTURE").get("LAYOUT") == "COG"
    check_every_sample(read_heights(cog), xs, ys, h)
    # south-up: first stored row is the southern one (positive e) -> not flipped
    south = write(tmp_path / "s.tif", h, Affine(d, 0, UTM[0] - d / 2, 0, d, UTM[1] - d / 2))
    s = read_raster(south)
    assert not s.flip_rows and s.origin == UTM
    check_every_sample(read_heights(south), xs, ys, h)
    # x running west (negative a): first stored column is the eastern one
    west = write(tmp_path / "w.tif", h[::-1, ::-1], Affine(-d, 0, xs[-1] + d / 2, 0, -d, ys[-1] + d / 2))
    assert read_raster(west).flip_cols
    check_every_sample(read_heights(west), xs, ys, h)


# ---- SRTM .hgt ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name, n, lon, lat", [("N45E006.hgt", 1201, 6, 45), ("S12W078.hgt", 3601, -78, -12)])
def test_hgt_corner_samples_sit_on_whole_degrees(tmp_path, name, n, lon, lat):
    rng = np.random.default_rng(n)
    stored = rng.integers(-400, 4800, size=(n, n)).astype(">i2")  # big-endian int16, north row first
    stored[0, 0] = -32768  # SRTM void: the north-west corner
    (tmp_path / name).write_bytes(stored.tobytes())
    s = read_raster(tmp_path / name)
    assert s.crs == "EPSG:4326" and s.units == "m" and s.values.dtype == np.int16
    assert CRS.from_user_input(s.crs).is_geographic
    assert s.origin == (float(lon), float(lat)) and s.spacing == (1.0 / (n - 1), 1.0 / (n - 1))
    assert s.missing.sum() == 1 and s.missing[0, 0] and s.xy_of(0, 0) == (float(lon), lat + 1.0)
    # kept on the degree lattice (no resampling: the samples stay exact), x and y in degrees times the
    # stated lengths of a degree (splinevis.io.georef; by default the tile is reprojected to UTM)
    g = read_heights(tmp_path / name, fill="nearest", keep_geographic=True)
    mx, my = degree_lengths(lat + 0.5)
    known = stored[::-1].astype(np.float64)
    assert g.extent == pytest.approx((lon * mx, (lon + 1.0) * mx, lat * my, (lat + 1.0) * my), rel=1e-12)
    assert g.x[0] == lon * mx and g.y[0] == lat * my and f"{mx:.6g} m" in g.source
    np.testing.assert_array_equal(g.heights[:-1], known[:-1])  # all but the northern row exactly
    np.testing.assert_array_equal(g.heights[-1, 1:], known[-1, 1:])  # the void (NW corner) is filled
    assert g.heights[-1, 0] in (known[-1, 1], known[-2, 0])  # by one of its two nearest samples


# ---- ESRI ASCII grid --------------------------------------------------------------------------------------
@pytest.mark.parametrize("keyword, origin", [("corner", (500015.0, 5100015.0)), ("center", (500000.0, 5100000.0))])
def test_ascii_grid_xllcorner_and_xllcenter(tmp_path, keyword, origin):
    rows = [[1, 2, 3], [4, -9999, 6]]  # north row first
    path = tmp_path / f"{keyword}.asc"
    path.write_text(f"ncols 3\nnrows 2\nxll{keyword} 500000\nyll{keyword} 5100000\ncellsize 30\n"
                    "NODATA_value -9999\n" + "\n".join(" ".join(map(str, r)) for r in rows) + "\n")
    s = read_raster(path)
    assert s.origin == origin and s.spacing == (30.0, 30.0) and s.crs is None
    assert s.missing.tolist() == [[False, False, False], [False, True, False]]
    assert s.xy_of(1, 1) == (origin[0] + 30.0, origin[1])
    g = read_heights(path, fill="linear")
    check_every_sample(g, origin[0] + 30.0 * np.arange(3), origin[1] + 30.0 * np.arange(2),
                       np.array([[4.0, 5.0, 6.0], [1.0, 2.0, 3.0]]))


# ---- other formats, unknown extension ---------------------------------------------------------------------
def test_img_and_unknown_extension_tried_with_gdal(tmp_path):
    d = 10.0
    xs, ys = UTM[0] + d * np.arange(4), UTM[1] + d * np.arange(3)
    h = plane_at(xs[None, :], ys[:, None])
    img = write(tmp_path / "h.img", h[::-1], Affine(d, 0, UTM[0] - d / 2, 0, -d, ys[-1] + d / 2), driver="HFA")
    assert ".img" in SUPPORTED_EXTENSIONS
    check_every_sample(read_heights(img), xs, ys, h)
    other = tmp_path / "heights.sdat"  # SAGA grid: no extension of ours, GDAL reads it
    rasterio.shutil.copy(img, other, driver="SAGA")
    assert other.suffix not in SUPPORTED_EXTENSIONS
    check_every_sample(read_heights(other), xs, ys, h)
    (tmp_path / "h.xyzw").write_text("not a raster\n")
    with pytest.raises(ValueError, match=r"h\.xyzw: extension '\.xyzw' is not supported; supported: \.vti .*\.tif "
                                         r"\(GeoTIFF/COG \(rasterio/GDAL\)\).* GDAL could not open it either \(.+\)"):
        read_heights(tmp_path / "h.xyzw")


# ---- errors -----------------------------------------------------------------------------------------------------
def test_rotated_geotransform_says_warp_north_up(tmp_path):
    path = write(tmp_path / "rot.tif", np.zeros((3, 3), np.float32), Affine(1.0, 0.2, 100.0, 0.1, -1.0, 200.0))
    with pytest.raises(ValueError, match=r"rot\.tif: the geotransform is rotated/sheared \(terms 0\.2, 0\.1\).*gdalwarp"):
        read_heights(path)


def test_ground_control_points_only_say_warp(tmp_path):
    from rasterio.control import GroundControlPoint

    path = tmp_path / "gcp.tif"
    gcps = [GroundControlPoint(0, 0, 500000.0, 5100060.0), GroundControlPoint(0, 3, 500090.0, 5100060.0),
            GroundControlPoint(2, 0, 500000.0, 5100000.0)]
    with rasterio.open(path, "w", driver="GTiff", width=3, height=2, count=1, dtype="float32",
                       gcps=gcps, crs="EPSG:32633") as ds:
        ds.write(np.zeros((2, 3), np.float32), 1)
    with rasterio.open(path) as ds:
        assert ds.transform.is_identity and len(ds.gcps[0]) == 3
    with pytest.raises(ValueError, match=r"gcp\.tif: georeferenced by 3 ground control points only.*gdalwarp"):
        read_heights(path)


def test_truncated_geotiff_is_a_clear_error(tmp_path):
    h = plane_at(UTM[0] + np.arange(200)[None, :], UTM[1] + np.arange(150)[:, None])
    full = write_geotiff(tmp_path / "full.tif", h, 1.0, UTM, epsg=32633)
    check_every_sample(read_heights(full), UTM[0] + np.arange(200.0), UTM[1] + np.arange(150.0), h)
    data = full.read_bytes()
    cut = tmp_path / "cut.tif"
    cut.write_bytes(data[:len(data) // 2])
    with pytest.raises(ValueError, match=r"cut\.tif: .*truncated or corrupt"):
        read_heights(cut)
    junk = tmp_path / "junk.tif"
    junk.write_bytes(b"II*\x00" + b"\x00" * 10)
    with pytest.raises(ValueError, match=r"junk\.tif: GDAL cannot open it as a raster \(.+\); if it is one, it is "
                                         r"truncated or corrupt\. Rasters are read through "
                                         r"GDAL: \.tif \(GeoTIFF/COG\).*\.hgt \(SRTM HGT\)"):
        read_heights(junk)


def test_multiband_picks_band_and_refuses_one_out_of_range(tmp_path):
    d = 5.0
    xs, ys = UTM[0] + d * np.arange(3), UTM[1] + d * np.arange(2)
    h = plane_at(xs[None, :], ys[:, None])
    bands = np.stack([h[::-1], 2 * h[::-1], 3 * h[::-1]])
    path = write(tmp_path / "three.tif", bands, Affine(d, 0, UTM[0] - d / 2, 0, -d, ys[-1] + d / 2))
    check_every_sample(read_heights(path), xs, ys, h)
    check_every_sample(read_heights(path, band=3), xs, ys, 3 * h)
    for band in (0, 4, "2"):
        with pytest.raises(ValueError, match=rf"three\.tif: band {band!r} does not exist; the raster has 3 band\(s\), "
                                             r"pass band=1\.\.3"):
            read_heights(path, band=band)


def test_plain_image_needs_geometry_and_georeferenced_refuses_it(tmp_path):
    plain = tmp_path / "plain.tif"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        write(plain, np.array([[2.0, 3.0], [0.0, 1.0]]), Affine.identity(), crs=None)
    with pytest.raises(ValueError, match=r"plain\.tif: no georeference .* pass spacing= and origin="):
        read_heights(plain)
    g = read_heights(plain, spacing=(2, 3), origin=UTM)
    check_every_sample(g, [UTM[0], UTM[0] + 2.0], [UTM[1], UTM[1] + 3.0], np.array([[0.0, 1.0], [2.0, 3.0]]))
    assert g.crs is None
    geo = write_geotiff(tmp_path / "geo.tif", np.zeros((2, 2)), (1.0, 1.0), (0.0, 0.0))
    with pytest.raises(ValueError, match=r"geo\.tif \(georeferenced\) carries its own spacing and origin; origin= "):
        read_heights(geo, origin=(5.0, 5.0))
    with pytest.raises(ValueError, match=r"geo\.tif: scalars= names a VTK point array; a raster has bands"):
        read_heights(geo, scalars="h")


def test_mask_band_and_scale_offset_and_units(tmp_path):
    d = 10.0
    xs, ys = UTM[0] + d * np.arange(3), UTM[1] + d * np.arange(3)
    raw = np.arange(9, dtype=np.int16).reshape(3, 3)  # north row first
    path = tmp_path / "m.tif"
    with rasterio.open(path, "w", driver="GTiff", width=3, height=3, count=1, dtype="int16", crs="EPSG:32633",
                       transform=Affine(d, 0, UTM[0] - d / 2, 0, -d, ys[-1] + d / 2)) as ds:
        ds.write(raw, 1)
        ds.scales, ds.offsets, ds.units = (0.5,), (100.0,), ("ft",)
        mask = np.full((3, 3), 255, np.uint8)
        mask[1, 2] = 0  # GDAL mask band: middle row, east column invalid
        ds.write_mask(mask)
    s = read_raster(path)
    assert s.units == "ft" and s.missing.tolist() == [[False] * 3, [False, False, True], [False] * 3]
    np.testing.assert_array_equal(s.values, raw * 0.5 + 100.0)
    g = read_heights(path, fill="nearest")
    known = (raw * 0.5 + 100.0)[::-1].copy()
    assert g.units == "ft"
    np.testing.assert_array_equal(g.x, xs)
    np.testing.assert_array_equal(g.y, ys)
    np.testing.assert_array_equal(g.heights[[0, 2]], known[[0, 2]])
    np.testing.assert_array_equal(g.heights[1, :2], known[1, :2])
    assert g.heights[1, 2] in (known[0, 2], known[2, 2], known[1, 1])  # the masked sample, filled by a neighbour


def test_crs_without_epsg_code_is_kept_as_wkt_and_round_trips(tmp_path):
    wkt = ('PROJCS["local TM",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],'
           'PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],'
           'PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",12.345],PARAMETER["scale_factor",1],'
           'PARAMETER["false_easting",0],PARAMETER["false_northing",0],UNIT["metre",1]]')
    path = write(tmp_path / "tm.tif", np.zeros((2, 2), np.float32), Affine(1, 0, 0, 0, -1, 2), crs=CRS.from_wkt(wkt))
    s = read_raster(path)
    assert s.crs.startswith("PROJCS[") or s.crs.startswith("PROJCRS[")
    back = CRS.from_user_input(s.crs)
    assert back.is_projected and not back.is_geographic and back.to_epsg() is None
    assert back.to_dict().get("lon_0") == 12.345
    geo = write(tmp_path / "g.tif", np.zeros((2, 2), np.float32), Affine(0.1, 0, 6, 0, -0.1, 46), crs="EPSG:4326")
    assert read_raster(geo).crs == "EPSG:4326" and CRS.from_user_input(read_raster(geo).crs).is_geographic
