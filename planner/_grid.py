"""The one world <-> grid conversion used everywhere.

World axes: x and z span the ground plane, y is up (metres). A grid has
``n_rows x n_cols`` square cells of ``cell_size`` metres; rows run along world
z and columns along world x, and ``origin_x, origin_z`` is the world position
of the *corner* of cell (0, 0) (its low-x, low-z corner). Hence:

* cell ``(r, c)`` covers ``x in [origin_x + c*cell, origin_x + (c+1)*cell)`` and
  ``z in [origin_z + r*cell, origin_z + (r+1)*cell)``;
* its centre is ``(origin_x + (c + 0.5)*cell, origin_z + (r + 0.5)*cell)``;
* world ``(x, z)`` lies in cell ``(floor((z - origin_z)/cell), floor((x - origin_x)/cell))``.

The numba kernels use the same two formulas, spelled out in
:func:`cell_of` / :func:`cell_centre` below (they are njit-compiled so kernels can
call them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np


@nb.njit(cache=True, inline="always")
def cell_of(x: float, z: float, origin_x: float, origin_z: float, cell: float) -> tuple[int, int]:
    """(row, col) of the cell containing world point (x, z)."""
    return int(math.floor((z - origin_z) / cell)), int(math.floor((x - origin_x) / cell))


@nb.njit(cache=True, inline="always")
def cell_centre(r: int, c: int, origin_x: float, origin_z: float, cell: float) -> tuple[float, float]:
    """World (x, z) of the centre of cell (r, c)."""
    return origin_x + (c + 0.5) * cell, origin_z + (r + 0.5) * cell


@dataclass(frozen=True)
class GridFrame:
    """Placement of a grid in the world (see the module docstring for the convention).

    A ``cell_size`` that is not a positive finite number, or a shape with fewer than one row
    or column, raises ValueError.

    Attributes
    ----------
    origin_x, origin_z : float
        World position (m) of the low-x, low-z corner of cell (0, 0).
    cell_size : float
        Side of a square cell (m), > 0.
    n_rows, n_cols : int
        Number of rows (along world z) and columns (along world x), >= 1.
    shape : tuple of int
        ``(n_rows, n_cols)``.

    Examples
    --------
    >>> from footfall.planner import GridFrame
    >>> grid = GridFrame(origin_x=0.0, origin_z=0.0, cell_size=0.5, n_rows=4, n_cols=6)
    >>> grid.shape
    (4, 6)
    >>> rows, cols = grid.world_to_cell([1.2, -0.1], [0.7, 0.0])   # x, z -> row from z, column from x
    >>> rows.tolist(), cols.tolist()
    ([1, 0], [2, -1])
    >>> x, z = grid.cell_to_world(1, 2)                            # centre of cell (1, 2)
    >>> float(x), float(z)
    (1.25, 0.75)
    >>> grid.contains_cell([0, 3], [5, 6]).tolist()                # column 6 is past the last one
    [True, False]
    """

    origin_x: float
    origin_z: float
    cell_size: float
    n_rows: int
    n_cols: int

    def __post_init__(self) -> None:
        if not (self.cell_size > 0 and math.isfinite(self.cell_size)):
            raise ValueError(f"cell_size must be a positive finite number of metres, got {self.cell_size!r}")
        if self.n_rows < 1 or self.n_cols < 1:
            raise ValueError(f"grid shape must be positive, got {(self.n_rows, self.n_cols)}")

    @property
    def shape(self) -> tuple[int, int]:
        return (self.n_rows, self.n_cols)

    def world_to_cell(self, x, z):
        """Vectorised (row, col) integer arrays of the cells containing (x, z)."""
        x = np.asarray(x, dtype=np.float64)
        z = np.asarray(z, dtype=np.float64)
        r = np.floor((z - self.origin_z) / self.cell_size).astype(np.int64)
        c = np.floor((x - self.origin_x) / self.cell_size).astype(np.int64)
        return r, c

    def cell_to_world(self, r, c):
        """Vectorised world (x, z) of cell centres."""
        r = np.asarray(r, dtype=np.float64)
        c = np.asarray(c, dtype=np.float64)
        return self.origin_x + (c + 0.5) * self.cell_size, self.origin_z + (r + 0.5) * self.cell_size

    def contains_cell(self, r, c):
        r = np.asarray(r)
        c = np.asarray(c)
        return (r >= 0) & (r < self.n_rows) & (c >= 0) & (c < self.n_cols)
