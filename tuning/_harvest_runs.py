"""The tuning's harvest: short seeded crowd runs over built-in scenarios and creatures, named.

Every planning request of every frame becomes a situation (:class:`footfall.planner.Harvest`: every
couple the search could pick, with its raw numbers). Each (creature, scenario, seed) run is an
independent task (:func:`harvest_chunk`), so a caller may hand them to worker processes
(``map_tasks``). The runs themselves are the planner's (:func:`footfall.planner.harvest_run`); this
module names them: it loads the scenarios, creatures and gaits, which the planner never does.
No JAX here: ``footfall.tuning`` re-exports these names lazily.
"""

from __future__ import annotations

from footfall.planner import (GaitTiming, Harvest, ScoringWeights, harvest_run, merge_harvest_chunks, pack_harvest,
                              task_mapper)


def harvest_situations(scenarios=("mixed",), creatures=("spider",), *, seeds=(0,), frames: int = 30,
                       n_characters: int = 2, weights: ScoringWeights | None = None, timing=None,
                       max_situations: int | None = None, map_tasks=None) -> Harvest:
    """Run ``frames`` frames of a seeded crowd (LOD off: the paper's full search) per scenario,
    creature and seed, and harvest every planning request.

    Creatures use their default gait. Stops once ``max_situations`` situations are
    collected (whole frames: the last frame's requests are all kept).

    The runs are independent chunks, one per (creature, scenario, seed) (:func:`harvest_tasks`,
    :func:`harvest_chunk`). ``map_tasks(function, tasks) -> list`` (results in task order, e.g.
    from ``footfall._distribute.task_runner``) runs them, on workers or not; None runs them here,
    one after the other. The result is the same, bit for bit, either way.
    """
    if isinstance(scenarios, str) or isinstance(creatures, str):
        raise ValueError("scenarios, creatures: expected sequences of names")
    if not scenarios or not creatures or not seeds:
        raise ValueError("scenarios, creatures, seeds: expected at least one of each")
    if isinstance(frames, bool) or not isinstance(frames, int) or frames < 1:
        raise ValueError(f"frames: expected an integer >= 1, got {frames!r}")
    if isinstance(n_characters, bool) or not isinstance(n_characters, int) or n_characters < 1:
        raise ValueError(f"n_characters: expected an integer >= 1, got {n_characters!r}")
    if max_situations is not None and (isinstance(max_situations, bool) or not isinstance(max_situations, int)
                                       or max_situations < 1):
        raise ValueError(f"max_situations: expected None or an integer >= 1, got {max_situations!r}")
    run = task_mapper(map_tasks)
    weights = weights or ScoringWeights()
    timing = timing or GaitTiming()
    tasks = harvest_tasks(scenarios, creatures, seeds, frames, n_characters, weights, timing, max_situations)
    # In this process the chunks run lazily: once the cap is reached the rest never run. With a
    # map_tasks every chunk runs (in parallel) and those past the cap are dropped by the merge.
    chunks = run(harvest_chunk, tasks)
    rows = merge_harvest_chunks(chunks, max_situations)
    return pack_harvest(rows, creatures, scenarios, weights.to_array(), timing.to_array())


def harvest_tasks(scenarios, creatures, seeds, frames: int, n_characters: int, weights: ScoringWeights, timing,
                  max_situations: int | None) -> list[dict]:
    """One plain-dict task per (creature, scenario, seed), in the order the situations are packed.

    A task carries every input of its run (names, their indices in the harvest, parameters as
    lists of floats), so it gives the same rows wherever it runs. Its cap is the global one: a
    chunk never contributes more than ``max_situations`` rows (plus the rest of its last frame).
    """
    w = [float(x) for x in weights.to_array()]
    t = [float(x) for x in timing.to_array()]
    return [{"creature": str(creature_name), "creature_index": ci, "scenario": str(scenario_name),
             "scenario_index": si, "seed": int(seed), "frames": int(frames), "n_characters": int(n_characters),
             "weights": w, "timing": t, "max_situations": max_situations}
            for ci, creature_name in enumerate(creatures)
            for si, scenario_name in enumerate(scenarios)
            for seed in seeds]


def harvest_chunk(task: dict) -> dict:
    """Run one task of :func:`harvest_tasks`: ``{"rows": [...], "frame_ends": [...]}``, the situations
    of its crowd run in order and the row count after each harvested frame (where a global cap may cut).

    Rows hold numpy arrays and :class:`footfall.planner.FootHarvest` records: picklable, for a worker
    to send back.
    """
    from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

    creature = load_creature(task["creature"])
    gait = load_gait(default_gait_name(creature.name), creature)
    scenario = load_scenario(task["scenario"])
    meta = {"creature": task["creature_index"], "scenario": task["scenario_index"], "seed": task["seed"]}
    return harvest_run(scenario, creature, gait, weights=ScoringWeights.from_array(task["weights"]),
                       timing=GaitTiming.from_array(task["timing"]), n_characters=task["n_characters"],
                       seed=task["seed"], frames=task["frames"], max_situations=task["max_situations"], meta=meta)
