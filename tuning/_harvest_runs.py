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
from footfall.tuning._defaults import creature_defaults


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

    Parameters
    ----------
    scenarios, creatures : sequence of str
        Built-in scenario and creature names (not a bare string), at least one of each.
    seeds : sequence of int, optional
        Crowd seeds, one run each (default ``(0,)``).
    frames : int, optional
        Frames per run, >= 1 (default 30).
    n_characters : int, optional
        Characters of each crowd, >= 1 (default 2).
    weights : ScoringWeights, optional
        The scoring weights of the runs. Default: with one creature, its defaults
        (:func:`tuning.creature_defaults`, as the runtime gives it); with several, who share one
        weights vector, ``ScoringWeights()``.
    timing : GaitTiming, optional
        The gait timing of the runs (default ``GaitTiming()``).
    max_situations : int, optional
        Stop after this many situations (whole frames); None (default): no cap.
    map_tasks : callable, optional
        ``map_tasks(function, tasks) -> list`` running the chunks; None: here, in order.

    Returns
    -------
    footfall.planner.Harvest
        Every planning request: candidates, couples, their raw numbers and the runtime's scores
        and choices, with the ``weights`` and ``timing`` arrays used.

    Raises
    ------
    ValueError
        If an argument is of the wrong kind or out of range.

    Examples
    --------
    One spider on flat ground, one frame: its first three steps (forced steps as it starts):

    >>> from footfall.tuning import harvest_situations
    >>> harvest = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> harvest.n_situations, harvest.creatures, harvest.scenarios
    (3, ('spider',), ('flat',))
    >>> harvest.cand_mask.shape, harvest.couple_raw.shape            # (F, K) and (F, K, S, 5)
    ((3, 20), (3, 20, 1, 5))
    >>> again = harvest_situations(("flat",), ("spider",), frames=1, n_characters=1, max_situations=2)
    >>> bool((again.couple_scores == harvest.couple_scores).all())    # seeded: the same numbers
    True
    >>> harvest_situations("flat")
    Traceback (most recent call last):
        ...
    ValueError: scenarios, creatures: expected sequences of names
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
    if weights is None:
        weights = creature_defaults(creatures[0]) if len(creatures) == 1 else ScoringWeights()
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

    Parameters
    ----------
    scenarios, creatures, seeds : sequence
        Scenario names, creature names and seeds (:func:`harvest_situations`).
    frames, n_characters : int
        Frames per run and characters per crowd.
    weights : ScoringWeights
        The scoring weights of the runs.
    timing : GaitTiming
        The gait timing of the runs.
    max_situations : int or None
        The global cap (None: none).

    Returns
    -------
    list of dict
        One task per (creature, scenario, seed): creature by creature, then scenario, then seed.

    Examples
    --------
    >>> from footfall.planner import GaitTiming, ScoringWeights
    >>> from footfall.tuning import harvest_tasks
    >>> tasks = harvest_tasks(("flat", "crates"), ("spider",), (0, 1), 1, 1, ScoringWeights(), GaitTiming(), None)
    >>> len(tasks), [(t["scenario"], t["seed"]) for t in tasks]
    (4, [('flat', 0), ('flat', 1), ('crates', 0), ('crates', 1)])
    >>> sorted(tasks[0])
    ['creature', 'creature_index', 'frames', 'max_situations', 'n_characters', 'scenario', 'scenario_index', 'seed',
     'timing', 'weights']
    >>> len(tasks[0]["weights"]), len(tasks[0]["timing"])           # plain floats
    (19, 7)
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

    Parameters
    ----------
    task : dict
        One task of :func:`harvest_tasks`.

    Returns
    -------
    dict
        ``{"rows": list, "frame_ends": list of int}``.

    Examples
    --------
    Two frames of one spider: three requests in the first, one in the second:

    >>> from footfall.planner import GaitTiming, ScoringWeights
    >>> from footfall.tuning import harvest_chunk, harvest_tasks
    >>> task, = harvest_tasks(("flat",), ("spider",), (0,), 2, 1, ScoringWeights(), GaitTiming(), None)
    >>> chunk = harvest_chunk(task)
    >>> sorted(chunk), len(chunk["rows"]), chunk["frame_ends"]
    (['frame_ends', 'rows'], 4, [3, 4])
    """
    from footfall.scenarios import default_gait_name, load_creature, load_gait, load_scenario

    creature = load_creature(task["creature"])
    gait = load_gait(default_gait_name(creature.name), creature)
    scenario = load_scenario(task["scenario"])
    meta = {"creature": task["creature_index"], "scenario": task["scenario_index"], "seed": task["seed"]}
    return harvest_run(scenario, creature, gait, weights=ScoringWeights.from_array(task["weights"]),
                       timing=GaitTiming.from_array(task["timing"]), n_characters=task["n_characters"],
                       seed=task["seed"], frames=task["frames"], max_situations=task["max_situations"], meta=meta)
