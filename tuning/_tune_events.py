"""Terrain and style tunes of the scoring weights (issue 18): ``footfall tune --scenarios ... --targets ...``.

The legacy tune (:mod:`tuning._tune`) fits the gait timing to the stride law on a sweep of speeds;
with the generic law it rightly keeps the defaults. This one tunes the **scoring weights** for a
terrain or a style, the timing held at the targets file's stride law (so the runtime commands the
law the per-stride error is measured against):

Each outer round r (``rounds`` at most):

1. **harvest** every couple the search could pick (``footfall.tuning.harvest_situations``, seed ``seed + r``)
   on the training scenarios, each spawned :data:`HARVEST_SPAWN` of the way along its route so the
   situations meet the feature (risers, crates, slopes);
2. **fit** the weights alone (:func:`tuning._fit.fit` with the weights' blocks, ``fit_timing=False``,
   temperature :data:`TAU`): soft expectations of the offset from the preferred footprint and of the
   style's quantities, with real gradients for every weight;
3. **exact objective** (:mod:`tuning._events`) along the fitted step, a backtracking line search
   (:data:`tuning._tune.LINE_SEARCH`): a candidate is accepted if it is finite, its collisions and
   body overlaps do not rise over the defaults' (:func:`tuning._events.collisions_rise`), and lowers the paired per-run loss of the best so
   far by at least ``gain_noise_se`` standard errors.

Then the **held-out** runs: other terrains' parameters and other seeds (:func:`heldout_variant`,
``holdout_seeds``), each paired run by run with the defaults. A tuned preset whose held-out loss is
higher than the defaults' (a negative paired gain) is not shipped: the defaults are, and
``heldout_refused`` says why.

A checkpoint (JSON, atomic) after every round makes ``--resume`` continue to the same preset.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from footfall._atomic import write_text_atomic
from footfall._errors import InputError
from footfall.tuning._events import (EVENT_FRAMES, SPAWN_FRACTIONS, EventSetup, collisions_rise, event_metrics, paired,
                            spawn_variant)
from footfall.tuning._tune import (LINE_SEARCH, BestSoFar, TuneResult, _bucket, _floats, _objects, _pad_problem, _towards,
                          check_creature, check_output, checked_params, checkpoint_fields, checkpoint_path,
                          read_checkpoint_json)

CHECKPOINT_FORMAT = "footfall-tune-events-checkpoint"
CHECKPOINT_VERSION = 1
TAU = 0.01
"""Temperature of the soft selection (:mod:`tuning._proxies`, 'Temperature')."""
HARVEST_SPAWN = 0.3
PRIOR_LOG_SCALE = 2.0
"""The fit's prior on the log weights (:mod:`tuning._fit`): a factor e^2 costs one tolerance. Looser
than the timing tune's 1.0: the exact line search has the last word on every step."""
OFFSET_OFF_STYLES = ("min_clearance_body_heights",)
"""Style keys that switch the fit's offset block off (:func:`offset_weight`)."""


def offset_weight(targets) -> float:
    """The fit's offset block's weight (:mod:`tuning._fit`) for a tune against ``targets``: 0 for a
    style with a clearance bound, 1 otherwise.

    The offset block pulls the feet onto the preferred footprints, and beside a box that is where a
    clearance bound does not want them: with it, the crates and mixed style tunes first raised their
    collisions. A style without one keeps the stride law as well: a touch-down slope ceiling on stairs
    (spider, 0.03 rad) without the block kept a quarter step that cut the held-out slope 0.077 ->
    0.045 rad and raised the per-stride error 0.145 -> 0.157; with it, three rounds cut the slope to
    0.016 rad and the per-stride error to 0.104."""
    style = targets.style or {}
    return 0.0 if any(key in style for key in OFFSET_OFF_STYLES) else 1.0


GAIN_NOISE_SE = 2.0
DEFAULT_SCENARIOS = ("stairs", "crates", "hills", "mixed")
HELDOUT = {
    "stairs": "stairs@terrain.rise=0.1,terrain.run=0.3",
    "crates": "crates@seed=13",
    "crates-moving": "crates-moving@seed=17",
    "hills": "hills@seed=5",
    "mixed": "mixed@seed=19",
    "flat": "flat@crowd.speed=0.2",
}
"""Per built-in scenario, its held-out variant: other terrain parameters or another layout."""


def heldout_variant(name: str) -> str:
    """The held-out variant of a training scenario: :data:`HELDOUT` for a built-in, ``seed`` + 1000
    for a variant or a file (another layout or terrain of the same kind)."""
    if name in HELDOUT:
        return HELDOUT[name]
    base, sep, rest = name.partition("@")
    extra = "seed=1000"
    return f"{base}@{rest},{extra}" if sep and rest else f"{base}@{extra}"


@dataclass(frozen=True)
class EventTuneConfig:
    creature: str
    scenarios: tuple[str, ...] = DEFAULT_SCENARIOS
    targets_file: str | None = None
    rounds: int = 3
    seed: int = 0
    seeds: tuple[int, ...] = (0, 1, 2)
    frames: int = EVENT_FRAMES
    characters: int = 1
    spawn_fractions: tuple[float, ...] = SPAWN_FRACTIONS
    harvest_frames: int = 40
    harvest_characters: int = 2
    max_situations: int = 800
    fit_steps: int = 12
    tau: float = TAU
    holdout_scenarios: tuple[str, ...] | None = None  # None: heldout_variant of each scenario
    holdout_seeds: tuple[int, ...] = (101, 102, 103)
    gain_noise_se: float = GAIN_NOISE_SE
    prior_log_scale: float = PRIOR_LOG_SCALE

    def __post_init__(self) -> None:
        for name in ("scenarios", "seeds", "spawn_fractions", "holdout_seeds"):
            object.__setattr__(self, name, tuple(getattr(self, name)))
        if self.holdout_scenarios is not None:
            object.__setattr__(self, "holdout_scenarios", tuple(self.holdout_scenarios))
        if not self.scenarios:
            raise InputError("argument", "--scenarios", "expected at least one scenario")
        for name in ("rounds", "seed", "frames", "characters", "harvest_frames", "harvest_characters",
                     "max_situations", "fit_steps"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < (0 if name == "seed" else 1):
                raise InputError("argument", f"--{name}", f"expected a positive integer, got {value!r}")
        if not self.tau > 0.0:
            raise InputError("argument", "tau", f"expected > 0, got {self.tau}")

    def setup(self) -> EventSetup:
        return EventSetup(self.creature, self.scenarios, tuple(s + self.seed for s in self.seeds), self.frames,
                          self.characters, self.spawn_fractions)

    def holdout(self) -> EventSetup:
        names = self.holdout_scenarios or tuple(heldout_variant(n) for n in self.scenarios)
        return EventSetup(self.creature, names, tuple(s + self.seed for s in self.holdout_seeds), self.frames,
                          self.characters, self.spawn_fractions)

    def to_json(self) -> dict:
        return {k: list(v) if isinstance(v, tuple) else v for k, v in dataclasses.asdict(self).items()}


def check_scenarios(text: str) -> tuple[str, ...]:
    """The scenarios of a command line's ``--scenarios A,B,...`` (a variant's overrides kept with it,
    :func:`footfall.scenarios.split_scenario_list`); every one loads (one line on the first that does not)."""
    from footfall.scenarios import load_scenario, split_scenario_list

    names = split_scenario_list(text)
    if not names:
        raise InputError("argument", "--scenarios", "expected NAME[,NAME...]")
    for name in names:
        load_scenario(name)
    return names


def _start(config, targets) -> dict:
    """The creature's default weights and the targets' stride law: where the tune begins."""
    from footfall.tuning._defaults import creature_defaults

    return {"weights": _floats(creature_defaults(config.creature).to_array()),
            "timing": _floats(targets.timing().to_array())}


def style_start(params: dict, targets) -> dict:
    """The first point of a style tune: ``params`` with ``proximity_ref_m`` raised to the style's
    minimum clearance to forbidden boxes (metres), where that is the larger.

    The runtime's proximity goodness is min(1, d / proximity_ref_m) (:mod:`planner._weights`): every
    footprint farther than the reference (0.10 m) from a forbidden box scores 1, so below a bound
    beyond it the score cannot tell a footprint 0.12 m from a box from one 0.24 m away: the fit's
    gradient for the proximity weight comes only from the few candidates nearer than the reference,
    which the search does not pick. Measured (spider, crates + mixed, 18 runs, a bound
    of 2 h = 0.24 m; the share of touch-downs nearer than the bound): the defaults 3.5 %, the
    proximity weight x3 alone 3.5 % (bit for bit the same runs), the reference 0.25 m alone 2.9 %,
    both 0.9 %. The fit moves the weights on from there (its gradient for the proximity weight stays
    small: one term of ten, for the few footprints near a box); every candidate is judged against the
    defaults' runs, and the preset's change is measured from the defaults."""
    from footfall.planner.layout import W_PROXIMITY_REF

    bound = targets.style.get("min_clearance_body_heights") if targets.style else None
    if bound is None:
        return params
    weights = list(params["weights"])
    weights[W_PROXIMITY_REF] = max(weights[W_PROXIMITY_REF], float(bound) * targets.leg_length_m)
    return {**params, "weights": _floats(weights)}


def _fit_round(config: EventTuneConfig, params: dict, round_index: int, targets, map_tasks):
    from footfall.tuning._harvest_runs import harvest_situations
    from footfall.tuning._fit import fit, initial_loss, make_problem
    from footfall.tuning._proxies import situations_from_harvest

    weights, timing = _objects(params)
    scenarios = tuple(spawn_variant(n, HARVEST_SPAWN) for n in config.scenarios)
    harvest = harvest_situations(scenarios=scenarios, creatures=(config.creature,), seeds=(config.seed + round_index,),
                                 frames=config.harvest_frames, n_characters=config.harvest_characters, weights=weights,
                                 timing=timing, max_situations=config.max_situations, map_tasks=map_tasks)
    situations = situations_from_harvest(harvest)
    problem = make_problem(situations, harvest.creatures, {harvest.creatures[0]: targets}, config.tau,
                           weights_blocks=True, fit_timing=False, offset_weight=offset_weight(targets),
                           prior_log_scale=config.prior_log_scale)
    f, k, s = (int(x) for x in situations.couple_mask.shape)
    problem = _pad_problem(problem, _bucket(f, 128), _bucket(k, 32), _bucket(s, 4))
    loss0 = initial_loss(problem)
    w, _, history = fit(problem, n_steps=config.fit_steps)
    record = {"situations": f, "proxy_loss_before": loss0, "proxy_loss_after": float(history[-1]),
              "harvest_seed": config.seed + round_index}
    return {"weights": _floats(w), "timing": params["timing"]}, record


def accept(candidate: dict, best: dict, default: dict, gain_noise_se: float) -> tuple[bool, str]:
    """(accepted, why) of a candidate's event metrics against the best so far and the defaults'."""
    if not candidate["finite"]:
        return False, "non-finite run"
    rises, mean, se = collisions_rise(default, candidate)
    if rises:
        return False, f"more collisions and body overlaps than the defaults (+{mean:.3g} per run, SE {se:.3g})"
    if not candidate["exact_loss"] < best["exact_loss"]:
        return False, "loss did not improve"
    gain, se, _ = paired(best, candidate)
    if not gain >= gain_noise_se * se:
        return False, f"gain within the runs' noise ({gain:.3g} < {gain_noise_se:g} x SE {se:.3g})"
    return True, "improved"


def _save(path: Path, state: dict) -> None:
    write_text_atomic(path, json.dumps(state, indent=1, allow_nan=False, default=_json_default) + "\n")


def _json_default(value):
    raise TypeError(f"not JSON: {value!r}")


def _clean(value):
    """NaN -> None, recursively (JSON has no NaN)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


@dataclass(frozen=True)
class EventTuneCheckpoint:
    """The terrain / style tune's state after a round, as its checkpoint file holds it. Each round
    makes a new one (``dataclasses.replace``). The metrics (``best.exact``, ``default_exact``) are
    :func:`tuning._events.event_metrics` records: per-run metrics of the targets' style, kept as
    the plain records the preset's provenance and ``tuning/data/matrix.json`` store. ``to_json``
    gives the file's fields in this order with NaN written as null; ``from_json`` reads them back."""

    config: dict  # EventTuneConfig.to_json(): a resume with other settings is refused
    round: int  # rounds done
    stopped: bool  # the line search found no better step: the loop ends
    current: dict  # the parameters the next round starts from
    best: BestSoFar
    default_exact: dict  # the defaults' event metrics (the guards' reference)
    history: tuple[dict, ...]  # one record per round (fit, line search, decision)

    def to_json(self) -> dict:
        return _clean({"format": CHECKPOINT_FORMAT, "version": CHECKPOINT_VERSION, "config": self.config,
                       "round": self.round, "stopped": self.stopped, "current": self.current,
                       "best": {"params": self.best.params, "exact": self.best.exact, "round": self.best.round},
                       "default_exact": self.default_exact, "history": list(self.history)})

    @classmethod
    def from_json(cls, data: dict, path: Path) -> "EventTuneCheckpoint":
        """The checkpoint of a file's JSON; anything missing or of the wrong kind raises
        :class:`InputError` naming the file and the field."""
        checkpoint_fields(data, path, (("config", dict), ("round", int), ("stopped", bool), ("current", dict),
                                       ("best", dict), ("default_exact", dict), ("history", list)))
        best = data["best"]
        if not (isinstance(best.get("params"), dict) and isinstance(best.get("exact"), dict)
                and isinstance(best.get("round"), int)):
            raise InputError(path, "best", "corrupt checkpoint: expected params, exact and round")
        checked_params(path, data["current"], best["params"])
        return cls(config=data["config"], round=data["round"], stopped=data["stopped"], current=data["current"],
                   best=BestSoFar(best["params"], best["exact"], best["round"]), default_exact=data["default_exact"],
                   history=tuple(data["history"]))

    def through_json(self) -> "EventTuneCheckpoint":
        """This state as a resume reads it back (NaN as None): the loop goes on from exactly that."""
        return EventTuneCheckpoint.from_json(self.to_json(), Path(CHECKPOINT_FORMAT))


def _load(path: Path, config: EventTuneConfig) -> EventTuneCheckpoint:
    data = read_checkpoint_json(path, CHECKPOINT_FORMAT, CHECKPOINT_VERSION, config.to_json())
    return EventTuneCheckpoint.from_json(data, path)


def weights_max_rel_change(tuned: dict, default: dict) -> float:
    """max over the scoring weights and scales of |tuned / default - 1|."""
    a = np.asarray(tuned["weights"], dtype=np.float64)
    b = np.asarray(default["weights"], dtype=np.float64)
    return float(np.max(np.abs(a / b - 1.0)))


def tune_events(config: EventTuneConfig, out, resume: bool = False, progress=None, stop_after: int | None = None,
                write: bool = True, workers: int | None = None, cluster: str | None = None,
                spearman_candidates: int = 0, evaluate: bool = True) -> TuneResult:
    """Run (or resume) the terrain / style tune; write the preset to ``out`` (module docstring).
    ``spearman_candidates`` > 0: also validate the proxies on that many candidate presets
    (:func:`tuning._validate.metric_change_spearman`). ``evaluate`` False: stop after the outer loop
    (the checkpoint holds the result; ``footfall bench tuning --scenarios`` times the search alone)."""
    from footfall._distribute import check_workers, task_runner

    t0 = time.perf_counter()
    check_workers(workers, cluster)
    check_creature(config.creature)
    out = check_output(out)
    with task_runner(workers, cluster) as map_tasks:
        return _run(config, out, resume, progress, stop_after, write, map_tasks, t0, spearman_candidates, evaluate)


def _run(config, out, resume, progress, stop_after, write, map_tasks, t0, spearman_candidates,
         evaluate=True) -> TuneResult:
    from footfall.planner import preset_dict
    from footfall.scenarios import default_gait_name, load_creature
    from footfall.tuning._config import enable_x64
    from footfall.tuning._targets import load_tune_targets

    enable_x64()
    targets = load_tune_targets(config.targets_file, config.creature)
    setup = config.setup()
    ckpt = checkpoint_path(out)
    say = progress or (lambda *a: None)
    total = config.rounds + 2
    start = _start(config, targets)
    if resume:
        state = _load(ckpt, config)
        say(f"resumed at round {state.round}", state.round + 1, total)
    else:
        say("objective of the defaults", 0, total)
        default_exact = event_metrics(setup, *_objects(start), targets, map_tasks)
        state = EventTuneCheckpoint(config=config.to_json(), round=0, stopped=False,
                                    current=style_start(start, targets), best=BestSoFar(start, default_exact, -1),
                                    default_exact=default_exact, history=())
        _save(ckpt, state.to_json())
    while state.round < config.rounds and not state.stopped:
        r = state.round
        say(f"round {r + 1}/{config.rounds}: harvest + fit", r + 1, total)
        fitted, record = _fit_round(config, state.current, r, targets, map_tasks)
        say(f"round {r + 1}/{config.rounds}: exact runs", r + 1, total)
        tried = []
        for alpha in LINE_SEARCH:
            params = _towards(state.current, fitted, alpha)
            candidate = event_metrics(setup, *_objects(params), targets, map_tasks)
            accepted, why = accept(candidate, state.best.exact, state.default_exact, config.gain_noise_se)
            tried.append({"alpha": alpha, "exact_loss": candidate["exact_loss"],
                          "stride_rel_error": candidate["stride_rel_error"], "collisions": candidate["collisions"],
                          "decision": why})
            if accepted:
                break
        record.update(round=r, alpha=alpha, accepted=accepted, decision=why, line_search=tried)
        if accepted:
            state = dataclasses.replace(state, best=BestSoFar(params, candidate, r), current=params)
        state = dataclasses.replace(state, round=r + 1, stopped=not accepted, history=(*state.history, record))
        state = state.through_json()  # what a resume would read: NaN as None
        _save(ckpt, state.to_json())
        if stop_after is not None and state.round >= stop_after:
            return TuneResult(preset={}, summary={}, wall_s=time.perf_counter() - t0, finished=False)
    if not evaluate:
        return TuneResult(preset={}, summary={}, wall_s=time.perf_counter() - t0, finished=True)
    say("held-out runs", total - 1, total)
    best = state.best
    holdout = config.holdout()
    held_default = event_metrics(holdout, *_objects(start), targets, map_tasks)
    held_tuned = held_default if best.round < 0 else event_metrics(holdout, *_objects(best.params), targets,
                                                                      map_tasks)
    gain, se, n = paired(held_default, held_tuned)
    refused = None
    if best.round >= 0 and not gain > 0.0:
        refused = (f"round {best.round} refused on the held-out runs: paired loss gain {gain:.4g} "
                   f"(SE {se:.3g}, {n} runs) is not positive")
        best = BestSoFar(start, state.default_exact, -1)
        held_tuned, gain, se = held_default, 0.0, math.nan
    spearman = None
    if spearman_candidates > 0:
        from footfall.tuning._validate import metric_change_spearman

        say("proxy validation", total - 1, total)
        spearman = metric_change_spearman(config, targets, spearman_candidates, map_tasks)
    weights, timing = _objects(best.params)
    from footfall import __version__

    summary = {
        "creature": config.creature,
        "scenarios": list(config.scenarios),
        "targets": targets.to_json(),
        "heldout_scenarios": list(holdout.scenarios),
        "loss_default": state.default_exact["exact_loss"], "loss_tuned": best.exact["exact_loss"],
        "heldout_loss_default": held_default["exact_loss"], "heldout_loss_tuned": held_tuned["exact_loss"],
        "heldout_gain_se": None if not (se > 0.0) else gain / se,
        "heldout_runs": n,
        "heldout_stride_error_default": held_default["stride_rel_error"],
        "heldout_stride_error_tuned": held_tuned["stride_rel_error"],
        "heldout_collisions_default": held_default["collisions"], "heldout_collisions_tuned": held_tuned["collisions"],
        "weights_max_rel_change": weights_max_rel_change(best.params, start),
        "spearman_metric_change": None if spearman is None else spearman["spearman_min"],
        "rounds_run": state.round, "best_round": best.round, "heldout_refused": refused,
    }
    provenance = {
        "tool": "footfall tune (terrain / style)", "footfall_version": __version__,
        "config": config.to_json(), "targets": targets.to_json(),
        "fit": {"method": "optimistix.LevenbergMarquardt on the weights' blocks (tuning._fit), weights only, "
                          "timing = the targets' stride law", "tau": config.tau},
        "objective": "tuning._events: runs spawned along the route, per-event metrics, paired run losses",
        "rounds": list(state.history),
        "heldout": {"default": _clean(held_default), "tuned": _clean(held_tuned)},
        "spearman": spearman,
        "summary": _clean(summary),
    }
    creature = load_creature(config.creature)
    preset = preset_dict(creature.name, weights, timing, default_gait_name(creature), _clean(provenance))
    if write:
        write_text_atomic(out, json.dumps(preset, indent=1, allow_nan=False) + "\n")
    return TuneResult(preset=preset, summary=_clean(summary), wall_s=time.perf_counter() - t0)
