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
    heights:
        (R, C) float64, m, read-only, R >= 2 and C >= 2, all finite.
    origin_x, origin_z:
        World x and z (m) of ``heights[0, 0]``.
    cell_size:
        Grid spacing (m), > 0, the same along x and z.
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
        """Whether world point (x, z) lies on the grid, at least ``margin`` m inside its border."""
        (x0, x1), (z0, z1) = self.x_range, self.z_range
        return x0 + margin <= x <= x1 - margin and z0 + margin <= z <= z1 - margin

    def height_at(self, x: np.ndarray | float, z: np.ndarray | float) -> np.ndarray:
        """Ground height (m) at world points (x, z), by bilinear interpolation.

        ``x`` and ``z`` (m) broadcast against each other; the result has their
        broadcast shape (a 0-d array for scalars). Points outside the grid take
        the height of the nearest border point. NaN coordinates give NaN.
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
