"""NIfTI files (``.nii``, ``.nii.gz``; NIfTI-1 and NIfTI-2), read with nibabel, placed in their true frame.

What a NIfTI file stores: a header (348 bytes for NIfTI-1, 540 for NIfTI-2; either byte order) and the samples
right after it, the first index ``i`` fastest. The header gives the lattice size ``dim``, the voxel sizes
``pixdim``, a linear rescale ``scl_slope``/``scl_inter`` and up to two placements of the lattice in the world,
each with a code that says whether it is set and which space it refers to (scanner, aligned, Talairach, MNI):

* the **sform** (``sform_code``): a general 3 x 4 affine, rows ``srow_x``, ``srow_y``, ``srow_z``;
* the **qform** (``qform_code``): a rotation as a quaternion, the ``pixdim`` voxel sizes, a sign ``qfac`` for
  the third axis and an offset.

Which transform wins (the three methods of the NIfTI-1 data format definition, ``nifti1.h``):

* ``sform_code > 0``: method 3, the sform (what nibabel's ``image.affine`` gives too);
* else ``qform_code > 0``: method 2, the qform (quaternion, ``pixdim`` and ``qfac``; nibabel computes the matrix);
* else method 1, the Analyze 7.5 scaling: ``(x, y, z) = (pixdim[1] i, pixdim[2] j, pixdim[3] k)``, origin 0.
  (nibabel's ``image.affine`` differs here: it centres the volume and flips x; splinevis follows the standard.)

When both forms are set and place the lattice differently (the standard allows it: the qform often holds the
scanner frame, the sform a template's), the sform is used and a warning says how far apart they are.

How the 4 x 4 affine ``A`` becomes a :class:`~splinevis.io.VolumeGrid`: the columns of its 3 x 3 part are the
world steps of ``i``, ``j``, ``k``; their lengths are the spacing, ``A[:3, 3]`` the position of the first stored
sample. Unit-column entries within 4 float32 rounding units of 0 (the header stores the sform in float32 and the
quaternion in float32) count as 0. Then, as the other readers do (:mod:`.nrrd`, :mod:`.cube`):

* diagonal up to signs: axis flips. Every flipped axis is reversed and the origin moved to the smallest
  coordinate (``VolumeSamples.from_steps``), so the grid has positive spacing and no direction;
* any other orthonormal matrix (a permutation of the axes, an oblique acquisition): a rotated orthogonal
  lattice, kept as ``VolumeGrid.direction`` with the stored first sample as origin; orthonormal is judged at the
  precision of float32 storage (:func:`.volume_samples.orthonormal_direction`);
* a shear (non-orthogonal columns beyond that precision) raises ValueError naming the transform.

World coordinates are the file's: NIfTI's world is RAS+ (x to the right, y anterior, z superior), NRRD's
usually LPS+. splinevis converts neither (the NRRD reader keeps the coordinates of the file's ``space`` too), so
an NRRD export of the same scan in LPS has x and y negated. Units are the file's (``xyzt_units``, almost always
millimetres), not converted.

Samples: the stored type is kept (``VolumeGrid.dtype``), byte-swapped to native order; a valid ``scl_slope``
(finite, non-zero, per the standard) rescales them, ``values = scl_slope * stored + scl_inter`` in float64,
recorded in ``VolumeGrid.rescale``. RGB and complex types are refused.

Dimensions: 3-D files, and 4-D or 5-D files whose extra axes have one sample, read as volumes. A 4-D file
``(nx, ny, nz, nt)`` holds ``nt`` volumes (time points, diffusion directions): ``component=t`` picks volume
``t`` (0-based); without it the file is refused, with its shape in the message. A 5-D file ``(nx, ny, nz, 1,
nc)`` holds ``nc`` values per voxel (a vector field, the NIfTI convention for per-voxel components):
``component=`` picks one or takes the ``"magnitude"``.

nibabel is the ``[nifti]`` extra (``pip install 'splinevis[nifti]'``), imported only when a NIfTI file is read;
without it reading one raises ModuleNotFoundError naming the file and that command.

Why nibabel: it is the library the neuroimaging field keeps for NIfTI (both versions, both byte orders,
gzip, qform quaternions); VTK's ``vtkNIFTIImageReader`` (what ``pyvista.read`` uses) returns the lattice at
origin 0 with the voxel sizes and leaves the sform and qform aside as separate matrices.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .volume_samples import VolumeSamples, check_samples, check_size, orthonormal_direction, pick_component, \
    unit_rounding

__all__ = ["read_nifti", "nifti_affine"]

# float32 rounding unit (half an ulp, relative): the header stores srow, quaternion and pixdim in float32
_F32 = 2.0 ** -24
_METHODS = {3: "sform (NIfTI-1 method 3)", 2: "qform (NIfTI-1 method 2)", 1: "pixdim scaling (NIfTI-1 method 1)"}


def nifti_affine(header) -> tuple:
    """``(affine, method)``: the 4 x 4 float64 voxel-to-world matrix the NIfTI-1 standard picks, and which.

    ``method`` is 3 (sform, ``sform_code > 0``), 2 (qform, ``qform_code > 0``) or 1 (``pixdim`` scaling, no
    offset); see the module notes.

    Parameters
    ----------
    header : nibabel.Nifti1Header or nibabel.Nifti2Header

    Returns
    -------
    ((4, 4) ndarray, int)

    Examples
    --------
    >>> import nibabel as nib
    >>> h = nib.Nifti1Header(); h.set_data_shape((4, 5, 6)); h.set_zooms((2.0, 3.0, 4.0))
    >>> h.set_sform(np.diag([-2.0, 3.0, 4.0, 1.0]), code=4)
    >>> nifti_affine(h)[1], nifti_affine(h)[0][0, 0]
    (3, np.float64(-2.0))
    >>> h.set_sform(None, code=0); h.set_qform(None, code=0)
    >>> nifti_affine(h)[0].diagonal().tolist(), nifti_affine(h)[1]
    ([2.0, 3.0, 4.0, 1.0], 1)
    """
    if int(header["sform_code"]) > 0:
        return np.asarray(header.get_sform(), dtype=np.float64), 3
    if int(header["qform_code"]) > 0:
        return np.asarray(header.get_qform(), dtype=np.float64), 2
    affine = np.eye(4)
    affine[[0, 1, 2], [0, 1, 2]] = np.asarray(header["pixdim"][1:4], dtype=np.float64)
    return affine, 1


def _load(path: Path):
    try:  # here only: nibabel is the [nifti] extra, and no other reader needs it
        import nibabel as nib
    except ModuleNotFoundError as exc:  # the advice of splinevis._optional, with the file it was needed for
        if exc.name != "nibabel":
            raise
        raise ModuleNotFoundError(f"{path}: {exc}", name=exc.name) from None

    try:
        img = nib.load(str(path))
    except Exception as exc:  # nibabel's ImageFileError, a damaged gzip stream (OSError, EOFError, zlib.error)
        raise ValueError(f"{path}: could not be read as NIfTI ({type(exc).__name__}: {exc}).") from exc
    if not isinstance(img, (nib.Nifti1Image, nib.Nifti2Image)):
        raise ValueError(f"{path}: nibabel reads it as {type(img).__name__}, not a single-file NIfTI image.")
    return img


def _pick_volume(raw: np.ndarray, shape: tuple, where: str, component) -> np.ndarray:
    """The 3-D ``(nx, ny, nz)`` samples of a file of ``shape`` (trailing axes of one sample dropped)."""
    dims = list(shape)
    while len(dims) > 3 and dims[-1] == 1:
        dims.pop()
    if len(dims) < 3:
        raise ValueError(f"{where}: a NIfTI image of shape {tuple(shape)} is {len(dims)}-D; a volume needs 3 axes."
                         + (" A 2-D image is a height field: use splinevis.io.read_heights." if len(dims) == 2
                            else ""))
    raw = raw.reshape(dims)
    if len(dims) == 3:
        if component is not None:
            raise ValueError(f"{where}: component= picks a volume of a 4-D NIfTI file or a value of a 5-D one; "
                             f"this file is 3-D {tuple(dims)}. Drop component=.")
        return raw
    if len(dims) == 4:
        nt = dims[3]
        if component is None or isinstance(component, str):
            raise ValueError(f"{where}: a 4-D NIfTI file of shape (nx, ny, nz, nt) = {tuple(dims)} holds {nt} "
                             "volumes (time points or directions); a volume is 3-D. "
                             + ("A series has no magnitude: " if isinstance(component, str) else "")
                             + f"Pass component=0..{nt - 1} (an int) to read one of them, or split the series "
                             "first (e.g. nibabel's image.slicer[..., t]).")
        if not -nt <= int(component) < nt:
            raise ValueError(f"{where}: component={component} is out of range; the file holds {nt} volumes "
                             f"(0..{nt - 1}).")
        return raw[..., int(component)]
    if len(dims) == 5 and dims[3] == 1:
        return pick_component(raw[:, :, :, 0, :], dims[4], "per-voxel values (5th NIfTI axis)", where, component)
    raise ValueError(f"{where}: a NIfTI image of shape {tuple(shape)}; a volume needs 3 spatial axes, plus at most "
                     "a series axis (4-D, component= picks one) or a 5th axis of per-voxel values.")


def _lattice(affine: np.ndarray, method: int, where: str):
    """``(steps, origin, direction)``: signed steps and first sample of an axis-aligned lattice (direction None),
    or positive steps and the first stored sample of a rotated one."""
    m = affine[:3, :3]
    lengths = np.linalg.norm(m, axis=0)
    how = _METHODS[method]
    if not np.isfinite(affine[:3]).all() or np.any(lengths == 0):
        raise ValueError(f"{where}: the {how} {np.round(affine[:3], 9).tolist()} has a zero or non-finite axis; "
                         "the lattice has no placement. Fix the header (e.g. nibabel's set_sform).")
    unit = m / lengths
    unit = np.where(np.abs(unit) <= 4 * _F32, 0.0, unit)  # float32 storage: rounding, not a rotation
    origin = affine[:3, 3].copy()
    if np.count_nonzero(unit) == 3 and np.count_nonzero(np.diag(unit)) == 3 \
            and np.all(np.abs(np.abs(np.diag(unit)) - 1.0) <= 4 * _F32):
        return np.diag(m).copy(), origin, None  # axis flips at most: the stored steps, signed
    rounding = unit_rounding(m, _F32 * np.abs(m).max(axis=0))  # each entry within _F32 |entry| of the stored one
    direction = orthonormal_direction(unit, f"{where}, {how}", rounding=rounding)  # a shear raises, naming it
    return lengths, origin, direction


def read_nifti(path: Path, scalars=None, component=None) -> VolumeSamples:
    """Read a NIfTI-1 or NIfTI-2 file (``.nii``, ``.nii.gz``), placed by the transform the standard picks.

    Parameters
    ----------
    path : Path
        An existing NIfTI file.
    scalars : None
        A NIfTI file holds one unnamed array; a name raises.
    component : None, int or "magnitude"
        A 4-D file: the volume index ``t`` (0-based, required). A 5-D file of per-voxel values: one of them or
        their norm. A 3-D file: None.

    Returns
    -------
    VolumeSamples
        ``values[k, j, i]`` in the stored type (native byte order); ``rescale`` holds ``(scl_slope, scl_inter)``
        (``(1.0, 0.0)`` without scaling); flips or ``direction`` as the module notes say.

    Examples
    --------
    >>> import tempfile, nibabel as nib
    >>> data = np.arange(24, dtype=np.int16).reshape(4, 3, 2)  # nibabel's order: [i, j, k]
    >>> affine = np.diag([-2.0, 1.0, 3.0, 1.0]); affine[:3, 3] = (10.0, -5.0, 0.0)  # x flipped
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     p = Path(folder) / "a.nii.gz"
    ...     nib.save(nib.Nifti1Image(data, affine), p)
    ...     s = read_nifti(p)
    >>> s.spacing, s.origin, s.flips, s.values.shape
    ((2.0, 1.0, 3.0), (4.0, -5.0, 0.0), (True, False, False), (2, 3, 4))
    """
    where = str(path)
    if scalars is not None:
        raise ValueError(f"{path}: scalars={scalars!r} names an array of a VTK file; a NIfTI file holds one "
                         "unnamed array. Drop scalars=.")
    img = _load(path)
    hdr = img.header
    dt = hdr.get_data_dtype()
    if dt.names is not None or dt.kind == "c":
        raise ValueError(f"{path}: NIfTI data type {dt} ({'RGB' if dt.names else 'complex'}) is not a scalar per "
                         "voxel; a volume needs real numbers. Convert to one channel first.")
    raw = np.asanyarray(img.dataobj.get_unscaled())
    values = _pick_volume(raw, img.shape, where, component)
    values = np.transpose(values, (2, 1, 0))  # [i, j, k] -> [k, j, i]
    if not values.dtype.isnative:
        values = values.astype(values.dtype.newbyteorder("="))
    check_samples(values, where)
    check_size(values.shape, where)
    # nibabel moves scl_slope/scl_inter from the header into the array proxy on load (1 and 0 when the file's slope
    # is 0 or not finite: no scaling, per the standard)
    slope, inter = float(img.dataobj.slope), float(img.dataobj.inter)
    if not (np.isfinite(slope) and np.isfinite(inter) and slope != 0):
        raise ValueError(f"{path}: invalid data scaling scl_slope = {slope!r}, scl_inter = {inter!r}.")
    try:
        affine, method = nifti_affine(hdr)
    except Exception as exc:  # nibabel's HeaderDataError: e.g. a qform with negative pixdim
        raise ValueError(f"{path}: the NIfTI placement cannot be computed ({type(exc).__name__}: {exc}).") from None
    if method == 3 and int(hdr["qform_code"]) > 0:
        _compare_forms(hdr, affine, values.shape, where)
    counts = values.shape[::-1]
    steps, origin, direction = _lattice(affine, method, where)
    if direction is None:
        samples = VolumeSamples.from_steps(values, origin, steps, counts, where)
    else:
        samples = VolumeSamples(values=values, spacing=tuple(float(s) for s in steps),
                                origin=tuple(float(o) for o in origin), source=where, direction=direction)
    # read by read_volume's last step (VolumeGrid.rescale); VolumeSamples has no field for it
    samples.rescale = (slope, inter)
    return samples


def _compare_forms(hdr, sform: np.ndarray, shape: tuple, where: str) -> None:
    """Warn when the qform places the lattice's corners elsewhere than the sform (which is used)."""
    try:
        qform = np.asarray(hdr.get_qform(), dtype=np.float64)
    except Exception:  # a damaged qform that the sform overrides anyway
        return
    nz, ny, nx = shape
    corners = np.array([[i, j, k, 1.0] for i in (0, nx - 1) for j in (0, ny - 1) for k in (0, nz - 1)])
    apart = float(np.linalg.norm(corners @ (sform - qform)[:3].T, axis=1).max())
    voxel = float(np.linalg.norm(sform[:3, :3], axis=0).min())
    if apart > 1e-3 * voxel:
        from .._warnings import warn_user

        warn_user(f"{where}: the sform (code {int(hdr['sform_code'])}) and the qform (code {int(hdr['qform_code'])}) "
                  f"place the volume differently (corners up to {apart:.4g} apart, voxel {voxel:.4g}); drawn with the "
                  "sform (NIfTI-1 method 3, as nibabel does).")
