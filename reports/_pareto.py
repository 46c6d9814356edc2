"""Per-setting summary rows, the quality-vs-cost Pareto front and the recommended budget.

Axes of the front (both minimised), from the paired runs (``reports._sweep.run_paired``:
every budget planning the same requests of a no-LOD crowd, timed interleaved):
* cost = ``paired_cost_vs_first_valid``: time per foot plan on one core relative to the
  first valid couple's on the same requests, timed interleaved (best of 3), so that
  the load of other programs on the machine cancels out (``paired_us_per_foot`` is
  the same in microseconds, for reading, not for ranking);
* loss = ``paired_loss_pct``: how much couple score the budget gives up against the
  exhaustive search on those situations, 100 * (1 - sum(chosen) / sum(exhaustive)).

Each setting's own runs give the rest of its row: ``plan_cost_vs_first_valid``,
``plan_us_per_foot`` and ``score_loss_pct`` on the situations that setting's crowd met, frame timings,
collisions, strides, etc. The front and the recommendation cover the fixed budgets
(``kind == "budget"``); the paper's LOD modes mix budgets per character, so they are
shown beside the front (at their own runs' numbers), not on it.

Recommended budget rule: among the fixed budgets, the cheapest whose score loss is
at most :data:`LOSS_TOLERANCE_PCT` percentage points above the smallest loss of any
budget (ties in cost: the smaller loss). Such a budget is always on the front: a
budget dominating it would be as cheap and within the tolerance too.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

LOSS_TOLERANCE_PCT = 0.25
COST = "paired_cost_vs_first_valid"
LOSS = "paired_loss_pct"

# (column, how tasks combine, unit / meaning) of the summary table, in order.
COLUMNS = (
    ("setting", "key", ""),
    ("kind", "first", "lod or budget"),
    ("couples_after_first", "first", "couples after the first valid one (none = no limit)"),
    ("slice_size_m", "first", "m (none = no slices)"),
    ("tasks", "count", "runs"),
    ("plan_cost_vs_first_valid", "mean", "plan time / first valid couple's, same requests (own runs)"),
    ("plan_us_per_foot", "mean", "µs per foot plan (own runs, one core)"),
    ("ms_per_frame", "mean", "ms, median frame"),
    ("ms_per_character", "mean", "ms per character per frame"),
    ("planner_calls", "sum", "foot plans"),
    ("cells_per_plan", "mean", "wavefront cells expanded per plan"),
    ("couples_per_plan", "mean", "3D couples evaluated per plan"),
    ("situations", "sum", "plans compared with the exhaustive search"),
    ("score_loss_pct", "derived", "% of the exhaustive couple score lost"),
    ("deficit_mean", "weighted", "mean couple-score deficit"),
    ("deficit_p95", "max", "95th percentile deficit (worst run)"),
    ("suboptimal_fraction", "weighted", "plans not exhaustive-optimal"),
    ("collisions", "sum", "feet in boxes (feet x frames)"),
    ("forbidden_footprints", "sum", "landings on forbidden boxes"),
    ("leg_crossings", "sum", "crossing leg pairs (x frames)"),
    ("stride_error_median", "mean", "median |stride - target| / target"),
    ("curvature_energy_mean", "mean", "l ∫κ² ds of swing paths"),
    ("ik_residual_p95_m", "max", "m"),
)
# Filled from the paired runs by analyse().
PAIRED_COLUMNS = (("paired_cost_vs_first_valid", "plan time / first valid couple's, all budgets on the same requests"),
                  ("paired_us_per_foot", "µs per foot plan, all budgets on the same requests"),
                  ("paired_loss_pct", "% of the exhaustive couple score lost on the same requests"))


def summarise(results: list[dict]) -> list[dict]:
    """One row per setting (in first-seen order), combining its tasks as :data:`COLUMNS` says."""
    groups: dict[str, list[dict]] = defaultdict(list)
    for r in results:
        groups[r["setting"]].append(r)
    rows = []
    for setting, rs in groups.items():
        row = {}
        weights = np.array([r["situations"] for r in rs], dtype=np.float64)
        for name, how, _ in COLUMNS:
            values = [r.get(name) for r in rs]
            if how == "key":
                row[name] = setting
            elif how == "first":
                row[name] = values[0]
            elif how == "count":
                row[name] = len(rs)
            elif how == "sum":
                row[name] = int(sum(values))
            elif how == "max":
                row[name] = float(max(values))
            elif how == "mean":
                finite = [v for v in values if v is not None and math.isfinite(v)]
                row[name] = float(np.mean(finite)) if finite else None
            elif how == "weighted":
                row[name] = float(np.average(values, weights=weights)) if weights.sum() > 0 else 0.0
        chosen = sum(r["situations"] * (r["exhaustive_score_mean"] - r["deficit_mean"]) for r in rs)
        best = sum(r["situations"] * r["exhaustive_score_mean"] for r in rs)
        row["score_loss_pct"] = 100.0 * (1.0 - chosen / best) if best > 0 else 0.0
        rows.append(row)
    return rows


def dominates(a: dict, b: dict, cost: str = "plan_us_per_foot", loss: str = "score_loss_pct") -> bool:
    """a is at least as good as b on both axes and better on one."""
    return a[cost] <= b[cost] and a[loss] <= b[loss] and (a[cost] < b[cost] or a[loss] < b[loss])


def pareto_front(rows: list[dict], cost: str = "plan_us_per_foot", loss: str = "score_loss_pct") -> list[str]:
    """Settings of the rows no other row dominates, by increasing cost."""
    front = [r for r in rows if not any(dominates(o, r, cost, loss) for o in rows if o is not r)]
    return [r["setting"] for r in sorted(front, key=lambda r: (r[cost], r[loss]))]


def recommend(rows: list[dict], tolerance_pct: float = LOSS_TOLERANCE_PCT, cost: str = "plan_us_per_foot",
              loss: str = "score_loss_pct") -> str | None:
    """The recommended budget (module doc), or None without budget rows."""
    if not rows:
        return None
    best = min(r[loss] for r in rows)
    eligible = [r for r in rows if r[loss] <= best + tolerance_pct]
    return min(eligible, key=lambda r: (r[cost], r[loss]))["setting"]


def analyse(results: list[dict], tolerance_pct: float = LOSS_TOLERANCE_PCT) -> dict:
    """Rows for every setting, the budgets' front and the recommended budget.

    The paired runs (every budget on the same situations) give the budgets'
    ``paired_us_per_foot`` and ``paired_loss_pct``, the axes of the front.
    """
    rows = summarise([r for r in results if r["kind"] not in ("paired", "lod-scaling")])
    paired: dict[str, list[dict]] = defaultdict(list)
    for r in results:
        if r["kind"] == "paired":
            for b in r["budgets"]:
                paired[b["budget"]].append(b)
    for r in rows:
        got = paired.get(r["setting"], [])
        r["paired_us_per_foot"] = float(np.mean([b["us_per_foot"] for b in got])) if got else None
        r["paired_loss_pct"] = float(np.mean([b["score_loss_pct"] for b in got])) if got else None
        ratios = [b["cost_vs_first_valid"] for b in got if b["cost_vs_first_valid"] is not None]
        r["paired_cost_vs_first_valid"] = float(np.mean(ratios)) if ratios else None
    budgets = [r for r in rows if r["kind"] == "budget" and r[COST] is not None]
    front = pareto_front(budgets, COST, LOSS)
    recommended = recommend(budgets, tolerance_pct, COST, LOSS)
    for r in rows:
        r["on_front"] = r["setting"] in front
        r["recommended"] = r["setting"] == recommended
    return {"rows": rows, "front": front, "recommended_budget": recommended, "tolerance_pct": tolerance_pct,
            "cost_axis": COST, "loss_axis": LOSS}
