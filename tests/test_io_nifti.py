"""NIfTI files through read_volume: placed by the transform the NIfTI-1 standard picks (sform, else qform, else
pixdim), every known sample at its known world position.

Files are written with nibabel with chosen affines. Unless a test says otherwise the steps, origins and indices are
small binary fractions (multiples of 0.5 below 2**20), so every product and sum of ``origin + i * step`` and of
``affine @ (i, j, k, 1)`` is exact in float64 and in the float32 header: world positions must agree *exactly*.
"""

from __future__ import annotations

import gzip
import warnings

import nibabel as nib
import numpy as np
import pytest
from nibabel.affines import apply_affine

from splinevis.check.detect import detect_family
from splinevis.io import read_volume

EPS = 2.0 ** -53  # float64 rounding unit


def ramp(shape=(5, 4, 3), dtype=np.int16):
    """``data[i, j, k] = 100 i + 10 j + k - 50`` (distinct, some negative), nibabel's [i, j, k] order."""
    i, j, k = np.indices(shape)
    return (100 * i + 10 * j + k - 50).astype(dtype)


def write(path, data, *, sform=None, sform_code=0, qform=None, qform_code=0, endian="<", zooms=None,
          slope=None, inter=0.0):
    hdr = nib.Nifti1Header(endianness=endian)
    hdr.set_data_dtype(data.dtype)
    hdr.set_data_shape(data.shape)
    if zooms is not None:
        hdr.set_zooms(zooms)
    img = nib.Nifti1Image(data, None, header=hdr)
    img.header.set_sform(sform, code=sform_code)
    img.header.set_qform(qform, code=qform_code)
    if slope is not None:
        img.header.set_slope_inter(slope, inter)
    nib.save(img, path)
    return path


def placed(grid):
    """(world points, values) of every sample of a VolumeGrid, in float64."""
    k, j, i = np.indices(grid.shape).reshape(3, -1)
    world = grid.lattice_to_world(grid.to_world(np.column_stack([i, j, k]).astype(float)))
    return world, grid.values[k, j, i]


def stored(data, affine):
    """(world points, values) of every stored sample under ``affine`` (nibabel's apply_affine)."""
    ijk = np.indices(data.shape[:3]).reshape(3, -1).T
    return apply_affine(affine, ijk), data[tuple(ijk.T)].astype(np.float64)


def assert_same_samples(grid, data, affine, tol=0.0):
    """Every stored sample appears in the grid at the world point ``affine`` gives it, with its value."""
    wa, va = placed(grid)
    wb, vb = stored(data, affine)
    oa = np.lexsort(np.round(wa, 6).T[::-1])
    ob = np.lexsort(np.round(wb, 6).T[::-1])
    assert np.abs(wa[oa] - wb[ob]).max() <= tol
    assert np.array_equal(va[oa], vb[ob])


def test_sform_only_places_every_sample_exactly(tmp_path):
    data = ramp()
    A = np.diag([1.5, 2.0, 0.5, 1.0])
    A[:3, 3] = (-90.0, 126.5, 1e6)
    p = write(tmp_path / "s.nii", data, sform=A, sform_code=4)
    g = read_volume(p)
    assert (g.spacing, g.origin, g.dtype, g.rescale) == ((1.5, 2.0, 0.5), (-90.0, 126.5, 1e6), "int16", (1.0, 0.0))
    assert not g.is_rotated and g.shape == (3, 4, 5)
    assert g.values[2, 3, 4] == data[4, 3, 2]
    assert g.to_world([4, 3, 2]).tolist() == apply_affine(A, [4, 3, 2]).tolist()
    assert_same_samples(g, data, A)


def test_qform_only_with_a_flip_and_a_code_zero_sform_ignored(tmp_path):
    data = ramp()
    Q = np.diag([2.0, -3.0, 4.0, 1.0])  # det < 0: qfac = -1 and a 180 degree quaternion (0, 1, 0, 0), exact
    Q[:3, 3] = (10.0, 20.0, -30.0)
    decoy = np.diag([7.0, 7.0, 7.0, 1.0])
    p = write(tmp_path / "q.nii.gz", data, qform=Q, qform_code=1, sform=decoy, sform_code=0)
    assert np.array_equal(nib.load(p).header.get_qform(), Q)
    g = read_volume(p)
    assert g.spacing == (2.0, 3.0, 4.0) and g.origin == (10.0, 20.0 - 3.0 * 3, -30.0) and not g.is_rotated
    assert_same_samples(g, data, Q)


def test_sform_wins_over_a_different_qform_and_says_so(tmp_path):
    data = ramp()
    S = np.diag([2.0, 2.0, 2.0, 1.0])
    S[:3, 3] = (-90.0, -126.0, -72.0)
    Q = np.diag([2.0, 2.0, 2.0, 1.0])  # the scanner frame, 5 mm away
    Q[:3, 3] = (-85.0, -126.0, -72.0)
    p = write(tmp_path / "both.nii", data, sform=S, sform_code=4, qform=Q, qform_code=1)
    with pytest.warns(UserWarning, match=r"sform \(code 4\) and the qform \(code 1\) place the volume differently "
                                         r"\(corners up to 5 apart.*drawn with the sform"):
        g = read_volume(p)
    assert g.origin == (-90.0, -126.0, -72.0)
    assert_same_samples(g, data, S)
    write(tmp_path / "same.nii", data, sform=S, sform_code=4, qform=S, qform_code=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # equal forms: nothing to say
        assert read_volume(tmp_path / "same.nii").origin == (-90.0, -126.0, -72.0)


def test_no_form_is_the_pixdim_scaling_of_method_1(tmp_path):
    data = ramp()
    p = write(tmp_path / "plain.nii", data, zooms=(1.5, 2.0, 2.5))
    g = read_volume(p)
    assert g.spacing == (1.5, 2.0, 2.5) and g.origin == (0.0, 0.0, 0.0)
    assert_same_samples(g, data, np.diag([1.5, 2.0, 2.5, 1.0]))


def test_flipped_axes_are_reversed_like_the_other_readers(tmp_path):
    data = ramp()
    A = np.diag([-2.0, 1.0, -0.5, 1.0])  # x and z stored from right to left, top to bottom
    A[:3, 3] = (90.0, -126.0, 72.0)
    g = read_volume(write(tmp_path / "flip.nii", data, sform=A, sform_code=2))
    assert g.spacing == (2.0, 1.0, 0.5) and g.origin == (90.0 - 2.0 * 4, -126.0, 72.0 - 0.5 * 2)
    assert not g.is_rotated
    assert g.values[0, 0, 0] == data[4, 0, 2]  # the smallest x and z: the last stored i and k
    assert_same_samples(g, data, A)


def test_permuted_axes_are_a_rotated_lattice_with_its_direction(tmp_path):
    data = ramp()
    A = np.array([[0.0, -3.0, 0.0, 5.0],  # i runs along +y, j along -x, k along +z
                  [2.0, 0.0, 0.0, -7.0],
                  [0.0, 0.0, 1.5, 0.5],
                  [0.0, 0.0, 0.0, 1.0]])
    g = read_volume(write(tmp_path / "perm.nii", data, sform=A, sform_code=1))
    assert g.is_rotated and g.spacing == (2.0, 3.0, 1.5) and g.origin == (5.0, -7.0, 0.5)
    assert g.direction == ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert_same_samples(g, data, A)


def test_oblique_qform_matches_nibabels_affine_to_float64_rounding(tmp_path):
    data = ramp()
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    Q = np.array([[2 * c, -3 * s, 0, -20.0], [2 * s, 3 * c, 0, 10.0], [0, 0, 4.0, 3.0], [0, 0, 0, 1.0]])
    p = write(tmp_path / "oblique.nii", data, qform=Q, qform_code=1)
    A = nib.load(p).affine  # the matrix of the stored float32 quaternion: orthonormal to float64 rounding
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no correction beyond float64 rounding to report
        g = read_volume(p)
    assert g.is_rotated
    # world = o + D (s * i) against A (i, 1): the unit columns of A, their polar factor (moved by at most 64
    # rounding units, else a warning) and three products and sums, each a few rounding units of the extent
    extent = np.abs(stored(data, A)[0]).max()
    assert_same_samples(g, data, A, tol=(3 * 64 + 16) * EPS * extent)


def test_oblique_sform_is_orthonormal_only_to_float32(tmp_path):
    data = ramp()
    ca, sa, cb, sb = np.cos(np.pi / 6), np.sin(np.pi / 6), np.cos(np.pi / 9), np.sin(np.pi / 9)
    R = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]]) @ np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    A = np.eye(4)
    A[:3, :3] = R @ np.diag([2.0, 3.0, 1.5])
    A[:3, 3] = (-20.0, 10.0, 3.0)
    p = write(tmp_path / "oblique_s.nii", data, sform=A, sform_code=1)
    stored_A = nib.load(p).affine  # the float32 srow values: their unit columns are orthogonal to ~3e-8 only
    with pytest.warns(UserWarning, match=r"sform \(NIfTI-1 method 3\): the lattice axes are orthonormal only to the "
                                         "precision"):
        g = read_volume(p)
    # each stored entry within 2**-24 of its value relative to the column's largest: unit columns within
    # e = 2 sqrt(3) 2**-24 (Euclidean) of the true ones, so |U^T U - I| <= 2e + e^2 entrywise (else refused) and
    # the nearest orthonormal matrix Q is within 3 (2e + e^2) of U in the 2-norm; a world point moves by at most
    # that times the length of its lattice vector (below `extent`), plus a few float64 roundings
    e = 2 * np.sqrt(3) * 2.0 ** -24
    extent = np.linalg.norm([2.0 * 4, 3.0 * 3, 1.5 * 2])
    assert_same_samples(g, data, stored_A, tol=3 * (2 * e + e * e) * extent + 64 * EPS * 30)


def test_big_endian_header_and_samples(tmp_path):
    data = ramp(dtype=np.int16)
    A = np.diag([2.0, 2.0, 2.0, 1.0])
    A[:3, 3] = (-4.0, 6.0, -8.0)
    p = write(tmp_path / "big.nii.gz", data.astype(">i2"), sform=A, sform_code=1, endian=">")
    assert nib.load(p).header.endianness == ">"
    g = read_volume(p)
    assert g.dtype == "int16" and g.value_range == (-50.0, 100 * 4 + 10 * 3 + 2 - 50.0)
    assert_same_samples(g, data, A)


def set_scaling(path, slope, inter):
    """Write scl_slope and scl_inter (float32 at bytes 112 and 116 of a NIfTI-1 header) into an uncompressed file:
    nibabel recomputes the scaling of the array it saves, so the stored integers are kept by patching the header."""
    blob = bytearray(path.read_bytes())
    order = nib.load(path).header.endianness
    blob[112:120] = np.array([slope, inter], dtype=order + "f4").tobytes()
    path.write_bytes(bytes(blob))
    return path


def test_scl_slope_and_inter_are_applied_in_float64(tmp_path):
    data = ramp()
    A = np.diag([1.0, 1.0, 1.0, 1.0])
    for endian in "<>":
        p = set_scaling(write(tmp_path / f"scaled{endian == '>'}.nii", data, sform=A, sform_code=1, endian=endian),
                        0.5, -10.0)
        assert (nib.load(p).dataobj.slope, nib.load(p).dataobj.inter) == (0.5, -10.0)
        g = read_volume(p)
        assert g.dtype == "int16" and g.rescale == (0.5, -10.0)
        assert_same_samples(g, 0.5 * data.astype(np.float64) - 10.0, A)  # halves of integers: exact
        assert np.array_equal(g.values, np.transpose(nib.load(p).get_fdata(), (2, 1, 0)))
    # scl_slope = 0: no scaling, per the standard (the intercept is ignored too)
    p0 = set_scaling(write(tmp_path / "slope0.nii", data, sform=A, sform_code=1), 0.0, 7.0)
    g0 = read_volume(p0)
    assert g0.rescale == (1.0, 0.0) and g0.value_range == (-50.0, 382.0)


def test_a_file_like_the_mni_template_is_placed_by_its_sform(tmp_path):
    """The header of the MNI avg152 T1 template file: 91 x 109 x 91 uint8, 2 mm, big-endian, sform_code 4 (MNI)
    with origin (-90, -126, -72), qform_code 0 (VTK and pyvista put it at origin 0)."""
    data = np.zeros((91, 109, 91), np.uint8)
    marks = np.array([[0, 0, 0], [90, 108, 90], [45, 63, 36], [10, 100, 80]])
    data[tuple(marks.T)] = (11, 22, 33, 44)
    A = np.diag([2.0, 2.0, 2.0, 1.0])
    A[:3, 3] = (-90.0, -126.0, -72.0)
    p = write(tmp_path / "avg152T1_like.nii.gz", data, sform=A, sform_code=4, endian=">")
    h = nib.load(p).header
    assert (h.endianness, int(h["sform_code"]), int(h["qform_code"])) == (">", 4, 0)
    assert detect_family(p) == ("volume", "NIfTI")
    g = read_volume(p)
    assert g.origin == (-90.0, -126.0, -72.0) and g.spacing == (2.0, 2.0, 2.0) and g.dtype == "uint8"
    assert g.bounds == (-90.0, 90.0, -126.0, 90.0, -72.0, 108.0)
    for (i, j, k), v in zip(marks, (11, 22, 33, 44)):
        assert g.to_world([i, j, k]).tolist() == apply_affine(A, [i, j, k]).tolist()
        assert g.values[k, j, i] == v


def test_4d_files_need_a_volume_index(tmp_path):
    series = np.stack([ramp() + 1000 * t for t in range(5)], axis=-1)  # (5, 4, 3, 5)
    A = np.diag([2.0, 2.0, 2.0, 1.0])
    p = write(tmp_path / "series.nii", series, sform=A, sform_code=1)
    with pytest.raises(ValueError, match=r"series\.nii: a 4-D NIfTI file of shape \(nx, ny, nz, nt\) = "
                                         r"\(5, 4, 3, 5\) holds 5 volumes .* Pass component=0\.\.4"):
        read_volume(p)
    with pytest.raises(ValueError, match="A series has no magnitude"):
        read_volume(p, component="magnitude")
    with pytest.raises(ValueError, match=r"component=5 is out of range; the file holds 5 volumes"):
        read_volume(p, component=5)
    assert_same_samples(read_volume(p, component=2), series[..., 2], A)
    single = write(tmp_path / "one.nii", series[..., :1], sform=A, sform_code=1)  # (5, 4, 3, 1): a volume
    assert_same_samples(read_volume(single), series[..., 0], A)
    vec = np.stack([ramp(), 2 * ramp()], axis=-1)[:, :, :, None, :].astype(np.float32)  # (5, 4, 3, 1, 2)
    pv = write(tmp_path / "vec.nii", vec, sform=A, sform_code=1)
    norm = np.sqrt(vec[:, :, :, 0, 0].astype(np.float64) ** 2 + vec[:, :, :, 0, 1].astype(np.float64) ** 2)
    assert_same_samples(read_volume(pv, component="magnitude"), norm, A)


def test_sheared_affine_is_refused_with_the_reason(tmp_path):
    A = np.diag([2.0, 2.0, 2.0, 1.0])
    A[0, 1] = 0.2  # j steps 0.2 along x as well: columns not orthogonal (cos 0.0995, far beyond float32)
    p = write(tmp_path / "shear.nii", ramp(), sform=A, sform_code=1)
    with pytest.raises(ValueError, match=r"shear\.nii, sform \(NIfTI-1 method 3\): the direction matrix .* is not "
                                         r"orthonormal \(a shear or non-orthogonal axes"):
        read_volume(p)


def test_missing_damaged_and_misused_files(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"volume file not found: .*nothere\.nii\.gz"):
        read_volume(tmp_path / "nothere.nii.gz")
    (tmp_path / "junk.nii").write_bytes(b"not a nifti header" * 40)
    with pytest.raises(ValueError, match=r"junk\.nii: could not be read as NIfTI"):
        read_volume(tmp_path / "junk.nii")
    (tmp_path / "junk.nii.gz").write_bytes(gzip.compress(b"\0" * 400))
    with pytest.raises(ValueError, match=r"junk\.nii\.gz: could not be read as NIfTI"):
        read_volume(tmp_path / "junk.nii.gz")
    p = write(tmp_path / "ok.nii", ramp(), sform=np.eye(4), sform_code=1)
    with pytest.raises(ValueError, match="carries its own spacing and origin"):
        read_volume(p, spacing=(1, 1, 1))
    with pytest.raises(ValueError, match="a NIfTI file holds one unnamed array"):
        read_volume(p, scalars="intensity")
    with pytest.raises(ValueError, match="describe headerless raw files"):
        read_volume(p, dtype="int16")
    flat = write(tmp_path / "flat.nii", ramp((5, 4, 1)), sform=np.eye(4), sform_code=1)
    with pytest.raises(ValueError, match="at least 2 samples on every axis"):
        read_volume(flat)
    (tmp_path / "other.gz").write_bytes(gzip.compress(b"x"))
    with pytest.raises(ValueError, match=r"gzip-compressed \(other than \.nii\.gz\) files are not read"):
        read_volume(tmp_path / "other.gz")


@pytest.mark.parametrize("form", ["sform", "qform"])
def test_the_check_judge_places_vtks_reading_by_the_files_transform(tmp_path, form):
    """``vtkNIFTIImageReader`` returns the lattice at origin 0 and keeps the sform/qform as a separate matrix; the
    volume judge moves VTK's points by it before matching them with the reader's world positions. The transform
    has an offset, a rotation about z and (for the qform) qfac = -1, so VTK's bare points are far from every world
    position: without the move all 60 samples differ. Tolerance: the judge matches positions to 1e-3 of the
    smallest spacing; float32 storage of the transform moves a point by ~1e-7 of its coordinates, far below."""
    import pyvista as pv

    from splinevis.io import VolumeGrid
    from splinevis.volume.judge import _compare_in_world

    c, s = np.cos(0.3), np.sin(0.3)
    A = np.eye(4)
    A[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.diag([2.0, 3.0, -4.0 if form == "qform" else 4.0])
    A[:3, 3] = [10.0, -20.0, 5.0]
    kw = {"sform": A, "sform_code": 2} if form == "sform" else {"qform": A, "qform_code": 1}
    p = write(tmp_path / f"{form}.nii", ramp(), **kw)
    with warnings.catch_warnings():  # the float32 sform is orthonormal to its precision only: the reader says so
        warnings.simplefilter("ignore", UserWarning)
        grid = read_volume(p)
    ds = pv.read(p)
    theirs = np.asarray(ds.point_data[ds.active_scalars_name], dtype=np.float64)
    assert _compare_in_world(p, ds, theirs, grid, np.asarray(grid.values, dtype=np.float64)) == (0, "")
    moved = VolumeGrid(grid.values, spacing=grid.spacing, origin=np.asarray(grid.origin) + [0.5, 0, 0],
                       direction=grid.direction)
    bad, why = _compare_in_world(p, ds, theirs, moved, np.asarray(grid.values, dtype=np.float64))
    assert bad == 60 and "sample positions differ" in why
