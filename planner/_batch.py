"""Batched planning: many feet of many characters in one kernel call."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from footfall.planner._kernels_batch import FootRequests, FootResults, plan_feet_parallel, plan_feet_serial
from footfall.planner._kernels_foot import N_COUNTERS, N_RAW
from footfall.planner._maps import LocalMaps
from footfall.planner._params import DEFAULT_BUDGET, PlannerConfig, SearchBudget
from footfall.planner._search import MODES, FootQuery
from footfall.planner._weights import N_TERMS, ScoringWeights
from footfall.planner.layout import N_LEG_COLUMNS


@dataclass(frozen=True)
class FootBatch:
    """Struct-of-arrays planning requests (see :func:`make_batch`).

    F feet of C characters, whose local maps (N x N cells each) are stacked; foot i plans on
    the maps of character ``foot_char[i]``. Every array is read-only in spirit: the planning
    kernel reads them as they are.

    Attributes
    ----------
    elevation, ground, forbidden : ndarray, shape (C, N, N)
        The characters' stacked local maps (:class:`LocalMaps`).
    origins : ndarray, shape (C, 2)
        World (x, z) of each local map's origin corner.
    foot_char : ndarray of int, shape (F,)
        Index of each foot's maps.
    foot_shape : ndarray, shape (F, 3)
        Each foot's length, width (m) and yaw (rad).
    sources : ndarray, shape (F, 3)
        Where each foot is now, world (x, y, z).
    preferred, hips : ndarray, shape (F, 2)
        Each foot's preferred footprint and its leg's hip, world (x, z).
    reach_xz, step_height, block_radius : ndarray, shape (F,)
        Each leg's horizontal reach, its preferred step height and the room other feet leave
        the foot (:attr:`FootQuery.feet_block_radius`), m.
    legs, legs_start : ndarray
        The legs every foot keeps clear of, rows ``planner.layout.LEG_ROW`` (x, z to x, z, and 1.0
        when a foot ends the row: :attr:`FootQuery.kernel_legs`), shape (sum M, 5); foot i's are rows
        ``legs_start[i]:legs_start[i + 1]`` (shape (F + 1,)).
    couples_after_first, slice_size, early : ndarray, shape (F,)
        Each foot's search budget (:meth:`SearchBudget.kernel_args`): couples after the first
        valid one (-1 = unlimited), slice size in m (-1 = no slices), the paper's early stop.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import FootQuery, GridFrame, LocalMaps, make_batch
    >>> flat = np.zeros((35, 35))
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> batch = make_batch([maps], [(0, query)])
    >>> batch.n_feet, batch.elevation.shape, batch.sources
    (1, (1, 35, 35), array([[1.2, 0. , 1.2]]))
    """

    elevation: np.ndarray  # (C, N, N)
    ground: np.ndarray
    forbidden: np.ndarray
    origins: np.ndarray  # (C, 2) local-map origin (x, z)
    foot_char: np.ndarray  # (F,) index into the maps
    foot_shape: np.ndarray  # (F, 3) length, width, yaw
    sources: np.ndarray  # (F, 3)
    preferred: np.ndarray  # (F, 2)
    hips: np.ndarray  # (F, 2)
    reach_xz: np.ndarray  # (F,)
    step_height: np.ndarray  # (F,)
    legs: np.ndarray  # (sum M, 5) planner.layout.LEG_ROW
    legs_start: np.ndarray  # (F + 1,)
    block_radius: np.ndarray  # (F,)
    couples_after_first: np.ndarray  # (F,) int, -1 = unlimited
    slice_size: np.ndarray  # (F,) m, -1 = no slices
    early: np.ndarray  # (F,) bool

    @property
    def n_feet(self) -> int:
        return int(self.foot_char.size)


@dataclass(frozen=True)
class BatchResult:
    """What :func:`plan_batch` found for each foot of a :class:`FootBatch` (row i: foot i).

    The same numbers as :class:`CoupleResult` gives for one foot, as arrays. A foot with no
    valid couple holds: its ``target`` is its source and its ``trajectory`` repeats it.

    Attributes
    ----------
    valid : ndarray of bool, shape (F,)
        A couple was found.
    target : ndarray, shape (F, 3)
        The footprints, world (x, y, z).
    slice_index : ndarray of int, shape (F,)
        The elevation slice of each trajectory (0: no slices, as in :class:`CoupleResult`).
    slice_level : ndarray, shape (F,)
        Height above the terrain of that slice, m (``inf``: no slices).
    scores : ndarray, shape (F, 3)
        Couple, footprint and trajectory scores.
    terms : ndarray, shape (F, 10)
        Goodness per criterion, in :data:`SCORE_TERMS` order.
    raw : ndarray, shape (F, 5)
        Raw trajectory metrics, in :data:`RAW_METRICS` order.
    counters : ndarray of int, shape (F, 6)
        The search's work, in :data:`COUNTERS` order.
    trajectory : ndarray, shape (F, K, 3)
        Each swing's samples, source to target (K = ``PlannerConfig.trajectory_samples``).

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import FootQuery, GridFrame, LocalMaps, make_batch, plan_batch
    >>> flat = np.zeros((35, 35))
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> result = plan_batch(make_batch([maps], [(0, query)]))
    >>> result.valid, result.scores.shape, result.terms.shape, result.trajectory.shape
    (array([ True]), (1, 3), (1, 10), (1, 32, 3))
    """

    valid: np.ndarray  # (F,) bool
    target: np.ndarray  # (F, 3)
    slice_index: np.ndarray
    slice_level: np.ndarray
    scores: np.ndarray  # (F, 3) couple, footprint, trajectory
    terms: np.ndarray  # (F, 10)
    raw: np.ndarray  # (F, 5)
    counters: np.ndarray  # (F, 6)
    trajectory: np.ndarray  # (F, K, 3)


def make_batch(maps: list[LocalMaps], requests: list[tuple[int, FootQuery]],
               budgets: SearchBudget | list[SearchBudget] = DEFAULT_BUDGET) -> FootBatch:
    """Pack ``(map index, query)`` pairs into arrays (once, outside the hot path).

    Parameters
    ----------
    maps : list of LocalMaps
        The characters' local maps, at least one, all of the same shape.
    requests : list of (int, FootQuery)
        One pair per foot: the index into ``maps`` of the maps it plans on, and its query.
    budgets : SearchBudget or list of SearchBudget, optional
        One budget for every foot, or one per request; default :data:`DEFAULT_BUDGET`.

    Returns
    -------
    FootBatch
        The requests as arrays, in request order.

    Raises
    ------
    ValueError
        For no maps, maps of different shapes, a map index out of range or a number of budgets
        other than the number of requests.

    Examples
    --------
    Two feet planned on one character's maps, the second with the first valid couple only:

    >>> import numpy as np
    >>> from footfall.planner import DEFAULT_BUDGET, FIRST_VALID, FootQuery, GridFrame, LocalMaps, make_batch
    >>> flat = np.zeros((35, 35))
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> def foot(x):
    ...     return FootQuery(source=(x, 0.0, 1.2), preferred=(x + 0.2, 1.2), hip=(x, 1.1), reach_xz=0.5,
    ...                      step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> batch = make_batch([maps], [(0, foot(1.0)), (0, foot(1.2))], [DEFAULT_BUDGET, FIRST_VALID])
    >>> batch.n_feet, batch.foot_char, batch.couples_after_first
    (2, array([0, 0]), array([6, 0]))
    """
    if not maps:
        raise ValueError("maps: at least one local map is needed")
    shape = maps[0].elevation.shape
    for k, m in enumerate(maps):
        if m.elevation.shape != shape:
            raise ValueError(f"maps[{k}]: every local map must have shape {shape}")
    n = len(requests)
    if isinstance(budgets, SearchBudget):
        budgets = [budgets] * n
    if len(budgets) != n:
        raise ValueError(f"budgets: expected {n} budgets, got {len(budgets)}")
    legs = [q.kernel_legs for _, q in requests]
    starts = np.zeros(n + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(a) for a in legs])
    args = [b.kernel_args() for b in budgets]
    for k, (ch, _) in enumerate(requests):
        if not 0 <= ch < len(maps):
            raise ValueError(f"requests[{k}]: map index {ch} out of range")
    return FootBatch(
        elevation=np.stack([m.elevation for m in maps]), ground=np.stack([m.ground for m in maps]),
        forbidden=np.stack([m.forbidden for m in maps]),
        origins=np.array([[m.frame.origin_x, m.frame.origin_z] for m in maps], dtype=np.float64),
        foot_char=np.array([ch for ch, _ in requests], dtype=np.int64),
        foot_shape=np.array([[q.foot_length, q.foot_width, q.foot_yaw] for _, q in requests], dtype=np.float64).reshape(n, 3),
        sources=np.array([q.source for _, q in requests], dtype=np.float64).reshape(n, 3),
        preferred=np.array([q.preferred for _, q in requests], dtype=np.float64).reshape(n, 2),
        hips=np.array([q.hip for _, q in requests], dtype=np.float64).reshape(n, 2),
        reach_xz=np.array([q.reach_xz for _, q in requests], dtype=np.float64),
        step_height=np.array([q.step_height for _, q in requests], dtype=np.float64),
        legs=np.ascontiguousarray(np.concatenate(legs) if n else np.zeros((0, N_LEG_COLUMNS))).reshape(-1, N_LEG_COLUMNS),
        legs_start=starts,
        block_radius=np.array([q.feet_block_radius for _, q in requests], dtype=np.float64),
        couples_after_first=np.array([a[0] for a in args], dtype=np.int64),
        slice_size=np.array([a[1] for a in args], dtype=np.float64),
        early=np.array([a[2] for a in args], dtype=np.bool_),
    )


def plan_batch(batch: FootBatch, weights: ScoringWeights | None = None, config: PlannerConfig | None = None,
               mode: str = "search", parallel: bool = False) -> BatchResult:
    """Plan every foot of ``batch`` in one kernel call (``parallel``: over the cores; same results).

    Each foot is planned as :func:`plan_foot` plans it, with its own budget from the batch.

    Parameters
    ----------
    batch : FootBatch
        The requests (:func:`make_batch`).
    weights : ScoringWeights, optional
        The criteria's weights; default ``ScoringWeights()``.
    config : PlannerConfig, optional
        Static planner parameters; default ``PlannerConfig()``. Its cell size must be the maps'.
    mode : {"search", "per_target", "brute_force"}, optional
        As for :func:`plan_foot`.
    parallel : bool, optional
        Spread the feet over the cores (numba ``prange``); the results are the same.

    Returns
    -------
    BatchResult
        Row i is foot i's couple.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import FootQuery, GridFrame, LocalMaps, make_batch, plan_batch, plan_foot
    >>> flat = np.zeros((35, 35))
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> def foot(x):
    ...     return FootQuery(source=(x, 0.0, 1.2), preferred=(x + 0.2, 1.2), hip=(x, 1.1), reach_xz=0.5,
    ...                      step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> result = plan_batch(make_batch([maps], [(0, foot(1.0)), (0, foot(1.2))]))
    >>> result.valid, result.target
    (array([ True,  True]), array([[1.2, 0. , 1.2],
           [1.4, 0. , 1.2]]))
    >>> bool(np.array_equal(result.trajectory[1], plan_foot(maps, foot(1.2)).trajectory))  # as plan_foot plans
    True
    """
    weights = weights or ScoringWeights()
    config = config or PlannerConfig()
    n = batch.n_feet
    k = config.trajectory_samples
    out = BatchResult(
        valid=np.zeros(n, dtype=np.bool_), target=np.zeros((n, 3)), slice_index=np.zeros(n, dtype=np.int64),
        slice_level=np.zeros(n), scores=np.zeros((n, 3)), terms=np.zeros((n, N_TERMS)), raw=np.zeros((n, N_RAW)),
        counters=np.zeros((n, N_COUNTERS), dtype=np.int64), trajectory=np.zeros((n, k, 3)))
    kernel = plan_feet_parallel if parallel else plan_feet_serial
    kernel(kernel_requests(batch), weights.to_array(), config.to_array(), MODES[mode], kernel_results(out))
    return out


def kernel_requests(batch: FootBatch) -> FootRequests:
    """The batch's arrays as the planning kernel reads them (the same arrays, by name)."""
    return FootRequests(*(getattr(batch, name) for name in FootRequests._fields))


def kernel_results(result: BatchResult) -> FootResults:
    """The result's arrays as the planning kernel writes them (the same arrays, by name)."""
    return FootResults(*(getattr(result, name) for name in FootResults._fields))
