"""Planner parameters (static model) and the search budget (the LOD lever).

Tuning guide
------------
* ``map_cells`` x ``cell_size`` is the local map (paper §7: 70 x 70 cells of 7 cm).
  Smaller cells find footholds between close obstacles but cost quadratically.
* ``search_radius_m`` is the disc of candidate footprints around the preferred one
  (paper Fig. 13); its area times the number of slices bounds the work per foot.
* ``roi_margin_cells`` bounds detours: the wavefront runs in the bounding box of the
  source and the candidate disc grown by this many cells, so a foot never plans a
  path that wanders across the whole map.
* ``potential_gain`` / ``potential_range_m`` shape the potential field (paper §4,
  Khatib): near blocked cells a move costs up to (1 + gain) times its length, so paths
  keep away from obstacles when there is room.
* ``obstacle_margin_m`` is the least height of a swing over the (foot-dilated)
  elevation under it; ``trajectory_samples`` is how many constant-arc-length samples
  the chosen trajectory is returned with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PlannerConfig:
    """Static planner parameters. Units: metres, cells, counts.

    The module docstring is the tuning guide. An integer field that is not an integer or
    below its least value, or a length that is not a finite positive number, raises
    ValueError naming the field.

    Attributes
    ----------
    map_cells : int
        Cells per side of the local obstacles' and elevations' maps, >= 3 (default 70).
    cell_size : float
        Side of a map cell (m), > 0 (default 0.07).
    search_radius_m : float
        Radius of the candidate-footprint disc (m), > 0 (default 0.25).
    roi_margin_cells : int
        Cells added around the source and the candidates for the wavefront, >= 0 (default 6).
    potential_range_m : float
        Distance to a blocked cell where the potential vanishes (m), > 0 (default 0.14).
    potential_gain : float
        Extra cost factor of a move right next to a blocked cell, >= 0 (default 2).
    obstacle_margin_m : float
        Least clearance of a swing above the dilated elevation (m), >= 0 (default 0.01).
    trajectory_samples : int
        Samples of the chosen trajectory at constant arc-length spacing, >= 2 (default 32).
    slice_epsilon_m : float
        Heights above the terrain below this are terrain, not obstacles (m), > 0
        (default 0.001).

    Examples
    --------
    >>> from footfall.planner import PlannerConfig
    >>> config = PlannerConfig()
    >>> round(config.map_cells * config.cell_size, 2)   # side of the local map (m), paper §7
    4.9
    >>> config.to_array().shape                        # the floats the kernels read
    (8,)
    >>> PlannerConfig(map_cells=2)
    Traceback (most recent call last):
        ...
    ValueError: PlannerConfig.map_cells: expected an integer >= 3, got 2
    """

    map_cells: int = 70  # cells per side of the local obstacles' and elevations' maps
    cell_size: float = 0.07  # m, side of a map cell
    search_radius_m: float = 0.25  # m, radius of the candidate-footprint disc
    roi_margin_cells: int = 6  # cells added around source + candidates for the wavefront
    potential_range_m: float = 0.14  # m, distance to a blocked cell where the potential vanishes
    potential_gain: float = 2.0  # -, extra cost factor of a move right next to a blocked cell
    obstacle_margin_m: float = 0.01  # m, least clearance of a swing above the dilated elevation
    trajectory_samples: int = 32  # samples of the chosen trajectory, constant arc-length spacing
    slice_epsilon_m: float = 1e-3  # m, heights above terrain below this are terrain, not obstacles

    def __post_init__(self) -> None:
        ints = {"map_cells": 3, "roi_margin_cells": 0, "trajectory_samples": 2}
        for name, least in ints.items():
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ValueError(f"PlannerConfig.{name}: expected an integer >= {least}, got {v!r}")
        positive = ("cell_size", "search_radius_m", "potential_range_m", "slice_epsilon_m")
        for name in positive + ("potential_gain", "obstacle_margin_m"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0 or (name in positive and v == 0):
                raise ValueError(f"PlannerConfig.{name}: expected a finite number {'> 0' if name in positive else '>= 0'}, got {v!r}")

    def to_array(self) -> np.ndarray:
        """Floats the kernels read, in :data:`CONFIG_FIELDS` order."""
        return np.array([float(getattr(self, n)) for n in CONFIG_FIELDS], dtype=np.float64)


CONFIG_FIELDS = (
    "cell_size",
    "search_radius_m",
    "roi_margin_cells",
    "potential_range_m",
    "potential_gain",
    "obstacle_margin_m",
    "trajectory_samples",
    "slice_epsilon_m",
)
C_CELL, C_RADIUS, C_MARGIN, C_POT_RANGE, C_POT_GAIN, C_OBST_MARGIN, C_SAMPLES, C_SLICE_EPS = range(len(CONFIG_FIELDS))


@dataclass(frozen=True)
class SearchBudget:
    """How much of the couple search to do (paper §6, LOD).

    ``FIRST_VALID``, ``DEFAULT_BUDGET`` and ``EXHAUSTIVE`` are the three usual budgets. A
    negative or non-integer ``couples_after_first`` or a ``slice_size_m`` that is not a
    positive number raises ValueError.

    Attributes
    ----------
    couples_after_first : int or None
        3D couples evaluated after the first valid one; ``None`` = no limit.
        ``0`` is the off-screen mode: the first valid couple wins (default 6).
    slice_size_m : float or None
        Height of the elevation slices (m) used to decide between going over and
        around obstacles; ``None`` = no slices (go over everything not forbidden)
        (default 0.10).
    paper_early_stop : bool
        Stop as soon as a target's best couple does not beat the best so far
        (paper §5.2). Off for the exhaustive search, which only stops when no
        remaining couple can win (an exact bound) (default True).

    Examples
    --------
    >>> from footfall.planner import EXHAUSTIVE, FIRST_VALID, SearchBudget
    >>> SearchBudget().kernel_args()      # (couples after the first, slice size m, early stop)
    (6, 0.1, True)
    >>> FIRST_VALID.kernel_args()         # None is passed to the kernels as -1
    (0, -1.0, True)
    >>> EXHAUSTIVE.kernel_args()
    (-1, 0.05, False)
    """

    couples_after_first: int | None = 6
    slice_size_m: float | None = 0.10
    paper_early_stop: bool = True

    def __post_init__(self) -> None:
        c = self.couples_after_first
        if c is not None and (isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < 0):
            raise ValueError(f"SearchBudget.couples_after_first: expected None or an integer >= 0, got {c!r}")
        s = self.slice_size_m
        if s is not None and (not isinstance(s, (int, float)) or not math.isfinite(s) or s <= 0):
            raise ValueError(f"SearchBudget.slice_size_m: expected None or a positive number of metres, got {s!r}")

    def kernel_args(self) -> tuple[int, float, bool]:
        """(couples_after_first or -1, slice size or -1.0, paper_early_stop)."""
        c = -1 if self.couples_after_first is None else int(self.couples_after_first)
        s = -1.0 if self.slice_size_m is None else float(self.slice_size_m)
        return c, s, bool(self.paper_early_stop)


FIRST_VALID = SearchBudget(couples_after_first=0, slice_size_m=None, paper_early_stop=True)
DEFAULT_BUDGET = SearchBudget()
EXHAUSTIVE = SearchBudget(couples_after_first=None, slice_size_m=0.05, paper_early_stop=False)
