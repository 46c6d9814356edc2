"""The terrain: a regular grid of ground heights (the paper's height map, §7)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from footfall.scenarios._arrays import finite_float, frozen_array, invalid, positive_float


@dataclass(frozen=True, eq=False)
class Heightfield:
    """Ground height y (m) sampled on a regular x/z grid.

    ``heights[r, c]`` is the ground height at world
    ``x = origin_x + c * cell_size`` and ``z = origin_z + r * cell_size``:
    rows run along z, columns along x, and ``(origin_x, origin_z)`` is the
    centre of ``heights[0, 0]``. Between samples the ground is bilinear.

    Attributes
    ----------
    heights : (R, C) ndarray
        float64, m, read-only, R >= 2 and C >= 2, all finite.
    origin_x, origin_z : float
        World x and z (m) of ``heights[0, 0]``.
    cell_size : float
        Grid spacing (m), > 0, the same along x and z.

    Examples
    --------
    A 2 x 2 grid, 1 m apart: corners at x, z in {0, 1} m.

    >>> import numpy as np
    >>> from footfall.scenarios import Heightfield
    >>> ground = Heightfield(np.array([[0.0, 1.0], [2.0, 3.0]]), origin_x=0.0, origin_z=0.0, cell_size=1.0)
    >>> ground.x_range, ground.z_range
    ((0.0, 1.0), (0.0, 1.0))
    >>> float(ground.height_at(1.0, 0.0))    # heights[0, 1]: row 0 is z = 0, column 1 is x = 1
    1.0
    >>> float(ground.height_at(0.5, 0.5))    # bilinear: the mean of the four corners
    1.5
    >>> ground.contains(0.5, 0.5, margin=0.25), ground.contains(0.9, 0.5, margin=0.25)
    (True, False)
    >>> ground.heights.flags.writeable
    False
    """

    heights: np.ndarray
    origin_x: float
    origin_z: float
    cell_size: float

    def __post_init__(self) -> None:
        heights = frozen_array(self.heights, "heights", (None, None))
        if heights.shape[0] < 2 or heights.shape[1] < 2:
            raise invalid("heights", f"needs at least 2x2 samples, got {heights.shape[0]}x{heights.shape[1]}")
        object.__setattr__(self, "heights", heights)
        object.__setattr__(self, "origin_x", finite_float(self.origin_x, "origin_x"))
        object.__setattr__(self, "origin_z", finite_float(self.origin_z, "origin_z"))
        object.__setattr__(self, "cell_size", positive_float(self.cell_size, "cell_size"))

    @property
    def x_range(self) -> tuple[float, float]:
        """World x (m) of the first and last grid columns: (min, max)."""
        return self.origin_x, self.origin_x + (self.heights.shape[1] - 1) * self.cell_size

    @property
    def z_range(self) -> tuple[float, float]:
        """World z (m) of the first and last grid rows: (min, max)."""
        return self.origin_z, self.origin_z + (self.heights.shape[0] - 1) * self.cell_size

    def contains(self, x: float, z: float, margin: float = 0.0) -> bool:
        """Whether world point (x, z) lies on the grid, at least ``margin`` m inside its border.

        Parameters
        ----------
        x, z : float
            World point (m).
        margin : float, optional
            Distance (m) the point must keep from the grid's border; 0 (default) accepts the border itself.

        Returns
        -------
        bool

        Examples
        --------
        >>> from footfall.scenarios import flat_heightfield
        >>> ground = flat_heightfield((2.0, 2.0), 0.5)    # x and z in [-1, 1] m
        >>> ground.contains(1.0, 0.0), ground.contains(1.0, 0.0, margin=0.1), ground.contains(1.5, 0.0)
        (True, False, False)
        """
        (x0, x1), (z0, z1) = self.x_range, self.z_range
        return x0 + margin <= x <= x1 - margin and z0 + margin <= z <= z1 - margin

    def height_at(self, x: np.ndarray | float, z: np.ndarray | float) -> np.ndarray:
        """Ground height (m) at world points (x, z), by bilinear interpolation.

        ``x`` and ``z`` (m) broadcast against each other; the result has their
        broadcast shape (a 0-d array for scalars). Points outside the grid take
        the height of the nearest border point. NaN coordinates give NaN.

        Parameters
        ----------
        x, z : float or array_like
            World coordinates (m).

        Returns
        -------
        ndarray
            float64 ground heights y (m), of the broadcast shape of ``x`` and ``z``.

        Examples
        --------
        >>> import numpy as np
        >>> from footfall.scenarios import Heightfield
        >>> ground = Heightfield(np.array([[0.0, 1.0], [2.0, 3.0]]), origin_x=0.0, origin_z=0.0, cell_size=1.0)
        >>> ground.height_at([0.0, 0.5, 5.0], 0.0)    # x = 5 m is beyond the grid: the border's height
        array([0. , 0.5, 1. ])
        >>> ground.height_at(0.5, [[0.0], [1.0]]).shape
        (2, 1)
        >>> ground.height_at(np.nan, 0.0)
        array(nan)
        """
        x = np.asarray(x, dtype=np.float64)
        z = np.asarray(z, dtype=np.float64)
        n_rows, n_cols = self.heights.shape
        col = np.clip((x - self.origin_x) / self.cell_size, 0.0, n_cols - 1)
        row = np.clip((z - self.origin_z) / self.cell_size, 0.0, n_rows - 1)
        col, row = np.broadcast_arrays(col, row)
        bad = ~(np.isfinite(col) & np.isfinite(row))
        if bad.any():
            col = np.where(bad, 0.0, col)
            row = np.where(bad, 0.0, row)
        c0 = np.minimum(np.floor(col).astype(np.intp), n_cols - 2)
        r0 = np.minimum(np.floor(row).astype(np.intp), n_rows - 2)
        tc = col - c0
        tr = row - r0
        h = self.heights
        near = h[r0, c0] * (1.0 - tc) + h[r0, c0 + 1] * tc
        far = h[r0 + 1, c0] * (1.0 - tc) + h[r0 + 1, c0 + 1] * tc
        result = near * (1.0 - tr) + far * tr
        if bad.any():
            result = np.where(bad, np.nan, result)
        return result
