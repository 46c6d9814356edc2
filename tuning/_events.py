"""The exact objective of the terrain and style tunes: runs that meet the terrain, measured per event.

The legacy objective (:mod:`tuning._exact`) runs 150 frames at a sweep of speeds: under 1 m, so
the ``stairs`` runs stop before the first riser and the ``mixed`` runs never meet a crate
(issue 18). Here every run crosses its feature:

* **spawns along the route**: each scenario is run from :data:`SPAWN_FRACTIONS` of the way from
  its crowd's spawn to its goal (the variant ``crowd.centre=[x,z]``: a scenario's random crates
  keep out of the new spawn, so each spawn is also another layout), for :data:`EVENT_FRAMES`
  frames (10 s, 3 m at the spider's 0.3 m/s): a spider spawned 2 m before the stairs climbs them;
* each run is exactly ``footfall simulate VARIANT --creature C --seed S --characters N --frames F
  --preset P --json`` (the same gait, the same summary, :func:`replay_command`): the per-stride
  error, speed reached, holds, stuck time, collisions and body overlaps are the simulation's own
  metrics (:class:`planner._simulation.SimulationSummary`), not re-derived here;
* measured beside them, from the plans of the run (every valid plan of a swing; the last plan of a
  swing is where its foot touches down): the curvature energy's 95th percentile, the touch-down
  slope and roughness under the planned footprints, the touch-downs' clearance to forbidden
  boxes (5th percentile, in body heights h), and the distance walked / asked.

Per run (:data:`EVENT_METRICS`):

* ``stride_error``: the summary's ``stride_rel_error_median`` (per stride |lambda_i / lambda*(v_i) - 1|;
  the timing commands the targets' stride law, :meth:`tuning._targets.CreatureTargets.timing`);
* ``speed_ratio``: ``speed_reached`` / min(asked, cap);
* ``holds_per_100_steps``, ``stuck_s_per_100_steps``: ``holds`` and ``stuck_seconds`` per 100 ``steps``;
* ``collisions``: ``collisions`` + ``body_overlaps`` (feet in boxes, bodies in bodies: held at 0);
* ``leg_crossings``: the summary's crossing frames (not in the run loss; the preset matrix's guard);
* ``curvature_p95``: 95th percentile of the plans' raw curvature energy (``RAW_CURVATURE``);
* ``touchdown_slope_rad``, ``touchdown_roughness_m``: mean over the touch-downs of the ground's slope
  and roughness under the foot (:func:`planner.ground_under_feet`: the planner's footprint features,
  read on the terrain where the foot landed at the planner's cell spacing). Whatever the weights: read back
  from the plans' goodnesses (x = (1 - s) critical, capped at the critical value), a preset that
  lowered ``slope_critical_rad`` 1.0 -> 0.32 lowered its own metric 0.058 -> 0.036 rad on rough
  ground while its feet landed on ground as steep as the defaults' (0.0741 against 0.0747 rad);
* ``clearance_p05_h``: 5th percentile over the touch-downs of the foot's horizontal distance to the
  nearest forbidden box (its footprint rectangle at that time, the boxes the creature may not step
  on) / h, capped at :data:`CLEARANCE_CAP_H` (no forbidden box: the cap). The plans' own clearance
  metric (``RAW_CLEARANCE``) is not used: it counts the other legs' cells as blocked, so its 5th
  percentile is one cell whatever the weights;
* ``near_box_share``: the share of the touch-downs closer than the clearance target to a forbidden box
  (the style's ``min_clearance_body_heights`` x h, else the ``clearance`` target's minimum x h): most
  touch-downs are far from every box (the crowd steers around them), so a percentile says little;
* ``distance_ratio``: ground distance the pelvis walked / what the asked speed (at most the cap) would
  have walked, over the frames after the first second (the start from standing) in which a character
  had not yet arrived.

Run loss (what the line search and the held-out comparison add up, paired run by run)::

    (stride_error / relative_tolerance)^2 + holds_per_100_steps / HOLDS_REF
    + COLLISION_PENALTY * [collisions > 0] + sum over the style's keys of hinge^2,

hinges (0 when the style is met): near_box_share / NEAR_SHARE_REF for the minimum clearance, and
log ratios (scale-free) for the others: relu(log(curvature_p95 / ceiling)),
relu(log(min_distance_ratio / distance_ratio)), relu(log(touchdown_slope_rad / ceiling)).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from footfall.planner import task_mapper
from footfall.planner.layout import RAW_CURVATURE

EVENT_FRAMES = 300
SPAWN_FRACTIONS = (0.15, 0.3, 0.45)
"""Where along the route (spawn -> goal) the runs of a scenario start."""
HOLDS_REF = 10.0
"""Holds per 100 steps that cost as much as a per-stride error of one tolerance."""
COLLISION_PENALTY = 4.0
"""Cost of a run with any collision or body overlap (a stride error of two tolerances): per run, not
per foot-frame -- one run whose foot stays in a box for 100 frames made the paired losses' spread
100x, and no candidate could show a gain beyond it."""
CLEARANCE_CAP_H = 10.0
LOG_FLOOR = 1e-6
NEAR_SHARE_REF = 0.05
"""A share of touch-downs near a box that costs as much as a stride error of one tolerance."""
EVENT_METRICS = ("stride_error", "speed_ratio", "holds_per_100_steps", "stuck_s_per_100_steps", "collisions",
                 "leg_crossings", "curvature_p95", "touchdown_slope_rad", "touchdown_roughness_m", "clearance_p05_h", "near_box_share",
                 "distance_ratio")
STYLE_METRIC = {"min_clearance_body_heights": "near_box_share", "curvature_p95_max": "curvature_p95",
                "min_distance_ratio": "distance_ratio", "max_touchdown_slope_rad": "touchdown_slope_rad"}
"""The run metric each style key bounds."""
LOWER_BOUND_STYLES = ("min_distance_ratio",)
"""Style keys whose metric moves toward the bound by rising (the others: by falling)."""


@dataclass(frozen=True)
class EventSetup:
    """Which runs make the objective of one creature: scenarios x spawns x seeds."""

    creature: str
    scenarios: tuple[str, ...]
    seeds: tuple[int, ...] = (0,)
    frames: int = EVENT_FRAMES
    n_characters: int | None = 1  # None: the scenario's own crowd
    spawn_fractions: tuple[float, ...] = SPAWN_FRACTIONS

    def __post_init__(self) -> None:
        for name in ("scenarios", "seeds", "spawn_fractions"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        if not self.scenarios or not self.seeds or not self.spawn_fractions:
            raise ValueError("EventSetup: expected at least one scenario, seed and spawn")
        if self.frames < 60:
            raise ValueError(f"EventSetup.frames: expected >= 60, got {self.frames}")
        if not all(0.0 <= f < 1.0 for f in self.spawn_fractions):
            raise ValueError(f"EventSetup.spawn_fractions: expected numbers in [0, 1), got {self.spawn_fractions}")

    @property
    def n_runs(self) -> int:
        return len(self.scenarios) * len(self.seeds) * len(self.spawn_fractions)

    def to_json(self) -> dict:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in dataclasses.asdict(self).items()}


SPAWN_NUDGES = ((0.0, 0.0), (0.0, 0.5), (0.0, -0.5), (0.0, 1.0), (0.0, -1.0), (0.5, 0.0), (-0.5, 0.0))
"""Offsets (along the route, across it; m) tried in order when a spawn along the route overlaps a box."""


@functools.lru_cache(maxsize=256)
def spawn_variant(name: str, fraction: float) -> str:
    """The scenario ``name`` (a built-in or a variant) with its crowd spawned ``fraction`` of the way
    to its goal (``fraction`` 0: ``name`` itself). Where that spawn overlaps a box (the scenario refuses
    it), the first of :data:`SPAWN_NUDGES` that loads: deterministic, so a task carries a plain string."""
    from footfall._errors import InputError
    from footfall.scenarios import load_scenario

    if fraction == 0.0:
        return name
    crowd = load_scenario(name).crowd
    goal = np.asarray(crowd.route, dtype=np.float64)[-1]
    centre = np.asarray(crowd.centre, dtype=np.float64)
    along = (goal - centre) / max(float(np.hypot(*(goal - centre))), 1e-12)
    across = np.array([-along[1], along[0]])
    base, sep, rest = name.partition("@")
    error = None
    for da, dc in SPAWN_NUDGES:
        x, z = (float(round(c, 4)) for c in centre + fraction * (goal - centre) + da * along + dc * across)
        extra = f"crowd.centre=[{x!r},{z!r}]"
        variant = f"{base}@{rest},{extra}" if sep and rest else f"{base}@{extra}"
        try:
            load_scenario(variant)
        except InputError as e:
            error = error or e
            continue
        return variant
    raise error


def event_tasks(setup: EventSetup, weights, timing) -> list[dict]:
    """One plain-dict task per scenario x spawn x seed, in the order the runs are merged."""
    w = [float(x) for x in weights.to_array()]
    t = [float(x) for x in timing.to_array()]
    return [{"creature": setup.creature, "scenario": spawn_variant(scenario, fraction), "base": scenario,
             "spawn": float(fraction), "seed": int(seed), "frames": int(setup.frames),
             "characters": setup.n_characters, "weights": w, "timing": t}
            for scenario in setup.scenarios
            for fraction in setup.spawn_fractions
            for seed in setup.seeds]


def replay_command(task: dict, preset: str = "PRESET.json") -> str:
    """The ``footfall simulate`` command that runs the same run (its summary is the run's)."""
    characters = "" if task["characters"] is None else f" --characters {task['characters']}"
    return (f"footfall simulate '{task['scenario']}' --creature {task['creature']} --seed {task['seed']}{characters} "
            f"--frames {task['frames']} --preset {preset} --json")


def run_event_task(task: dict) -> dict:
    """One run of :func:`event_tasks`: the simulation's summary and the plan metrics (picklable)."""
    from footfall.scenarios._gait_choice import resolve_gait
    from footfall.planner import (
        GaitTiming,
        ScoringWeights,
        arrived,
        asked_speed,
        ground_under_feet,
        hip_height,
        init_crowd,
        simulate,
        single_threaded,
    )
    from footfall.scenarios import load_creature, load_scenario

    weights = ScoringWeights.from_array(task["weights"])
    timing = GaitTiming.from_array(task["timing"])
    scenario = load_scenario(task["scenario"])
    creature = load_creature(task["creature"])
    own = task["creature"] == scenario.crowd.creature
    gait, _, _ = resolve_gait(scenario if own else None, creature)
    with single_threaded():
        model, state = init_crowd(scenario, creature, gait, n_characters=task["characters"], seed=task["seed"],
                                  weights=weights, timing=timing, lod_mode="off")
        h = hip_height(creature)
        goal = asked_speed(model, state)
        curvature, slope, rough, clearance = [], [], [], []
        obstacles = model.raster.obstacles
        forbidden = np.asarray(obstacles.forbidden, dtype=np.bool_) if len(obstacles.yaws) else np.zeros(0, bool)
        half = 0.5 * np.asarray(obstacles.sizes, dtype=np.float64)[forbidden][:, [0, 2]] if forbidden.any() else None
        prev = [state.in_stance.copy()]
        walked = np.zeros(state.pelvis.shape[0])
        asked = np.zeros(state.pelvis.shape[0])
        before = [state.pelvis[:, [0, 2]].copy()]

        started = int(round(1.0 / model.dt))

        def after(k, record):
            now = state.pelvis[:, [0, 2]]
            walking = ~arrived(model, state) & (k > started)
            walked[walking] += np.hypot(*(now - before[0]).T)[walking]
            asked[walking] += goal[walking] * model.dt
            before[0] = now.copy()
            landed = state.in_stance & ~prev[0]
            prev[0] = state.in_stance.copy()
            if landed.any():
                feet = state.feet[landed][:, [0, 2]]
                ground_slope, ground_rough = ground_under_feet(scenario.terrain, feet, model.config.cell_size)
                slope.append(ground_slope)
                rough.append(ground_rough)
                if half is not None:
                    centres, yaws = obstacles.poses_at(state.t)
                    clearance.append(box_distance(feet, centres[forbidden][:, [0, 2]], half,
                                                  yaws[forbidden]).min(axis=1))
            if record.plans is not None:
                out = record.plans.result
                curvature.append(out.raw[out.valid, RAW_CURVATURE])

        summary = simulate(model, state, task["frames"], on_step=after).to_json()

    def cat(parts):
        return np.concatenate(parts) if parts else np.zeros(0)

    curvature, clearance, slope, rough = cat(curvature), cat(clearance), cat(slope), cat(rough)
    clear_h = np.minimum(clearance / h, CLEARANCE_CAP_H)
    steps = max(int(summary["steps"]), 1)
    goal_speed = min(summary["speed_asked"], summary["speed_cap"] if summary["speed_cap"] is not None else math.inf)
    error = summary["stride_rel_error_median"]
    metrics = {
        "stride_error": math.nan if error is None else float(error),
        "speed_ratio": float(summary["speed_reached"] / goal_speed) if goal_speed > 0 else math.nan,
        "holds_per_100_steps": 100.0 * summary["holds"] / steps,
        "stuck_s_per_100_steps": 100.0 * summary["stuck_seconds"] / steps,
        "collisions": int(summary["collisions"]) + int(summary["body_overlaps"]),
        "leg_crossings": int(summary["leg_crossings"]),
        "curvature_p95": float(np.percentile(curvature, 95)) if curvature.size else 0.0,
        "touchdown_slope_rad": float(np.mean(slope)) if slope.size else 0.0,
        "touchdown_roughness_m": float(np.mean(rough)) if rough.size else 0.0,
        "clearance_p05_h": float(np.percentile(clear_h, 5)) if clear_h.size else CLEARANCE_CAP_H,
        "distance_ratio": float(walked.sum() / asked.sum()) if asked.sum() > 0 else math.nan,
    }
    return {"scenario": task["scenario"], "base": task["base"], "spawn": task["spawn"], "seed": task["seed"],
            "metrics": metrics, "touchdown_clearance_h": clear_h, "finite": bool(summary["finite"]), "strides": int(summary["strides_measured"]),
            "replay": replay_command(task)}


def box_distance(points, centres, half, yaws):
    """(P, B) horizontal distance of points (P, 2) to oriented rectangles (B: centres (B, 2), half
    extents (B, 2) along the box's local x and z, yaws (B,)); 0 inside. The box frame is the
    runtime's (``planner._kernels_avoidance._nearest_on_box``): local x = (cos yaw, sin yaw)."""
    d = points[:, None, :] - centres[None, :, :]
    c, s = np.cos(yaws)[None, :], np.sin(yaws)[None, :]
    a = d[..., 0] * c + d[..., 1] * s
    b = -d[..., 0] * s + d[..., 1] * c
    return np.hypot(np.maximum(np.abs(a) - half[None, :, 0], 0.0), np.maximum(np.abs(b) - half[None, :, 1], 0.0))


def _hinge(ratio: float) -> float:
    return max(0.0, math.log(max(ratio, LOG_FLOOR)))


def style_terms(metrics: dict, style: dict | None) -> dict[str, float]:
    """{style key: hinge} of one run (module docstring; 0 when the run meets that key)."""
    out = {}
    for key, bound in (style or {}).items():
        value = metrics[STYLE_METRIC[key]]
        if key == "min_clearance_body_heights":  # the share of touch-downs nearer than the bound
            out[key] = value / NEAR_SHARE_REF
        elif key in LOWER_BOUND_STYLES:
            out[key] = _hinge(bound / max(value, LOG_FLOOR))
        else:
            out[key] = _hinge(value / bound)
    return out


def run_loss(metrics: dict, targets) -> float:
    """One run's loss (module docstring) against ``targets`` (:class:`tuning._targets.CreatureTargets`)."""
    tol = targets["stride_length"].values["relative_tolerance"]
    error = metrics["stride_error"]
    stride = 0.0 if math.isnan(error) else (error / tol) ** 2
    holds = metrics["holds_per_100_steps"] / HOLDS_REF  # linear: a stuck run (a hold every step) is not 100x
    style = sum(v * v for v in style_terms(metrics, targets.style).values())
    return float(stride + holds + style + COLLISION_PENALTY * (metrics["collisions"] > 0))


def event_metrics(setup: EventSetup, weights, timing, targets, map_tasks=None) -> dict:
    """Run the setup under ``weights`` / ``timing`` (``map_tasks`` as in :mod:`tuning._exact`); the
    runs with their metrics and losses, and the means (plain numbers, JSON-ready).

    The keys the tune's bookkeeping shares with the legacy objective: ``exact_loss`` (mean run loss),
    ``stride_rel_error`` (mean per-run stride error), ``collisions`` (summed), ``finite``, ``runs``
    (each with its ``run_loss``)."""
    run = task_mapper(map_tasks)
    results = list(run(run_event_task, event_tasks(setup, weights, timing)))
    near = targets.clearance_min_m / targets.leg_length_m
    runs = []
    for r in results:
        clear = np.asarray(r["touchdown_clearance_h"])
        metrics = {**r["metrics"], "near_box_share": float(np.mean(clear < near)) if clear.size else 0.0}
        runs.append({**{k: r[k] for k in ("scenario", "base", "spawn", "seed", "strides", "replay")},
                     **metrics, "run_loss": run_loss(metrics, targets)})
    means = {}
    for key in EVENT_METRICS:
        values = np.array([r[key] for r in runs], dtype=np.float64)
        values = values[np.isfinite(values)]
        means[key] = float(values.mean()) if values.size else None
    return {"exact_loss": float(np.mean([r["run_loss"] for r in runs])),
            "stride_rel_error": means["stride_error"] if means["stride_error"] is not None else math.nan,
            "collisions": int(sum(r["collisions"] for r in runs)), "finite": all(r["finite"] for r in results),
            "means": means, "runs": runs}


def paired(a: dict, b: dict, key: str = "run_loss") -> tuple[float, float, int]:
    """(mean, standard error, n) over the runs of a's ``key`` - b's: the same runs in the same order
    (runs where either is not a number are left out)."""
    x = np.array([r[key] for r in a["runs"]], dtype=np.float64)
    y = np.array([r[key] for r in b["runs"]], dtype=np.float64)
    if x.shape != y.shape:
        raise ValueError("paired: expected the same runs in both")
    keep = np.isfinite(x) & np.isfinite(y)
    d = (x - y)[keep]
    if d.size < 2:
        return math.nan, math.nan, int(d.size)
    return float(d.mean()), float(d.std(ddof=1) / math.sqrt(d.size)), int(d.size)


COLLISION_NOISE_SE = 1.0
"""Collisions (feet in boxes, bodies in bodies) rise when the share of runs with any is higher, paired
run by run, by at least this many standard errors (a rise from none in every run is always one):
the foot-frame counts are rare, chaotic events carried by a few runs, so a strict 'no more than the
defaults' refused on noise."""


def collisions_rise(default: dict, other: dict, key: str = "collisions") -> tuple[bool, float, float]:
    """(rises, mean, SE) of other's runs with collisions - default's ([collisions > 0]), paired run by run;
    ``key``: another count of rare events per run read the same way (``leg_crossings``: the matrix)."""
    x = np.array([r[key] > 0 for r in default["runs"]], dtype=np.float64)
    y = np.array([r[key] > 0 for r in other["runs"]], dtype=np.float64)
    d = y - x
    mean = float(d.mean()) if d.size else 0.0
    se = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else 0.0
    return bool(mean > 0.0 and mean >= COLLISION_NOISE_SE * se), mean, se
