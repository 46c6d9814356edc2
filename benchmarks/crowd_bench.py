"""``footfall bench crowd``: the paper's Table 1 for crowds of spiders on ``mixed``.

For each crowd size and LOD mode: a fresh crowd, ``warmup`` frames not measured
(the crowd gets moving), then ``frames`` measured frames. Reported per mode: the
median ms per frame (all stages: 'total for characters'), the median of the maps
preparation stage, of the CCD IK stage, and the average FPS (1000 / mean frame ms).
"""

from __future__ import annotations


from planner._crowd import init_crowd
from planner import PlannerConfig, WorldRaster
from planner._simulation import simulate
from scenarios import load_creature, load_gait, load_scenario, default_gait_name

MODES = ("on", "zoomed", "off")


def run(sizes=(100, 1000), frames: int = 60, warmup: int = 30, seed: int = 0, scenario_name: str = "mixed",
        progress=None) -> dict:
    scenario = load_scenario(scenario_name)
    creature = load_creature("spider")
    gait = load_gait(default_gait_name("spider"), creature)
    raster = WorldRaster.build(scenario.terrain, scenario.obstacles, PlannerConfig().cell_size)
    out: dict = {}
    for n in sizes:
        out[str(n)] = {}
        for mode in MODES:
            model, state = init_crowd(scenario, creature, gait, n_characters=n, seed=seed, lod_mode=mode,
                                      raster=raster)
            simulate(model, state, warmup)
            summary = simulate(model, state, frames)
            out[str(n)][mode] = {
                "ms_per_frame": summary.ms_per_frame_median,
                "maps_ms": summary.stage_ms_median["maps"],
                "plan_ms": summary.stage_ms_median["plan"],
                "ik_ms": summary.stage_ms_median["ik"],
                "fps": 1000.0 / max(summary.ms_per_frame_mean, 1e-9),
                "plans_per_frame": summary.plans / frames,
                "collisions": summary.collisions,
            }
            if progress:
                progress(f"{n} spiders, LOD {mode}")
    return out
