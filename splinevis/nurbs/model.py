"""A NURBS model: patches that keep their identity, with optional trim loops in each patch's domain.

Trim loops are closed chains of 2-D NURBS curves in the patch's ``(u, v)`` parameter domain (IGES entity
144, a Rhino BrepFace's loops, an OpenCASCADE face's wires). A parameter is kept when it lies inside an
odd number of the patch's loops (even-odd rule: the outer loop and nested holes/islands need no labels);
a patch without loops keeps its whole domain.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .basis import at_fraction, check_knots, ders_basis_funs, find_span
from .surface import NurbsSurface

__all__ = ["TrimCurve", "NurbsModel"]


@dataclass(frozen=True, eq=False)
class TrimCurve:
    """A 2-D (rational) B-spline curve in a patch's parameter domain.

    Examples
    --------
    >>> c = TrimCurve(1, [0, 0, 1, 1], [[0.1, 0.1], [0.9, 0.1]])
    >>> c.evaluate([0.5])
    array([[0.5, 0.1]])
    """

    degree: int
    knots: np.ndarray
    control_points: np.ndarray
    weights: np.ndarray | None = None

    def __post_init__(self):
        P = np.array(self.control_points, dtype=np.float64)
        if P.ndim != 2 or P.shape[1] != 2:
            raise ValueError(f"trim curve control_points must have shape (n, 2), got {P.shape}.")
        U = check_knots(self.knots, int(self.degree), P.shape[0], "trim curve knots")
        W = None if self.weights is None else np.array(self.weights, dtype=np.float64)
        if W is not None and (W.shape != (P.shape[0],) or not (np.isfinite(W) & (W > 0)).all()):
            raise ValueError(f"trim curve weights must be {P.shape[0]} positive numbers, got {self.weights!r}.")
        object.__setattr__(self, "degree", int(self.degree))
        object.__setattr__(self, "knots", U)
        object.__setattr__(self, "control_points", P)
        object.__setattr__(self, "weights", W)

    @property
    def domain(self) -> tuple:
        """``(t0, t1)``.

        >>> TrimCurve(1, [0, 0, 2, 2], [[0, 0], [1, 1]]).domain
        (0.0, 2.0)
        """
        n = self.control_points.shape[0]
        return float(self.knots[self.degree]), float(self.knots[n])

    def evaluate(self, t) -> np.ndarray:
        """Points ``(len(t), 2)`` [PieglTiller1997, A4.1].

        >>> from splinevis.nurbs.exact import circle_net
        >>> xy, w = circle_net()
        >>> from splinevis.nurbs.exact import CIRCLE_KNOTS
        >>> c = TrimCurve(2, CIRCLE_KNOTS, 0.5 + 0.25 * xy, w)  # a circle of radius 1/4 about (1/2, 1/2)
        >>> np.round(c.evaluate([0.125, 0.5]), 12).tolist()
        [[0.676776695297, 0.676776695297], [0.25, 0.5]]
        """
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        p, U = self.degree, self.knots
        span = find_span(p, U, t)
        N = ders_basis_funs(span, t, p, 0, U)[:, 0, :]
        idx = span[:, None] - p + np.arange(p + 1)
        w = np.ones(self.control_points.shape[0]) if self.weights is None else self.weights
        Pw = self.control_points[idx] * w[idx][..., None]
        return np.einsum("ma,mac->mc", N, Pw) / np.einsum("ma,ma->m", N, w[idx])[:, None]


@dataclass(frozen=True, eq=False)
class NurbsModel:
    """Patches of a NURBS model.

    Parameters
    ----------
    surfaces : sequence of NurbsSurface
        Each keeps its ``name`` (the file's entity / object id).
    trims : sequence (one per surface) of None or a list of loops (each a list of TrimCurve)
    source : str
        Where the model came from (a file name, "sphere", ...), and what a reader skipped.
    skipped : dict
        Entity type -> count of what a reader did not read.
    report : dict
        Findings about the model (e.g. ``report["orientation"]`` from
        :func:`splinevis.nurbs.orient.orient_faces`: faces flipped, shells closed, seams' continuity); empty
        by default.
    meshes : sequence of (name, points (n, 3), cells (m, k))
        Plain geometry the file holds beside its surfaces, drawn as it is next to the exact surfaces
        (:meth:`companion_meshes`): triangles (k = 3: a CAD file's mesh objects), line segments (k = 2: its
        curves, sampled) or points (k = 1); empty by default.

    Examples
    --------
    >>> from splinevis.nurbs.exact import sphere, torus
    >>> m = NurbsModel([sphere(), torus()], source="two shapes")
    >>> len(m), m.names, m.trims
    (2, ('sphere', 'torus'), (None, None))
    >>> m.bounds()[4:]  # z range of the control points
    (-1.0, 1.0)
    """

    surfaces: tuple
    trims: tuple = ()
    source: str = ""
    skipped: dict = field(default_factory=dict)
    report: dict = field(default_factory=dict)
    meshes: tuple = ()

    def __post_init__(self):
        surfaces = tuple(self.surfaces)
        if not surfaces:
            raise ValueError(f"a NurbsModel needs at least one surface ({self.source or 'no source'}).")
        for k, s in enumerate(surfaces):
            if not isinstance(s, NurbsSurface):
                raise TypeError(f"surfaces[{k}] must be a NurbsSurface, got {type(s).__name__}.")
        trims = tuple(self.trims) if self.trims else (None,) * len(surfaces)
        if len(trims) != len(surfaces):
            raise ValueError(f"trims must have one entry (None or loops) per surface: {len(trims)} for {len(surfaces)}.")
        object.__setattr__(self, "surfaces", surfaces)
        object.__setattr__(self, "trims", tuple(None if t is None else tuple(tuple(loop) for loop in t) for t in trims))
        meshes = []
        for k, (name, points, triangles) in enumerate(self.meshes):
            P = np.asarray(points, dtype=np.float64)
            T = np.asarray(triangles, dtype=np.int64)
            T = T.reshape(-1, 3) if T.ndim != 2 else T
            if P.ndim != 2 or P.shape[1] != 3 or not np.isfinite(P).all():
                raise ValueError(f"meshes[{k}] ({name!r}): points must be a finite (n, 3) array, got shape {P.shape}.")
            if T.shape[1] not in (1, 2, 3):
                raise ValueError(f"meshes[{k}] ({name!r}): cells must be triangles (m, 3), segments (m, 2) or "
                                 f"points (m, 1), got shape {T.shape}.")
            if T.size and (T.min() < 0 or T.max() >= len(P)):
                raise ValueError(f"meshes[{k}] ({name!r}): a cell refers to point {int(T.max())} of {len(P)}.")
            meshes.append((str(name), P, T))
        object.__setattr__(self, "meshes", tuple(meshes))

    def companion_meshes(self) -> tuple:
        """The plain geometry drawn beside the surfaces: ``(name, points, cells)`` each, cells triangles,
        segments or points (the Plotter draws any model's ``companion_meshes`` as ordinary meshes, lines and
        points).

        >>> from splinevis.nurbs.exact import saddle
        >>> m = NurbsModel([saddle()], meshes=[("tri", [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])])
        >>> [(n, P.shape, T.tolist()) for n, P, T in m.companion_meshes()]
        [('tri', (3, 3), [[0, 1, 2]])]
        """
        return self.meshes

    def __len__(self) -> int:
        return len(self.surfaces)

    @property
    def names(self) -> tuple:
        """Each patch's name.

        >>> from splinevis.nurbs.exact import saddle
        >>> NurbsModel([saddle()]).names
        ('saddle',)
        """
        return tuple(s.name for s in self.surfaces)

    def curvature_samples(self, n: int = 41) -> dict:
        """Curvatures (``K``, ``H``, ``k1``, ``k2``, as :meth:`NurbsSurface.curvature`) at an ``n x n`` grid of
        every patch's domain, concatenated: the surface's true range for a colour legend, in float64. Samples
        where a patch's parametrization degenerates (poles) are NaN (see :meth:`NurbsSurface.curvature`).

        >>> from splinevis.nurbs.exact import sphere
        >>> c = NurbsModel([sphere(2.0)]).curvature_samples(11)
        >>> c["K"].size, round(float(np.nanmedian(c["K"])), 12)
        (121, 0.25)
        """
        t = np.linspace(0.0, 1.0, n)
        parts = []
        for s in self.surfaces:
            (u0, u1), (v0, v1) = s.domain
            U, V = np.meshgrid(at_fraction(u0, u1, t), at_fraction(v0, v1, t))
            parts.append(s.curvature(U.ravel(), V.ravel()))
        return {key: np.concatenate([c[key] for c in parts]) for key in parts[0]}

    def bounds(self) -> tuple:
        """``(xmin, xmax, ymin, ymax, zmin, zmax)`` of all control points (the convex-hull box).

        >>> from splinevis.nurbs.exact import saddle
        >>> NurbsModel([saddle(2.0)]).bounds()
        (-2.0, 2.0, -2.0, 2.0, -8.0, 8.0)
        """
        P = np.concatenate([s.control_points.reshape(-1, 3) for s in self.surfaces])
        lo, hi = P.min(axis=0), P.max(axis=0)
        return tuple(float(v) for pair in zip(lo, hi) for v in pair)
