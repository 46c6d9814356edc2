"""The evaluation sweep: scenarios x LOD settings x crowd sizes, as independent tasks.

A task is a plain dict (:func:`build_tasks`); :func:`run_task` turns it into a plain
dict of metrics and depends on nothing but the task (no shared state; the same task
gives the same metrics, timings aside), so tasks can be spread over processes.

Settings (the LOD lever of paper §6):
* ``lod-on``, ``lod-zoomed``, ``lod-off``: the paper's three modes of Table 1, the
  budgets coming from the camera (``planner._lod``);
* ``budget-c{K}-s{S}``: no LOD (IK for everyone) and one fixed
  :class:`planner.SearchBudget` for every search: ``K`` couples after the first valid
  one (``inf`` = no limit) and slices of ``S`` m (``none`` = no slices).

Quality is measured on the planning situations of the run itself: every foot plan
the crowd makes is captured (its :class:`planner.FootBatch`) and, between frames so
the frame timings are not disturbed, planned again with :data:`planner.EXHAUSTIVE`;
the *couple-score deficit* of a plan is the exhaustive couple score minus the score
the budgeted search picked (>= 0: 5 cm slices contain every level of 10 or 20 cm
slices and the exhaustive search has no couple limit and an exact stop).

Cost: the crowd's median ms per frame (and per character), planner calls and cells
expanded; ``plan_us_per_foot``: every :data:`OWN_TIMING_EVERY`-th planning call
planned again on one core with its own budgets, per foot: the search cost the
budget controls without the rest of the frame. Budgets are compared on the same
requests by :func:`run_paired` (interleaved, best of :data:`TIMING_REPEATS`): the
frame timings of separate runs move by +-20 % with the load of the machine.

A fixed budget is the crowd's own setting (``init_crowd(..., budget=...)``); the
requests of a frame are what the step returns
(:class:`planner._crowd.StepRecord`'s ``plans``), so nothing in the planner is wrapped.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time

import numpy as np

from footfall._errors import InputError
from footfall.planner._batch import plan_batch
from footfall.planner._simulation import realised_strides

TIMING_REPEATS = 3  # rounds of the paired benchmark (the best per batch and budget counts)
OWN_TIMING_EVERY = 4  # a run's own requests: every n-th planning call is timed once (cheap, noisier)
CURVATURE_WINDOW = (0.05, 0.95)  # fraction of the arc length where the curvature is evaluated
STRIDE_MIN_SPEED = 0.02  # m/s: strides slower than this are a creature standing, not walking
STRIDE_SAMPLES_KEPT = 150  # (speed, stride) pairs kept per task for the plot
LOD_SETTINGS = ("lod-on", "lod-zoomed", "lod-off")

# --------------------------------------------------------------------------- settings


def setting_name(couples_after_first: int | None, slice_size_m: float | None) -> str:
    c = "inf" if couples_after_first is None else str(int(couples_after_first))
    s = "none" if slice_size_m is None else f"{slice_size_m:.2f}"
    return f"budget-c{c}-s{s}"


def parse_setting(name: str) -> dict:
    """``{"setting", "kind", "lod_mode", "couples_after_first", "slice_size_m"}`` of a setting name."""
    if name in LOD_SETTINGS:
        return {"setting": name, "kind": "lod", "lod_mode": name[4:], "couples_after_first": None,
                "slice_size_m": None}
    parts = name.split("-")
    try:
        if len(parts) != 3 or parts[0] != "budget" or parts[1][0] != "c" or parts[2][0] != "s":
            raise ValueError
        couples = None if parts[1][1:] == "inf" else int(parts[1][1:])
        slices = None if parts[2][1:] == "none" else float(parts[2][1:])
        from footfall.planner import SearchBudget

        SearchBudget(couples, slices)
    except (ValueError, IndexError):
        raise InputError("argument", "setting", f"expected {', '.join(LOD_SETTINGS)} or budget-cK-sS "
                         f"(K an integer or inf, S metres or none), got {name!r}") from None
    return {"setting": setting_name(couples, slices), "kind": "budget", "lod_mode": "off",
            "couples_after_first": couples, "slice_size_m": slices}


@dataclasses.dataclass(frozen=True)
class SweepOptions:
    """What to sweep. ``frames`` are measured after ``warmup`` frames that get the crowd moving."""

    scenarios: tuple[str, ...]
    settings: tuple[str, ...]
    sizes: tuple[int, ...]
    seeds: tuple[int, ...] = (0,)
    frames: int = 90
    warmup: int = 30
    scene_characters: int = 6
    scene_frames: int = 120
    # Crowd sizes run with the LOD modes only (``lod-on``, ``lod-zoomed``, ``lod-off`` among the
    # settings): crowds large enough that the camera puts characters at the far level of detail
    # (beyond LodConfig.far_m), for the quality of every level; and the sizes of the LOD scaling task
    # (ms per frame against crowd size, the three modes stepped in turns, :func:`run_lod_scaling`).
    lod_sizes: tuple[int, ...] = ()


# c0 with slices decides as c0 without (the first slice, "go over", is searched first), so it is left out.
_BUDGETS_DEFAULT = (setting_name(0, None), setting_name(2, 0.10), setting_name(6, 0.10), setting_name(None, 0.10),
                    setting_name(6, None), setting_name(6, 0.20))
_BUDGETS_FULL = (setting_name(0, None),) + tuple(setting_name(c, s) for s in (None, 0.05, 0.10, 0.20)
                                                  for c in (1, 2, 4, 8, None))

PRESETS = {
    # The tests: seconds.
    "quick": SweepOptions(scenarios=("mixed",), settings=("lod-on", "lod-off", setting_name(0, None),
                                                          setting_name(2, 0.10), setting_name(None, 0.10)),
                          sizes=(4,), frames=30, warmup=10, scene_characters=3, scene_frames=45, lod_sizes=(24,)),
    # The main job: about two minutes on two cores.
    "default": SweepOptions(scenarios=("mixed", "crates"), settings=LOD_SETTINGS + _BUDGETS_DEFAULT,
                            sizes=(8, 32), frames=50, warmup=15, scene_characters=6, scene_frames=90,
                            lod_sizes=(150,)),
    # Everything: every built-in scenario, 21 budgets, up to 100 characters (about an hour on two cores).
    "full": SweepOptions(scenarios=("flat", "hills", "stairs", "crates", "crates-moving", "mixed"),
                         settings=LOD_SETTINGS + _BUDGETS_FULL, sizes=(10, 50, 100), frames=240, warmup=60,
                         scene_characters=10, scene_frames=240, lod_sizes=(300, 1000)),
}


TIMING_KEYS = frozenset({"ms_per_frame", "ms_per_character", "plan_ms_per_frame", "ik_ms_per_frame",
                         "plan_us_per_foot", "wall_seconds", "plan_cost_vs_first_valid", "us_per_foot",
                         "cost_vs_first_valid", "cost_ratios",
                         # the LOD scaling task (benchmarks.crowd_bench)
                         "ms_per_frame_ci", "maps_ms", "plan_ms", "ik_ms", "fps", "ratio_on_off", "ratio_on_off_ci"})
"""Result fields measured with a clock: they move with the load of the machine; every other
field of a task's result depends only on the task (same task, same numbers, on any worker)."""


def without_timings(result):
    """A task's result with the :data:`TIMING_KEYS` fields left out, nested rows included."""
    if isinstance(result, dict):
        return {k: without_timings(v) for k, v in result.items() if k not in TIMING_KEYS}
    if isinstance(result, list):
        return [without_timings(v) for v in result]
    return result


def build_tasks(options: SweepOptions) -> list[dict]:
    """One task per (scenario, seed, setting, crowd size), then one paired cost task per
    (scenario, seed, crowd size) over every fixed budget; in a fixed order."""
    tasks = []
    budgets = [n for n in options.settings if parse_setting(n)["kind"] == "budget"]
    for scenario in options.scenarios:
        for seed in options.seeds:
            for size in options.sizes:
                common = {"scenario": scenario, "seed": int(seed), "characters": int(size),
                          "frames": int(options.frames), "warmup": int(options.warmup)}
                for name in options.settings:
                    tasks.append({**common, **parse_setting(name)})
                if budgets:
                    tasks.append({**common, **parse_setting("lod-off"), "kind": "paired", "setting": "paired",
                                  "budgets": [parse_setting(n)["setting"] for n in budgets]})
            lods = [n for n in options.settings if parse_setting(n)["kind"] == "lod"]
            for size in options.lod_sizes:
                common = {"scenario": scenario, "seed": int(seed), "characters": int(size),
                          "frames": int(options.frames), "warmup": int(options.warmup)}
                for name in lods:
                    tasks.append({**common, **parse_setting(name)})
            if lods and options.lod_sizes:
                sizes = sorted(set(options.sizes) | set(options.lod_sizes))
                tasks.append({"scenario": scenario, "seed": int(seed), "kind": "lod-scaling", "setting": "lod-scaling",
                              "characters": max(sizes), "sizes": sizes,
                              "frames": int(options.frames), "warmup": int(options.warmup)})
    return tasks


def check_scenarios(names) -> None:
    """Load every scenario once so a bad name fails before any work (InputError)."""
    from footfall.scenarios import load_scenario

    for name in names:
        load_scenario(name)


# --------------------------------------------------------------------------- the tap


def with_budget(batch, couples: int, slice_size: float, early: bool):
    n = batch.n_feet
    return dataclasses.replace(batch, couples_after_first=np.full(n, couples, np.int64),
                               slice_size=np.full(n, slice_size, np.float64), early=np.full(n, early, np.bool_))


class PlanTap:
    """Sees every planning call of a crowd, frame by frame (:meth:`record` after each frame).

    ``capture`` on: each frame's (batch, result) is kept until :meth:`flush` (called
    between frames, outside the frame timings), which plans them again exhaustively and
    (every :data:`OWN_TIMING_EVERY`-th call) timed, and keeps only numbers, plus every
    ``keep_every``-th batch for :func:`run_paired`.
    """

    def __init__(self, keep_every: int = 0, keep_feet: int = 0, measure: bool = True):
        self.measure = measure  # exhaustive scores, timings and curvature at each flush
        self.capture = False
        self.keep_every = keep_every  # keep every n-th planning call's batch for a paired benchmark (0: none)
        self.keep_feet = keep_feet  # ... up to this many feet
        self.kept = []
        self.calls = 0
        self.pending = []
        self.budget_scores = []
        self.exhaustive_scores = []
        self.budget_valid = []
        self.exhaustive_valid = []
        self.levels = []  # the LOD level of each compared plan's character
        self.curvature = []
        self.timed_seconds = 0.0
        self.ref_seconds = 0.0
        self.timed_feet = 0
        self.sample = None  # (batch, result, foot index, weights, config, interest) for the Fig. 13 heatmap

    def record(self, model, state, plans) -> None:
        """After a frame: keep the frame's planning calls (``plans``, planner._crowd.FramePlans, None if it
        planned nothing) for the next flush.

        With a LOD mode a frame may plan in several calls (the far characters' on compact maps,
        ``planner._far_planning``); their requests are put back on the paper's 70 x 70 maps (built
        here, outside the frame timings) so that the exhaustive reference of every plan is the same
        search on the same maps, whatever the level of detail that planned it. Each plan keeps its
        character's level (``self.levels``)."""
        if not self.capture or plans is None:
            return
        cs, out = plans.chars, plans.result
        if plans.batch is not None and len(plans.calls) <= 1:
            self.pending.append((plans.batch, out, model.weights, model.config, state.lod_level[cs]))
            return
        from footfall.planner._crowd import _boxes_now, stage_maps

        for batch, config, rows, chars in plans.calls:
            if config is not model.config:
                elev, ground, forb, origin = stage_maps(model, state, chars, _boxes_now(model, state.t), count=False)
                batch = dataclasses.replace(batch, elevation=elev, ground=ground, forbidden=forb, origins=origin)
            self.pending.append((batch, _take_result(out, rows), model.weights, model.config,
                                 state.lod_level[cs[rows]]))

    def flush(self) -> None:
        """Exhaustive scores, timed re-plans and curvature of the plans since the last flush."""
        from footfall.planner import EXHAUSTIVE, FIRST_VALID

        for batch, out, weights, config, levels in self.pending:
            self.calls += 1
            if (self.keep_every and self.calls % self.keep_every == 0
                    and sum(b.n_feet for b, _, _ in self.kept) < self.keep_feet):
                self.kept.append((batch, weights, config))
            if not self.measure:
                continue
            exhaustive = plan_batch(with_budget(batch, *EXHAUSTIVE.kernel_args()), weights, config,
                                              "search", False)
            self.budget_scores.append(out.scores[:, 0].copy())
            self.exhaustive_scores.append(exhaustive.scores[:, 0].copy())
            self.budget_valid.append(out.valid.copy())
            self.exhaustive_valid.append(exhaustive.valid.copy())
            self.levels.append(np.asarray(levels).copy())
            if self.calls % OWN_TIMING_EVERY == 0:
                # Timed beside the first valid couple on the same requests, alternating: the ratio of the
                # two stands still when other programs load the machine, the microseconds do not.
                own, ref = _time_interleaved([batch, with_budget(batch, *FIRST_VALID.kernel_args())], weights,
                                             config, rounds=2)
                self.timed_seconds += own
                self.ref_seconds += ref
                self.timed_feet += batch.n_feet
            for k in np.flatnonzero(out.valid):
                self.curvature.append(curvature_energy(out.trajectory[k]))
            # Fig. 13 sample: the valid plan with the most slices (obstacles around), then the most
            # candidate cells (first found wins ties: deterministic).
            if out.valid.any():
                interest = np.where(out.valid, 1000 * out.counters[:, 5] + out.counters[:, 4], -1)
                k = int(np.argmax(interest))
                if self.sample is None or interest[k] > self.sample[5]:
                    self.sample = (batch, out, k, weights, config, int(interest[k]))
        self.pending.clear()


def _take_result(out, rows):
    """The BatchResult of the requests ``rows`` of ``out``."""
    return type(out)(**{name: getattr(out, name)[rows] for name in type(out).__dataclass_fields__})


def _time_interleaved(batches, weights, config, rounds: int = TIMING_REPEATS) -> np.ndarray:
    """Seconds to plan each batch on one core: best of ``rounds``, the order rotating each round."""
    return _time_calls([functools.partial(plan_batch, b, weights, config, "search", False) for b in batches], rounds)


def _time_calls(calls, rounds: int = TIMING_REPEATS) -> np.ndarray:
    """Seconds of each call: best of ``rounds``, the order rotating each round."""
    best = np.full(len(calls), np.inf)
    for r in range(rounds):
        for j in np.roll(np.arange(len(calls)), r):
            t0 = time.perf_counter()
            calls[j]()
            best[j] = min(best[j], time.perf_counter() - t0)
    return best


def plan_far(batch, weights, first, fallback):
    """A far character's planning (``planner._far_planning``) of ``batch`` on one core: the first
    try near the preferred footprints, the full first-valid search for the feet it left without a
    couple. Returns the BatchResult of every foot."""
    from footfall.planner._crowd import _merge_results, _take_requests
    from footfall.planner._params import FIRST_VALID

    batch = with_budget(batch, *FIRST_VALID.kernel_args())
    out = plan_batch(batch, weights, first, "search", False)
    missed = np.flatnonzero(~out.valid)
    if missed.size == 0:
        return out
    retry = dataclasses.replace(_take_requests(batch, missed), elevation=batch.elevation, ground=batch.ground,
                                forbidden=batch.forbidden, origins=batch.origins, foot_char=batch.foot_char[missed])
    again = plan_batch(retry, weights, fallback, "search", False)
    return _merge_results([(np.flatnonzero(out.valid), _take_result(out, np.flatnonzero(out.valid))),
                           (missed, again)], batch.n_feet)


# --------------------------------------------------------------------------- metrics


def curvature_energy(points: np.ndarray, window=CURVATURE_WINDOW) -> float:
    """E = l * integral of kappa^2 ds of the horizontal (x, z) projection of a path (scale-free).

    Discrete: at each interior vertex the turning angle theta_i over the mean length
    ds_i of its two segments gives kappa_i = theta_i / ds_i, so kappa^2 ds = theta_i^2 / ds_i;
    only vertices at arc-length fractions in ``window`` count (lift-off and touch-down
    are singular: the foot moves mostly vertically there). A circular arc turning by
    theta gives theta^2, a straight path 0.
    """
    p = np.asarray(points, dtype=np.float64)[:, [0, 2]]
    seg = np.diff(p, axis=0)
    seg_len = np.hypot(seg[:, 0], seg[:, 1])
    total = float(seg_len.sum())
    if total <= 0.0 or p.shape[0] < 3:
        return 0.0
    s = np.concatenate([[0.0], np.cumsum(seg_len)]) / total
    energy = 0.0
    tiny = 1e-9 * total
    for i in range(1, p.shape[0] - 1):
        if not (window[0] <= s[i] <= window[1]):
            continue
        a, b = seg_len[i - 1], seg_len[i]
        if a <= tiny or b <= tiny:
            continue
        cross = seg[i - 1, 0] * seg[i, 1] - seg[i - 1, 1] * seg[i, 0]
        dot = seg[i - 1, 0] * seg[i, 0] + seg[i - 1, 1] * seg[i, 1]
        theta = math.atan2(cross, dot)
        energy += theta * theta / (0.5 * (a + b))
    return total * energy


def stride_law_text(creature: str = "spider", html: bool = False) -> str:
    """The creature's target stride law as text, its numbers read from ``tuning/data/targets.toml``
    (e.g. ``2.3 h Fr^0.3``; ``html``: the exponent as a superscript)."""
    t = _stride_target(creature)
    c, e = t["coefficient"], t["exponent"]
    return f"{c:g} h Fr<sup>{e:g}</sup>" if html else f"{c:g} h Fr^{e:g}"


def target_stride_length(speed, hip_height: float, creature: str = "spider"):
    """The biomechanics target lambda = coefficient h Fr^exponent, Fr = v^2 / (g h), m: the
    creature's ``stride_length`` entry of ``tuning/data/targets.toml`` (2.3 h Fr^0.3, Alexander
    1976), the one definition the tuning fits to (``tuning._targets`` does not load JAX)."""
    from footfall.planner._timing import GRAVITY

    t = _stride_target(creature)
    v = np.asarray(speed, dtype=np.float64)
    return t["coefficient"] * hip_height * np.power(v * v / (GRAVITY * hip_height), t["exponent"])


@functools.lru_cache(maxsize=None)
def _stride_target(creature: str) -> dict:
    from footfall.tuning._targets import load_targets

    return dict(load_targets(creatures=(creature,))[creature]["stride_length"].values)


def _load_inputs(scenario_name: str):
    from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

    scenario = load_scenario(scenario_name)
    creature = load_creature(scenario.crowd.creature)
    gait = load_gait(default_gait_name(creature.name), creature)
    return scenario, creature, gait


def _run_crowd(task: dict, recorder_frames: bool = True, keep_every: int = 0, keep_feet: int = 0,
               measure: bool = True):
    """Simulate the task's crowd; returns (scenario, model, state, summary, recorder, tap)."""
    from footfall.planner import SearchBudget
    from footfall.planner._crowd import init_crowd
    from footfall.planner._simulation import Recorder, simulate

    scenario, creature, gait = _load_inputs(task["scenario"])
    budget = None
    if task["kind"] == "budget":
        budget = SearchBudget(task["couples_after_first"], task["slice_size_m"], paper_early_stop=True)
    model, state = init_crowd(scenario, creature, gait, n_characters=task["characters"], seed=task["seed"],
                              lod_mode=task["lod_mode"], budget=budget)
    tap = PlanTap(keep_every, keep_feet, measure)
    if task["warmup"] > 0:
        simulate(model, state, task["warmup"])
    recorder = Recorder(model, state, task["frames"]) if recorder_frames else None
    tap.capture = True

    def after_frame(_k, record):
        tap.record(model, state, record.plans)
        tap.flush()

    summary = simulate(model, state, task["frames"], recorder, on_step=after_frame)
    return scenario, model, state, summary, recorder, tap


def run_task(task: dict) -> dict:
    """Metrics of one task (plain numbers and lists; JSON-ready)."""
    t0 = time.perf_counter()
    if task["kind"] == "paired":
        result = run_paired(task)
    elif task["kind"] == "lod-scaling":
        result = run_lod_scaling(task)
    else:
        result = _run_setting(task)
    result["wall_seconds"] = time.perf_counter() - t0
    return result


def _run_setting(task: dict) -> dict:
    scenario, model, state, summary, recorder, tap = _run_crowd(task)
    n = summary.characters
    b = np.concatenate(tap.budget_scores) if tap.budget_scores else np.zeros(0)
    e = np.concatenate(tap.exhaustive_scores) if tap.exhaustive_scores else np.zeros(0)
    bv = np.concatenate(tap.budget_valid) if tap.budget_valid else np.zeros(0, bool)
    ev = np.concatenate(tap.exhaustive_valid) if tap.exhaustive_valid else np.zeros(0, bool)
    # A situation the exhaustive search solves counts; a budget that found nothing there lost the whole score.
    deficit = np.where(bv[ev], e[ev] - b[ev], e[ev])
    lv = np.concatenate(tap.levels)[ev] if tap.levels else np.zeros(0, np.int8)
    a = recorder.arrays
    speeds, strides = realised_strides(a["feet"], a["in_stance"], a["pelvis"], model.dt)
    walking = speeds > STRIDE_MIN_SPEED
    speeds, strides = speeds[walking], strides[walking]
    target = target_stride_length(speeds, model.leg_height, model.creature.name)
    error = (strides - target) / target if strides.size else np.zeros(0)
    keep = np.linspace(0, strides.size - 1, min(strides.size, STRIDE_SAMPLES_KEPT)).astype(int) if strides.size else []
    curv = np.asarray(tap.curvature)
    frame_ms = summary.ms_per_frame_median
    return {
        "scenario": scenario.name, "seed": task["seed"], "setting": task["setting"], "kind": task["kind"],
        "lod_mode": task["lod_mode"], "couples_after_first": task["couples_after_first"],
        "slice_size_m": task["slice_size_m"], "characters": n, "frames": summary.frames,
        "creature": model.creature.name, "hip_height_m": model.leg_height,
        # cost
        "ms_per_frame": frame_ms, "ms_per_character": frame_ms / n,
        "plan_ms_per_frame": summary.stage_ms_median["plan"], "ik_ms_per_frame": summary.stage_ms_median["ik"],
        "plan_us_per_foot": 1e6 * tap.timed_seconds / max(tap.timed_feet, 1),
        "plan_cost_vs_first_valid": float(tap.timed_seconds / tap.ref_seconds) if tap.ref_seconds > 0 else None,
        "planner_calls": summary.plans, "plans_per_frame": summary.plans / summary.frames,
        "cells_expanded": summary.cells_expanded, "cells_per_plan": summary.cells_expanded / max(summary.plans, 1),
        "couples_per_plan": summary.couples_evaluated / max(summary.plans, 1),
        # quality
        "situations": int(ev.sum()),
        "deficit_mean": float(deficit.mean()) if deficit.size else 0.0,
        "deficit_p95": float(np.percentile(deficit, 95)) if deficit.size else 0.0,
        "deficit_max": float(deficit.max()) if deficit.size else 0.0,
        "deficit_min": float(deficit.min()) if deficit.size else 0.0,
        "suboptimal_fraction": float((deficit > 1e-9).mean()) if deficit.size else 0.0,
        "exhaustive_score_mean": float(e[ev].mean()) if ev.any() else 0.0,
        "missed_plans": int((ev & ~bv).sum()),
        "collisions": summary.collisions, "forbidden_footprints": summary.forbidden_footprints,
        "leg_crossings": summary.leg_crossings, "holds": summary.holds, "steps": summary.steps,
        "body_overlaps": summary.body_overlaps,
        "strides": int(strides.size),
        "stride_error_median": float(np.median(np.abs(error))) if strides.size else None,
        "stride_bias_median": float(np.median(error)) if strides.size else None,
        "stride_samples": [[float(speeds[i]), float(strides[i])] for i in keep],
        "curvature_energy_mean": float(curv.mean()) if curv.size else 0.0,
        "curvature_energy_p95": float(np.percentile(curv, 95)) if curv.size else 0.0,
        "ik_residual_p95_m": summary.ik_residual_p95_m, "max_stance_slip_m": summary.max_stance_slip_m,
        "finite": summary.finite,
        "lod_levels": _levels_with_loss(summary.lod_levels, e[ev], deficit, lv),
    }


def _levels_with_loss(levels: dict | None, exhaustive: np.ndarray, deficit: np.ndarray, level: np.ndarray):
    """The run's per-level quality (``planner._lod_quality``) with each level's couple-score loss
    against the exhaustive search (% of the exhaustive score) and how many plans it rests on."""
    if levels is None:
        return None
    from footfall.planner._lod import LEVEL_NAMES

    out = {**levels, "levels": {name: dict(row) for name, row in levels["levels"].items()}}
    for k, name in enumerate(LEVEL_NAMES):
        if name not in out["levels"]:
            continue
        mine = level == k
        best = float(exhaustive[mine].sum())
        out["levels"][name]["situations"] = int(mine.sum())
        out["levels"][name]["score_loss_pct"] = (100.0 * float(deficit[mine].sum()) / best) if best > 0 else None
    return out


def run_lod_scaling(task: dict) -> dict:
    """ms per frame against crowd size for the three LOD modes (``footfall bench crowd``'s
    measurement: one crowd per mode, stepped in turns so they share the machine's load; the median
    frame with its 95 % interval, and LOD on / LOD off with a bootstrap interval)."""
    from footfall.benchmarks.crowd_bench import run

    _, creature, _ = _load_inputs(task["scenario"])
    sizes = run(sizes=tuple(task["sizes"]), frames=task["frames"], warmup=task["warmup"], seed=task["seed"],
                scenario_name=task["scenario"], creature_name=creature.name)
    return {"kind": "lod-scaling", "setting": "lod-scaling", "scenario": task["scenario"], "seed": task["seed"],
            "sizes": sizes}


FAR_LEVEL = "lod-far-planning"
"""The paired benchmark's row of the far level of detail's planning (``planner._far_planning``:
first valid couple, first near the preferred footprint), beside the fixed budgets."""
PAIRED_KEEP_EVERY = 3  # planning calls (frames) between two kept for the paired benchmark
PAIRED_KEEP_FEET = 800  # bounds the memory of the kept local maps (~100 MB at 100 characters)


def run_paired(task: dict) -> dict:
    """Every fixed budget on the same situations: the requests of a no-LOD run.

    Cost: each kept batch is planned on one core with every budget in turn, the order
    rotating, :data:`TIMING_REPEATS` rounds, best per (batch, budget): a load spike from
    another program hits all budgets alike, which a comparison of separate runs cannot
    promise. Quality: the same plans' couple scores against the exhaustive search's.
    """
    from footfall.planner import EXHAUSTIVE, FIRST_VALID

    scenario, model, state, summary, recorder, tap = _run_crowd(task, recorder_frames=False,
                                                                keep_every=PAIRED_KEEP_EVERY,
                                                                keep_feet=PAIRED_KEEP_FEET, measure=False)
    names = list(task["budgets"])
    args = []
    for name in names:
        p = parse_setting(name)
        from footfall.planner import SearchBudget

        args.append(SearchBudget(p["couples_after_first"], p["slice_size_m"], paper_early_stop=True).kernel_args())
    from footfall.planner._far_planning import far_configs
    from footfall.planner._lod import LodConfig

    lod = LodConfig()
    span = model.rest_radius + model.config.search_radius_m + float(np.max(model.reach))
    first, fallback = far_configs(model.config, span, lod.far_radius_cells, lod.far_margin_cells,
                                  lod.far_fallback_margin_cells)
    names = names + [FAR_LEVEL]  # the far level of detail's planning, on the same requests
    seconds = np.zeros(len(names) + 1)  # the last: the first valid couple, the reference of the cost ratios
    ratios = [[] for _ in names]  # per kept batch: each variant's time / the first valid couple's
    chosen = np.zeros(len(names))
    suboptimal = np.zeros(len(names))
    best_total = 0.0
    feet = 0
    for batch, weights, config in tap.kept:
        exhaustive = plan_batch(with_budget(batch, *EXHAUSTIVE.kernel_args()), weights, config, "search",
                                          False)
        ok = exhaustive.valid
        best_total += float(exhaustive.scores[ok, 0].sum())
        feet += int(ok.sum())
        variants = [with_budget(batch, *a) for a in args] + [with_budget(batch, *FIRST_VALID.kernel_args())]
        calls = [functools.partial(plan_batch, v, weights, config, "search", False) for v in variants]
        calls.insert(len(args), functools.partial(plan_far, batch, weights, first, fallback))
        for j, call in enumerate(calls[:-1]):
            out = call()
            got = np.where(out.valid[ok], out.scores[ok, 0], 0.0)
            chosen[j] += float(got.sum())
            suboptimal[j] += float((exhaustive.scores[ok, 0] - got > 1e-9).sum())
        timed = _time_calls(calls)
        seconds += timed
        for j in range(len(names)):
            ratios[j].append(float(timed[j] / timed[-1]) if timed[-1] > 0 else None)
    all_feet = sum(b.n_feet for b, _, _ in tap.kept)
    rows = []
    for j, name in enumerate(names):
        rows.append({"budget": name, "us_per_foot": float(1e6 * seconds[j] / max(all_feet, 1)),
                     "cost_vs_first_valid": float(seconds[j] / seconds[-1]) if seconds[-1] > 0 else None,
                     "cost_ratios": [r for r in ratios[j] if r is not None],
                     "score_loss_pct": float(100.0 * (1.0 - chosen[j] / best_total)) if best_total > 0 else 0.0,
                     "suboptimal_fraction": float(suboptimal[j] / max(feet, 1))})
    return {"kind": "paired", "scenario": scenario.name, "seed": task["seed"], "characters": task["characters"],
            "situations": feet, "feet_timed": all_feet, "budgets": rows}


# --------------------------------------------------------------------------- the scene (pictures)


def run_scene(scenario_name: str, seed: int, characters: int, frames: int) -> dict:
    """A small crowd with no LOD, for the pictures: numpy arrays and plain values.

    Returns the terrain, the boxes at the last frame, every foot's track and
    footprints, a gait snapshot (Fig. 8) and one planning situation (Fig. 13).
    """
    task = {"scenario": scenario_name, "seed": seed, "characters": characters, "frames": frames,
            "warmup": 0, **parse_setting("lod-off")}
    scenario, model, state, summary, recorder, tap = _run_crowd(task)
    a = recorder.arrays
    down = np.zeros_like(a["in_stance"])
    down[1:] = a["in_stance"][1:] & ~a["in_stance"][:-1]
    f, c, leg = np.nonzero(down)
    centres, yaws = scenario.obstacles.poses_at(state.t)
    terrain = scenario.terrain
    g = state.gaits
    scene = {
        "scenario": scenario.name, "creature": model.creature.name, "leg_names": list(model.creature.leg_names),
        "terrain_heights": np.asarray(terrain.heights), "terrain_origin": np.array([terrain.origin_x, terrain.origin_z]),
        "terrain_cell": float(terrain.cell_size),
        "box_centres": np.asarray(centres, np.float64).reshape(-1, 3), "box_sizes": np.asarray(scenario.obstacles.sizes, np.float64).reshape(-1, 3),
        "box_yaws": np.asarray(yaws, np.float64).reshape(-1), "box_forbidden": np.asarray(scenario.obstacles.forbidden, bool).reshape(-1),
        "feet": a["feet"].astype(np.float64), "pelvis": a["pelvis"].astype(np.float64),
        "footprints": a["feet"][f, c, leg].astype(np.float64), "footprint_character": c,
        "gait_needle": float(g.needle[0]), "gait_start": np.asarray(g.disk_start[0]),
        "gait_duration": np.asarray(g.disk_duration[0]), "gait_in_stance": np.asarray(state.in_stance[0]),
        "gait_name": model.gait.name,
    }
    scene["heatmap"] = footprint_situation(tap.sample) if tap.sample is not None else None
    return scene


def footprint_situation(sample, n_other: int = 14) -> dict:
    """The Fig. 13 picture of one captured plan: candidate cells and their footprint scores,
    the chosen trajectory, and the best trajectory to other candidates.

    The foot is planned again from its captured request with :func:`planner.plan_foot`
    (same maps, query and budget); the other trajectories come from planning the same foot
    with a candidate disc of half a cell around each of ``n_other`` candidates spread over
    the score order (so that cell is the only target).
    """
    from footfall.planner import FootQuery, GridFrame, LocalMaps, SearchBudget, plan_foot
    from footfall.planner._search import split_leg_rows

    batch, out, k, weights, config, _ = sample
    ch = int(batch.foot_char[k])
    n = batch.elevation.shape[1]
    frame = GridFrame(float(batch.origins[ch, 0]), float(batch.origins[ch, 1]), config.cell_size, n, n)
    maps = LocalMaps(frame, batch.elevation[ch], batch.ground[ch], batch.forbidden[ch])
    query = FootQuery(source=batch.sources[k], preferred=batch.preferred[k], hip=batch.hips[k],
                      reach_xz=float(batch.reach_xz[k]), step_height=float(batch.step_height[k]),
                      foot_length=float(batch.foot_shape[k, 0]), foot_width=float(batch.foot_shape[k, 1]),
                      foot_yaw=float(batch.foot_shape[k, 2]),
                      **split_leg_rows(batch.legs[batch.legs_start[k]:batch.legs_start[k + 1]]))
    couples = int(batch.couples_after_first[k])
    slices = float(batch.slice_size[k])
    budget = SearchBudget(None if couples < 0 else couples, None if slices <= 0 else slices,
                          bool(batch.early[k]))
    chosen = plan_foot(maps, query, weights, budget, config)
    cells = chosen.candidate_cells
    cx, cz = frame.cell_to_world(cells[:, 0], cells[:, 1])
    others = []
    single = dataclasses.replace(config, search_radius_m=0.45 * config.cell_size)
    picks = np.unique(np.linspace(0, len(cells) - 1, min(n_other, len(cells))).astype(int))
    for j in picks:
        if (int(cells[j, 0]), int(cells[j, 1])) == chosen.target_cell:
            continue
        q = dataclasses.replace(query, preferred=np.array([cx[j], cz[j]]))
        r = plan_foot(maps, q, weights, budget, single)
        if r.valid:
            others.append(r.trajectory)
    return {
        "cell_size": config.cell_size, "cells_xz": np.column_stack([cx, cz]), "scores": chosen.candidate_scores,
        "chosen": chosen.trajectory, "others": others, "source": query.source, "preferred": query.preferred,
        "forbidden_xz": np.column_stack(frame.cell_to_world(*np.nonzero(maps.forbidden))),
        "elevation": np.asarray(maps.elevation), "origin": np.array([frame.origin_x, frame.origin_z]),
        "valid": chosen.valid, "matches_crowd": bool(np.allclose(chosen.target, out.target[k])),
        "couple_score": chosen.couple_score, "counters": chosen.counters,
    }
