"""``footfall bench crowd``: the paper's Table 1 for crowds of spiders on ``mixed``.

For each crowd size, one fresh crowd per LOD mode (``on``, ``zoomed``, ``off``, the same seed and
spawn), ``warmup`` frames not measured (the crowds get moving), then ``frames`` measured rounds.
A round steps every mode's crowd by one frame, the order rotating from round to round: the three
modes share whatever load the machine has at that moment, so their ratio holds still when other
programs slow every frame down (their milliseconds do not).

Per mode: the median ms per frame (all stages: 'total for characters') with a 95 % confidence
interval of that median (order statistics of the frames), the medians of the maps preparation,
planning and IK stages, the average FPS (1000 / mean frame ms), and the work done per frame
(plans, local-map cells built, legs solved by CCD and by the two-bone IK, wavefront cells
expanded, couples evaluated), counted by the runtime. Per size:
``ratio_on_off``, the LOD-on median over the LOD-off median, with a 95 % bootstrap interval over
the rounds (``ratio_on_off_ci``).

Crowds of more than :data:`SMALL_WORLD_MAX` spiders do not fit the 20 m square of ``mixed``:
they walk the same scenario on a 60 m square (:data:`LARGE_SCENARIO`; the crates stay where they are).
"""

from __future__ import annotations

import numpy as np

from footfall.planner import WorldRaster
from footfall.planner._crowd import init_crowd, step
from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

MODES = ("on", "zoomed", "off")
SIZES = (100, 1000, 3000, 5000)
SMALL_WORLD_MAX = 1000
LARGE_SCENARIO = "mixed@terrain.size=[60.0,60.0]"
BOOTSTRAP = 400  # resamples of the rounds for the ratio's interval
WORK = ("plans", "map_cells_built", "ik_ccd_legs", "ik_two_bone_legs", "cells_expanded", "couples_evaluated")


def scenario_for(n: int, scenario_name: str = "mixed") -> str:
    """The scenario a crowd of ``n`` spiders is benchmarked on (module doc)."""
    return scenario_name if n <= SMALL_WORLD_MAX or scenario_name != "mixed" else LARGE_SCENARIO


def median_ci(values) -> tuple[float, float]:
    """Distribution-free 95 % interval of the median of ``values``: the order statistics whose
    ranks bracket n/2 by 1.96 sqrt(n)/2 (the binomial's normal approximation).

    Examples
    --------
    >>> median_ci(np.arange(100.0))
    (40.0, 60.0)
    """
    v = np.sort(np.asarray(values, dtype=np.float64))
    n = v.size
    half = 1.96 * np.sqrt(n) / 2.0
    lo = int(max(0, np.floor(n / 2.0 - half)))
    hi = int(min(n - 1, np.ceil(n / 2.0 + half)))
    return float(v[lo]), float(v[hi])


def ratio_ci(on: np.ndarray, off: np.ndarray, seed: int = 0) -> tuple[float, float]:
    """95 % bootstrap interval of median(on) / median(off), resampling the rounds (paired)."""
    rng = np.random.default_rng(seed)
    k = rng.integers(0, on.size, size=(BOOTSTRAP, on.size))
    ratios = np.median(on[k], axis=1) / np.median(off[k], axis=1)
    lo, hi = np.percentile(ratios, [2.5, 97.5])
    return float(lo), float(hi)


def run(sizes=(100, 1000), frames: int = 60, warmup: int = 30, seed: int = 0, scenario_name: str = "mixed",
        progress=None, creature_name: str = "spider") -> dict:
    creature = load_creature(creature_name)
    gait = load_gait(default_gait_name(creature.name), creature)
    out: dict = {}
    rasters: dict = {}
    for n in sizes:
        name = scenario_for(n, scenario_name)
        scenario = load_scenario(name)
        if name not in rasters:
            from footfall.planner._crowd import planner_config_for

            rasters[name] = WorldRaster.build(scenario.terrain, scenario.obstacles,
                                              planner_config_for(creature).cell_size)
        crowds = {mode: init_crowd(scenario, creature, gait, n_characters=n, seed=seed, lod_mode=mode,
                                   raster=rasters[name]) for mode in MODES}
        for k in range(warmup):
            for mode in MODES:
                step(*crowds[mode])
        before = {mode: dict(crowds[mode][1].counters) for mode in MODES}
        frame_ms = {mode: np.zeros(frames) for mode in MODES}
        stage_ms = {mode: {s: np.zeros(frames) for s in ("maps", "plan", "ik")} for mode in MODES}
        for k in range(frames):
            for j in np.roll(np.arange(len(MODES)), k):
                mode = MODES[j]
                timings = step(*crowds[mode]).timings
                frame_ms[mode][k] = 1e3 * sum(timings.values())
                for s in stage_ms[mode]:
                    stage_ms[mode][s][k] = 1e3 * timings[s]
            if progress and (k + 1) % 10 == 0:
                progress(f"{n} spiders: round {k + 1}/{frames}")
        out[str(n)] = {"scenario": name}
        for mode in MODES:
            counters = crowds[mode][1].counters
            ms = frame_ms[mode]
            out[str(n)][mode] = {
                "ms_per_frame": float(np.median(ms)),
                "ms_per_frame_ci": list(median_ci(ms)),
                "maps_ms": float(np.median(stage_ms[mode]["maps"])),
                "plan_ms": float(np.median(stage_ms[mode]["plan"])),
                "ik_ms": float(np.median(stage_ms[mode]["ik"])),
                "fps": 1000.0 / max(float(np.mean(ms)), 1e-9),
                **{f"{key}_per_frame": (counters[key] - before[mode][key]) / frames for key in WORK},
            }
        on, off = frame_ms["on"], frame_ms["off"]
        out[str(n)]["ratio_on_off"] = float(np.median(on) / np.median(off))
        out[str(n)]["ratio_on_off_ci"] = list(ratio_ci(on, off, seed))
        if progress:
            progress(f"{n} spiders done")
    return out
