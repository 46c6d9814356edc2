"""The report's plots (matplotlib, Agg, no pyplot state: each function builds its own Figure).

* :func:`pareto_plot`: score loss vs planning cost per setting, the budgets' front and
  the recommended budget;
* :func:`stride_plot`: realised stride length vs speed against the targets' law lambda = c h Fr^e;
* :func:`gait_disks`: the gait manager's disks (paper Fig. 8);
* :func:`footprint_heatmap`: candidate footprints and trajectories of one plan (paper Fig. 13);
* :func:`lod_scaling_plot`: ms per frame against crowd size per LOD mode, with 95 % intervals.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.colors import LinearSegmentedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Rectangle, Wedge

DPI = 110
# Paper Fig. 13: green = best target, blue = worst; a cyan middle keeps neighbouring scores apart.
SCORE_COLOURS = LinearSegmentedColormap.from_list("footprint_score", ["#1f3fbf", "#2aa7c9", "#7ddc3a"])


def _save(fig: Figure, path) -> None:
    fig.savefig(path, dpi=DPI)


def pareto_plot(analysis: dict, path) -> None:
    rows = analysis["rows"]
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.subplots()
    cost, loss = analysis["cost_axis"], analysis["loss_axis"]
    budgets = [r for r in rows if r["kind"] == "budget" and r[cost] is not None]
    lods = [r for r in rows if r["kind"] == "lod"]
    def xerr(rs):
        return [[r[cost] - (r.get("paired_cost_ci_low") if r.get("paired_cost_ci_low") is not None else r[cost])
                 for r in rs],
                [(r.get("paired_cost_ci_high") if r.get("paired_cost_ci_high") is not None else r[cost]) - r[cost]
                 for r in rs]]

    ax.errorbar([r[cost] for r in budgets], [r[loss] for r in budgets], xerr=xerr(budgets), fmt="o", c="#4c72b0",
                capsize=3, label="fixed budget, 95 % interval of its cost (all on the same requests)", zorder=3)
    far = analysis.get("far_level")
    if far is not None and far[cost] is not None:
        ax.errorbar([far[cost]], [far[loss]], xerr=xerr([far]), fmt="D", c="#8172b2", capsize=3, zorder=3,
                    label="far level of detail's planning (same requests)")
        ax.annotate("LOD far", (far[cost], far[loss]), textcoords="offset points", xytext=(4, 4), fontsize=7,
                    color="#8172b2")
    for r in budgets:
        ax.annotate(r["setting"].removeprefix("budget-"), (r[cost], r[loss]),
                    textcoords="offset points", xytext=(4, 4), fontsize=7)
    lods = [r for r in lods if r["plan_cost_vs_first_valid"] is not None]
    ax.scatter([r["plan_cost_vs_first_valid"] for r in lods], [r["score_loss_pct"] for r in lods], marker="s",
               facecolors="none", edgecolors="#dd8452", label="paper LOD mode (its own runs)", zorder=3)
    for r in lods:
        ax.annotate(r["setting"], (r["plan_cost_vs_first_valid"], r["score_loss_pct"]), textcoords="offset points",
                    xytext=(4, -10), fontsize=7, color="#a0522d")
    front = [next(r for r in budgets if r["setting"] == s) for s in analysis["front"]]
    if front:
        ax.step([r[cost] for r in front], [r[loss] for r in front], where="post",
                c="#4c72b0", alpha=0.6, label="Pareto front (budgets)")
    rec = next((r for r in budgets if r["setting"] == analysis["recommended_budget"]), None)
    if rec is not None:
        ax.scatter([rec[cost]], [rec[loss]], marker="*", s=260, c="#c44e52",
                   edgecolors="k", zorder=4, label=f"recommended: {rec['setting']}")
    # The whole range from no work: the differences between budgets are read against the noise bars,
    # not against an axis zoomed onto them.
    ax.set_xlim(left=0.0)
    ax.set_xlabel("cost: time per foot plan / the first valid couple's (same requests, interleaved)")
    ax.set_ylabel("quality loss: % of the exhaustive couple score")
    ax.set_title("Search budget: quality vs cost")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _save(fig, path)


def stride_plot(results: list[dict], path) -> None:
    """Every kept (speed, stride) sample, by scenario, and the target curve per hip height."""
    from footfall.reports._sweep import stride_law_text, target_stride_length

    fig = Figure(figsize=(7.0, 4.8), layout="constrained")
    ax = fig.subplots()
    by_scenario: dict[str, list] = {}
    heights = set()
    for r in results:
        by_scenario.setdefault(r["scenario"], []).extend(r["stride_samples"])
        heights.add((r["creature"], r["hip_height_m"]))
    v_max = 0.05
    for name, samples in by_scenario.items():
        if samples:
            s = np.asarray(samples)
            ax.scatter(s[:, 0], s[:, 1], s=8, alpha=0.5, label=f"realised, {name}")
            v_max = max(v_max, float(s[:, 0].max()))
    every = np.asarray([x for samples in by_scenario.values() for x in samples]).reshape(-1, 2)
    if len(every):
        edges = np.arange(0.0, every[:, 0].max() + 0.05, 0.05)
        which = np.digitize(every[:, 0], edges)
        centres, medians = [], []
        for b in np.unique(which):
            inside = every[which == b]
            if len(inside) >= 5:  # a median of fewer strides says little
                centres.append(float(inside[:, 0].mean()))
                medians.append(float(np.median(inside[:, 1])))
        if centres:
            ax.plot(centres, medians, c="#dd8452", lw=2.0, marker="o", label="median realised stride per 0.05 m/s bin")
    v = np.linspace(1e-3, 1.1 * v_max, 200)
    for creature, h in sorted(heights):
        ax.plot(v, target_stride_length(v, h, creature), c="k", lw=1.8,
                label=f"target {stride_law_text(creature)} ({creature}, h = {h:.3f} m)")
    ax.set_xlabel("speed v (m/s), pelvis over the stride")
    ax.set_ylabel("stride length λ (m), same foot, one cycle")
    ax.set_title("Stride length vs speed")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _save(fig, path)


def _phase_angle(phase):
    """Degrees of a phase on a disk read like a clock: 0 at 12 o'clock, clockwise."""
    return 90.0 - 360.0 * np.asarray(phase)


SWING_NOW = "#e4572e"  # the sector of a foot in the air now
SWING_LATER = "#f6c3a8"  # the sector of a foot on the ground now
NEEDLE = "#8b0000"


def gait_disk_states(scene: dict) -> list[str]:
    """Per foot, how its state at the snapshot relates to its disk (paper Fig. 8).

    ``"swing"``: in the air, the needle in its sector; ``"stance"``: on the ground, the needle
    outside. The two others are not errors of the plot: ``"forced"``, in the air with the needle
    outside its sector (a step the controller forced: the foot out of reach, or stepping away from
    a moving box, or a swing that lands late); ``"hold"``, on the ground with the needle inside its
    sector (the foot landed early, or holds because no valid footprint was found yet).
    """
    needle = float(scene["gait_needle"])
    states = []
    for start, duration, on_ground in zip(scene["gait_start"], scene["gait_duration"], scene["gait_in_stance"]):
        inside = (needle - float(start)) % 1.0 < float(duration)
        if on_ground:
            states.append("hold" if inside else "stance")
        else:
            states.append("swing" if inside else "forced")
    return states


GAIT_STATE_TITLES = {"swing": "in the air", "stance": "on the ground", "forced": "in the air *",
                     "hold": "on the ground †"}


def gait_disks(scene: dict, path) -> None:
    """One disk per foot, its swing sector and the needle (paper Fig. 8), with a legend.

    The sector is the part of the cycle in which the foot should be in the air; it is dark when
    the foot is in the air at the snapshot, light when it is on the ground. The marks * and †
    flag a foot off its schedule (:func:`gait_disk_states`).
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    names = scene["leg_names"]
    n = len(names)
    cols = min(n, 4) if n <= 4 else math.ceil(n / 2)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(2.0 * cols, 2.1 * rows + 1.1), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    needle = scene["gait_needle"]
    states = gait_disk_states(scene)
    for i, ax in enumerate(axes):
        ax.set_aspect("equal")
        ax.axis("off")
        if i >= n:
            continue
        start, duration = float(scene["gait_start"][i]), float(scene["gait_duration"][i])
        in_air = states[i] in ("swing", "forced")
        ax.add_patch(Circle((0, 0), 1.0, fc="#f2f2f2", ec="k", lw=1.2))
        ax.add_patch(Wedge((0, 0), 1.0, _phase_angle(start + duration), _phase_angle(start),
                           fc=SWING_NOW if in_air else SWING_LATER, ec="k", lw=0.8))
        a = math.radians(float(_phase_angle(needle)))
        ax.plot([0, 0.95 * math.cos(a)], [0, 0.95 * math.sin(a)], c=NEEDLE, lw=2.2)
        ax.add_patch(Circle((0, 0), 0.06, fc="k"))
        ax.set_xlim(-1.15, 1.15)
        ax.set_ylim(-1.15, 1.15)
        ax.set_title(f"{names[i]}: {GAIT_STATE_TITLES[states[i]]}", fontsize=9)
    handles = [Patch(fc=SWING_NOW, ec="k", label="swing sector, foot in the air now"),
               Patch(fc=SWING_LATER, ec="k", label="swing sector, foot on the ground now"),
               Line2D([], [], c=NEEDLE, lw=2.2, label="needle: the gait's phase now (clockwise from 12)")]
    notes = []
    if "forced" in states:
        notes.append("* in the air outside its sector: a forced step (out of reach, away from a moving box) "
                     "or a late landing")
    if "hold" in states:
        notes.append("† on the ground inside its sector: landed early, or holds (no valid footprint yet)")
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize=7, frameon=False)
    fig.suptitle(f"Gait manager: {scene['creature']}, gait {scene['gait_name']}" + "".join(f"\n{t}" for t in notes),
                 fontsize=9)
    _save(fig, path)


def chosen_cell(h: dict) -> int | None:
    """Index of the candidate cell the plan chose (the one its trajectory ends in), or None."""
    cells = np.asarray(h["cells_xz"], dtype=np.float64)
    if not len(cells) or not len(h["chosen"]):
        return None
    end = np.asarray(h["chosen"])[-1, [0, 2]]
    k = int(np.argmin(np.hypot(*(cells - end).T)))
    return k if np.all(np.abs(cells[k] - end) <= 0.5 * h["cell_size"] + 1e-9) else None


def score_range(scores) -> tuple[float, float]:
    """The colour range of the footprint scores: the candidates' own range, never empty."""
    lo, hi = float(np.min(scores)), float(np.max(scores))
    if hi - lo < 1e-6:
        lo, hi = lo - 0.005, hi + 0.005
    return lo, hi


def footprint_heatmap(scene: dict, path) -> None:
    """One foot plan's candidate footprints, coloured by score over the candidates' own range (Fig. 13).

    Marks: the chosen cell outlined in black, its trajectory in black, the best trajectories
    to other candidates in pink, the foot now (white dot), the preferred footprint (red x),
    forbidden cells (dark grey) over the ground height (grey, darker = higher). Cells with no
    colour were not candidates (outside the search disc, or refused).
    """
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    h = scene["heatmap"]
    cell = h["cell_size"]
    fig = Figure(figsize=(7.0, 6.4), layout="constrained")
    ax = fig.subplots()
    cells = h["cells_xz"]
    scores = np.asarray(h["scores"], dtype=np.float64)
    pts = np.vstack([cells, h["source"][None, [0, 2]], h["preferred"][None, :], h["chosen"][:, [0, 2]]])
    lo = pts.min(axis=0) - 4 * cell
    hi = pts.max(axis=0) + 4 * cell
    elev = h["elevation"]
    extent = (h["origin"][0], h["origin"][0] + elev.shape[1] * cell, h["origin"][1], h["origin"][1] + elev.shape[0] * cell)
    low, high = _visible(elev, extent, lo, hi)
    flat = high - low < 1e-3  # one shade (white) for flat ground, not a grey of no meaning
    ax.imshow(elev, origin="lower", extent=extent, cmap="Greys", alpha=0.55, interpolation="nearest",
              vmin=low, vmax=low + 1.0 if flat else high)
    ground = (f"ground height: flat here ({low:.2f} m)" if flat
              else f"ground height, darker = higher ({low:.2f}-{high:.2f} m)")
    for x, z in h["forbidden_xz"]:
        if lo[0] <= x <= hi[0] and lo[1] <= z <= hi[1]:
            ax.add_patch(Rectangle((x - cell / 2, z - cell / 2), cell, cell, fc="#404040", ec="none"))
    norm = Normalize(*score_range(scores))
    for (x, z), s in zip(cells, scores):
        ax.add_patch(Rectangle((x - cell / 2, z - cell / 2), cell, cell, fc=SCORE_COLOURS(norm(float(s))), ec="w",
                               lw=0.3))
    pick = chosen_cell(h)
    if pick is not None:
        x, z = cells[pick]
        ax.add_patch(Rectangle((x - cell / 2, z - cell / 2), cell, cell, fc="none", ec="k", lw=2.6, zorder=4))
    for traj in h["others"]:
        ax.plot(traj[:, 0], traj[:, 2], c="#ff69b4", lw=1.2, alpha=0.9)
    ax.plot(h["chosen"][:, 0], h["chosen"][:, 2], c="k", lw=2.4)
    ax.scatter([h["source"][0]], [h["source"][2]], marker="o", s=60, c="w", edgecolors="k", zorder=5)
    ax.scatter([h["preferred"][0]], [h["preferred"][1]], marker="x", s=70, c="#c00000", zorder=5)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    bar = fig.colorbar(_scalar_mappable(norm), ax=ax, shrink=0.8)
    bar.set_label(f"footprint score (colours span the candidates' range, {norm.vmin:.3f}-{norm.vmax:.3f})")
    chosen_score = f" (score {scores[pick]:.3f})" if pick is not None else ""
    handles = [Patch(fc="none", ec="k", lw=2.6, label=f"chosen footprint{chosen_score}"),
               Line2D([], [], c="k", lw=2.4, label="chosen trajectory"),
               Line2D([], [], c="#ff69b4", lw=1.2, label="best trajectories to other candidates"),
               Line2D([], [], ls="none", marker="o", ms=7, mfc="w", mec="k", label="foot now"),
               Line2D([], [], ls="none", marker="x", ms=8, mec="#c00000", label="preferred footprint"),
               Patch(fc="#404040", label="forbidden cell (box)"),
               Patch(fc="w" if flat else "#c8c8c8", ec="#bbbbbb", label=ground),
               Patch(fc="none", ec="#bbbbbb", label="no colour: not a candidate")]
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=7, frameon=False)
    ax.set_title(f"Potential footprints of one foot plan: {len(cells)} candidates scoring "
                 f"{scores.min():.3f}-{scores.max():.3f}; couple score {h['couple_score']:.3f}", fontsize=9)
    _save(fig, path)


def _visible(elev: np.ndarray, extent, lo, hi) -> tuple[float, float]:
    """Lowest and highest ground height inside the plotted window (the grey scale spans them)."""
    ny, nx = elev.shape
    xs = np.linspace(extent[0], extent[1], nx, endpoint=False) + (extent[1] - extent[0]) / (2 * nx)
    zs = np.linspace(extent[2], extent[3], ny, endpoint=False) + (extent[3] - extent[2]) / (2 * ny)
    inside = elev[np.ix_((zs >= lo[1]) & (zs <= hi[1]), (xs >= lo[0]) & (xs <= hi[0]))]
    values = inside[np.isfinite(inside)] if inside.size else elev[np.isfinite(elev)]
    if not values.size:
        return 0.0, 0.0
    return float(values.min()), float(values.max())


def _scalar_mappable(norm=None):
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    return ScalarMappable(norm=norm or Normalize(0.0, 1.0), cmap=SCORE_COLOURS)


MODE_COLOURS = {"on": "#4c72b0", "zoomed": "#55a868", "off": "#c44e52"}


def lod_scaling_plot(scaling: list[dict], path) -> None:
    """Median ms per frame against crowd size (log-log), one line per LOD mode and scenario, the
    bars the 95 % interval of each median (the modes stepped in turns: the same load for all)."""
    fig = Figure(figsize=(7.5, 4.6), layout="constrained")
    ax = fig.subplots()
    styles = ("-", "--", ":", "-.")
    for k, task in enumerate(scaling):
        sizes = sorted(task["sizes"], key=int)
        x = np.array([int(n) for n in sizes], dtype=np.float64)
        for mode in ("on", "zoomed", "off"):
            rows = [task["sizes"][n][mode] for n in sizes]
            y = np.array([r["ms_per_frame"] for r in rows])
            lo = np.array([r["ms_per_frame_ci"][0] for r in rows])
            hi = np.array([r["ms_per_frame_ci"][1] for r in rows])
            ax.errorbar(x, y, yerr=[y - lo, hi - y], marker="o", ms=4, capsize=3, ls=styles[k % len(styles)],
                        c=MODE_COLOURS[mode], label=f"LOD {mode}" + (f", {task['scenario']}" if len(scaling) > 1 else ""))
        for n, xv in zip(sizes, x):
            r = task["sizes"][n]
            ax.annotate(f"on/off {r['ratio_on_off']:.2f}", (xv, r["on"]["ms_per_frame"]), textcoords="offset points",
                        xytext=(4, -12), fontsize=7, color=MODE_COLOURS["on"])
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    ax.set_xscale("log")
    ax.set_yscale("log")
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_formatter(ScalarFormatter())
        axis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.set_xticks([int(n) for task in scaling for n in task["sizes"]])
    ax.set_xlabel("characters")
    ax.set_ylabel("ms per frame (median, 95 % interval)")
    ax.set_title("Cost of a frame against crowd size, per LOD mode (modes stepped in turns)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    _save(fig, path)
