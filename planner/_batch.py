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


@dataclass(frozen=True)
class FootBatch:
    """Struct-of-arrays planning requests (see :func:`make_batch`)."""

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
    legs: np.ndarray  # (sum M, 4)
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
    """Pack ``(map index, query)`` pairs into arrays (once, outside the hot path)."""
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
    legs = [q.other_legs for _, q in requests]
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
        legs=np.ascontiguousarray(np.concatenate(legs) if n else np.zeros((0, 4))).reshape(-1, 4),
        legs_start=starts,
        block_radius=np.array([q.feet_block_radius for _, q in requests], dtype=np.float64),
        couples_after_first=np.array([a[0] for a in args], dtype=np.int64),
        slice_size=np.array([a[1] for a in args], dtype=np.float64),
        early=np.array([a[2] for a in args], dtype=np.bool_),
    )


def plan_batch(batch: FootBatch, weights: ScoringWeights | None = None, config: PlannerConfig | None = None,
               mode: str = "search", parallel: bool = False) -> BatchResult:
    """Plan every foot of ``batch`` in one kernel call (``parallel``: over the cores; same results)."""
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
