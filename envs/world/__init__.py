"""Worlds: the unstructured 2-D maps the robot moves in.

Lives here: :mod:`.world` (``World``: polygonal obstacles and a raster), :mod:`.geometry` and its kernels
:mod:`.geometry_jit` (rigorous distances and sector ranges), :mod:`.raster`, :mod:`.tracing` (marching
squares), :mod:`.generators` (``ThesisRoom``, ``RockField``, ``Caves``, ``RoomsCorridors``, ``FileMap``) and
:mod:`.render` (pygame/numpy pictures).

May import: :mod:`digslam.observer.core`; numpy, scipy, pymunk, pygame (on use).
"""

from .generators import (
    GENERATORS,
    THESIS_ROOM,
    Caves,
    FileMap,
    RockField,
    RoomsCorridors,
    ThesisRoom,
    WorldGenerator,
)
from .geometry import (
    Edges,
    edge_bboxes,
    point_edge_distance,
    point_free,
    rings_to_edges,
    sector_distance,
)
from .geometry_jit import (
    edge_boxes,
    points_edges_kernel,
    sector_bounds_kernel,
    sector_kernel,
)
from .raster import (
    cell_centres,
    grid_shape,
    rasterize,
)
from .render import (
    FREE,
    MIXED,
    Renderer,
)
from .tracing import (
    chain_rings,
    marching_squares,
    mask_edges,
    smooth_noise,
)
from .world import (
    World,
)

__all__ = [
    "Caves",
    "Edges",
    "FREE",
    "FileMap",
    "GENERATORS",
    "MIXED",
    "Renderer",
    "RockField",
    "RoomsCorridors",
    "THESIS_ROOM",
    "ThesisRoom",
    "World",
    "WorldGenerator",
    "cell_centres",
    "chain_rings",
    "edge_bboxes",
    "edge_boxes",
    "grid_shape",
    "marching_squares",
    "mask_edges",
    "point_edge_distance",
    "point_free",
    "points_edges_kernel",
    "rasterize",
    "rings_to_edges",
    "sector_bounds_kernel",
    "sector_distance",
    "sector_kernel",
    "smooth_noise",
]
