"""Harvest for tuning (issue 4): every couple the search could pick, with its raw numbers.

The runtime search returns one couple per foot. Tuning needs, per planning
situation, the whole choice set: per candidate footprint its raw features
(FEATURES), per (candidate, slice) couple its raw trajectory metrics
(RAW_METRICS) and ``d_ref``, and which couple the runtime picked. The numbers come
from :func:`planner._kernels_search.harvest_foot_kernel`, which uses the search's
own goodness and scoring functions, so the runtime's scores are stored alongside
(tuning/ recomputes them from the raw numbers and must find the same values).

* :func:`harvest_foot`: one foot (``LocalMaps`` + ``FootQuery``), validated.
* :func:`harvest_run`: one short seeded crowd run (``init_crowd`` / ``step``) of a
  loaded scenario, creature and gait; every planning request of every frame becomes
  a row. :func:`merge_harvest_chunks` and :func:`pack_harvest` make the rows of several
  runs one :class:`Harvest`: struct-of-arrays, padded to the largest candidate and
  slice counts, with masks. Deterministic for a seed. The runs by name, as tasks a
  caller may hand to worker processes, are the tuning's
  (``footfall.tuning.harvest_situations``); planner/ itself never imports Dask, nor
  the scenarios.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.planner._kernels_search import MODE_SEARCH, harvest_foot_kernel, plan_foot_kernel
from footfall.planner._maps import LocalMaps
from footfall.planner._params import DEFAULT_BUDGET, PlannerConfig, SearchBudget
from footfall.planner._search import FootQuery, checked_foot_shape
from footfall.planner._threads import single_threaded
from footfall.planner._weights import N_FOOTPRINT_TERMS, N_TERMS, ScoringWeights
from footfall.planner.layout import CNT_BOXED, FEATURES, N_FEATURES, N_RAW  # FEATURES: the order of ``cand_features``



@dataclass(frozen=True)
class FootHarvest:
    """All couples of one foot. n candidates (the search's order), S slices.

    Attributes
    ----------
    cand_cells : ndarray of int, shape (n, 2)
        Local (row, col) of each candidate footprint, by descending footprint score.
    cand_xyz : ndarray, shape (n, 3)
        Target points: the continuous footprint in the cell, at the dilated elevation.
    cand_features : ndarray, shape (n, 5)
        Raw footprint features, columns :data:`FEATURES`.
    cand_terms : ndarray, shape (n, 5)
        Footprint goodnesses (the runtime's).
    cand_scores : ndarray, shape (n,)
        Footprint scores (the runtime's).
    levels : ndarray, shape (S,)
        Slice levels, m above terrain (``inf``: no slices).
    d_ref : ndarray, shape (n,)
        Each candidate's reference of the length goodness (source to footprint), m.
    couple_valid : ndarray of bool, shape (n, S)
        A path exists.
    couple_raw : ndarray, shape (n, S, 5)
        Raw trajectory metrics, in :data:`RAW_METRICS` order.
    couple_terms : ndarray, shape (n, S, 10)
        Goodnesses (the runtime's), in :data:`SCORE_TERMS` order.
    couple_scores : ndarray, shape (n, S, 3)
        Couple, footprint and trajectory scores (the runtime's).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import FootQuery, GridFrame, LocalMaps, harvest_foot
    >>> flat = np.zeros((35, 35))                   # 35 x 35 cells of 7 cm, flat ground at y = 0
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> harvest = harvest_foot(maps, query)
    >>> harvest.cand_cells.shape, harvest.levels     # flat ground: one level, no slices
    ((37, 2), array([inf]))
    >>> harvest.couple_valid.shape, harvest.couple_scores.shape
    ((37, 1), (37, 1, 3))
    """

    cand_cells: np.ndarray  # (n, 2) local (row, col)
    cand_xyz: np.ndarray  # (n, 3) target points (continuous footprint in the cell, dilated elevation)
    cand_features: np.ndarray  # (n, 5) FEATURES
    cand_terms: np.ndarray  # (n, 5) footprint goodnesses (the runtime's)
    cand_scores: np.ndarray  # (n,) footprint scores (the runtime's)
    levels: np.ndarray  # (S,) slice levels, m above terrain (inf: no slices)
    d_ref: np.ndarray  # (n,) m, each candidate's reference of the length goodness (source -> footprint)
    couple_valid: np.ndarray  # (n, S) bool: a path exists
    couple_raw: np.ndarray  # (n, S, 5) RAW_METRICS
    couple_terms: np.ndarray  # (n, S, 10) goodnesses (the runtime's)
    couple_scores: np.ndarray  # (n, S, 3) couple, footprint, trajectory scores (the runtime's)


def _harvest_kernel_call(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source, preferred, hip, reach_xz,
                         step_height, legs, block_radius, w, cfg, slice_size) -> FootHarvest:
    out = harvest_foot_kernel(elevation, ground, forbidden, origin_x, origin_z, foot_shape, source, preferred, hip,
                              reach_xz, step_height, legs, block_radius, w, cfg, slice_size)
    rc, xyz, feats, terms, scores, levels, d_ref, valid, raw, cterms, cscores = out
    return FootHarvest(rc, xyz, feats, terms, scores, levels, d_ref, valid, raw, cterms, cscores)


def harvest_foot(maps: LocalMaps, query: FootQuery, weights: ScoringWeights | None = None,
                 budget: SearchBudget = DEFAULT_BUDGET, config: PlannerConfig | None = None) -> FootHarvest:
    """Every (candidate, slice) couple of one foot, scored in 3D (the budget gives only the slice size).

    The candidates are the search's (:func:`plan_foot`), in its order, and the couples are
    scored as the search scores them, with no pruning: the best valid couple is the exhaustive
    search's pick.

    Parameters
    ----------
    maps : LocalMaps
        The character's local maps (cell size ``config.cell_size``, containing the source).
    query : FootQuery
        The foot.
    weights : ScoringWeights, optional
        The criteria's weights; default ``ScoringWeights()``.
    budget : SearchBudget, optional
        Only its ``slice_size_m`` is used; default :data:`DEFAULT_BUDGET`.
    config : PlannerConfig, optional
        Static planner parameters; default ``PlannerConfig()``.

    Returns
    -------
    FootHarvest
        Every candidate and (candidate, slice) couple with its features, metrics and scores.

    Raises
    ------
    ValueError
        For maps whose cell size differs from ``config.cell_size`` or a source outside them.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import EXHAUSTIVE, FootQuery, GridFrame, LocalMaps, harvest_foot, plan_foot
    >>> flat = np.zeros((35, 35))                   # 35 x 35 cells of 7 cm, flat ground at y = 0
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> harvest = harvest_foot(maps, query)
    >>> best = plan_foot(maps, query, budget=EXHAUSTIVE)
    >>> bool(np.array_equal(harvest.cand_cells, best.candidate_cells))   # the search's candidates, in order
    True
    >>> float(harvest.couple_scores[..., 0].max()) == best.couple_score   # its best couple is the search's
    True
    """
    weights = weights or ScoringWeights()
    config = config or PlannerConfig()
    foot_shape = checked_foot_shape(maps, query, config)
    _, slice_size, _ = budget.kernel_args()
    return _harvest_kernel_call(maps.elevation, maps.ground, maps.forbidden, maps.frame.origin_x, maps.frame.origin_z,
                                foot_shape, query.source, query.preferred, query.hip, float(query.reach_xz),
                                float(query.step_height), query.kernel_legs, query.feet_block_radius,
                                weights.to_array(), config.to_array(), slice_size)


@dataclass(frozen=True)
class Harvest:
    """Planning situations (F) of seeded crowd runs, padded to K candidates and S slices.

    Per situation: where it came from, the kinematics the timing model needs
    (tuning/_proxies.py moves the preferred footprint with the timing parameters),
    the candidate set, and the exhaustive search's pick (``chosen``: (k, s) or
    (-1, -1) when no couple exists) with its scores, goodnesses and raw metrics.
    ``crowd_choice`` is the couple the crowd's own (budgeted) search took. A boxed-in
    foot's way out (``planner.layout.CNT_BOXED``) is no harvested couple: it counts
    as no pick in both.

    Made by :func:`pack_harvest`; the per-candidate and per-couple arrays are those of each
    situation's :class:`FootHarvest`, padded (``cand_mask`` and ``couple_mask`` say which
    entries are real).

    Attributes
    ----------
    creatures, scenarios : tuple of str
        The names the ``creature`` and ``scenario`` indices refer to.
    creature, scenario, seed, frame, character, leg, kind : ndarray of int, shape (F,)
        Where each situation came from; ``kind`` is a request kind, ``planner.layout.KIND_*``.
    leg_height, speed, relative_swing, cell_size : ndarray, shape (F,)
        h of the Froude number (m), the character's speed when it planned (m/s), the leg's
        authored swing duration over the mean of its legs', the maps' cell size (m).
    forward, preferred : ndarray, shape (F, 2)
        Unit heading and preferred footprint, (x, z).
    source : ndarray, shape (F, 3)
        Where the foot was, (x, y, z).
    d_ref, cand_mask, cand_xyz, cand_centre_xz, cand_features, cand_terms, cand_scores : ndarray
        Per candidate, shape (F, K, ...): as in :class:`FootHarvest`, plus the centres of the
        candidate cells (``cand_centre_xz``; a footprint is its cell's point nearest the
        preferred one); ``d_ref`` pads with 1.
    couple_mask, couple_raw, couple_terms, couple_scores : ndarray
        Per couple, shape (F, K, S, ...): as in :class:`FootHarvest`.
    chosen, crowd_choice : ndarray of int, shape (F, 2)
        (candidate, slice) of the exhaustive search's pick and of the crowd's; (-1, -1): none.
    chosen_scores, chosen_terms, chosen_raw : ndarray
        The exhaustive pick's scores (F, 3), goodnesses (F, 10) and raw metrics (F, 5).
    weights, timing : ndarray
        ``ScoringWeights.to_array()`` and ``GaitTiming.to_array()`` of the runs.

    Examples
    --------
    >>> from footfall.planner import GaitTiming, ScoringWeights, harvest_run, pack_harvest
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> spider = load_creature("spider")
    >>> run = harvest_run(load_scenario("flat"), spider, default_gait(spider), weights=ScoringWeights(),
    ...                   timing=GaitTiming(), n_characters=1, seed=0, frames=5,
    ...                   meta={"creature": 0, "scenario": 0, "seed": 0})
    >>> harvest = pack_harvest(run["rows"], ["spider"], ["flat"], ScoringWeights().to_array(),
    ...                        GaitTiming().to_array())
    >>> harvest.n_situations == len(run["rows"]), harvest.cand_mask.shape[0] == harvest.n_situations
    (True, True)
    >>> bool(harvest.has_couple.all()), harvest.creatures, harvest.scenarios
    (True, ('spider',), ('flat',))
    """

    creatures: tuple[str, ...]
    scenarios: tuple[str, ...]
    creature: np.ndarray  # (F,) index into creatures
    scenario: np.ndarray  # (F,) index into scenarios
    seed: np.ndarray  # (F,)
    frame: np.ndarray  # (F,)
    character: np.ndarray  # (F,)
    leg: np.ndarray  # (F,)
    kind: np.ndarray  # (F,) planner.layout.KIND_*
    leg_height: np.ndarray  # (F,) m, h of the Froude number (planner._timing.hip_height)
    speed: np.ndarray  # (F,) m/s, the character's speed when it planned
    forward: np.ndarray  # (F, 2) unit heading (x, z)
    relative_swing: np.ndarray  # (F,) the leg's authored swing duration / mean over the legs
    source: np.ndarray  # (F, 3)
    preferred: np.ndarray  # (F, 2)
    cell_size: np.ndarray  # (F,) m
    d_ref: np.ndarray  # (F, K) m, each candidate's reference of the length goodness (padding: 1)
    cand_mask: np.ndarray  # (F, K) bool
    cand_xyz: np.ndarray  # (F, K, 3)
    cand_centre_xz: np.ndarray  # (F, K, 2) centres of the candidate cells (a footprint is its cell's point nearest P)
    cand_features: np.ndarray  # (F, K, 5) FEATURES
    cand_terms: np.ndarray  # (F, K, 5)
    cand_scores: np.ndarray  # (F, K)
    couple_mask: np.ndarray  # (F, K, S) bool
    couple_raw: np.ndarray  # (F, K, S, 5) RAW_METRICS
    couple_terms: np.ndarray  # (F, K, S, 10)
    couple_scores: np.ndarray  # (F, K, S, 3)
    chosen: np.ndarray  # (F, 2) int
    chosen_scores: np.ndarray  # (F, 3)
    chosen_terms: np.ndarray  # (F, 10)
    chosen_raw: np.ndarray  # (F, 5)
    crowd_choice: np.ndarray  # (F, 2) int, (-1, -1) if the crowd's search found none
    weights: np.ndarray  # ScoringWeights.to_array() the situations were scored with
    timing: np.ndarray  # GaitTiming.to_array() of the runs

    @property
    def n_situations(self) -> int:
        return int(self.kind.size)

    @property
    def has_couple(self) -> np.ndarray:
        """(F,) bool: at least one couple exists (the softmax of tuning/ needs one)."""
        return self.couple_mask.any(axis=(1, 2))


def _row_of(cells: np.ndarray, levels_count: int, target_cell, slice_index: int) -> tuple[int, int]:
    hit = np.flatnonzero((cells[:, 0] == target_cell[0]) & (cells[:, 1] == target_cell[1]))
    if hit.size != 1 or not 0 <= slice_index < levels_count:
        raise RuntimeError("harvest: the search's couple is not among the harvested ones")
    return int(hit[0]), int(slice_index)


def _harvest_batch(batch, weights, config, out, cs, ls, kinds, state, model, meta, rows) -> None:
    """One plan_batch call of the crowd: harvest every foot, and run the exhaustive search on it."""
    w = weights.to_array()
    cfg = config.to_array()
    lengths = np.asarray(state.gaits.gait_duration)
    for i in range(batch.n_feet):
        ch = int(batch.foot_char[i])
        legs = np.ascontiguousarray(batch.legs[batch.legs_start[i]:batch.legs_start[i + 1]])
        args = (batch.elevation[ch], batch.ground[ch], batch.forbidden[ch], batch.origins[ch, 0], batch.origins[ch, 1],
                batch.foot_shape[i], batch.sources[i], batch.preferred[i], batch.hips[i], float(batch.reach_xz[i]),
                float(batch.step_height[i]), legs, float(batch.block_radius[i]), w, cfg)
        slice_size = float(batch.slice_size[i])
        foot = _harvest_kernel_call(*args, slice_size)
        # The exhaustive search (no couple limit, no early stop) on the same foot and slices.
        best = plan_foot_kernel(*args, -1, slice_size, False, MODE_SEARCH)
        chosen = (-1, -1)
        if best.valid and not best.counters[CNT_BOXED]:
            chosen = _row_of(foot.cand_cells, foot.levels.size, best.target_rc, int(best.slice_index))
        crowd = (-1, -1)
        if out.valid[i] and not out.counters[i, CNT_BOXED]:
            # The target is a candidate's continuous footprint, computed by the same kernel: equal bit for bit.
            hit = np.flatnonzero((foot.cand_xyz[:, 0] == out.target[i, 0]) & (foot.cand_xyz[:, 2] == out.target[i, 2]))
            if hit.size != 1:
                raise RuntimeError("harvest: the search's couple is not among the harvested ones")
            crowd = _row_of(foot.cand_cells, foot.levels.size, foot.cand_cells[hit[0]], int(out.slice_index[i]))
        c, leg = int(cs[i]), int(ls[i])
        rows.append(dict(
            meta, frame=state.frame, character=c, leg=leg, kind=int(kinds[i]), leg_height=model.leg_height,
            speed=float(state.speed[c]), forward=(math.cos(state.heading[c]), math.sin(state.heading[c])),
            relative_swing=float(lengths[c, leg] / np.mean(lengths[c])), source=batch.sources[i].copy(),
            preferred=batch.preferred[i].copy(), cell_size=config.cell_size, origin=batch.origins[ch].copy(), foot=foot,
            chosen=chosen,
            chosen_scores=best.scores.copy(), chosen_terms=best.terms.copy(), chosen_raw=best.raw.copy(),
            crowd_choice=crowd))


def pack_harvest(rows: list[dict], creatures, scenarios, weights: np.ndarray, timing: np.ndarray) -> Harvest:
    """The rows of :func:`harvest_run` (merged by :func:`merge_harvest_chunks`) as one :class:`Harvest`:
    ``creatures`` and ``scenarios`` name the rows' indices; ``weights`` and ``timing`` are the packed
    parameters the runs used.

    Parameters
    ----------
    rows : list of dict
        Situations from :func:`harvest_run`; each must carry ``creature``, ``scenario`` and
        ``seed`` (indices and seed, from the run's ``meta``).
    creatures, scenarios : sequence of str
        The names of the rows' ``creature`` and ``scenario`` indices.
    weights : ndarray
        ``ScoringWeights.to_array()`` the runs used.
    timing : ndarray
        ``GaitTiming.to_array()`` the runs used.

    Returns
    -------
    Harvest
        F = ``len(rows)`` situations, padded to the most candidates (K) and slices (S) of any.

    Examples
    --------
    >>> from footfall.planner import GaitTiming, ScoringWeights, harvest_run, pack_harvest
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> spider = load_creature("spider")
    >>> run = harvest_run(load_scenario("flat"), spider, default_gait(spider), weights=ScoringWeights(),
    ...                   timing=GaitTiming(), n_characters=1, seed=0, frames=5,
    ...                   meta={"creature": 0, "scenario": 0, "seed": 0})
    >>> harvest = pack_harvest(run["rows"], ["spider"], ["flat"], ScoringWeights().to_array(),
    ...                        GaitTiming().to_array())
    >>> f, k = harvest.cand_mask.shape
    >>> f == len(run["rows"]), k == max(row["foot"].cand_scores.size for row in run["rows"])
    (True, True)
    >>> harvest.chosen.shape == (f, 2), harvest.couple_scores.shape[-1]   # (candidate, slice); 3 scores
    (True, 3)
    """
    f = len(rows)
    k = max([r["foot"].cand_scores.size for r in rows] + [1])
    s = max([r["foot"].levels.size for r in rows] + [1])
    cand_mask = np.zeros((f, k), np.bool_)
    cand_xyz = np.zeros((f, k, 3))
    cand_centre_xz = np.zeros((f, k, 2))
    cand_features = np.zeros((f, k, N_FEATURES))
    cand_terms = np.zeros((f, k, N_FOOTPRINT_TERMS))
    cand_scores = np.zeros((f, k))
    d_ref = np.ones((f, k))
    couple_mask = np.zeros((f, k, s), np.bool_)
    couple_raw = np.zeros((f, k, s, N_RAW))
    couple_terms = np.zeros((f, k, s, N_TERMS))
    couple_scores = np.zeros((f, k, s, 3))
    for i, r in enumerate(rows):
        h = r["foot"]
        n, m = h.cand_scores.size, h.levels.size
        cand_mask[i, :n] = True
        cand_xyz[i, :n] = h.cand_xyz
        cand_centre_xz[i, :n] = r["origin"] + (h.cand_cells[:, ::-1] + 0.5) * r["cell_size"]
        cand_features[i, :n] = h.cand_features
        cand_terms[i, :n] = h.cand_terms
        cand_scores[i, :n] = h.cand_scores
        d_ref[i, :n] = h.d_ref
        couple_mask[i, :n, :m] = h.couple_valid
        couple_raw[i, :n, :m] = h.couple_raw
        couple_terms[i, :n, :m] = h.couple_terms
        couple_scores[i, :n, :m] = h.couple_scores

    def col(name, dtype=np.float64):
        return np.array([r[name] for r in rows], dtype=dtype)

    return Harvest(
        creatures=tuple(creatures), scenarios=tuple(scenarios), creature=col("creature", np.int64),
        scenario=col("scenario", np.int64), seed=col("seed", np.int64), frame=col("frame", np.int64),
        character=col("character", np.int64), leg=col("leg", np.int64), kind=col("kind", np.int64),
        leg_height=col("leg_height"), speed=col("speed"), forward=col("forward").reshape(f, 2),
        relative_swing=col("relative_swing"), source=col("source").reshape(f, 3),
        preferred=col("preferred").reshape(f, 2), cell_size=col("cell_size"),
        d_ref=d_ref, cand_mask=cand_mask, cand_xyz=cand_xyz,
        cand_centre_xz=cand_centre_xz,
        cand_features=cand_features, cand_terms=cand_terms, cand_scores=cand_scores, couple_mask=couple_mask,
        couple_raw=couple_raw, couple_terms=couple_terms, couple_scores=couple_scores,
        chosen=col("chosen", np.int64).reshape(f, 2), chosen_scores=col("chosen_scores").reshape(f, 3),
        chosen_terms=col("chosen_terms").reshape(f, N_TERMS), chosen_raw=col("chosen_raw").reshape(f, N_RAW),
        crowd_choice=col("crowd_choice", np.int64).reshape(f, 2), weights=weights, timing=timing)


def task_mapper(map_tasks=None):
    """``map_tasks`` checked, or (``None``) a lazy in-process map: ``run(function, tasks)`` gives the
    results in task order. One check for every caller that takes a ``map_tasks`` (the tuning's
    harvests and exact runs).

    Parameters
    ----------
    map_tasks : callable or None, optional
        ``map_tasks(function, tasks)``, results in task order (for instance one that runs the
        tasks on workers); ``None``: the built-in :func:`map`, lazy, in this process.

    Returns
    -------
    callable
        ``map_tasks`` itself, or :func:`map`.

    Raises
    ------
    ValueError
        When ``map_tasks`` is neither ``None`` nor callable.

    Examples
    --------
    >>> from footfall.planner import task_mapper
    >>> run = task_mapper()
    >>> list(run(abs, [-1, 2, -3]))
    [1, 2, 3]
    >>> task_mapper(42)
    Traceback (most recent call last):
    ...
    ValueError: map_tasks: expected None or a callable, got int
    """
    if map_tasks is None:
        return map
    if not callable(map_tasks):
        raise ValueError(f"map_tasks: expected None or a callable, got {type(map_tasks).__name__}")
    return map_tasks


def harvest_run(scenario, creature, gait, *, weights: ScoringWeights, timing, n_characters: int, seed: int,
                frames: int, max_situations: int | None = None, meta: dict | None = None) -> dict:
    """Run ``frames`` frames of a seeded crowd (LOD off: the paper's full search) and harvest every
    planning request: ``{"rows": [...], "frame_ends": [...]}``, the situations in order and the row
    count after each harvested frame (where a global cap may cut; the run stops at the end of the
    frame that reaches ``max_situations``). ``meta`` (a dict) is copied into every row.

    Rows hold numpy arrays and :class:`FootHarvest` records: picklable, for a worker to send back.

    Parameters
    ----------
    scenario : scenarios.Scenario
        The world and the crowd's spawn.
    creature : scenarios.Creature
        The characters' creature.
    gait : scenarios.Gait or GaitSchedule
        Its gait, as for :func:`init_crowd`.
    weights : ScoringWeights
        The weights the crowd plans with and the situations are scored with.
    timing : GaitTiming or None
        The gait timing of the run (``None``: the default).
    n_characters : int
        Characters in the crowd.
    seed : int
        The crowd's seed (:func:`init_crowd`).
    frames : int
        Frames to run at most.
    max_situations : int, optional
        Stop at the end of the frame whose rows reach this many.
    meta : dict, optional
        Copied into every row (:func:`pack_harvest` reads ``creature``, ``scenario`` and ``seed``).

    Returns
    -------
    dict
        ``rows``: one dict per planning request, in order (its situation: frame, character,
        leg, kind, kinematics, the :class:`FootHarvest` ``foot``, the exhaustive search's pick
        ``chosen`` and the crowd's ``crowd_choice``...); ``frame_ends``: the row count after each
        frame that planned.

    Examples
    --------
    >>> from footfall.planner import GaitTiming, ScoringWeights, harvest_run
    >>> from footfall.scenarios import default_gait, load_creature, load_scenario
    >>> spider = load_creature("spider")
    >>> run = harvest_run(load_scenario("flat"), spider, default_gait(spider), weights=ScoringWeights(),
    ...                   timing=GaitTiming(), n_characters=1, seed=0, frames=5, meta={"seed": 0})
    >>> run["frame_ends"][-1] == len(run["rows"])
    True
    >>> row = run["rows"][0]
    >>> row["frame"], row["character"], row["seed"]     # planned in frame 1, by character 0
    (1, 0, 0)
    >>> row["chosen"]                                   # flat ground: the best footprint, the first slice
    (0, 0)
    """
    from footfall.planner._crowd import init_crowd, planner_config_for, step
    from footfall.planner._maps import WorldRaster

    meta = dict(meta or {})
    # A few characters plan a few feet per frame: fanning each small kernel call out over
    # the cores costs more than it saves (x20 on a busy 2-core machine), and the parallel
    # and serial kernels give identical results (tests/test_planner_properties.py). Set here,
    # not by the caller, so a run on any worker gets it.
    with single_threaded():
        cell = planner_config_for(creature).cell_size
        # Built per run (deterministic), not shared between the seeds of a scenario: a run
        # depends on nothing but its arguments.
        raster = WorldRaster.build(scenario.terrain, scenario.obstacles, cell)
        model, state = init_crowd(scenario, creature, gait, n_characters=n_characters, seed=seed,
                                  weights=weights, timing=timing, lod_mode="off", raster=raster)
        rows: list[dict] = []
        frame_ends: list[int] = []
        for _ in range(frames):
            plans = step(model, state).plans
            if plans is None:
                continue
            _harvest_batch(plans.batch, model.weights, model.config, plans.result, plans.chars, plans.legs, plans.kinds,
                           state, model, meta, rows)
            frame_ends.append(len(rows))
            # The global count is at least this run's, so the global cap never cuts later than here.
            if max_situations is not None and len(rows) >= max_situations:
                break
    return {"rows": rows, "frame_ends": frame_ends}


def merge_harvest_chunks(chunks, max_situations: int | None) -> list[dict]:
    """Concatenate the chunks' rows in task order, cut as the sequential loop cut: at the end of the
    first frame at which the running total reaches ``max_situations`` (whole frames; later chunks
    add nothing, and are not even pulled from a lazy ``chunks``).

    Parameters
    ----------
    chunks : iterable of dict
        :func:`harvest_run` results (``rows`` and ``frame_ends``), in task order; may be lazy.
    max_situations : int or None
        The cap; ``None``: every row.

    Returns
    -------
    list
        The rows, in order.

    Examples
    --------
    Rows are letters here (any objects are merged the same way); the first chunk planned two
    frames, of two rows and one row:

    >>> from footfall.planner import merge_harvest_chunks
    >>> chunks = [{"rows": ["a", "b", "c"], "frame_ends": [2, 3]}, {"rows": ["d", "e"], "frame_ends": [1, 2]}]
    >>> merge_harvest_chunks(chunks, None)
    ['a', 'b', 'c', 'd', 'e']
    >>> merge_harvest_chunks(chunks, 4)   # the total reaches 4 at the end of the second chunk's first frame
    ['a', 'b', 'c', 'd']
    >>> merge_harvest_chunks(chunks, 1)                 # whole frames: the first frame's two rows
    ['a', 'b']
    """
    rows: list[dict] = []
    for chunk in chunks:
        if max_situations is not None:
            for end in chunk["frame_ends"]:
                if len(rows) + end >= max_situations:
                    rows.extend(chunk["rows"][:end])
                    return rows
        rows.extend(chunk["rows"])
    return rows
