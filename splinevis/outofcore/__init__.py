"""Splines of data past memory: terrain and volume schemes run tile by tile on dask arrays, written to zarr
stores with their min-max pyramids, read back a window of tiles at a time.

dask does the chunking and the scheduling (its threaded scheduler by default, a ``dask.distributed`` cluster
unchanged when a ``Client`` exists), zarr stores the chunks; the halos, the border padding and the pyramids
are the schemes' own, so a chunked build equals the in-memory one (:mod:`.halo`, :mod:`.terrain`,
:mod:`.volume`, :mod:`.pyramid`, :mod:`.store`, :mod:`.volume_store`, :mod:`.view`, :mod:`.schedule`); a store is
drawn a view at a time, at the finest level that fits the renderer (:mod:`.render`, :mod:`.overview`; the
isosurface of a volume store: :mod:`.render_volume`).
"""

from .overview import overview_spline as overview_spline
from .pyramid import pyramid_levels_dask as pyramid_levels_dask
from .render import add_terrain_store as add_terrain_store
from .render_volume import add_volume_store as add_volume_store
from .schedule import run as run
from .store import TerrainStore as TerrainStore, open_terrain_store as open_terrain_store
from .store import write_terrain_store as write_terrain_store
from .terrain import terrain_coefficients_dask as terrain_coefficients_dask, terrain_halo as terrain_halo
from .terrain import terrain_input_chunks as terrain_input_chunks
from .view import tiles_in_view as tiles_in_view
from .volume import padded_volume_dask as padded_volume_dask, volume_coefficients_dask as volume_coefficients_dask
from .volume import volume_cube_ranges_dask as volume_cube_ranges_dask, volume_input_chunks as volume_input_chunks
from .volume_store import VolumeStore as VolumeStore, open_volume_store as open_volume_store
from .volume_store import write_volume_store as write_volume_store

__all__ = ["terrain_coefficients_dask", "terrain_halo", "terrain_input_chunks", "volume_coefficients_dask",
           "volume_cube_ranges_dask", "padded_volume_dask", "volume_input_chunks", "pyramid_levels_dask",
           "write_terrain_store", "open_terrain_store", "TerrainStore", "write_volume_store", "open_volume_store",
           "VolumeStore", "tiles_in_view", "run", "overview_spline", "add_terrain_store", "add_volume_store"]
