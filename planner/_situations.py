"""Planning situations: a creature standing on the world, each foot asked to step.

This is the minimal placement the benchmarks, the ``footfall plan`` command and the
property tests need before the character controller exists: pelvis pose -> hips
and feet in the world -> one :class:`FootQuery` per foot whose preferred footprint
is its rest position moved forward by a step length.

Body frame: (forward, up, lateral); a heading psi (radians) puts forward at world
(cos psi, 0, sin psi) and lateral at (-sin psi, 0, cos psi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.planner._kernels_geometry import foot_offsets
from footfall.planner._maps import LocalMaps, WorldRaster
from footfall.planner._params import PlannerConfig
from footfall.planner._search import FootQuery


def body_to_world_xz(x: float, z: float, heading: float, forward, lateral):
    """World (x, z) of body-frame (forward, lateral) offsets for a pelvis at (x, z)."""
    c, s = math.cos(heading), math.sin(heading)
    forward = np.asarray(forward, dtype=np.float64)
    lateral = np.asarray(lateral, dtype=np.float64)
    return x + forward * c - lateral * s, z + forward * s + lateral * c


def foot_rest_height(maps: LocalMaps, row: int, col: int, offsets: np.ndarray) -> float:
    """Height a foot centred in cell (row, col) rests at: the highest elevation under
    its size-increase stencil (the dilated elevation of paper §5.1)."""
    n = maps.frame.n_rows
    rr = np.clip(row + offsets[:, 0], 0, n - 1)
    cc = np.clip(col + offsets[:, 1], 0, maps.frame.n_cols - 1)
    return float(maps.elevation[rr, cc].max())


@dataclass(frozen=True)
class StandingCreature:
    """A creature standing at a pose: its local maps, hips and feet (world, m)."""

    maps: LocalMaps
    heading: float
    hips: np.ndarray  # (L, 3)
    feet: np.ndarray  # (L, 3), feet on cell centres at their rest height
    foot_yaws: np.ndarray  # (L,) direction hip -> foot


def stand(creature, raster: WorldRaster, x: float, z: float, heading: float, t: float = 0.0,
          config: PlannerConfig | None = None) -> StandingCreature:
    """Place ``creature`` with its pelvis above (x, z), feet at their rest positions."""
    config = config or PlannerConfig()
    maps = raster.local_maps(x, z, t, config.map_cells)
    hx, hz = body_to_world_xz(x, z, heading, creature.hips[:, 0], creature.hips[:, 2])
    fx, fz = body_to_world_xz(x, z, heading, creature.rest_feet[:, 0], creature.rest_feet[:, 1])
    rows, cols = maps.frame.world_to_cell(fx, fz)
    rows = np.clip(rows, 0, maps.frame.n_rows - 1)
    cols = np.clip(cols, 0, maps.frame.n_cols - 1)
    cx, cz = maps.frame.cell_to_world(rows, cols)
    yaws = np.arctan2(cz - hz, cx - hx)
    feet = np.empty((creature.n_legs, 3))
    for i in range(creature.n_legs):
        off = foot_offsets(creature.foot_length, creature.foot_width, float(yaws[i]), config.cell_size)
        feet[i] = (cx[i], foot_rest_height(maps, int(rows[i]), int(cols[i]), off), cz[i])
    r0, c0 = maps.frame.world_to_cell(x, z)
    ground = float(maps.ground[int(np.clip(r0, 0, maps.frame.n_rows - 1)), int(np.clip(c0, 0, maps.frame.n_cols - 1))])
    hips = np.column_stack([hx, ground + creature.standing_height + creature.hips[:, 1], hz])
    return StandingCreature(maps, float(heading), hips, feet, yaws)


def step_queries(creature, standing: StandingCreature, step_length: float, step_height: float) -> list[FootQuery]:
    """One query per foot: preferred footprint = current foot + step_length forward."""
    fwd = np.array([math.cos(standing.heading), math.sin(standing.heading)])
    queries = []
    n = creature.n_legs
    for i in range(n):
        others = [j for j in range(n) if j != i]
        legs = np.column_stack([standing.hips[others, 0], standing.hips[others, 2],
                                standing.feet[others, 0], standing.feet[others, 2]])
        dy = standing.hips[i, 1] - standing.feet[i, 1]
        reach = 0.95 * float(creature.leg_reach[i])
        reach_xz = math.sqrt(max(reach * reach - dy * dy, (0.1 * reach) ** 2))
        preferred = standing.feet[i, [0, 2]] + step_length * fwd
        queries.append(FootQuery(
            source=standing.feet[i], preferred=preferred, hip=standing.hips[i, [0, 2]], reach_xz=reach_xz,
            step_height=float(step_height), foot_length=float(creature.foot_length),
            foot_width=float(creature.foot_width), foot_yaw=float(standing.foot_yaws[i]), other_legs=legs))
    return queries
