"""The level-of-detail part of the report (issue 15): quality per level and cost per crowd size.

* ``levels``: one row per (LOD mode, level of detail) over the sweep's LOD runs
  (``planner._lod_quality`` per run, the couple-score loss from the sweep's exhaustive re-plans of
  the same requests, ``reports._sweep``), the characters' frames at that level summed, the stride
  error and the IK residual averaged over the runs weighted by what they rest on, the worst slip,
  jump and pop, the feet in boxes and the body overlaps summed; LOD off is one row, the paper's
  search for every character.
* ``scaling``: one row per (scenario, crowd size, mode) of the LOD scaling task (the three modes
  stepped in turns): the median ms per frame with its 95 % interval and LOD on / off.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np

# The report's table: at most 10 columns (the rest of every row is in lod_levels.csv).
LEVEL_TABLE = (
    ("mode", "LOD mode"),
    ("level", "level of detail"),
    ("share", "share of the character-frames"),
    ("score_loss_pct", "couple-score loss, % of the exhaustive search's (same requests)"),
    ("stride_rel_error_median", "per-stride error, median"),
    ("max_stance_slip_mm", "largest stance slip, mm (rendered feet)"),
    ("ik_residual_p95_mm", "IK residual p95, mm"),
    ("feet_in_boxes", "feet in boxes (feet x frames)"),
    ("body_overlaps", "body overlaps (pairs x frames)"),
    ("pop_max_mm", "largest foot jump at a level switch, mm (jump without a switch in lod_levels.csv)"),
)


def _weighted(values, weights):
    pairs = [(v, w) for v, w in zip(values, weights) if v is not None and w > 0]
    if not pairs:
        return None
    v, w = np.array(pairs, dtype=np.float64).T
    return float(np.average(v, weights=w))


def level_rows(runs: list[dict]) -> list[dict]:
    """Rows of the per-level table (module doc) from the sweep's LOD runs."""
    groups: dict[tuple[str, str], list[tuple[dict, dict]]] = defaultdict(list)
    totals: dict[str, int] = defaultdict(int)
    for r in runs:
        if r.get("kind") != "lod":
            continue
        mode = r["lod_mode"]
        if r.get("lod_levels") is None:  # LOD off: every character at the paper's full search
            row = {"character_frames": r["characters"] * r["frames"], "stride_rel_error_median": r["stride_error_median"],
                   "strides_measured": r["strides"], "max_stance_slip_m": r["max_stance_slip_m"],
                   "ik_residual_p95_m": r["ik_residual_p95_m"], "feet_in_boxes": r["collisions"],
                   "body_overlaps": r.get("body_overlaps", 0), "jump_max_m": None, "situations": r["situations"],
                   "score_loss_pct": 100.0 * r["deficit_mean"] / r["exhaustive_score_mean"]
                   if r["exhaustive_score_mean"] > 0 else None}
            groups[mode, "full (no LOD)"].append((row, {"pop_max_m": None, "switches": 0}))
            totals[mode] += row["character_frames"]
            continue
        for level, row in r["lod_levels"]["levels"].items():
            groups[mode, level].append((row, r["lod_levels"]))
            totals[mode] += row["character_frames"]
    out = []
    for (mode, level), items in groups.items():
        rows = [row for row, _ in items]
        frames = sum(row["character_frames"] for row in rows)
        situations = [row.get("situations", 0) for row in rows]
        pops = [run["pop_max_m"] for _, run in items if run["pop_max_m"] is not None]
        jumps = [row["jump_max_m"] for row in rows if row.get("jump_max_m") is not None]
        best = [row["score_loss_pct"] for row in rows]
        out.append({
            "mode": mode, "level": level, "runs": len(rows), "character_frames": frames,
            "share": frames / max(totals[mode], 1),
            "situations": int(sum(situations)),
            "score_loss_pct": _weighted(best, situations),
            "stride_rel_error_median": _weighted([row["stride_rel_error_median"] for row in rows],
                                                 [row["strides_measured"] for row in rows]),
            "strides_measured": int(sum(row["strides_measured"] for row in rows)),
            "max_stance_slip_mm": 1e3 * max(row["max_stance_slip_m"] for row in rows),
            "ik_residual_p95_mm": (1e3 * max(v for v in (row["ik_residual_p95_m"] for row in rows) if v is not None)
                                   if any(row["ik_residual_p95_m"] is not None for row in rows) else None),
            "feet_in_boxes": int(sum(row["feet_in_boxes"] for row in rows)),
            "body_overlaps": int(sum(row["body_overlaps"] for row in rows)),
            "jump_max_mm": 1e3 * max(jumps) if jumps else None,
            "pop_max_mm": 1e3 * max(pops) if pops else None,
            "switches": int(sum(run["switches"] for _, run in items)),
        })
    order = {"off": 0, "on": 1, "zoomed": 2}
    levels = {"full (no LOD)": 0, "full": 1, "far": 2, "hidden": 3}
    return sorted(out, key=lambda row: (order.get(row["mode"], 9), levels.get(row["level"], 9)))


def scaling_rows(scaling: list[dict]) -> list[dict]:
    """Rows (scenario, characters, mode, ms_per_frame, ci_low, ci_high, ratio_on_off, ratio_ci_low,
    ratio_ci_high) of the LOD scaling tasks."""
    out = []
    for task in scaling:
        for size, modes in task["sizes"].items():
            for mode in ("on", "zoomed", "off"):
                row = modes[mode]
                out.append({"scenario": task["scenario"], "seed": task["seed"], "characters": int(size), "mode": mode,
                            "ms_per_frame": row["ms_per_frame"], "ci_low": row["ms_per_frame_ci"][0],
                            "ci_high": row["ms_per_frame_ci"][1], "ratio_on_off": modes["ratio_on_off"],
                            "ratio_ci_low": modes["ratio_on_off_ci"][0], "ratio_ci_high": modes["ratio_on_off_ci"][1],
                            "plans_per_frame": row["plans_per_frame"],
                            "map_cells_built_per_frame": row["map_cells_built_per_frame"],
                            "ik_ccd_legs_per_frame": row["ik_ccd_legs_per_frame"],
                            "ik_two_bone_legs_per_frame": row["ik_two_bone_legs_per_frame"]})
    return out


def analyse(runs: list[dict], scaling: list[dict]) -> dict:
    """{"levels": level_rows, "scaling": scaling_rows, "level_table": LEVEL_TABLE columns}."""
    return {"levels": level_rows(runs), "scaling": scaling_rows(scaling),
            "level_table": [name for name, _ in LEVEL_TABLE]}
