"""Gaussian cube files (``.cube``): a volume on a possibly rotated orthogonal lattice, with an atoms header.

Why a parser here: no library kept in this project reads a cube file into a lattice *with its axes*.
``ase`` (``ase.io.cube``) and ``cclib`` are not installed, and VTK's ``vtkGaussianCubeReader2`` (what
``pyvista.read`` uses) returns an axis-aligned ``ImageData`` that keeps only the lengths of the axis
vectors: a rotated lattice silently loses its orientation. The format is simple text:

* two comment lines;
* ``natoms ox oy oz [nval]``: the number of atoms (negative: an orbital-index line follows the atoms),
  the origin, and (optional) the number of values per point;
* three lines ``n_a vx vy vz``: samples along lattice axis ``a`` and its step vector (``n_a > 0``: Bohr,
  ``n_a < 0``: Angstrom - units are kept as the file gives them, no conversion);
* ``|natoms|`` lines ``Z charge x y z``; with ``natoms < 0`` a line ``m i_1 ... i_m`` (orbital indices);
* the samples, first axis slowest, third axis fastest (``data[i1][i2][i3]``), any number per line.

The three step vectors must be orthogonal (a rotated orthogonal lattice); their lengths become the
spacing and their directions the columns of ``VolumeGrid.direction``. Orthogonal is judged at the precision
the file prints: writers print the vectors with a fixed number of decimals (6 with Gaussian's ``%12.6f``), so
the vectors of a rotated lattice are orthogonal only to within half a unit of their last digit; the tolerance
is derived from those digits (:func:`.volume_samples.orthonormal_direction`), the matrix replaced by the
nearest orthonormal one and the correction reported in a warning. A sheared lattice (beyond that tolerance)
raises ValueError. With several values per point (``nval > 1``, e.g. several orbitals) ``component=`` picks one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .volume_samples import (VolumeSamples, check_size, orthonormal_direction, pick_component, printed_rounding,
                             unit_rounding)

__all__ = ["read_cube"]


def _numbers(line: str, path, lineno: int, what: str, count: int | None = None) -> list:
    parts = line.split()
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise ValueError(f"{path}: line {lineno} should hold {what}, got {line.strip()!r}; is this a Gaussian "
                         "cube file?") from None
    if count is not None and len(vals) < count:
        raise ValueError(f"{path}: line {lineno} should hold {what} ({count} numbers), got {line.strip()!r}; "
                         "the header is truncated or not a Gaussian cube header.")
    return vals


def read_cube(path: Path, scalars=None, component=None) -> VolumeSamples:
    """Read a Gaussian cube file (see the module notes).

    Parameters
    ----------
    path : Path
        An existing, non-empty ``.cube`` file.
    scalars : None
        Cube files hold one unnamed array; a name raises.
    component : None or int or "magnitude"
        For files with several values per point.

    Returns
    -------
    VolumeSamples
        ``values[k, j, i]`` with ``i`` along the first lattice axis; ``direction`` columns are the unit
        step vectors.

    Examples
    --------
    >>> import tempfile
    >>> text = "c\\nc\\n1 0.0 0.0 0.0\\n2 0.0 1.0 0.0\\n2 -1.0 0.0 0.0\\n2 0.0 0.0 2.0\\n8 0.0 0.0 0.0 0.0\\n"
    >>> text += " ".join(str(v) for v in range(8)) + "\\n"
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     p = Path(folder) / "a.cube"
    ...     _ = p.write_text(text)
    ...     s = read_cube(p)
    >>> s.spacing, s.direction[0], int(s.values[1, 0, 0])  # data[i=0][j=0][k=1] = 1
    ((1.0, 1.0, 2.0), (0.0, -1.0, 0.0), 1)
    """
    if scalars is not None:
        raise ValueError(f"{path}: scalars={scalars!r} names an array of a VTK file; a cube file holds one "
                         "unnamed array. Drop scalars= (use component= for several values per point).")
    lines = path.read_text(errors="replace").splitlines()
    if len(lines) < 6:
        raise ValueError(f"{path}: a Gaussian cube file needs at least 6 header lines (2 comments, the atom "
                         f"count/origin, 3 axes), got {len(lines)}; the file is truncated or not a cube file.")
    head = _numbers(lines[2], path, 3, "natoms ox oy oz [nval]", 4)
    natoms, origin = int(head[0]), tuple(head[1:4])
    nval = int(head[4]) if len(head) > 4 else 1
    counts, steps, printed = [], [], []
    for a in range(3):
        n, *vec = _numbers(lines[3 + a], path, 4 + a, f"the sample count and step vector of axis {a + 1}", 4)
        if int(n) == 0:
            raise ValueError(f"{path}: line {4 + a}: axis {a + 1} has 0 samples; a volume needs at least 2.")
        counts.append(abs(int(n)))
        steps.append(np.asarray(vec[:3], dtype=np.float64))
        printed += lines[3 + a].split()[1:4]
    pos = 6 + abs(natoms)
    if len(lines) < pos:
        raise ValueError(f"{path}: the header announces {abs(natoms)} atoms but the file ends after {len(lines)} "
                         "lines; the file is truncated.")
    tokens = " ".join(lines[pos:]).split()
    if natoms < 0:  # orbital indices: m then m numbers
        if not tokens:
            raise ValueError(f"{path}: natoms < 0 announces an orbital-index line, the file ends before it.")
        m = int(float(tokens[0]))
        tokens = tokens[1 + m:]
        nval = max(nval, m)
    n = counts[0] * counts[1] * counts[2] * nval
    if len(tokens) != n:
        raise ValueError(f"{path}: expected {n} samples ({counts[0]} x {counts[1]} x {counts[2]}"
                         f"{f' x {nval} values' if nval > 1 else ''}), the file holds {len(tokens)}; the file "
                         "is truncated or the header counts are wrong.")
    try:
        data = np.array(tokens, dtype=np.float64)
    except ValueError:
        raise ValueError(f"{path}: the sample section holds text that is not a number; the file is damaged.") \
            from None
    data = data.reshape(counts + [nval])
    if nval > 1:
        data = pick_component(data, nval, "values per point", str(path), component)
    else:
        if component is not None:
            raise ValueError(f"{path}: component= applies to cube files with several values per point; this one "
                             "has one.")
        data = data[..., 0]
    values = np.ascontiguousarray(np.transpose(data, (2, 1, 0)))  # [i1, i2, i3] -> [k, j, i]
    check_size(values.shape, str(path))
    lengths = [float(np.linalg.norm(v)) for v in steps]
    if min(lengths) == 0.0:
        raise ValueError(f"{path}: an axis step vector is zero: {[v.tolist() for v in steps]}.")
    # orthogonal to the decimals the file prints (module notes): judged at that precision
    direction = orthonormal_direction(np.column_stack([v / L for v, L in zip(steps, lengths)]), str(path),
                                      rounding=unit_rounding(np.column_stack(steps),
                                                             printed_rounding(printed).reshape(3, 3).max(axis=1)))
    return VolumeSamples(values=values, spacing=tuple(lengths), origin=tuple(float(o) for o in origin),
                         source=str(path), direction=direction)
