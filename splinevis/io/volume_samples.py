"""Volume samples as a source stores them, and the checks every volume reader applies to them.

Every volume reader (numpy arrays here, pyvista/VTK objects and files in :mod:`.volume_vtk`, NRRD in
:mod:`.nrrd`, headerless files in :mod:`.raw`) hands a :class:`VolumeSamples` to
:func:`splinevis.io.read_volume`, which reverses flipped axes, reports or fills NaN/inf samples and
returns a :class:`~splinevis.io.VolumeGrid`. Shared here: multi-component arrays (``component=``),
the minimum size, and direction matrices that are only axis flips.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._common import check_exact_in_float64, check_real_dtype

__all__ = ["VolumeSamples", "GEOMETRY_ARGS_APPLY_TO", "check_samples", "check_size", "pick_component", "from_array",
           "axis_signs", "orthonormal_direction", "printed_rounding", "unit_rounding"]

#: The sources ``spacing=``/``origin=`` are meant for (the others carry their own geometry).
GEOMETRY_ARGS_APPLY_TO = "numpy arrays and raw files"


@dataclass
class VolumeSamples:
    """Samples in the source's dtype and order, with the geometry of the grid they become.

    Parameters
    ----------
    values : (nz, ny, nx) ndarray
        In the source's dtype and stored order.
    spacing, origin : (3,) tuples
        Already describe the flipped (returned) grid: spacing > 0, origin at the smallest coordinates.
    source : str
        Where the data came from.
    scalars : str or None
        Name of the array read, if the source names it.
    flips : (3,) bools
        ``flips[a]`` reverses axis ``a`` (x, y, z) of ``values``.

    Examples
    --------
    >>> s = VolumeSamples(np.zeros((2, 3, 4), dtype=np.int16), (1.0, 1.0, 2.5), (0.0, 0.0, 0.0), "ct.raw")
    >>> s.values.dtype, s.flips
    (dtype('int16'), (False, False, False))
    """

    values: np.ndarray
    spacing: tuple
    origin: tuple
    source: str
    scalars: str | None = None
    flips: tuple = (False, False, False)
    direction: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    @classmethod
    def from_steps(cls, values, first, steps, counts, source: str, scalars=None) -> VolumeSamples:
        """Samples whose stored index runs with signed world ``steps`` from the ``first`` stored point.

        Parameters
        ----------
        values : (nz, ny, nx) ndarray
            In stored order.
        first : (3,) floats
            World position of the first stored sample.
        steps : (3,) floats
            Signed world step of the stored index along x, y, z; a negative step flips that axis.
        counts : (3,) ints
            Samples along x, y, z.
        source, scalars : str
            As in the class.

        Returns
        -------
        VolumeSamples

        Examples
        --------
        A z axis stored from top to bottom (step -2 from z = 10):

        >>> s = VolumeSamples.from_steps(np.zeros((3, 2, 2)), (0.0, 0.0, 10.0), (1.0, 1.0, -2.0), (2, 2, 3), "x")
        >>> s.spacing, s.origin, s.flips
        ((1.0, 1.0, 2.0), (0.0, 0.0, 6.0), (False, False, True))
        """
        flips = tuple(bool(s < 0) for s in steps)
        origin = tuple(float(f + s * (m - 1)) if s < 0 else float(f) for f, s, m in zip(first, steps, counts))
        return cls(values=values, spacing=tuple(float(abs(s)) for s in steps), origin=origin, source=source,
                   scalars=scalars, flips=flips)

    def oriented(self) -> np.ndarray:
        """``values`` with the flipped axes reversed (a view).

        Examples
        --------
        >>> s = VolumeSamples(np.arange(8).reshape(2, 2, 2), (1.0,) * 3, (0.0,) * 3, "x", flips=(True, False, False))
        >>> s.oriented()[0].tolist()  # x reversed
        [[1, 0], [3, 2]]
        """
        v = self.values
        fx, fy, fz = self.flips
        v = v[::-1 if fz else 1, ::-1 if fy else 1, ::-1 if fx else 1]
        return v


def check_samples(arr: np.ndarray, where: str) -> None:
    """Raise unless ``arr`` holds real numbers that float64 represents exactly.

    Parameters
    ----------
    arr : ndarray
        The samples.
    where : str
        The source, for the messages.

    Examples
    --------
    >>> check_samples(np.array([1, 2], dtype=np.uint64), "numpy array")  # exact in float64: fine
    >>> check_samples(np.array(["7", "8"]), "numpy array")
    Traceback (most recent call last):
    TypeError: numpy array: samples must be real numbers, got dtype <U1 (strings).
    """
    check_real_dtype(arr, where, "samples")
    check_exact_in_float64(arr, where)


def check_size(shape, where: str) -> None:
    """Raise ValueError unless every axis of ``shape`` (nz, ny, nx) has at least 2 samples.

    Parameters
    ----------
    shape : (3,) ints
        ``(nz, ny, nx)``.
    where : str
        The source, for the message.

    Examples
    --------
    >>> check_size((1, 64, 64), "scan.nrrd")
    Traceback (most recent call last):
    ValueError: scan.nrrd: a volume needs at least 2 samples on every axis; shape (nz, ny, nx) = (1, 64, 64) has 1 along z. A single slice is a 2-D image (see splinevis.io.read_heights).
    """
    if min(shape) < 2:
        axis = "zyx"[int(np.argmin(shape))]
        raise ValueError(f"{where}: a volume needs at least 2 samples on every axis; shape (nz, ny, nx) = "
                         f"{tuple(int(s) for s in shape)} has {min(shape)} along {axis}."
                         + (" A single slice is a 2-D image (see splinevis.io.read_heights)." if min(shape) == 1
                            else ""))


def pick_component(arr: np.ndarray, ncomp: int, label: str, where: str, component) -> np.ndarray:
    """One value per sample from an array with ``ncomp`` components on its last axis.

    Parameters
    ----------
    arr : ndarray
        Components on the last axis.
    ncomp : int
        Number of components.
    label : str
        The array, for the messages.
    where : str
        The source, for the messages.
    component : None, int or "magnitude"
        None raises (the choice is the caller's); an int picks that component (negative counts from
        the end); ``"magnitude"`` takes the Euclidean norm.

    Returns
    -------
    ndarray
        ``arr`` without its last axis.

    Examples
    --------
    >>> v = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 2.0]])
    >>> pick_component(v, 3, "velocity", "flow.vti", "magnitude"), pick_component(v, 3, "velocity", "flow.vti", -1)
    (array([5., 2.]), array([0., 2.]))
    """
    if component is None:
        raise ValueError(f"{where}: array {label!r} has {ncomp} components per sample; a volume needs one. "
                         f"Pass component=0..{ncomp - 1} to pick one or component='magnitude' for the norm.")
    if component == "magnitude":
        return np.sqrt(np.sum(np.square(arr.astype(np.float64)), axis=-1))
    if not -ncomp <= int(component) < ncomp:
        raise ValueError(f"{where}: component={component} is out of range; array {label!r} has {ncomp} "
                         f"components (0..{ncomp - 1}).")
    return arr[..., int(component)]


def from_array(arr: np.ndarray, spacing, origin, component, where: str) -> VolumeSamples:
    """Check a numpy array ``values[k, j, i]`` (or ``[k, j, i, c]`` with ``component=``) and wrap it.

    Parameters
    ----------
    arr : ndarray
        3-D samples, or 4-D with the components last.
    spacing, origin : (3,) tuples or None
        Checked already; None gives ``(1, 1, 1)`` and ``(0, 0, 0)``.
    component : None, int or "magnitude"
        See :func:`pick_component`.
    where : str
        The source, for the messages.

    Returns
    -------
    VolumeSamples

    Examples
    --------
    >>> s = from_array(np.zeros((2, 3, 4, 2)), (1.0, 1.0, 2.0), None, 0, "numpy array")  # component 0
    >>> s.values.shape, s.spacing, s.origin
    ((2, 3, 4), (1.0, 1.0, 2.0), (0.0, 0.0, 0.0))
    >>> from_array(np.zeros((4, 4)), None, None, None, "numpy array")
    Traceback (most recent call last):
    ValueError: numpy array: volume samples must be a 3-D array (nz, ny, nx), got shape (4, 4). A 2-D image is a height field: use splinevis.io.read_heights.
    """
    check_samples(arr, where)
    if arr.ndim == 4:
        arr = pick_component(arr, arr.shape[3], "the last axis", where, component)
    elif component is not None:
        raise ValueError(f"{where}: component= applies to multi-component data; this array has shape {arr.shape}.")
    if arr.ndim != 3:
        hint = (" A 2-D image is a height field: use splinevis.io.read_heights." if arr.ndim == 2 else
                " A 4-D array (nz, ny, nx, c) is read with component=." if arr.ndim > 4 else "")
        raise ValueError(f"{where}: volume samples must be a 3-D array (nz, ny, nx), got shape {arr.shape}.{hint}")
    check_size(arr.shape, where)
    return VolumeSamples(values=arr, spacing=spacing or (1.0, 1.0, 1.0), origin=origin or (0.0, 0.0, 0.0),
                         source=where)


def axis_signs(direction: np.ndarray, where: str) -> np.ndarray:
    """+-1 per axis when ``direction`` is diagonal with entries +-1 (to rounding); else ValueError.

    Parameters
    ----------
    direction : (3, 3) array_like
        A direction matrix (columns: the world direction of each index axis).
    where : str
        The source, for the message.

    Returns
    -------
    (3,) ndarray of float64
        -1 for a flipped axis, +1 otherwise.

    Raises
    ------
    ValueError
        A rotation, shear or axis permutation: the spline schemes need axis-aligned grids.

    Examples
    --------
    >>> axis_signs(np.diag([1.0, -1.0, 1.0]), "scan.mha")
    array([ 1., -1.,  1.])
    >>> axis_signs([[0, 1, 0], [1, 0, 0], [0, 0, 1]], "scan.mha")
    Traceback (most recent call last):
    ValueError: scan.mha: the direction matrix [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]] permutes the axes; ...
    """
    d = np.asarray(direction, dtype=np.float64)
    if d.shape != (3, 3) or not np.isfinite(d).all():
        raise ValueError(f"{where}: direction matrix {d.tolist()} is not a finite 3 x 3 matrix.")
    off = d - np.diag(np.diag(d))
    diag = np.diag(d)
    if np.abs(off).max() <= 1e-9 and np.all(np.abs(np.abs(diag) - 1.0) <= 1e-9):
        return np.sign(diag)
    perm = np.all(np.abs(np.round(d) - d) <= 1e-9) and np.all(np.abs(np.round(d)).sum(axis=0) == 1) and \
        np.all(np.abs(np.round(d)).sum(axis=1) == 1)
    what = "permutes the axes" if perm else "is not axis-aligned (a rotation or shear)"
    raise ValueError(f"{where}: the direction matrix {np.round(d, 12).tolist()} {what}; only axis-aligned "
                     "grids (the identity up to axis flips, i.e. diagonal +-1) are supported, and dropping the "
                     "direction would draw a wrong picture. Resample onto an axis-aligned grid first "
                     "(e.g. in 3D Slicer or SimpleITK), or set the direction to the identity if you know the "
                     "orientation does not matter.")


def printed_rounding(texts) -> np.ndarray:
    """Bounds on how far the values that the decimal numbers ``texts`` (printed by one writer) stand for can be
    from what they print.

    Two kinds of writers: **fixed decimals** (``%12.6f``: every entry shows the same ``D >= 2`` decimals,
    trailing zeros kept) are within half a unit of the last decimal, ``0.5 10^-D``; **trimmed** output
    (``%g``, shortest round-trip ``repr``: decimals vary, trailing zeros dropped, so ``"1"`` may stand for
    ``1.00000``) is within half a unit of the ``S``-th significant digit, ``S`` the most significant digits any
    entry shows and at least 6 (C's ``%g`` default: no writer prints fewer for a direction). One decimal
    everywhere (``"1.0"``, ``"0.5"``) is read as trimmed: it is what Python's ``repr`` prints for such values,
    and no writer of directions prints one fixed decimal.

    >>> printed_rounding(["0.707107", "-0.004998", "0.000000"]).tolist()  # fixed, 6 decimals
    [5e-07, 5e-07, 5e-07]
    >>> printed_rounding(["1", "0.5", "0"]).tolist()  # trimmed: 6 significant digits assumed
    [5e-06, 5e-07, 0.0]
    >>> bool(printed_rounding(["0.7071067811865476", "-0.7071067811865475", "0"])[0] < 1e-16)  # repr
    True
    """
    decimals, digits, exponents = [], [], []
    for text in texts:
        t = text.strip().lower().replace("d", "e")
        mantissa, _, exponent = t.partition("e")
        whole, _, frac = mantissa.lstrip("+-").partition(".")
        sig = (whole + frac).lstrip("0")
        decimals.append(len(frac) - int(exponent or 0))
        digits.append(len(sig) if sig else 0)
        value = float(t)
        exponents.append(np.floor(np.log10(abs(value))) if value != 0 else None)
    if len(set(decimals)) == 1 and decimals[0] >= 2 and len(texts) > 1:
        return np.full(len(texts), 0.5 * 10.0 ** -decimals[0])
    S = max(max(digits), 6)
    return np.array([0.0 if e is None else 0.5 * 10.0 ** (e - S + 1) for e in exponents])


def unit_rounding(steps, rounding) -> tuple:
    """Bounds on the error (Euclidean norm) of each unit column ``v / |v|`` of the step vectors ``steps``
    (columns) whose entries are each within ``rounding`` (per column) of the true ones: a perturbation ``e``
    of ``v`` moves ``v / |v|`` by at most ``2 |e| / |v|``, and ``|e| <= sqrt(3) rounding``.

    >>> unit_rounding(np.eye(3) * 0.2, [5e-7] * 3)[0]  # a 0.2 step printed with 6 decimals
    8.660254037844385e-06
    """
    m = np.asarray(steps, dtype=np.float64)
    lengths = np.linalg.norm(m, axis=0)
    return tuple(float(2.0 * np.sqrt(3.0) * r / L) for r, L in zip(np.broadcast_to(rounding, (3,)), lengths))


def orthonormal_direction(direction, where: str, *, rounding=None) -> tuple:
    """``direction`` as a 3 x 3 nested tuple of floats whose columns are orthonormal; else ValueError.

    The columns are judged at the precision the source carries: ``rounding`` bounds the error (Euclidean
    norm) ``e_i`` of each unit column as read (:func:`unit_rounding` of the printed decimals, or of float32
    storage); true orthonormal columns then have Gram entries ``|u_i . u_j - delta_ij| <= e_i + e_j + e_i
    e_j``, and the largest of those plus 16 float64 rounding units is the tolerance. ``None`` (a matrix in
    memory of unknown provenance): 1e-6. Within it the matrix is replaced by the nearest orthonormal one
    (the orthogonal polar factor ``U V^T`` of its SVD, nearest in the Frobenius norm); when that moves an entry by more than float64
    rounding, a warning reports the deviation, the tolerance and the correction. A shear, non-unit or
    non-orthogonal axis beyond the tolerance raises.

    Parameters
    ----------
    direction : (3, 3) array_like
        Columns: the world direction of the lattice axes x, y, z.
    where : str
        The source, for the message.
    rounding : float or (3,) floats, optional
        Per column: bound on the error of the unit column as read.

    Examples
    --------
    >>> orthonormal_direction(np.eye(3), "x")[0]
    (1.0, 0.0, 0.0)
    >>> orthonormal_direction([[1, 0.5, 0], [0, 1, 0], [0, 0, 1]], "a.cube")
    Traceback (most recent call last):
    ValueError: a.cube: the direction matrix [[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] is not orthonormal (a shear or non-orthogonal axes, deviation 0.5 beyond the tolerance 1e-06); only rotated orthogonal lattices are drawn. Resample onto an orthogonal lattice first (e.g. scipy.ndimage.map_coordinates).
    """
    d = np.asarray(direction, dtype=np.float64)
    if d.shape != (3, 3) or not np.isfinite(d).all():
        raise ValueError(f"{where}: direction matrix {np.asarray(direction).tolist()} is not a finite 3 x 3 matrix "
                         "(columns: world direction of the lattice axes x, y, z).")
    if rounding is None:
        tol, how = 1e-6, ""
    else:
        e = np.broadcast_to(np.asarray(rounding, dtype=np.float64), (3,))
        tol = float((e[:, None] + e[None, :] + e[:, None] * e[None, :]).max()) + 16 * 2.0 ** -53
        how = " derived from the precision the source prints"
    dev = float(np.abs(d.T @ d - np.eye(3)).max())
    if dev > tol:
        raise ValueError(f"{where}: the direction matrix {np.round(d, 12).tolist()} is not orthonormal (a shear or "
                         f"non-orthogonal axes, deviation {dev:.3g} beyond the tolerance {tol:.3g}{how}); only "
                         "rotated orthogonal lattices are drawn. Resample onto an orthogonal lattice first "
                         "(e.g. scipy.ndimage.map_coordinates).")
    if dev > 0:
        u, _, vt = np.linalg.svd(d)
        q = u @ vt
        moved = float(np.abs(q - d).max())
        if moved > 64 * 2.0 ** -53:
            from .._warnings import warn_user

            warn_user(f"{where}: the lattice axes are orthonormal only to the precision the source carries "
                      f"(deviation {dev:.3g}, tolerance {tol:.3g}{how}); drawn with the nearest orthonormal matrix, "
                      f"whose entries differ from the source's by at most {moved:.3g}.")
        d = q
    return tuple(tuple(float(x) for x in row) for row in d)
