"""``footfall bench planner``: microseconds per foot plan, and the shared wavefront's speedup.

Per-foot times are measured by calling the batch kernel on one foot at a time
(the best of ``repeats`` runs per foot, then the median over feet); they include
the kernel's dispatch overhead (a few microseconds), so they are conservative.

The wavefront comparison runs, on the same per-foot grids (the region of
interest of each foot with the potential field, no slices): one shared wavefront
from the source settling every candidate; one wavefront per candidate (each
stopping at its target); and scikit-image's ``MCP_Geometric`` from the source
with the candidates as ends.
"""

from __future__ import annotations

import time

import numpy as np

from footfall.planner import DEFAULT_BUDGET, EXHAUSTIVE, FIRST_VALID, PlannerConfig, ScoringWeights, make_batch
from footfall.planner._kernels_batch import FootRequests, FootResults, plan_feet_serial
from footfall.planner._kernels_foot import footprint_candidates, prepare_foot, slice_maps, swing_reach
from footfall.planner._kernels_geometry import foot_offsets
from footfall.planner._kernels_wavefront import per_target_wavefronts, wavefront
from footfall.planner._search import MODES
from footfall.planner.layout import N_COUNTERS, N_RAW, N_TERMS
from footfall.scenarios import load_creature, load_scenario

from footfall.benchmarks._situations import scenario_situations

BUDGETS = {"first_valid": FIRST_VALID, "default": DEFAULT_BUDGET, "exhaustive": EXHAUSTIVE}
SCENARIOS = ("crates", "mixed")


def _time_best(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _per_foot_us(batch, weights, config, repeats: int) -> np.ndarray:
    w = weights.to_array()
    cfg = config.to_array()
    k = config.trajectory_samples
    times = np.empty(batch.n_feet)
    outs = FootResults(np.zeros(1, np.bool_), np.zeros((1, 3)), np.zeros(1, np.int64), np.zeros(1), np.zeros((1, 3)),
                       np.zeros((1, N_TERMS)), np.zeros((1, N_RAW)), np.zeros((1, N_COUNTERS), np.int64),
                       np.zeros((1, k, 3)))
    for i in range(batch.n_feet):
        ls, le = batch.legs_start[i], batch.legs_start[i + 1]
        ch = batch.foot_char[i]
        request = FootRequests(
            elevation=batch.elevation[ch:ch + 1], ground=batch.ground[ch:ch + 1], forbidden=batch.forbidden[ch:ch + 1],
            origins=batch.origins[ch:ch + 1], foot_char=np.zeros(1, np.int64), foot_shape=batch.foot_shape[i:i + 1],
            sources=batch.sources[i:i + 1], preferred=batch.preferred[i:i + 1], hips=batch.hips[i:i + 1],
            reach_xz=batch.reach_xz[i:i + 1], step_height=batch.step_height[i:i + 1],
            legs=np.ascontiguousarray(batch.legs[ls:le]), legs_start=np.array([0, le - ls], np.int64),
            block_radius=batch.block_radius[i:i + 1], couples_after_first=batch.couples_after_first[i:i + 1],
            slice_size=batch.slice_size[i:i + 1], early=batch.early[i:i + 1])
        args = (request, w, cfg, MODES["search"], outs)
        times[i] = _time_best(lambda: plan_feet_serial(*args), repeats)
    return times * 1e6


def _wavefront_grids(maps, requests, weights, config):
    """Per-foot (passable, factor, wp, source, candidates, shape) on the no-slice map."""
    w = weights.to_array()
    cell = config.cell_size
    grids = []
    for ch, q in requests:
        m = maps[ch]
        offsets = foot_offsets(q.foot_length, q.foot_width, q.foot_yaw, cell)
        code, elev_dil, boxh, raw, r0, c0, hp, wp = prepare_foot(
            m.elevation, m.ground, m.forbidden, m.frame.origin_x, m.frame.origin_z, cell, offsets, q.source[0],
            q.source[2], q.preferred[0], q.preferred[1], config.search_radius_m, config.roi_margin_cells,
            q.kernel_legs, q.feet_block_radius)
        sr, sc = m.frame.world_to_cell(q.source[0], q.source[2])
        source = int((sr - r0 + 1) * wp + (sc - c0 + 1))
        cands = footprint_candidates(code, elev_dil, raw, r0, c0, hp, wp, m.frame.origin_x, m.frame.origin_z, cell,
                                     source, q.source[0], q.source[2], q.preferred[0], q.preferred[1],
                                     config.search_radius_m, q.hip[0], q.hip[1], q.reach_xz, q.kernel_legs,
                                     q.feet_block_radius, w)[0]
        if cands.size == 0:
            continue
        n = hp * wp
        passable = np.empty(n, np.uint8)
        factor = np.empty(n)
        dt = np.empty(n)
        in_reach = np.empty(n, np.uint8)
        swing_reach(r0, c0, hp, wp, m.frame.origin_x, m.frame.origin_z, cell, q.source[0], q.source[2], q.hip[0],
                    q.hip[1], q.reach_xz, in_reach)
        slice_maps(code, boxh, np.inf, config.slice_epsilon_m, source, in_reach, hp, wp, cell,
                   config.potential_range_m, config.potential_gain, passable, factor, dt)
        grids.append((passable, factor, wp, hp, source, cands))
    return grids


def _wavefront_speedups(grids, cell, repeats):
    from skimage.graph import MCP_Geometric

    t_shared = t_per_target = t_mcp = 0.0
    for passable, factor, wp, hp, source, cands in grids:
        dist = np.empty(passable.size)
        parent = np.empty(passable.size, np.int64)
        t_shared += _time_best(lambda: wavefront(passable, factor, wp, source, cell, cands, dist, parent), repeats)
        t_per_target += _time_best(
            lambda: per_target_wavefronts(passable, factor, wp, source, cell, cands, dist, parent), repeats)
        costs = np.where(passable.reshape(hp, wp) > 0, factor.reshape(hp, wp), np.inf)
        start = [divmod(source, wp)]
        ends = [divmod(int(c), wp) for c in cands]

        def mcp():
            MCP_Geometric(costs, fully_connected=True).find_costs(start, ends)

        t_mcp += _time_best(mcp, repeats)
    return t_per_target / t_shared, t_mcp / t_shared, len(grids)


def run(n_poses: int = 12, seed: int = 0, repeats: int = 3, progress=None) -> dict:
    """Run the planner benchmark; returns the ``--json`` object (plus a ``details`` key)."""
    config = PlannerConfig()
    weights = ScoringWeights()
    result: dict = {"scenarios": {}}
    details: dict = {}
    all_grids = []
    for name in SCENARIOS:
        scenario = load_scenario(name)
        creature = load_creature(scenario.crowd.creature)
        _, maps, requests = scenario_situations(scenario, creature, n_poses, seed, config)
        row = {}
        det = {}
        for label, budget in BUDGETS.items():
            batch = make_batch(maps, requests, budget)
            us = _per_foot_us(batch, weights, config, repeats)
            row[f"{label}_us"] = float(np.median(us))
            det[label] = {"p90_us": float(np.percentile(us, 90)), "feet": int(batch.n_feet)}
            if progress:
                progress(f"{name} {label}")
        result["scenarios"][name] = row
        details[name] = det
        all_grids += _wavefront_grids(maps, requests, weights, config)
    per_target, mcp, n_grids = _wavefront_speedups(all_grids, config.cell_size, repeats)
    result["speedup_vs_per_target"] = float(per_target)
    result["speedup_vs_skimage_mcp"] = float(mcp)
    result["details"] = {"per_scenario": details, "wavefront_grids": n_grids, "poses_per_scenario": n_poses,
                         "creature_step": "0.3 x leg reach"}
    return result
