"""The report's plots (matplotlib, Agg, no pyplot state: each function builds its own Figure).

* :func:`pareto_plot`: score loss vs planning cost per setting, the budgets' front and
  the recommended budget;
* :func:`stride_plot`: realised stride length vs speed against lambda = 2.3 h Fr^0.3;
* :func:`gait_disks`: the gait manager's disks (paper Fig. 8);
* :func:`footprint_heatmap`: candidate footprints and trajectories of one plan (paper Fig. 13).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.colors import LinearSegmentedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Rectangle, Wedge

DPI = 110
# Paper Fig. 13: green = best target (score 1), blue = worst (score 0).
SCORE_COLOURS = LinearSegmentedColormap.from_list("footprint_score", ["#1f3fbf", "#1fbf3f"])


def _save(fig: Figure, path) -> None:
    fig.savefig(path, dpi=DPI)


def pareto_plot(analysis: dict, path) -> None:
    rows = analysis["rows"]
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.subplots()
    cost, loss = analysis["cost_axis"], analysis["loss_axis"]
    budgets = [r for r in rows if r["kind"] == "budget" and r[cost] is not None]
    lods = [r for r in rows if r["kind"] == "lod"]
    ax.scatter([r[cost] for r in budgets], [r[loss] for r in budgets], c="#4c72b0",
               label="fixed budget (all on the same requests)", zorder=3)
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
    ax.set_xlabel("cost: time per foot plan / the first valid couple's (same requests, interleaved)")
    ax.set_ylabel("quality loss: % of the exhaustive couple score")
    ax.set_title("Search budget: quality vs cost")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _save(fig, path)


def stride_plot(results: list[dict], path) -> None:
    """Every kept (speed, stride) sample, by scenario, and the target curve per hip height."""
    from reports._sweep import target_stride_length

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
                label=f"target 2.3 h Fr^0.3 ({creature}, h = {h:.3f} m)")
    ax.set_xlabel("speed v (m/s), pelvis over the stride")
    ax.set_ylabel("stride length λ (m), same foot, one cycle")
    ax.set_title("Stride length vs speed")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _save(fig, path)


def _phase_angle(phase):
    """Degrees of a phase on a disk read like a clock: 0 at 12 o'clock, clockwise."""
    return 90.0 - 360.0 * np.asarray(phase)


def gait_disks(scene: dict, path) -> None:
    """One disk per foot: the swing sector coloured, the needle in red (paper Fig. 8)."""
    names = scene["leg_names"]
    n = len(names)
    cols = min(n, 4) if n <= 4 else math.ceil(n / 2)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(2.0 * cols, 2.1 * rows + 0.5), layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols)).ravel()
    needle = scene["gait_needle"]
    for i, ax in enumerate(axes):
        ax.set_aspect("equal")
        ax.axis("off")
        if i >= n:
            continue
        start, duration = float(scene["gait_start"][i]), float(scene["gait_duration"][i])
        swinging = not bool(scene["gait_in_stance"][i])
        ax.add_patch(Circle((0, 0), 1.0, fc="#f2f2f2", ec="k", lw=1.2))
        ax.add_patch(Wedge((0, 0), 1.0, _phase_angle(start + duration), _phase_angle(start),
                           fc="#e4572e" if swinging else "#76b041", ec="k", lw=0.8))
        a = math.radians(float(_phase_angle(needle)))
        ax.plot([0, 0.95 * math.cos(a)], [0, 0.95 * math.sin(a)], c="#c00000", lw=2.2)
        ax.add_patch(Circle((0, 0), 0.06, fc="k"))
        ax.set_xlim(-1.15, 1.15)
        ax.set_ylim(-1.15, 1.15)
        ax.set_title(f"{names[i]} ({'swing' if swinging else 'stance'})", fontsize=9)
    fig.suptitle(f"Gait manager: {scene['creature']}, gait {scene['gait_name']} (sector = swing phase, orange = swinging now, "
                 "red = needle)",
                 fontsize=10)
    _save(fig, path)


def footprint_heatmap(scene: dict, path) -> None:
    """Candidate cells coloured by footprint score, trajectories in pink, the chosen one in black."""
    h = scene["heatmap"]
    cell = h["cell_size"]
    fig = Figure(figsize=(6.4, 5.6), layout="constrained")
    ax = fig.subplots()
    cells = h["cells_xz"]
    pts = np.vstack([cells, h["source"][None, [0, 2]], h["preferred"][None, :], h["chosen"][:, [0, 2]]])
    lo = pts.min(axis=0) - 4 * cell
    hi = pts.max(axis=0) + 4 * cell
    elev = h["elevation"]
    extent = (h["origin"][0], h["origin"][0] + elev.shape[1] * cell, h["origin"][1], h["origin"][1] + elev.shape[0] * cell)
    ax.imshow(elev, origin="lower", extent=extent, cmap="Greys", alpha=0.55, interpolation="nearest")
    for x, z in h["forbidden_xz"]:
        if lo[0] <= x <= hi[0] and lo[1] <= z <= hi[1]:
            ax.add_patch(Rectangle((x - cell / 2, z - cell / 2), cell, cell, fc="#404040", ec="none"))
    for (x, z), s in zip(cells, h["scores"]):
        ax.add_patch(Rectangle((x - cell / 2, z - cell / 2), cell, cell, fc=SCORE_COLOURS(float(s)), ec="w", lw=0.3))
    for traj in h["others"]:
        ax.plot(traj[:, 0], traj[:, 2], c="#ff69b4", lw=1.2, alpha=0.9)
    ax.plot(h["chosen"][:, 0], h["chosen"][:, 2], c="k", lw=2.4, label="chosen trajectory")
    ax.plot([], [], c="#ff69b4", label="trajectories to other candidates")
    ax.scatter([h["source"][0]], [h["source"][2]], marker="o", s=60, c="w", edgecolors="k", zorder=5, label="foot now")
    ax.scatter([h["preferred"][0]], [h["preferred"][1]], marker="x", s=70, c="#c00000", zorder=5,
               label="preferred footprint")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    sm = fig.colorbar(_scalar_mappable(), ax=ax, shrink=0.8)
    sm.set_label("footprint score (green 1, blue 0)")
    ax.set_title(f"Potential footprints: {len(cells)} candidates, couple score {h['couple_score']:.3f}", fontsize=10)
    ax.legend(fontsize=7, loc="upper left")
    _save(fig, path)


def _scalar_mappable():
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    return ScalarMappable(norm=Normalize(0.0, 1.0), cmap=SCORE_COLOURS)
