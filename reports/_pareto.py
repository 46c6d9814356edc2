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

The paired cost of a budget is the mean over the kept batches (every budget timed on each, best
of 3 interleaved rounds) of its time over the first valid couple's on that batch, with a 95 %
interval of that mean (``paired_cost_ci_low`` / ``_high``, normal approximation over the batches):
the noise the recommendation must see through.

Recommended budget rule: among the fixed budgets whose score loss is at most
:data:`LOSS_TOLERANCE_PCT` percentage points above the smallest loss of any budget, the cheapest;
but a budget counts as cheaper only by more than the noise: every eligible budget whose cost
interval reaches down to the cheapest one's interval is as cheap as far as the timings can tell,
and of those the one with the smallest loss is recommended (then the cheaper). Without intervals
(one batch) it is the plain cheapest. The far level of detail's planning (``reports._sweep.FAR_LEVEL``)
is timed on the same requests and shown beside the budgets (``far_level``), not among them.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

from footfall.reports._sweep import FAR_LEVEL

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
                  ("paired_cost_ci_low", "95 % interval of that cost: low"),
                  ("paired_cost_ci_high", "95 % interval of that cost: high"),
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
              loss: str = "score_loss_pct", ci: tuple[str, str] | None = None) -> str | None:
    """The recommended budget (module doc), or None without budget rows. ``ci``: the keys of each
    row's cost interval (low, high); costs whose intervals overlap the cheapest's count as equal."""
    if not rows:
        return None
    best = min(r[loss] for r in rows)
    eligible = [r for r in rows if r[loss] <= best + tolerance_pct]
    cheapest = min(eligible, key=lambda r: (r[cost], r[loss]))
    if ci is None or any(r.get(ci[0]) is None or r.get(ci[1]) is None for r in eligible):
        return cheapest["setting"]
    as_cheap = [r for r in eligible if r[ci[0]] <= cheapest[ci[1]]]
    return min(as_cheap, key=lambda r: (r[loss], r[cost]))["setting"]


def mean_ci(values) -> tuple[float | None, float | None, float | None]:
    """(mean, low, high): the mean of ``values`` and its 95 % interval (normal approximation; None
    without values, no interval from one).

    Examples
    --------
    >>> mean_ci([1.0, 2.0, 3.0])[0]
    2.0
    """
    v = np.asarray([x for x in values if x is not None], dtype=np.float64)
    if v.size == 0:
        return None, None, None
    if v.size == 1:
        return float(v[0]), None, None
    half = 1.96 * float(v.std(ddof=1)) / np.sqrt(v.size)
    return float(v.mean()), float(v.mean() - half), float(v.mean() + half)


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
        _paired_cost(r, got)
    budgets = [r for r in rows if r["kind"] == "budget" and r[COST] is not None]
    front = pareto_front(budgets, COST, LOSS)
    recommended = recommend(budgets, tolerance_pct, COST, LOSS, ("paired_cost_ci_low", "paired_cost_ci_high"))
    far = None
    if paired.get(FAR_LEVEL):
        far = {"setting": FAR_LEVEL, "kind": "lod",
               "paired_us_per_foot": float(np.mean([b["us_per_foot"] for b in paired[FAR_LEVEL]])),
               "paired_loss_pct": float(np.mean([b["score_loss_pct"] for b in paired[FAR_LEVEL]]))}
        _paired_cost(far, paired[FAR_LEVEL])
    for r in rows:
        r["on_front"] = r["setting"] in front
        r["recommended"] = r["setting"] == recommended
    return {"rows": rows, "front": front, "recommended_budget": recommended, "tolerance_pct": tolerance_pct,
            "cost_axis": COST, "loss_axis": LOSS, "far_level": far}


def _paired_cost(row: dict, got: list[dict]) -> None:
    """``row``'s paired cost: the mean over every kept batch of its time / the first valid couple's,
    with the 95 % interval (module doc); runs without per-batch ratios give their overall ratio."""
    ratios = [x for b in got for x in b.get("cost_ratios") or []]
    if not ratios:
        ratios = [b["cost_vs_first_valid"] for b in got if b["cost_vs_first_valid"] is not None]
    mean, low, high = mean_ci(ratios)
    row["paired_cost_vs_first_valid"] = mean
    row["paired_cost_ci_low"] = low
    row["paired_cost_ci_high"] = high
    row["paired_cost_ci"] = f"{low:.2f}-{high:.2f}" if low is not None else None
