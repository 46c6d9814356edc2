"""How a far character plans its feet (``planner._lod``: ``LEVEL_FAR`` and ``LEVEL_HIDDEN``).

A far character takes the first valid couple (paper §6), but finding it costs almost as much as
the full search: the foot-shape dilation, the candidates' scores and the wavefront all run over
the whole region of interest (the source and the candidate disc grown by ``roi_margin_cells``,
about 25 x 25 cells for the spider), whatever the budget. Two things remove that work:

* **a first try near the preferred footprint**: the candidate disc shrunk to
  ``LodConfig.far_radius_cells`` cells and the margin to ``LodConfig.far_margin_cells``, so the
  region of interest is little more than the box around the source and the preferred footprint.
  Where the ground near the preferred footprint is free (most steps), the best candidate there is
  the one the full disc would rank first too, and its straight path needs no detour.
* **the full first-valid search** (the planner's own disc, a margin of
  ``LodConfig.far_fallback_margin_cells``, the planner's 6 by default) only for the feet whose
  first try found no valid couple. A foot that finds none there either searched its whole region
  of interest in vain, so that margin bounds the cost of the feet that hold: 3 cells made the
  fallback 3 x cheaper, but a stance foot that a moving crate runs at then found no way out more
  often (100 spiders on ``mixed``, 150 frames: holds 401 with LOD off, 528 with LOD on and 3
  cells, 451 with 6; the far characters' feet in boxes 139 with 3 cells, 62 with 6).

Both run on compact local maps: the smallest window that holds every region of interest of the
creature (:func:`compact_map_cells`), a fraction of the paper's 70 x 70 cells (36 x 36 for the
spider's first tries, 46 x 46 for its fallbacks); the fallback's maps are built only for the
characters that have a foot to retry.

Coarser cells (14 cm, 35 x 35) were tried first and refused: the other legs' projections block
whole 14 cm cells, and around a spider's body those fill the gaps between legs (half the far
requests had no candidate left, holds went from 25 to 490 per frame for 1000 spiders).
"""

from __future__ import annotations

import dataclasses
import math

from footfall.planner._params import PlannerConfig


def map_cells_holding(config: PlannerConfig, span_m: float) -> int:
    """The fewest (even) cells per side of a local map that holds every region of interest of a
    creature whose feet plan up to ``span_m`` (m) from its centre: the check of
    ``planner._crowd.init_crowd`` (the span, the margin and two cells of dilation), exactly met.

    >>> map_cells_holding(PlannerConfig(), 1.0)       # (1.0 + 8 x 0.07) / 0.07 = 22.3 -> 2 x 23
    46
    """
    need = span_m + (config.roi_margin_cells + 2) * config.cell_size
    return 2 * math.ceil(need / config.cell_size)


def compact_map_cells(config: PlannerConfig, span_m: float) -> int:
    """:func:`map_cells_holding`, at most the planner's own maps (and at least 4 cells)."""
    return min(config.map_cells, max(map_cells_holding(config, span_m), 4))


def far_configs(config: PlannerConfig, span_m: float, radius_cells: int, margin_cells: int,
                fallback_margin_cells: int) -> tuple[PlannerConfig, PlannerConfig]:
    """(first try, fallback) planner settings of a far character: the fallback is ``config`` with a
    margin of ``fallback_margin_cells`` (at most the planner's) on its compact maps; the first try
    also shrinks the candidate disc to ``radius_cells`` cells and the margin to ``margin_cells``, on
    maps compact for that margin (smaller still: the fallback's maps are built only for the
    characters with a foot that needs them)."""
    fallback = dataclasses.replace(config, roi_margin_cells=min(config.roi_margin_cells, fallback_margin_cells))
    fallback = dataclasses.replace(fallback, map_cells=compact_map_cells(fallback, span_m))
    first = dataclasses.replace(fallback, search_radius_m=min(config.search_radius_m, radius_cells * config.cell_size),
                                roi_margin_cells=min(config.roi_margin_cells, margin_cells))
    first = dataclasses.replace(first, map_cells=compact_map_cells(first, span_m))
    return first, fallback
