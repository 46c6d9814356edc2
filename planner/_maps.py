"""Local obstacles' and elevations' maps (paper §4, 'grid-based representation').

The world is rasterised once, at the planner's cell size, into a global grid:
terrain heights at cell centres, raised by the tops of the *static* boxes, and a
forbidden flag where a forbidden box covers a cell. A character's local maps are
a window of that grid centred on it (so all characters share cell boundaries),
with the *moving* boxes near the window voxelised on top at the current time.

Per foot, the planner kernels then add the foot-shape dilation, the other legs and
the elevation slices (see :mod:`planner._kernels_foot`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.planner._grid import GridFrame
from footfall.planner._kernels_geometry import rasterise_boxes
from footfall.planner.layout import FORBIDDEN_MOVING, FORBIDDEN_STATIC


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class LocalMaps:
    """A character's local maps. ``elevation`` = top of the highest thing in each cell
    (terrain or box, m); ``ground`` = terrain alone (m); ``forbidden`` = 1 where a
    forbidden box (or the world's edge) is.

    Made by :meth:`WorldRaster.local_maps`. A map whose shape is not ``frame.shape``, or a
    non-finite elevation or ground height, raises ValueError.

    Attributes
    ----------
    frame : GridFrame
        Placement of the maps in the world.
    elevation : ndarray
        (R, C) float64, top of the highest thing in each cell (m).
    ground : ndarray
        (R, C) float64, terrain height at the cell centres (m).
    forbidden : ndarray
        (R, C) uint8, nonzero where a forbidden box or the world's edge is: ``FORBIDDEN_MOVING`` (2) where
        a moving box is, 1 elsewhere (a foot beside a static box never swings through it; beside a
        moving one it may, the way out of its path: ``planner._kernels_foot._open_escape``).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import GridFrame, LocalMaps
    >>> frame = GridFrame(0.0, 0.0, 0.1, 2, 3)
    >>> maps = LocalMaps(frame, np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3), np.uint8))
    >>> maps.elevation.shape
    (2, 3)
    >>> LocalMaps(frame, np.zeros((2, 3)), np.zeros((3, 2)), np.zeros((2, 3), np.uint8))
    Traceback (most recent call last):
        ...
    ValueError: LocalMaps.ground: expected shape (2, 3), got (3, 2)
    """

    frame: GridFrame
    elevation: np.ndarray
    ground: np.ndarray
    forbidden: np.ndarray

    def __post_init__(self) -> None:
        shape = self.frame.shape
        for name in ("elevation", "ground", "forbidden"):
            a = getattr(self, name)
            if a.shape != shape:
                raise ValueError(f"LocalMaps.{name}: expected shape {shape}, got {a.shape}")
        if not (np.isfinite(self.elevation).all() and np.isfinite(self.ground).all()):
            raise ValueError("LocalMaps.elevation/ground: must be finite (NaN terrain?)")


@dataclass(frozen=True)
class WorldRaster:
    """The static world at the planner's resolution (computed once per scenario).

    Build it with :meth:`build`; :meth:`local_maps` cuts a character's maps out of it, with
    the moving boxes near them drawn at the time asked for.

    Attributes
    ----------
    frame : GridFrame
        The global grid, from the terrain's low-x, low-z corner, of whole cells.
    ground : ndarray
        (R, C) terrain height at the cell centres (m), read-only.
    static_top : ndarray
        (R, C) ground raised by the tops of the static boxes (m), read-only.
    static_forbidden : ndarray
        (R, C) uint8, 1 where a static forbidden box overlaps the cell, read-only.
    obstacles : Obstacles
        The scenario's boxes, static and moving (:class:`footfall.scenarios.Obstacles`).

    Examples
    --------
    A 2 m x 2 m flat ground in cells of 0.1 m, and a forbidden box 0.3 m wide and 0.2 m
    high in its middle: the box overlaps 4 x 4 cells.

    >>> from footfall.planner import WorldRaster
    >>> from footfall.scenarios import Obstacles, flat_heightfield
    >>> box = Obstacles(centres=[[0.0, 0.1, 0.0]], sizes=[[0.3, 0.2, 0.3]], yaws=[0.0], forbidden=[True])
    >>> world = WorldRaster.build(flat_heightfield((2.0, 2.0), 0.1), box, cell_size=0.1)
    >>> world.frame.shape, float(world.static_top.max()), int(world.static_forbidden.sum())
    ((20, 20), 0.2, 16)

    The 8 x 8 maps of a character near the world's edge at x = 1 m: the columns past it are
    forbidden.

    >>> maps = world.local_maps(0.95, 0.0, map_cells=8)
    >>> maps.forbidden.shape, maps.forbidden.sum(axis=0).tolist()
    ((8, 8), [0, 0, 0, 0, 0, 8, 8, 8])
    """

    frame: GridFrame
    ground: np.ndarray  # (R, C) terrain height at cell centres, m
    static_top: np.ndarray  # (R, C) ground raised by static boxes' tops, m
    static_forbidden: np.ndarray  # (R, C) uint8
    obstacles: object  # scenarios.Obstacles (struct of arrays, poses_at(t))

    @classmethod
    def build(cls, terrain, obstacles, cell_size: float) -> "WorldRaster":
        """Rasterise ``terrain`` (a Heightfield) and the static ``obstacles``.

        Parameters
        ----------
        terrain : Heightfield
            The ground (:class:`footfall.scenarios.Heightfield`).
        obstacles : Obstacles
            The boxes; only the static ones are drawn, the moving ones by :meth:`local_maps`.
        cell_size : float
            Side of a cell (m); the grid covers whole cells of the terrain's extent.

        Returns
        -------
        WorldRaster
            The rasterised static world.

        Examples
        --------
        >>> from footfall.planner import WorldRaster
        >>> from footfall.scenarios import Obstacles, flat_heightfield
        >>> world = WorldRaster.build(flat_heightfield((2.0, 1.0), 0.1), Obstacles.empty(), 0.25)
        >>> world.frame.shape, (world.frame.origin_x, world.frame.origin_z)   # rows along z
        ((4, 8), (-1.0, -0.5))
        """
        x0, x1 = terrain.x_range
        z0, z1 = terrain.z_range
        n_cols = max(1, int(math.floor((x1 - x0) / cell_size)))
        n_rows = max(1, int(math.floor((z1 - z0) / cell_size)))
        frame = GridFrame(float(x0), float(z0), float(cell_size), n_rows, n_cols)
        xs, zs = frame.cell_to_world(np.arange(n_rows)[:, None], np.arange(n_cols)[None, :])
        xs, zs = np.broadcast_arrays(xs, zs)
        ground = np.ascontiguousarray(terrain.height_at(xs, zs), dtype=np.float64)
        if not np.isfinite(ground).all():
            raise ValueError("terrain: heights must be finite (found NaN or inf)")
        top = ground.copy()
        forbidden = np.zeros(ground.shape, dtype=np.uint8)
        if len(obstacles.yaws):
            static = np.asarray(obstacles.is_static, dtype=np.bool_)
            centres, yaws = obstacles.poses_at(0.0)
            rasterise_boxes(top, forbidden, frame.origin_x, frame.origin_z, cell_size,
                            np.ascontiguousarray(centres, dtype=np.float64),
                            np.ascontiguousarray(obstacles.sizes, dtype=np.float64),
                            np.ascontiguousarray(yaws, dtype=np.float64),
                            np.ascontiguousarray(obstacles.forbidden, dtype=np.bool_), static)
        return cls(frame, _readonly(ground), _readonly(top), _readonly(forbidden), obstacles)

    def local_maps(self, centre_x: float, centre_z: float, t: float = 0.0, map_cells: int = 70) -> LocalMaps:
        """The ``map_cells`` x ``map_cells`` maps centred on (centre_x, centre_z) at time t.

        The window shares the global grid's cell boundaries; cells past the world's edge are
        forbidden, and the moving boxes whose bounding circle comes near the window are drawn
        where they are at ``t``.

        Parameters
        ----------
        centre_x, centre_z : float
            World position (m) the maps are centred on (cell ``map_cells // 2`` holds it).
        t : float, optional
            Time (s) at which the moving boxes are drawn.
        map_cells : int, optional
            Cells per side of the maps (``PlannerConfig.map_cells``).

        Returns
        -------
        LocalMaps
            The character's maps.

        Examples
        --------
        >>> from footfall.planner import WorldRaster
        >>> from footfall.scenarios import Obstacles, flat_heightfield
        >>> world = WorldRaster.build(flat_heightfield((2.0, 2.0), 0.1), Obstacles.empty(), 0.1)
        >>> maps = world.local_maps(0.0, 0.0, map_cells=4)
        >>> round(maps.frame.origin_x, 6), maps.frame.shape, int(maps.forbidden.sum())
        (-0.2, (4, 4), 0)
        """
        f = self.frame
        cell = f.cell_size
        half = map_cells // 2
        gc0 = int(math.floor((centre_x - f.origin_x) / cell)) - half
        gr0 = int(math.floor((centre_z - f.origin_z) / cell)) - half
        frame = GridFrame(f.origin_x + gc0 * cell, f.origin_z + gr0 * cell, cell, map_cells, map_cells)
        rows = np.clip(np.arange(gr0, gr0 + map_cells), 0, f.n_rows - 1)
        cols = np.clip(np.arange(gc0, gc0 + map_cells), 0, f.n_cols - 1)
        ground = self.ground[np.ix_(rows, cols)]
        top = self.static_top[np.ix_(rows, cols)]
        forbidden = self.static_forbidden[np.ix_(rows, cols)].copy()
        outside_r = (np.arange(gr0, gr0 + map_cells) < 0) | (np.arange(gr0, gr0 + map_cells) >= f.n_rows)
        outside_c = (np.arange(gc0, gc0 + map_cells) < 0) | (np.arange(gc0, gc0 + map_cells) >= f.n_cols)
        forbidden[outside_r, :] = FORBIDDEN_STATIC
        forbidden[:, outside_c] = FORBIDDEN_STATIC
        obstacles = self.obstacles
        if len(obstacles.yaws):
            moving = ~np.asarray(obstacles.is_static, dtype=np.bool_)
            if moving.any():
                centres, yaws = obstacles.poses_at(t)
                centres = np.ascontiguousarray(centres, dtype=np.float64)
                # Only the moving boxes whose bounding circle reaches the window.
                wx = frame.origin_x + 0.5 * map_cells * cell
                wz = frame.origin_z + 0.5 * map_cells * cell
                r_box = 0.5 * np.hypot(obstacles.sizes[:, 0], obstacles.sizes[:, 2])
                near = moving & (np.hypot(centres[:, 0] - wx, centres[:, 2] - wz) <= r_box + 0.75 * map_cells * cell)
                if near.any():
                    rasterise_boxes(top, forbidden, frame.origin_x, frame.origin_z, cell, centres,
                                    np.ascontiguousarray(obstacles.sizes, dtype=np.float64),
                                    np.ascontiguousarray(yaws, dtype=np.float64),
                                    np.ascontiguousarray(obstacles.forbidden, dtype=np.bool_), near, FORBIDDEN_MOVING)
        return LocalMaps(frame, np.ascontiguousarray(top), np.ascontiguousarray(ground), forbidden)
