"""One layout of a box as a mesh, for every drawing of the reports (the pyvista pictures and clips,
the USD scene): 8 corners and 6 quads.

>>> faces_of(2)[6]  # the second box's first face: the first one's, 8 corners on
array([ 8, 12, 14, 10])
"""

from __future__ import annotations

import numpy as np

BOX_CORNERS = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float64)
"""(8, 3) corners of the unit box [0, 1]^3, corner i at (x, y, z) with i = x + 2 y + 4 z."""
BOX_FACES = np.array([[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]])
"""(6, 4) each face's corners, counter-clockwise seen from outside (outward normals, right-handed:
USD's default orientation and VTK's)."""


def faces_of(n_boxes: int) -> np.ndarray:
    """(6 n, 4) the faces of ``n_boxes`` boxes whose corners are stacked 8 per box."""
    return (BOX_FACES[None] + 8 * np.arange(n_boxes)[:, None, None]).reshape(-1, 4)


def box_corners(centres, sizes, yaws) -> np.ndarray:
    """(B, 8, 3) corners of each box (numbered as :data:`BOX_CORNERS`): a box's local x is world
    (cos yaw, 0, sin yaw), its local z world (-sin yaw, 0, cos yaw) (a turn of -yaw about +y)."""
    centres, sizes, yaws = (np.asarray(a, dtype=np.float64) for a in (centres, sizes, yaws))
    local = (BOX_CORNERS[None] - 0.5) * sizes[:, None, :]
    cos, sin = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    world = np.empty_like(local)
    world[..., 0] = cos * local[..., 0] - sin * local[..., 2]
    world[..., 1] = local[..., 1]
    world[..., 2] = sin * local[..., 0] + cos * local[..., 2]
    return world + centres[:, None, :]
