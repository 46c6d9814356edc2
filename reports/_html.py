"""The report's ``index.html``: one self-contained page, images and data linked relatively."""

from __future__ import annotations

import html
import math

from footfall.reports._pareto import COLUMNS, LOSS_TOLERANCE_PCT, PAIRED_COLUMNS
from footfall.reports._sweep import stride_law_text

STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 1200px; color: #222; }
.scroll { overflow-x: auto; }
table { border-collapse: collapse; font-size: 12px; margin: 1em 0; }
td:first-child { white-space: nowrap; }
th, td { border: 1px solid #ccc; padding: 3px 6px; text-align: right; }
th { background: #f0f0f0; } td:first-child, th:first-child { text-align: left; }
tr.front td { background: #eef5ff; } tr.recommended td { background: #ffe9a8; font-weight: bold; }
.box { border: 2px solid #c44e52; padding: 0.6em 1em; background: #fff6f6; }
.warning { border: 2px solid #d08000; padding: 0.6em 1em; background: #fff4e0; }
img, video { max-width: 100%; border: 1px solid #ddd; margin: 0.4em 0; }
.pair { display: grid; grid-template-columns: 1fr 1fr; gap: 1em; }
figure { margin: 0; } figcaption { font-size: 12px; color: #444; }
"""


def _fmt(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        if not math.isfinite(value):
            return str(value)
        if value != 0 and (abs(value) < 1e-3 or abs(value) >= 1e5):
            return f"{value:.3g}"
        return f"{value:.4g}"
    return html.escape(str(value))


def _table(rows: list[dict], columns: list[tuple[str, ...]], row_class=None) -> str:
    """An HTML table of ``rows``; ``columns``: (key, unit) or (key, unit, header shown instead of the key)."""
    head = "".join(f'<th title="{html.escape(column[1])}">{html.escape(column[-1] if len(column) > 2 else column[0])}'
                   "</th>" for column in columns)
    body = []
    for r in rows:
        cls = row_class(r) if row_class else ""
        cells = "".join(f"<td>{_fmt(r.get(column[0]))}</td>" for column in columns)
        body.append(f'<tr class="{cls}">{cells}</tr>')
    return f"<div class='scroll'><table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table></div>"


def _img(src: str, alt: str) -> str:
    return f'<img src="{html.escape(src)}" alt="{html.escape(alt)}">'


def video(src: str, caption: str) -> str:
    """A looping, muted clip with its controls (autoplay is allowed only for muted video)."""
    return (f'<figure><video src="{html.escape(src)}" controls muted loop autoplay playsinline preload="auto" '
            f'width="640" title="{html.escape(caption)}"></video><figcaption>{html.escape(caption)}</figcaption>'
            '</figure>')


PLOT_CAPTIONS = {
    "gait_disks_": "One disk per foot at the last frame (paper Fig. 8). The needle (dark red) is the gait's phase, "
                   "turning clockwise from 12 o'clock; the sector is the part of the cycle in which the foot should "
                   "be in the air: dark orange if the foot is in the air now, light orange if it is on the ground. "
                   "* marks a foot in the air outside its sector (a step the controller forced: the foot out of "
                   "reach or stepping away from a moving box, or a late landing); † a foot on the ground inside its "
                   "sector (it landed early, or holds because it found no valid footprint yet).",
    "footprints_": "The candidate footprints of one foot plan (paper Fig. 13), coloured by footprint score over the "
                   "candidates' own range (the colour bar gives it; every candidate scores well above 0, so a 0-1 "
                   "scale would show one colour). Black outline: the chosen cell; black line: its trajectory; pink: "
                   "the best trajectory to other candidates; white dot: the foot now; red x: the preferred footprint "
                   "(where the gait wants the foot); dark grey: forbidden cells (boxes); the grey background is the "
                   "ground height (darker = higher; white where it is flat); cells with no colour were not "
                   "candidates.",
}
"""Caption of a scene plot, by the start of its file name."""


def plot_caption(src: str) -> str:
    """What every mark of the plot ``src`` means (:data:`PLOT_CAPTIONS`), or "" for another plot."""
    name = src.rsplit("/", 1)[-1]
    return next((text for prefix, text in PLOT_CAPTIONS.items() if name.startswith(prefix)), "")


SUMMARY_COLUMNS = [
    ("setting", "LOD mode, or fixed budget cK-sS: K couples after the first valid one, slices of S m", "setting"),
    ("paired_cost_vs_first_valid", "planning time per foot / the first valid couple's, all budgets on the same "
     "requests", "cost (x first valid)"),
    ("paired_loss_pct", "% of the exhaustive couple score lost, all budgets on the same requests", "loss %"),
    ("score_loss_pct", "% of the exhaustive couple score lost in the setting's own runs", "own loss %"),
    ("plan_us_per_foot", "µs per foot plan (own runs, one core)", "µs / foot plan"),
    ("paired_cost_ci", "95 % interval of the cost (over the batches planned by every budget)", "cost 95 % CI"),
    ("collisions", "feet in boxes (feet x frames)", "collisions"),
    ("leg_crossings", "crossing leg pairs (x frames)", "leg crossings"),
    ("stride_error_median", "median |stride - target| / target", "stride error"),
    ("on_front", "on the budgets' Pareto front (paired cost vs paired loss)", "on front"),
]
"""The short table of the report (at most 10 columns; the full one is behind a toggle and in summary.csv)."""

TASK_COLUMNS = [(n, "") for n in ("scenario", "seed", "setting", "characters", "frames", "ms_per_frame",
                                  "ms_per_character", "plan_us_per_foot", "planner_calls", "cells_per_plan",
                                  "situations", "deficit_mean", "collisions", "forbidden_footprints", "leg_crossings",
                                  "strides", "stride_error_median", "curvature_energy_mean", "ik_residual_p95_m")]


def write_index(path, *, analysis: dict, results: list[dict], meta: dict, scenes: list[dict],
                recording: dict | None, lod: dict | None = None) -> None:
    """Write ``index.html``. ``scenes``: per scenario, the relative image paths and render status."""
    rows = analysis["rows"]
    rec = next((r for r in rows if r["recommended"]), None)
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>footfall report</title>"
             f"<style>{STYLE}</style></head><body>",
             "<h1>footfall evaluation report</h1>",
             f"<p>footfall {html.escape(meta['footfall'])}, preset <b>{html.escape(meta['preset'])}</b>, seed "
             f"{meta['seed']}; scenarios {html.escape(', '.join(meta['scenarios']))}; crowd sizes "
             f"{', '.join(map(str, meta['sizes']))}; {meta['frames']} measured frames after {meta['warmup']} "
             f"warm-up frames; {len(results)} runs in {meta['wall_seconds']:.0f} s. "
             "Data: <a href='results.csv'>results.csv</a> (one row per run), <a href='summary.csv'>summary.csv</a> "
             "(one row per setting), <a href='paired.csv'>paired.csv</a> (the budgets on the same requests), "
             "<a href='results.json'>results.json</a> (everything).</p>"]
    if rec is not None:
        parts.append(
            f"<div class='box'><b>Recommended budget: {html.escape(rec['setting'])}</b> "
            f"({_fmt(rec['couples_after_first'])} couples after the first valid one, slices "
            f"{_fmt(rec['slice_size_m'])} m): {rec['paired_cost_vs_first_valid']:.3f} x the first valid couple's "
            f"planning time ({rec['paired_us_per_foot']:.1f} µs per foot plan), "
            f"{rec['paired_loss_pct']:.3f} % of the exhaustive couple score lost (every budget planning the same "
            "requests).<br>Rule: among the fixed budgets whose score loss is at most "
            f"{analysis['tolerance_pct']} percentage points above the smallest loss of any budget, the cheapest "
            "(planning time relative to the first valid couple's), where cheaper means by more than the noise: the "
            "budgets whose 95 % cost interval overlaps the cheapest one's count as just as cheap, and of those the one "
            "losing least is recommended.</div>")
    far = analysis.get("far_level")
    if far is not None and far.get("paired_cost_vs_first_valid") is not None:
        parts.append(f"<p>The far level of detail's planning on the same requests: {far['paired_cost_vs_first_valid']:.3f} "
                     f"x the first valid couple's time (95 % {_fmt(far['paired_cost_ci_low'])}-"
                     f"{_fmt(far['paired_cost_ci_high'])}), {far['paired_loss_pct']:.3f} % of the exhaustive couple "
                     "score lost (<code>planner._far_planning</code>).</p>")
    parts.append("<h2>Quality vs cost</h2>"
                 "<p>Cost: the planning time per foot relative to the first valid couple's on the same requests "
                 "(timed alternately on one core, so the load of other programs cancels out) and in µs, the crowd's "
                 "median ms per frame and per character, planner calls, wavefront cells expanded. Each setting's own "
                 "runs give its row; for the fixed budgets the cost and loss % columns (paired_* in the full table) come "
                 "from every budget planning the same requests (those of a no-LOD crowd): the Pareto front and the "
                 "recommendation use these; own loss % is from the setting's own runs. "
                 "Frame timings move with the load of the machine. Quality: the couple-score deficit against the exhaustive search "
                 "(planner.EXHAUSTIVE: no couple limit, 5 cm slices, exact stop) on the same situations, "
                 "collisions, forbidden footprints, leg crossings, stride length error against "
                 f"λ = {stride_law_text('spider', html=True)} (tuning/data/targets.toml), curvature energy E = l ∫κ² ds of the swing paths (horizontal, "
                 "u in [0.05, 0.95]) and the IK residual. Blue rows: on the budgets' Pareto front; yellow: recommended. "
                 "Hover a column name for its unit. The short table below has the figures that decide; "
                 "<i>All columns</i> opens the full one.</p>")
    columns = [(n, u) for n, _, u in COLUMNS]

    def row_class(r: dict) -> str:
        return "recommended" if r["recommended"] else ("front" if r["on_front"] else "")

    parts.append(_table(rows, SUMMARY_COLUMNS, row_class))
    every_column = columns[:4] + list(PAIRED_COLUMNS) + columns[4:] + [("on_front", "")]
    parts.append(f"<details><summary>All {len(every_column)} columns (also in <a href='summary.csv'>summary.csv</a>)"
                 "</summary>")
    parts.append(_table(rows, every_column, row_class))
    parts.append("</details>")
    parts.append(_img("pareto.png", "quality vs cost Pareto front"))
    parts.append("<h2>Stride length vs speed</h2><p>Every pair of consecutive touch-downs of a foot in the "
                 "measured frames: the distance between the two footprints against the pelvis speed over that time; "
                 "the black line is the biomechanics target (Alexander 1976), the orange one the median realised stride "
                 "per speed bin. Footprints are continuous points (the preferred footprint itself wherever its cell "
                 "is free), so on open ground single strides lie on the target (per stride within 5 % at the median "
                 "for every built-in creature on flat ground); the spread here is the sweep's crates, other "
                 "characters and turns moving footprints off their preferred points. At low speeds the gait keeps a "
                 "minimum stride frequency, so strides are shorter than the target there by design.</p>")
    parts.append(_img("stride.png", "stride length vs speed"))
    if lod is not None:
        parts.extend(lod_section(lod))
    for s in scenes:
        parts.append(f"<h2>Scenario {html.escape(s['scenario'])}</h2>")
        parts.append(f"<p>{html.escape(s['caption'])}</p><div class='pair'>")
        for src, alt in s["plots"]:
            parts.append(f"<figure>{_img(src, alt)}<figcaption>{html.escape(plot_caption(src))}</figcaption></figure>")
        parts.append("</div>")
        if s.get("clip"):
            parts.append(video(s["clip"], f"{s['scenario']}: the crowd walking (30 frames per second)"))
        if s["renders"]:
            parts.append("<div class='pair'>" + "".join(f"<div>{_img(src, alt)}</div>" for src, alt in s["renders"])
                         + "</div>")
        if s.get("render_error"):
            parts.append(f"<p class='warning'>3D rendering failed: {html.escape(s['render_error'])}</p>")
    if recording is not None:
        parts.append(f"<h2>Recording {html.escape(recording['name'])}</h2><p>{html.escape(recording['caption'])}</p>")
        if recording.get("clip"):
            parts.append(video(recording["clip"], f"{recording['name']}: the crowd walking (30 frames per second)"))
        if recording["renders"]:
            parts.append("<div class='pair'>" + "".join(f"<div>{_img(src, alt)}</div>"
                                                         for src, alt in recording["renders"]) + "</div>")
        if recording.get("render_error"):
            parts.append(f"<p class='warning'>3D rendering failed: {html.escape(recording['render_error'])}</p>")
    parts.append(matrix_section(load_matrix()))
    parts.append("<h2>Every run</h2><details><summary>one row per (scenario, seed, setting, crowd size)</summary>")
    parts.append(_table(results, TASK_COLUMNS))
    parts.append(f"</details><p>Score-loss tolerance of the rule: {LOSS_TOLERANCE_PCT} points.</p></body></html>")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(parts))


def lod_section(lod: dict) -> list[str]:
    """The level-of-detail section: cost against crowd size, and quality per level (issue 15)."""
    from footfall.reports._lod_report import LEVEL_TABLE

    parts = ["<h2>Level of detail: cost and quality per level</h2>"]
    if lod["scaling"]:
        ratios = {}
        for r in lod["scaling"]:
            ratios[r["scenario"], r["characters"]] = (r["ratio_on_off"], r["ratio_ci_low"], r["ratio_ci_high"])
        said = "; ".join(f"{n} characters on {sc}: {v[0]:.2f} (95 % {v[1]:.2f}-{v[2]:.2f})"
                         for (sc, n), v in sorted(ratios.items(), key=lambda kv: (kv[0][0], kv[0][1])))
        parts.append("<p>Cost: one crowd per LOD mode, the three stepped in turns (a frame each, the order rotating), "
                     "so they share whatever load the machine has; the median ms per frame with the 95 % interval of "
                     f"that median. LOD on / LOD off: {html.escape(said)} (bootstrap over the rounds). A far character "
                     "(on screen beyond LodConfig.far_m) plans on compact maps, first near its preferred footprint, and "
                     "solves its legs in closed form; an off-screen one plans the same way and has no IK "
                     "(<code>planner._lod</code>). Data: <a href='lod_scaling.csv'>lod_scaling.csv</a>.</p>")
        parts.append(_img("lod_scaling.png", "ms per frame against crowd size per LOD mode"))
    if lod["levels"]:
        parts.append("<p>Quality per level, measured on what is rendered in the sweep's LOD runs: each "
                     "character-frame counts at the level its character had then; the couple-score loss is that of "
                     "the level's plans against the exhaustive search on the same requests (the far plans put back on "
                     "the paper's maps). A pop is the largest move of a rendered foot beyond its planned foot's in a "
                     "frame where its character switched level. Hover a column name for its meaning; every column "
                     "(strides measured, jumps without a switch, switches, runs) is in "
                     "<a href='lod_levels.csv'>lod_levels.csv</a>.</p>")
        parts.append(_table(lod["levels"], [(name, unit) for name, unit in LEVEL_TABLE]))
    return parts


def load_matrix() -> dict | None:
    """The stored preset x terrain matrix (``tuning/data/matrix.json``, ``footfall bench presets``), or None."""
    import json

    from footfall.tuning._matrix import MATRIX_FILE

    if not MATRIX_FILE.exists():
        return None
    return json.loads(MATRIX_FILE.read_text(encoding="utf-8"))


def matrix_section(matrix: dict | None) -> str:
    """The report's section on the terrain and style presets: the held-out matrix as stored."""
    head = "<h2>Terrain and style presets on held-out terrains</h2>"
    if matrix is None:
        return head + "<p>No matrix stored (tuning/data/matrix.json): <code>footfall bench presets --out " \
                      "tuning/data/matrix.json</code> makes it.</p>"
    terrains = list(matrix["terrains"])
    parts = [head, f"<p>Each preset against the runtime's defaults, {matrix['runs_per_cell']} paired runs per cell "
             "(the same held-out scenario, spawn along the route and seed under both): "
             + ", ".join(f"{html.escape(t)} = <code>{html.escape(v)}</code>" for t, v in matrix["terrains"].items())
             + f". Per cell: the mean per-stride error, defaults -> preset, and the paired gain in standard errors "
             f"(&gt; 0: better); for a style preset also its style metric (gain toward its bound). A terrain preset "
             f"passes with &ge; {matrix['win_se']:g} SE on its own terrain and &ge; -{matrix['loss_se']:g} SE "
             f"elsewhere, a style preset with &ge; {matrix['win_se']:g} SE toward its bound on its terrains; neither "
             "with more collisions. Only passing presets ship (tuning/data/presets/); each is regenerated by its "
             "command, the matrix by <code>footfall bench presets --out tuning/data/matrix.json</code>.</p>",
             "<table><tr><th>preset</th>" + "".join(f"<th>{html.escape(t)}</th>" for t in terrains)
             + "<th>passes</th><th>regenerate</th></tr>"]
    for name, p in matrix["presets"].items():
        cells = []
        for t in terrains:
            if not p.get("found") or t not in p["cells"]:
                cells.append("<td>-</td>")
                continue
            c = p["cells"][t]
            m = c["main"]
            text = "-" if m["default"] is None else f"{m['default']:.3f} &rarr; {m['preset']:.3f} ({_se(m['gain_se'])})"
            for s in c["style"].values():
                if s["default"] is not None:
                    text += f"<br>{html.escape(s['metric'])} {s['default']:.3g} &rarr; {s['preset']:.3g} ({_se(s['gain_se'])})"
            text += f"<br>collisions {c['collisions_default']} &rarr; {c['collisions_preset']}"
            if "crossings_default" in c:  # matrices proved before 2026-11-26 have none
                text += f", leg crossings {c['crossings_default']} &rarr; {c['crossings_preset']}"
            cells.append(f"<td>{text}</td>")
        verdict = "yes" if p.get("passes") else "no: " + html.escape("; ".join(p.get("why", [])))
        parts.append(f"<tr><td>{html.escape(name)}</td>{''.join(cells)}<td>{verdict}</td>"
                     f"<td><code>{html.escape(p['command'])}</code></td></tr>")
    parts.append("</table>")
    return "".join(parts)


def _se(value) -> str:
    return "-" if value is None else f"{value:+.1f} SE"
