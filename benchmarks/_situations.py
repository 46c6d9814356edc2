"""Seeded planning situations on a scenario, shared by the planner benchmarks."""

from __future__ import annotations

import math

import numpy as np

from footfall.planner import PlannerConfig, WorldRaster
from footfall.planner._situations import stand, step_queries


def scenario_situations(scenario, creature, n_poses: int, seed: int, config: PlannerConfig):
    """``n_poses`` seeded poses of ``creature`` among the scenario's obstacles.

    Returns (raster, maps list, [(map index, FootQuery)]). Poses are drawn in the
    bounding box of the obstacles (where planning is hard), headings and times
    uniformly; each foot asks for a step of 0.3 x the leg reach forward.
    """
    raster = WorldRaster.build(scenario.terrain, scenario.obstacles, config.cell_size)
    rng = np.random.default_rng(seed)
    obstacles = scenario.obstacles
    if len(obstacles):
        lo = obstacles.centres[:, [0, 2]].min(axis=0) - 0.5
        hi = obstacles.centres[:, [0, 2]].max(axis=0) + 0.5
    else:
        lo = np.array([-2.0, -2.0])
        hi = np.array([2.0, 2.0])
    x0, x1 = scenario.terrain.x_range
    z0, z1 = scenario.terrain.z_range
    pad = config.map_cells * config.cell_size / 2
    lo = np.maximum(lo, [x0 + pad, z0 + pad])
    hi = np.minimum(hi, [x1 - pad, z1 - pad])
    maps, requests = [], []
    step_length = 0.3 * float(creature.max_reach)
    step_height = 0.3 * float(creature.standing_height)
    for _ in range(n_poses):
        x, z = rng.uniform(lo, hi)
        heading = rng.uniform(-math.pi, math.pi)
        t = rng.uniform(0.0, 10.0)
        standing = stand(creature, raster, float(x), float(z), float(heading), float(t), config)
        maps.append(standing.maps)
        for q in step_queries(creature, standing, step_length, step_height):
            requests.append((len(maps) - 1, q))
    return raster, maps, requests
