"""What a missing optional dependency means for the user: the ``pip install`` that brings it.

splinevis's core (numpy, scipy, VTK, PyVista, moderngl, scikit-image, matplotlib, tqdm, Pillow) draws terrains
from arrays and VTK files, volumes from arrays and VTK, NRRD, MetaImage, cube and raw files, NURBS given as arrays
and geometry images of given control grids. Readers and builders that need more import it where they use it, from
an extra: ``[nifti]`` (nibabel), ``[geo]`` (rasterio/GDAL), ``[cad]`` (rhino3dm, pyiges, shapely, PythonCDT,
OpenCASCADE), ``[mesh]`` (libigl, pymeshlab), ``[dask]`` (dask, distributed, zarr); ``[all]`` is all of them.
A finder placed last on ``sys.meta_path`` is asked only when no other finder found a module; for the extras'
modules it raises ``ModuleNotFoundError`` naming the extra and the command, instead of Python's bare "No module
named 'rasterio'". Code that probes for a module with ``try: import ... except ImportError`` still works: the
error is an ``ImportError``.

Why our own code: the import system's documented extension point (a meta-path finder) is the one place that sees
every import of those modules, without a wrapper at each of the ~150 import sites.
"""

from __future__ import annotations

import sys

__all__ = ["EXTRAS", "MissingExtraFinder", "install"]

#: top-level module -> (extra, what needs it)
EXTRAS = {
    "nibabel": ("nifti", "NIfTI volumes (.nii, .nii.gz)"),
    "rasterio": ("geo", "GeoTIFF, SRTM and other GDAL rasters, and reprojection of geographic grids"),
    "rhino3dm": ("cad", "Rhino .3dm files"),
    "pyiges": ("cad", "IGES files"),
    "OCP": ("cad", "STEP files and OpenCASCADE's tessellation"),
    "shapely": ("cad", "trimmed NURBS patches"),
    "pythoncdt": ("cad", "trimmed NURBS patches"),
    "igl": ("mesh", "geometry images of triangle meshes"),
    "pymeshlab": ("mesh", "decimation and subdivision of triangle meshes"),
    "dask": ("dask", "data past memory"),
    "distributed": ("dask", "data past memory"),
    "zarr": ("dask", "chunked stores of data past memory"),
}


class MissingExtraFinder:
    """A finder asked last: for a module of :data:`EXTRAS` that no other finder found, the install command.

    >>> finder = MissingExtraFinder()
    >>> finder.find_spec("rasterio.crs", None)
    Traceback (most recent call last):
    ModuleNotFoundError: No module named 'rasterio': splinevis needs it for GeoTIFF, SRTM and other GDAL rasters, and reprojection of geographic grids. Install it with: pip install 'splinevis[geo]' (or 'splinevis[all]').
    >>> finder.find_spec("not_ours", None) is None
    True
    """

    def find_spec(self, fullname, path=None, target=None):
        """None for a module not of :data:`EXTRAS` (Python then says it is missing); else the error.

        >>> MissingExtraFinder().find_spec("numpy_but_not_really") is None
        True
        """
        top = fullname.partition(".")[0]
        if top not in EXTRAS:
            return None
        extra, what = EXTRAS[top]
        raise ModuleNotFoundError(f"No module named {top!r}: splinevis needs it for {what}. Install it with: "
                                  f"pip install 'splinevis[{extra}]' (or 'splinevis[all]').", name=top)


def install() -> None:
    """Put :class:`MissingExtraFinder` last on ``sys.meta_path`` (once).

    >>> install(); install()
    >>> sum(isinstance(f, MissingExtraFinder) for f in sys.meta_path)
    1
    """
    if not any(isinstance(f, MissingExtraFinder) for f in sys.meta_path):
        sys.meta_path.append(MissingExtraFinder())
