"""The exact loss: the real crowd (``planner.init_crowd`` + ``step``) run with given weights
and timing over a speed sweep, measured against the biomechanics targets (issue 4).

Runs
----
For each scenario x seed x speed of an :class:`ExactSetup`, a small crowd
(``n_characters``, LOD off: the paper's full search) of the creature walks the
scenario's route for ``frames`` frames of 1/30 s with every character's
``desired_speed`` set to v. The speeds are a sweep in Froude number,
v = sqrt(Fr g h) (h: ``planner._timing.hip_height``), the same dynamic
similarity for every creature (:func:`sweep_froude`): from where the target stride is
:data:`STRIDE_MIN_CELLS` planner cells (shorter strides are resolution-limited: footprints
are cell centres) up to 2.8 times that Froude number. Above about Fr = 0.08 a spider's
stance legs cannot follow: the body waits, and the controller lowers the character's speed
limit (``planner._crowd.ControllerConfig``: sustainable speed). Its realised speed saturates,
which is why strides are compared with the target at the realised speed.
The first ``warmup`` frames (start-up, acceleration, gait transition) are not
measured. Everything is deterministic for a seed (the crowd is).

Measures (per run)
------------------
* **stride**: the distance a foot travels on the ground between two consecutive
  touch-downs of that foot (same foot, one cycle), paired with the pelvis's
  horizontal speed over the same frames (the *realised* speed, not the desired
  one). The run's stride ratio is mean(stride) / mean(lambda_target(v_stride)),
  lambda_target = coefficient h Fr^exponent of ``tuning/data/targets.toml``
  (the targets file's law, Alexander 1976 by default). Footprints are cell centres of the planner's grid,
  so single strides are quantised by the cell size; the mean over a run averages it out.
  ``stride_rel_error`` = mean over the runs of |ratio - 1| (the speed sweep).
* **duty factor**: fraction of the measured frames a foot spends in stance, mean over
  the feet; distance outside the target band [low, high] / (high - low) (0 inside),
  for runs below the band's Froude limit.
* **curvature energy**: the planner's own raw metric (E = l integral kappa^2 ds of the
  horizontal swing path, ``RAW_CURVATURE``) of every valid plan, mean.
* **clearance**: the raw horizontal margin of every valid plan to blocked cells, capped
  at the target minimum (m), mean (a run without obstacles has the cap everywhere).
* **jerk**: the raw normalised jerk of every valid plan, median -- reported, not part of
  the loss by default (``jerk_weight = 0``): the runtime's metric
  (``planner._kernels_foot.geometric_jerk``) is dominated by finite-difference sampling
  noise (median about 1.2e5 against the Flash & Hogan target of order 1e3), so the
  target cannot be met by any weights. :mod:`tuning._tune` keeps it as a guard: a
  tuned preset whose median jerk exceeds the default weights' by more than
  ``JERK_GUARD`` is not accepted.
* **collisions**: feet overlapping a box (``planner._simulation`` metric), summed.

Exact loss
----------
``0.5 * (mean_runs ((ratio - 1) / tolerance)^2 + mean_runs duty_out^2
+ relu(E_mean / E_max - 1)^2 + relu(1 - clearance / c)^2)
+ COLLISION_PENALTY * collisions + jerk_weight * relu(log(J / J_max))^2``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from footfall.planner import realised_strides, task_mapper
from footfall.planner.layout import RAW_CLEARANCE, RAW_CURVATURE, RAW_JERK

STRIDE_MIN_CELLS = 1.5
"""Lowest speed of the sweep: where the target stride is this many planner cells. Footprints are
cell centres: a stride of about one cell or less is resolution-limited (a spider at Fr = 0.005
has a 5.6 cm target stride on 7 cm cells, and realises about 1.3 times it whatever the weights)."""
FROUDE_FLOOR = 0.005
FROUDE_CEILING_MIN = 0.04
SWEEP_RATIO = 2.8
"""Highest / lowest Froude number of the sweep (at least up to FROUDE_CEILING_MIN)."""
SWEEP_POINTS = 4


def sweep_froude(creature_name: str, targets=None) -> tuple[float, ...]:
    """The creature's speed sweep as Froude numbers, geometric from Fr_lo to Fr_hi:
    Fr_lo = max(FROUDE_FLOOR, Fr at which lambda_target = STRIDE_MIN_CELLS cells),
    Fr_hi = max(SWEEP_RATIO Fr_lo, FROUDE_CEILING_MIN). lambda_target is the stride law of
    ``targets`` (:class:`tuning._targets.CreatureTargets`; None: the shipped targets file)."""
    from footfall.planner import hip_height, planner_config_for
    from footfall.scenarios import load_creature
    from footfall.tuning._targets import load_tune_targets

    creature = load_creature(creature_name)
    h = hip_height(creature)
    cell = planner_config_for(creature).cell_size
    coefficient, exponent = (targets or load_tune_targets(None, creature_name)).stride_law
    low = max(FROUDE_FLOOR, (STRIDE_MIN_CELLS * cell / (coefficient * h)) ** (1.0 / exponent))
    high = max(SWEEP_RATIO * low, FROUDE_CEILING_MIN)
    return tuple(float(x) for x in np.geomspace(low, high, SWEEP_POINTS))
COLLISION_PENALTY = 1.0
"""Each foot-frame overlapping a box costs as much as a stride missed by sqrt(2) tolerances."""
JERK_GUARD = 0.10
"""Relative rise of the median jerk over the default weights' beyond which a candidate is refused."""
STRIDE_MIN_SPEED = 0.02
"""m/s: strides at a slower pelvis speed are a creature standing, not walking (as in reports/)."""


@dataclass(frozen=True)
class ExactSetup:
    """Which runs make the exact loss of one creature."""

    creature: str
    scenarios: tuple[str, ...] = ("flat",)
    seeds: tuple[int, ...] = (0,)
    froude: tuple[float, ...] | None = None  # None: sweep_froude(creature)
    frames: int = 150
    warmup: int = 30
    n_characters: int = 2
    jerk_weight: float = 0.0

    def __post_init__(self) -> None:
        if self.froude is None:
            object.__setattr__(self, "froude", sweep_froude(self.creature))
        object.__setattr__(self, "froude", tuple(float(f) for f in self.froude))
        if not self.scenarios or not self.seeds or not self.froude:
            raise ValueError("ExactSetup: expected at least one scenario, seed and Froude number")
        if not all(isinstance(f, (int, float)) and 0.0 < f < 1.0 for f in self.froude):
            raise ValueError(f"ExactSetup.froude: expected numbers in (0, 1), got {self.froude!r}")
        if self.warmup < 0 or self.frames <= self.warmup + 10:
            raise ValueError(f"ExactSetup: expected frames > warmup + 10, got {self.frames}, {self.warmup}")
        if self.n_characters < 1:
            raise ValueError("ExactSetup.n_characters: expected >= 1")
        if not self.jerk_weight >= 0.0:
            raise ValueError("ExactSetup.jerk_weight: expected >= 0")

    def to_json(self) -> dict:
        out = dataclasses.asdict(self)
        return {k: list(v) if isinstance(v, tuple) else v for k, v in out.items()}


def speeds_for(setup: ExactSetup) -> np.ndarray:
    """The sweep's desired speeds (m/s): v = sqrt(Fr g h)."""
    from footfall.planner import GRAVITY, hip_height
    from footfall.scenarios import load_creature

    h = hip_height(load_creature(setup.creature))
    return np.sqrt(np.asarray(setup.froude, dtype=np.float64) * GRAVITY * h)


def run_one(creature_name: str, scenario_name: str, seed: int, speed: float, weights, timing, frames: int,
            warmup: int, n_characters: int) -> dict:
    """One crowd run at desired speed ``speed``; the raw measures (module docstring)."""
    from footfall.planner import init_crowd, planner_config_for, simulate
    from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

    creature = load_creature(creature_name)
    gait = load_gait(default_gait_name(creature.name), creature)
    scenario = load_scenario(scenario_name)
    raster = _raster(scenario_name, planner_config_for(creature).cell_size, scenario)
    model, state = init_crowd(scenario, creature, gait, n_characters=n_characters, seed=int(seed), weights=weights,
                              timing=timing, lod_mode="off", raster=raster)
    state.desired_speed[:] = float(speed)
    measured = frames - warmup
    feet = np.zeros((measured,) + state.feet.shape)
    stance = np.zeros((measured,) + state.in_stance.shape, np.bool_)
    pelvis = np.zeros((measured,) + state.pelvis.shape)
    raw = []

    def after(k, record):
        j = k - 1 - warmup
        if j < 0:
            return
        feet[j] = state.feet
        stance[j] = state.in_stance
        pelvis[j] = state.pelvis
        if record.plans is not None:
            out = record.plans.result
            raw.append(out.raw[out.valid])

    summary = simulate(model, state, frames, on_step=after)
    v, stride = realised_strides(feet, stance, pelvis, model.dt)
    walking = v > STRIDE_MIN_SPEED
    raw = np.concatenate(raw) if raw else np.zeros((0, 5))
    return {"speed": v[walking], "stride": stride[walking], "stance_fraction": float(stance.mean()),
            "raw": raw, "collisions": int(summary.collisions), "finite": bool(summary.finite),
            "leg_height": float(model.leg_height)}


# Worker-local state, but only a cache: a raster is rebuilt deterministically from the scenario
# and the cell size, so a task gives the same run whether or not its process built it before.
_RASTERS: dict = {}


def _raster(name, cell, scenario):
    from footfall.planner import WorldRaster

    key = (name, cell)
    if key not in _RASTERS:
        _RASTERS[key] = WorldRaster.build(scenario.terrain, scenario.obstacles, cell)
    return _RASTERS[key]


def exact_tasks(setup: ExactSetup, weights=None, timing=None) -> list[dict]:
    """One plain-dict task per scenario x seed x speed of the sweep, in the order the runs are merged.

    Parameters travel as lists of floats (``weights`` None: the planner's defaults), so a task
    carries every input of its run and gives the same result wherever it runs.
    """
    from footfall.planner import GaitTiming

    timing = timing or GaitTiming()
    speeds = speeds_for(setup)
    w = None if weights is None else [float(x) for x in weights.to_array()]
    t = [float(x) for x in timing.to_array()]
    return [{"creature": setup.creature, "scenario": scenario, "seed": int(seed), "froude": float(fr),
             "speed": float(v), "weights": w, "timing": t, "frames": int(setup.frames), "warmup": int(setup.warmup),
             "n_characters": int(setup.n_characters)}
            for scenario in setup.scenarios
            for seed in setup.seeds
            for fr, v in zip(setup.froude, speeds)]


def run_exact_task(task: dict) -> dict:
    """:func:`run_one` for a task of :func:`exact_tasks`, tagged with its scenario, seed and speed.
    The result holds numpy arrays (``speed``, ``stride``, ``raw``): picklable, for a worker to send back."""
    from footfall.planner import GaitTiming, ScoringWeights, single_threaded

    weights = None if task["weights"] is None else ScoringWeights.from_array(task["weights"])
    timing = GaitTiming.from_array(task["timing"])
    with single_threaded():  # small crowds: one core is faster and leaves the other to others
        r = run_one(task["creature"], task["scenario"], task["seed"], task["speed"], weights, timing, task["frames"],
                    task["warmup"], task["n_characters"])
    r.update(scenario=task["scenario"], seed=task["seed"], froude=task["froude"], desired_speed=task["speed"])
    return r


@dataclass(frozen=True)
class ExactRun:
    """One run of the sweep (a scenario x seed x speed), measured: the per-run parts of the loss."""

    scenario: str
    seed: int
    froude: float  # the sweep's Froude number (the asked speed's)
    run_loss: float  # this run's share of the loss's per-run terms (tuning._tune compares candidates run by run)
    desired_speed: float  # m/s
    realised_speed: float  # m/s, the pelvis's mean over the measured frames
    strides: int
    stride_ratio: float | None  # mean stride / mean target stride (None: no stride measured)
    commanded_ratio: float | None  # mean stride / mean commanded stride
    duty_factor: float  # realised stance fraction
    commanded_duty: float | None
    collisions: int


@dataclass(frozen=True)
class ExactMetrics:
    """The exact loss with its parts (:func:`exact_metrics`; module docstring). ``to_json`` gives the
    plain numbers a checkpoint and a preset's provenance store, in this order; ``from_json`` reads
    them back (a field missing or unknown raises ``ValueError`` naming it)."""

    exact_loss: float
    stride_rel_error: float  # mean over the runs of |stride ratio - 1|
    stride_ratio: tuple[float, ...]  # per run with strides
    stride_term: float
    duty_term: float
    curvature_energy_mean: float
    curvature_energy_se: float  # standard error of that mean (tuning._tune's guard)
    curvature_term: float
    clearance_mean_m: float
    clearance_term: float
    jerk_median: float
    collisions: int
    finite: bool
    plans: int
    leg_height_m: float
    runs: tuple[ExactRun, ...]

    def to_json(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["stride_ratio"] = list(self.stride_ratio)
        out["runs"] = [dataclasses.asdict(r) for r in self.runs]
        return out

    @classmethod
    def from_json(cls, data) -> "ExactMetrics":
        if not isinstance(data, dict):
            raise ValueError("exact metrics: expected an object")
        names = [f.name for f in dataclasses.fields(cls)]
        run_names = [f.name for f in dataclasses.fields(ExactRun)]
        for key in names:
            if key not in data:
                raise ValueError(f"exact metrics: {key}: missing field")
        for key in data:
            if key not in names:
                raise ValueError(f"exact metrics: {key}: unknown field")
        runs = []
        for i, run in enumerate(data["runs"]):
            if not isinstance(run, dict) or sorted(run) != sorted(run_names):
                raise ValueError(f"exact metrics: runs[{i}]: expected the fields {', '.join(run_names)}")
            runs.append(ExactRun(**run))
        return cls(**{**data, "stride_ratio": tuple(data["stride_ratio"]), "runs": tuple(runs)})


def exact_metrics(setup: ExactSetup, weights=None, timing=None, targets=None, map_tasks=None) -> ExactMetrics:
    """Run the sweep and return the exact loss with its parts (:class:`ExactMetrics`).

    Each run is a task (:func:`exact_tasks`, :func:`run_exact_task`); ``map_tasks(function, tasks)
    -> list`` (results in task order, e.g. from ``footfall._distribute.task_runner``) runs them, on
    workers or not; None runs them here, one after the other. The result is the same, bit for bit.
    """
    from footfall.planner import GaitTiming, duty_factor as commanded_duty, stride_length as commanded_stride
    from footfall.tuning._targets import load_targets

    run = task_mapper(map_tasks)
    timing = timing or GaitTiming()

    targets = targets or load_targets(creatures=(setup.creature,))
    t = targets[setup.creature]
    stride_t = t["stride_length"].values
    duty_t = t["duty_factor"].values
    curvature_max = t["curvature_energy"].values["maximum"]
    clearance_min = t.clearance_min_m
    jerk_max = t["swing_jerk"].values["maximum"]
    h = t.leg_length_m
    tasks = exact_tasks(setup, weights, timing)
    runs = list(run(run_exact_task, tasks))
    ratios, duty_out, per_run = [], [], []
    raw_all = np.concatenate([r["raw"] for r in runs]) if runs else np.zeros((0, 5))
    for r in runs:
        if r["stride"].size:
            target = t.stride_length_m(r["speed"])
            ratio = float(np.mean(r["stride"]) / np.mean(target))
            ratios.append(ratio)
            commanded = float(np.mean(r["stride"]) / np.mean(commanded_stride(timing, r["speed"], h)))
        else:
            ratio = commanded = math.nan
        duty = r["stance_fraction"]
        # The duty factor the timing commanded at the speeds the pelvis realised (the gait manager
        # uses the crowd's speed): the fit corrects its duty model by what was realised.
        duty_cmd = float(np.mean(commanded_duty(timing, r["speed"], h))) if r["speed"].size else math.nan
        out = 0.0
        if r["froude"] < duty_t["froude_max"]:
            out = (max(0.0, duty_t["low"] - duty) + max(0.0, duty - duty_t["high"])) / (duty_t["high"] - duty_t["low"])
        duty_out.append(out)
        # This run's share of the loss's per-run terms (tuning._tune compares candidates run by run).
        run_loss = 0.5 * ((0.0 if math.isnan(ratio) else ((ratio - 1.0) / stride_t["relative_tolerance"]) ** 2)
                          + out * out)
        per_run.append(ExactRun(
            scenario=r["scenario"], seed=r["seed"], froude=r["froude"], run_loss=run_loss,
            desired_speed=r["desired_speed"], realised_speed=float(np.mean(r["speed"])) if r["speed"].size else 0.0,
            strides=int(r["stride"].size), stride_ratio=None if math.isnan(ratio) else ratio,
            commanded_ratio=None if math.isnan(commanded) else commanded, duty_factor=duty,
            commanded_duty=None if math.isnan(duty_cmd) else duty_cmd, collisions=r["collisions"]))
    if not ratios:
        raise RuntimeError(f"exact loss: no strides measured for {setup.creature} (too few frames?)")
    ratios = np.asarray(ratios)
    tol = stride_t["relative_tolerance"]
    stride_term = float(np.mean(((ratios - 1.0) / tol) ** 2))
    duty_term = float(np.mean(np.square(duty_out)))
    curvature = float(np.mean(raw_all[:, RAW_CURVATURE])) if raw_all.size else 0.0
    # Standard error of that mean: a few detours around a crate or a hill carry most of it, so it
    # moves by tens of per cent between runs of nearly the same parameters (tuning._tune's guard).
    curvature_se = float(np.std(raw_all[:, RAW_CURVATURE]) / math.sqrt(raw_all.shape[0])) if raw_all.size else 0.0
    clearance_raw = raw_all[:, RAW_CLEARANCE] if raw_all.size else np.zeros(0)
    capped = np.where(np.isfinite(clearance_raw), np.minimum(clearance_raw, clearance_min), clearance_min)
    clearance = float(np.mean(capped)) if capped.size else clearance_min
    jerk = float(np.median(raw_all[:, RAW_JERK])) if raw_all.size else 0.0
    collisions = int(sum(r["collisions"] for r in runs))
    curvature_term = max(0.0, curvature / curvature_max - 1.0) ** 2
    clearance_term = max(0.0, 1.0 - clearance / clearance_min) ** 2
    jerk_term = max(0.0, math.log(max(jerk, 1e-300) / jerk_max)) ** 2
    loss = (0.5 * (stride_term + duty_term + curvature_term + clearance_term) + COLLISION_PENALTY * collisions
            + setup.jerk_weight * jerk_term)
    return ExactMetrics(
        exact_loss=float(loss), stride_rel_error=float(np.mean(np.abs(ratios - 1.0))),
        stride_ratio=tuple(float(x) for x in ratios), stride_term=stride_term, duty_term=duty_term,
        curvature_energy_mean=curvature, curvature_energy_se=curvature_se, curvature_term=curvature_term,
        clearance_mean_m=clearance, clearance_term=clearance_term, jerk_median=jerk, collisions=collisions,
        finite=all(r["finite"] for r in runs), plans=int(raw_all.shape[0]), leg_height_m=h, runs=tuple(per_run))
