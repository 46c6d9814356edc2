"""The ground under the feet: the planner's footprint features (slope, roughness) read on the terrain
where feet stand, whatever the scoring weights (a measure of where feet landed, for the tuning's
touch-down metrics)."""

from __future__ import annotations

import numpy as np

from footfall.planner._kernels_foot import footprint_features
from footfall.planner.layout import FEAT_ROUGHNESS, FEAT_SLOPE, N_FEATURES, N_LEG_COLUMNS

_CENTRE = 4
"""The foot's cell in its 3 x 3 neighbourhood, flattened row by row (z, then x)."""
_NO_LEGS = np.zeros((0, N_LEG_COLUMNS))  # planner.layout.LEG_ROW rows: none


def ground_under_feet(terrain, feet_xz: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The slope and roughness of the ground under feet: the planner's footprint features
    (``planner._kernels_foot.footprint_features``: the slope from one-sided differences through the
    slope limiter, the roughness as the largest height step to the 8 neighbours) read on the terrain's
    heights at ``spacing`` around each foot. The terrain's ground only: a foot on a safe box's top
    reads the ground under the box (the styles measured with it are tuned on open ground).

    Parameters
    ----------
    terrain : object with ``height_at(x, z)``
        The ground (a :class:`footfall.scenarios.Heightfield`): heights (m) at world points, broadcast.
    feet_xz : (n, 2) array
        The feet's ground positions x, z (m).
    spacing : float
        The neighbours' distance (m); the planner's cell size reads the ground as the planner does.

    Returns
    -------
    slope : (n,) array
        The ground's slope under each foot (rad).
    roughness : (n,) array
        The largest height difference (m) from the ground under the foot to its 8 neighbours.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import ground_under_feet
    >>> from footfall.scenarios import Heightfield
    >>> ramp = Heightfield(np.tile(0.5 * np.arange(5.0), (5, 1)), origin_x=0.0, origin_z=0.0, cell_size=1.0)
    >>> slope, rough = ground_under_feet(ramp, np.array([[2.0, 2.0]]), 1.0)
    >>> round(float(slope[0]), 4), float(rough[0])      # atan(0.5); a step of 0.5 m to the x neighbours
    (0.4636, 0.5)
    """
    feet_xz = np.asarray(feet_xz, dtype=np.float64).reshape(-1, 2)
    x, z = feet_xz[:, 0], feet_xz[:, 1]
    d = np.array([-spacing, 0.0, spacing])
    h = terrain.height_at(x[:, None, None] + d[None, None, :], z[:, None, None] + d[None, :, None])  # (n, z, x)
    # The planner's own features (one definition), on each foot's 3 x 3 neighbourhood: the terrain's
    # heights stand for both its dilated and raw elevation, with no other leg to cross.
    cells = np.ascontiguousarray(h.reshape(x.size, 9))
    features = np.empty(N_FEATURES)
    slope = np.empty(x.size)
    rough = np.empty(x.size)
    for i in range(x.size):
        footprint_features(_CENTRE, x[i], z[i], cells[i], cells[i], np.zeros(9), 3, x[i], z[i], x[i], z[i], _NO_LEGS,
                           spacing, features)
        slope[i] = features[FEAT_SLOPE]
        rough[i] = features[FEAT_ROUGHNESS]
    return slope, rough
