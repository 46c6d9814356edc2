"""Thin Python API over the planner kernels: validate and cast, call, wrap."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from footfall.planner._kernels_search import MODE_BRUTE_FORCE, MODE_PER_TARGET, MODE_SEARCH, plan_foot_kernel
from footfall.planner._kernels_wavefront import wavefront
from footfall.planner._maps import LocalMaps
from footfall.planner._params import DEFAULT_BUDGET, PlannerConfig, SearchBudget
from footfall.planner._weights import SCORE_TERMS, ScoringWeights
from footfall.planner.layout import (COUNTERS, LEG_FOOT, N_COUNTERS, N_LEG_COLUMNS, N_RAW, RAW_METRICS, SCORE_COUPLE,
                                     SCORE_FOOTPRINT, SCORE_TRAJECTORY)

MODES = {"search": MODE_SEARCH, "per_target": MODE_PER_TARGET, "brute_force": MODE_BRUTE_FORCE}


def _vec(name: str, value, n: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64).reshape(-1)
    if a.shape != (n,) or not np.isfinite(a).all():
        raise ValueError(f"{name}: expected {n} finite numbers, got {value!r}")
    return a


@dataclass(frozen=True)
class FootQuery:
    """What the planner needs to know about one foot (world coordinates, metres).

    The values are checked and cast when the query is made: the points become float64 arrays,
    and a wrong shape, a non-finite number or a length that is not positive raises
    ``ValueError``.

    Attributes
    ----------
    source : ndarray, shape (3,)
        (x, y, z) where the foot is now.
    preferred : ndarray, shape (2,)
        (x, z) preferred footprint from the character controller.
    hip : ndarray, shape (2,)
        (x, z) of this leg's hip (for reach and crossings).
    reach_xz : float
        Horizontal reach of the leg from its hip, m (> 0).
    step_height : float
        Preferred step height of the swing, m.
    foot_length, foot_width, foot_yaw : float
        The foot rectangle: length and width in m (> 0), the length along ``foot_yaw``
        (radians, world yaw convention: direction (cos, sin) in (x, z)).
    other_legs : ndarray, shape (M, 4)
        Rows (hip_x, hip_z, foot_x, foot_z) of the other legs; none by default.
    drawn_segments : ndarray, shape (K, 4)
        Rows (x0, z0, x1, z1): segments of other legs' ground projections as drawn (hip, knees,
        foot), where they leave the straight hip -> foot line; the footprint and its leg keep off
        their lines as off ``other_legs``, but no foot ends them. None by default.

    Examples
    --------
    >>> from footfall.planner import FootQuery
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> query.source, query.other_legs.shape
    (array([1.2, 0. , 1.2]), (0, 4))
    >>> round(query.feet_block_radius, 4)       # hypot(0.03, 0.02): other feet keep this far away
    0.0361
    >>> FootQuery(source=(1.2, 0.0), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5, step_height=0.05,
    ...           foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    Traceback (most recent call last):
    ...
    ValueError: FootQuery.source: expected 3 finite numbers, got (1.2, 0.0)
    """

    source: np.ndarray
    preferred: np.ndarray
    hip: np.ndarray
    reach_xz: float
    step_height: float
    foot_length: float
    foot_width: float
    foot_yaw: float
    other_legs: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    drawn_segments: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))

    def __post_init__(self) -> None:
        object.__setattr__(self, "source", _vec("FootQuery.source", self.source, 3))
        object.__setattr__(self, "preferred", _vec("FootQuery.preferred", self.preferred, 2))
        object.__setattr__(self, "hip", _vec("FootQuery.hip", self.hip, 2))
        legs = np.ascontiguousarray(np.asarray(self.other_legs, dtype=np.float64).reshape(-1, 4))
        if not np.isfinite(legs).all():
            raise ValueError("FootQuery.other_legs: must be finite")
        object.__setattr__(self, "other_legs", legs)
        drawn = np.ascontiguousarray(np.asarray(self.drawn_segments, dtype=np.float64).reshape(-1, 4))
        if not np.isfinite(drawn).all():
            raise ValueError("FootQuery.drawn_segments: must be finite")
        object.__setattr__(self, "drawn_segments", drawn)
        for name in ("reach_xz", "foot_length", "foot_width"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"FootQuery.{name}: expected a positive number of metres, got {v!r}")
        for name in ("step_height", "foot_yaw"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise ValueError(f"FootQuery.{name}: expected a finite number, got {v!r}")

    @property
    def kernel_legs(self) -> np.ndarray:
        """(M + K, 5) the rows the kernels read (``planner.layout.LEG_ROW``): ``other_legs``, each
        ending in a foot, then ``drawn_segments``, none."""
        return leg_rows(self.other_legs, self.drawn_segments)

    @property
    def feet_block_radius(self) -> float:
        """Other feet block cells within two foot half-diagonals (feet never overlap)."""
        return float(math.hypot(self.foot_length, self.foot_width))


def leg_rows(other_legs, drawn_segments=None) -> np.ndarray:
    """(M + K, 5) kernel rows (``planner.layout.LEG_ROW``) of legs ending in feet, (M, 4), and of
    segments of legs as drawn, (K, 4).

    >>> leg_rows(np.array([[0.0, 0.0, 1.0, 0.0]]), np.array([[0.0, 0.0, 0.5, 0.1]]))
    array([[0. , 0. , 1. , 0. , 1. ],
           [0. , 0. , 0.5, 0.1, 0. ]])
    """
    legs = np.asarray(other_legs, dtype=np.float64).reshape(-1, 4)
    drawn = np.zeros((0, 4)) if drawn_segments is None else np.asarray(drawn_segments, dtype=np.float64).reshape(-1, 4)
    out = np.zeros((legs.shape[0] + drawn.shape[0], N_LEG_COLUMNS))
    out[:legs.shape[0], :4] = legs
    out[:legs.shape[0], LEG_FOOT] = 1.0
    out[legs.shape[0]:, :4] = drawn
    return out


def split_leg_rows(rows) -> dict:
    """``{"other_legs": (M, 4), "drawn_segments": (K, 4)}``: the :class:`FootQuery` fields of kernel
    rows (``planner.layout.LEG_ROW``, those that end in a foot first, as a ``FootBatch`` holds them);
    the inverse of :func:`leg_rows`.

    >>> parts = split_leg_rows(leg_rows(np.array([[0.0, 0.0, 1.0, 0.0]]), np.array([[0.0, 0.0, 0.5, 0.1]])))
    >>> parts["other_legs"].tolist(), parts["drawn_segments"].tolist()
    ([[0.0, 0.0, 1.0, 0.0]], [[0.0, 0.0, 0.5, 0.1]])
    """
    rows = np.asarray(rows, dtype=np.float64).reshape(-1, N_LEG_COLUMNS)
    feet = rows[:, LEG_FOOT] != 0.0
    if feet.size and not (feet[:-1] >= feet[1:]).all():
        raise ValueError("rows: the rows that end in a foot must come first")
    return {"other_legs": rows[feet, :4].copy(), "drawn_segments": rows[~feet, :4].copy()}


@dataclass(frozen=True)
class CoupleResult:
    """The chosen footprint-trajectory couple, with its per-criterion breakdown.

    ``valid`` False means no couple exists: the foot holds (``target`` = source and
    ``trajectory`` repeats it).

    Attributes
    ----------
    valid : bool
        A couple was found.
    target_cell : tuple of int
        (row, col) of the footprint's cell in the local maps.
    target : ndarray, shape (3,)
        The footprint, world (x, y, z).
    slice_index : int
        The elevation slice the trajectory was planned in: 0 is no slices (over everything),
        higher indices ever lower levels that go around ever more obstacles.
    slice_level_m : float
        Height above the terrain of that slice, m; ``inf`` = no slices (the swing goes over
        everything).
    couple_score, footprint_score, trajectory_score : float
        The couple's score and its two halves, in [0, 1].
    breakdown : dict of str to float
        Goodness in [0, 1] per criterion, keys :data:`SCORE_TERMS`.
    metrics : dict of str to float
        The trajectory's raw metrics, keys :data:`RAW_METRICS` (``length_m``, ``clearance_m``...).
    counters : dict of str to int
        The search's work, keys :data:`COUNTERS` (couples evaluated, cells expanded...).
    trajectory : ndarray, shape (K, 3)
        Samples at constant arc length from the source to the target
        (K = ``PlannerConfig.trajectory_samples``).
    candidate_cells : ndarray, shape (n, 2)
        The candidate footprints' local (row, col), by descending footprint score.
    candidate_scores : ndarray, shape (n,)
        Their footprint scores.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import COUNTERS, FootQuery, GridFrame, LocalMaps, plan_foot
    >>> flat = np.zeros((35, 35))                   # 35 x 35 cells of 7 cm, flat ground at y = 0
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> result = plan_foot(maps, query)
    >>> result.valid, result.target
    (True, array([1.4, 0. , 1.2]))
    >>> round(result.metrics["length_m"], 3)        # a straight 20 cm step on flat ground
    0.2
    >>> list(result.counters) == list(COUNTERS)
    True
    >>> result.candidate_cells.shape[0] == result.candidate_scores.size
    True
    """

    valid: bool
    target_cell: tuple[int, int]
    target: np.ndarray  # (3,) world
    slice_index: int
    slice_level_m: float  # height above terrain of the slice (inf = no slices: go over)
    couple_score: float
    footprint_score: float
    trajectory_score: float
    breakdown: dict[str, float]  # goodness in [0, 1] per criterion (SCORE_TERMS)
    metrics: dict[str, float]  # raw trajectory metrics (RAW_METRICS)
    counters: dict[str, int]
    trajectory: np.ndarray  # (K, 3) samples at constant arc length, source -> target
    candidate_cells: np.ndarray  # (n, 2) local (row, col), descending footprint score
    candidate_scores: np.ndarray  # (n,)


def checked_foot_shape(maps: LocalMaps, query: FootQuery, config: PlannerConfig) -> np.ndarray:
    """Check that ``maps`` and ``query`` fit ``config``; the foot's (length, width, yaw) as the kernels take it."""
    if abs(maps.frame.cell_size - config.cell_size) > 1e-12:
        raise ValueError(f"maps: cell size {maps.frame.cell_size} differs from config.cell_size {config.cell_size}")
    r, c = maps.frame.world_to_cell(query.source[0], query.source[2])
    if not maps.frame.contains_cell(r, c):
        raise ValueError("query.source: outside the local maps")
    return np.array([query.foot_length, query.foot_width, query.foot_yaw], dtype=np.float64)


def plan_foot(maps: LocalMaps, query: FootQuery, weights: ScoringWeights | None = None,
              budget: SearchBudget = DEFAULT_BUDGET, config: PlannerConfig | None = None,
              mode: str = "search") -> CoupleResult:
    """Best footprint-trajectory couple for one foot (paper §5.2). Never raises for a
    boxed-in foot: the result is then ``valid=False``.

    Parameters
    ----------
    maps : LocalMaps
        The character's local maps; their cell size must be ``config.cell_size`` and they must
        contain ``query.source``.
    query : FootQuery
        The foot: where it is, its preferred footprint, its leg and the other legs.
    weights : ScoringWeights, optional
        The criteria's weights; default ``ScoringWeights()``.
    budget : SearchBudget, optional
        How much of the search to run (couples after the first valid one, slice size, the
        paper's early stop); default :data:`DEFAULT_BUDGET`.
    config : PlannerConfig, optional
        Static planner parameters; default ``PlannerConfig()`` (7 cm cells).
    mode : {"search", "per_target", "brute_force"}, optional
        ``"search"``: the runtime's search (one wavefront per slice); ``"per_target"``: the same
        search with one wavefront per (target, slice), for benchmarks; ``"brute_force"``: every
        (target, slice) couple scored in 3D with no pruning, the reference the tests compare
        the search with.

    Returns
    -------
    CoupleResult
        The chosen couple, its scores, goodnesses, raw metrics and counters.

    Raises
    ------
    ValueError
        For an unknown ``mode``, maps whose cell size differs from ``config.cell_size``, or a
        source outside the maps.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import FootQuery, GridFrame, LocalMaps, plan_foot
    >>> flat = np.zeros((35, 35))                   # 35 x 35 cells of 7 cm, flat ground at y = 0
    >>> maps = LocalMaps(GridFrame(0.0, 0.0, 0.07, 35, 35), flat, flat, np.zeros((35, 35), np.uint8))
    >>> query = FootQuery(source=(1.2, 0.0, 1.2), preferred=(1.4, 1.2), hip=(1.1, 1.1), reach_xz=0.5,
    ...                   step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    >>> result = plan_foot(maps, query)
    >>> result.valid, result.target                 # on open flat ground the preferred footprint wins
    (True, array([1.4, 0. , 1.2]))
    >>> result.trajectory.shape                     # source -> target, PlannerConfig.trajectory_samples
    (32, 3)
    >>> round(result.couple_score, 3), result.breakdown["distance"]
    (0.964, 1.0)

    A foot boxed in by forbidden cells holds:

    >>> walled = np.ones((35, 35), np.uint8)
    >>> walled[17, 17] = 0                          # forbidden everywhere but the foot's own cell
    >>> held = plan_foot(LocalMaps(maps.frame, flat, flat, walled), query)
    >>> held.valid, held.target
    (False, array([1.2, 0. , 1.2]))
    """
    weights = weights or ScoringWeights()
    config = config or PlannerConfig()
    if mode not in MODES:
        raise ValueError(f"mode: expected one of {sorted(MODES)}, got {mode!r}")
    foot_shape = checked_foot_shape(maps, query, config)
    couples_after_first, slice_size, early = budget.kernel_args()
    out = plan_foot_kernel(
        maps.elevation, maps.ground, maps.forbidden, maps.frame.origin_x, maps.frame.origin_z, foot_shape,
        query.source, query.preferred, query.hip, float(query.reach_xz), float(query.step_height),
        query.kernel_legs, query.feet_block_radius, weights.to_array(), config.to_array(),
        couples_after_first, slice_size, early, MODES[mode])
    return CoupleResult(
        valid=bool(out.valid), target_cell=(int(out.target_rc[0]), int(out.target_rc[1])), target=out.target_xyz,
        slice_index=int(out.slice_index), slice_level_m=float(out.slice_level),
        couple_score=float(out.scores[SCORE_COUPLE]), footprint_score=float(out.scores[SCORE_FOOTPRINT]),
        trajectory_score=float(out.scores[SCORE_TRAJECTORY]),
        breakdown=dict(zip(SCORE_TERMS, map(float, out.terms))), metrics=dict(zip(RAW_METRICS, map(float, out.raw))),
        counters=dict(zip(COUNTERS, map(int, out.counters))), trajectory=out.trajectory,
        candidate_cells=out.candidate_rc, candidate_scores=out.candidate_scores)


def wavefront_distances(passable, source: tuple[int, int], cell_size: float = 1.0, cost_factor=None,
                        targets=None) -> np.ndarray:
    """Wavefront (8-connected, no corner cutting) costs from ``source`` over a boolean grid.

    ``cost_factor`` (same shape, >= 1) multiplies the cost of entering a cell (the
    potential field); unreached cells are inf. With ``targets`` ((k, 2) cells) the
    wavefront stops once they are all settled; otherwise it covers the grid.

    Parameters
    ----------
    passable : array_like of bool, shape (H, W)
        Cells a path may enter.
    source : tuple of int
        (row, col) the wavefront starts from (cost 0).
    cell_size : float, optional
        Side of a cell: a straight move costs ``cell_size``, a diagonal one ``sqrt(2) * cell_size``.
    cost_factor : array_like of float, shape (H, W), optional
        Factor on the cost of entering each cell (positive and finite; the planner's are >= 1).
    targets : array_like of int, shape (k, 2), optional
        (row, col) cells after whose settling the wavefront stops; cells not settled by then
        hold provisional costs (or ``inf``). A target that is not passable is reached but never
        passed through.

    Returns
    -------
    ndarray of float, shape (H, W)
        The least cost of a path from ``source`` to each cell, ``inf`` where none exists.

    Raises
    ------
    ValueError
        For a grid that is not 2-D, a source outside it, or a malformed ``cost_factor``.

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.planner import wavefront_distances
    >>> passable = np.ones((3, 4), bool)
    >>> passable[:, 2] = False                      # a wall across column 2
    >>> d = wavefront_distances(passable, (0, 0), cell_size=0.5)
    >>> float(d[2, 0]), round(float(d[1, 1]), 4)    # two straight moves; one diagonal move
    (1.0, 0.7071)
    >>> bool(np.isinf(d[:, 2:]).all())              # the wall and the cells behind it are unreached
    True
    """
    passable = np.asarray(passable, dtype=bool)
    if passable.ndim != 2:
        raise ValueError(f"passable: expected a 2-D grid, got shape {passable.shape}")
    h, w = passable.shape
    sr, sc = source
    if not (0 <= sr < h and 0 <= sc < w):
        raise ValueError(f"source: {source} is outside the {h} x {w} grid")
    wp = w + 2
    flat_pass = np.zeros((h + 2, wp), dtype=np.uint8)
    flat_pass[1:-1, 1:-1] = passable
    factor = np.ones((h + 2, wp), dtype=np.float64)
    if cost_factor is not None:
        cf = np.asarray(cost_factor, dtype=np.float64)
        if cf.shape != passable.shape or not np.isfinite(cf).all() or (cf <= 0).any():
            raise ValueError("cost_factor: expected positive finite numbers with the shape of passable")
        factor[1:-1, 1:-1] = cf
    if targets is None:
        stop = np.array([(r + 1) * wp + c + 1 for r in range(h) for c in range(w) if passable[r, c]], dtype=np.int64)
    else:
        t = np.asarray(targets, dtype=np.int64).reshape(-1, 2)
        stop = (t[:, 0] + 1) * wp + t[:, 1] + 1
    dist = np.empty((h + 2) * wp)
    parent = np.empty((h + 2) * wp, dtype=np.int64)
    wavefront(flat_pass.ravel(), factor.ravel(), wp, (sr + 1) * wp + sc + 1, float(cell_size), stop, dist, parent)
    return dist.reshape(h + 2, wp)[1:-1, 1:-1].copy()
