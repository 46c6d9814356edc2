"""An independent oracle for the couple search (issue 20, item 4).

(a) :class:`Oracle` is a brute force written apart from the runtime, in plain numpy / scipy /
Python. It imports no planner kernel for scoring or paths: ``planner`` is used only to build the
inputs (``LocalMaps``, ``FootQuery``, ``ScoringWeights``, ``PlannerConfig``) and to call the public
API whose answers are checked (``plan_foot``, and ``harvest_foot`` for every couple). Every step is re-derived from the paper (§4 3D path
construction, §5.1 potential footprints, §5.2 best pair and trajectory scoring) and from the
documented definitions (the field docs of ``planner/_weights.py``, the docstrings of the kernels):

* the foot-shape stencil, the 'size increase' and the dilated elevations (paper Fig. 12);
* the other legs' projections and the other feet as blocked cells (§4, §5.1);
* the potential footprints and their continuous points (the preferred footprint when it lies in
  the cell, else the cell's point nearest to it; a point within a foot's room of another foot, or
  in the preferred footprint's own cell under another leg within a foot's room of that leg, moved
  straight out of that room), the five footprint features and goodnesses;
* the elevation slices (§5.2), the passable cells of each (free, and within the swing's reach of
  the hip), the distance to blocked cells (the documented chamfer metric: octile distance between
  cell centres) and the potential field;
* the wavefront as scipy's Dijkstra, with *every* shortest path enumerated (ties between equal
  paths are explicit: a couple whose paths differ keeps the set of their scores);
* a path sample within ``BORDER_TOL`` of a cell border lies in the cells on both sides (the runtime
  and the oracle compute the samples in different orders of operations, ulps apart): the ground
  under it, so the 3D profile and its jerk, may be either side's, and both are accepted;
* line-of-sight refinement of the naive cells, the Hermite path (Catmull-Rom tangents, then
  halved, then zero), its length, curvature energy and clearance, the climb;
* the 3D height profile (scipy's PCHIP through the elevated waypoints), its length, its climb and
  its geometric jerk; the ten goodnesses and the weighted means.

The exhaustive search must pick the oracle's best couple (same cell, same point, same slice,
same score to ``SCORE_TOL``); couples tied with it are named and any of them is accepted. Every
couple of the runtime's harvest must score as the oracle says, too.

Two disagreements were found, and the runtime was wrong in both (the worked-out scenes at the end of
part (a)): a footprint on the border of its cell was refused when the neighbour across was blocked and
``(x - origin) / cell`` rounded into it; a size-increase cell under another leg became an other-leg
cell, which hid it from the obstacle-proximity term and let a foot land on it, on the box. The oracle
keeps the old conventions as options (``endpoint="floor"``, ``leg_over_size_increase=True``).

A third, on two fresh seeds (jerk 0.4 % apart on a path lifted over a box), was neither side's error: a
sample lay on a row border and the two rounded it into different rows (see ``FIXED_SEEDS``).

(b) each score term on a 5 x 5 grid against numbers worked out by hand (``test_hand_*``): the runtime's
own functions for the term (``harvest_foot``; the goodness and jerk kernels) against literal numbers.
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from conftest import fresh_seeds
from footfall.planner import EXHAUSTIVE, FootQuery, GridFrame, LocalMaps, PlannerConfig, ScoringWeights, harvest_foot, plan_foot
from footfall.planner.layout import FEAT_LEG_GAP

SCORE_TOL = 1e-9  # a score or goodness, dimensionless
METRIC_TOL = 1e-9  # a raw metric (m, rad, or the scale-free energies, relative)
PATH_TIE_TOL = 1e-12  # m: two wavefront costs this close are the same cost (a tie between paths)
POINT_TOL = 1e-12  # m: a footprint moved out of another foot's room, computed in another order of operations
BORDER_TOL = 1e-12  # m: a path sample this close to a cell border lies in the cells on both sides (a tie)
MAX_BORDER_VARIANTS = 64  # assignments of border samples to cells tried per path
SQRT2 = math.sqrt(2.0)

# Documented constants of the path construction (planner/_kernels_foot.py's module constants and
# docstrings), restated here rather than imported.
MIN_STEP_CELLS = 1e-3  # a footprint closer to the source than this (cells) is no step
PUSH_BEYOND_M = 1e-9  # a footprint moved out of another foot's room ends this far beyond it
DENSE_SPACING = 0.35  # target spacing of the Hermite samples (cells)
DENSE_SPACING_MAX = 0.40  # no chord between samples longer than this (cells)
JERK_SAMPLES = 48  # constant arc-length samples of the jerk integral
U_LO, U_HI = 0.05, 0.95  # curvature and jerk are integrated over u in [U_LO, U_HI]
MAX_SLICES = 12
SOURCE_GRACE = 0.5  # x the foot's room: a chord may meet another leg's cell within this of its source

FREE, FORBIDDEN, SIZE_INCREASE, OTHER_LEG = range(4)


# ============================================================================ the oracle's geometry


def cell_of(x, z, ox, oz, cell):
    """planner/_grid.py's documented convention: (x, z) lies in cell (floor((z-oz)/cell), floor((x-ox)/cell))."""
    return int(math.floor((z - oz) / cell)), int(math.floor((x - ox) / cell))


def cell_centre(r, c, ox, oz, cell):
    return ox + (c + 0.5) * cell, oz + (r + 0.5) * cell


def foot_stencil(foot_length, foot_width, foot_yaw, cell):
    """Offsets (dr, dc) of the cells a foot centred anywhere in cell (0, 0) may touch: the square of
    cell (dr, dc) grown by half a cell overlaps the foot rectangle (touching counts)."""
    hx, hz = 0.5 * foot_length, 0.5 * foot_width
    cs, sn = math.cos(foot_yaw), math.sin(foot_yaw)
    ext_x = hx * abs(cs) + hz * abs(sn)
    ext_z = hx * abs(sn) + hz * abs(cs)
    reach = int(math.ceil(math.hypot(hx, hz) / cell)) + 1
    out = []
    for dr in range(-reach, reach + 1):
        for dc in range(-reach, reach + 1):
            dx, dz = dc * cell, dr * cell
            if abs(dx) > cell + ext_x or abs(dz) > cell + ext_z:
                continue  # separated along x or z
            if abs(dx * cs + dz * sn) > hx + cell * (abs(cs) + abs(sn)):
                continue  # along the foot's length
            if abs(-dx * sn + dz * cs) > hz + cell * (abs(sn) + abs(cs)):
                continue  # along its width
            out.append((dr, dc))
    return out


def point_segment_distance(px, pz, ax, az, bx, bz):
    ab = np.array([bx - ax, bz - az])
    ap = np.array([px - ax, pz - az])
    t = 0.0 if ab @ ab == 0 else min(1.0, max(0.0, float(ap @ ab) / float(ab @ ab)))
    return float(math.hypot(ax + t * ab[0] - px, az + t * ab[1] - pz))


def nearest_on_segment(px, pz, ax, az, bx, bz):
    """The point of segment a-b nearest to p."""
    ab = np.array([bx - ax, bz - az])
    t = 0.0 if ab @ ab == 0 else min(1.0, max(0.0, float(np.array([px - ax, pz - az]) @ ab) / float(ab @ ab)))
    return ax + t * ab[0], az + t * ab[1]


def pushed_out(x, z, cx, cz, half, legs, radius, whole_legs):
    """A footprint within ``radius`` of another foot (``whole_legs``: of another leg's hip -> foot
    segment, or a segment of a leg as drawn) moved straight away from the nearest one to ``radius`` +
    PUSH_BEYOND_M; None when that leaves the cell's closed square or comes within ``radius`` of
    another. (The documented rule of ``out_of_other_feet``.) ``legs``: (a, b, fx, fz, ends in a foot)."""
    if not whole_legs:
        legs = [leg for leg in legs if leg[4]]  # a drawn segment's end is no foot

    def nearest(px, pz, leg):
        a, b, fx, fz, _ = leg
        return nearest_on_segment(px, pz, a, b, fx, fz) if whole_legs else (fx, fz)

    near = [(math.hypot(x - qx, z - qz), qx, qz) for qx, qz in (nearest(x, z, leg) for leg in legs)]
    near = [n for n in near if n[0] <= radius]
    if not near:
        return x, z
    d, qx, qz = min(near, key=lambda n: n[0])  # the first of equals
    if d <= 1e-12:
        return None
    nx, nz = qx + (x - qx) * (radius + PUSH_BEYOND_M) / d, qz + (z - qz) * (radius + PUSH_BEYOND_M) / d
    if abs(nx - cx) > half or abs(nz - cz) > half:
        return None
    if any(math.hypot(nx - qx2, nz - qz2) <= radius for qx2, qz2 in (nearest(nx, nz, leg) for leg in legs)):
        return None
    return nx, nz


def proper_crossing(a, b, c, d):
    """Segments a-b and c-d cross at one interior point of both (touching does not count)."""

    def orient(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return orient(a, b, c) * orient(a, b, d) < 0 and orient(c, d, a) * orient(c, d, b) < 0


def segment_clip_to_square(ax, az, bx, bz, x0, x1, z0, z1, tol=0.0):
    """The part of the closed segment a-b in the closed square [x0, x1] x [z0, z1] (grown by ``tol``), as its
    two end points, or None (Liang-Barsky clipping)."""
    t0, t1 = 0.0, 1.0
    for p, q in ((-(bx - ax), ax - (x0 - tol)), (bx - ax, (x1 + tol) - ax),
                 (-(bz - az), az - (z0 - tol)), (bz - az, (z1 + tol) - az)):
        if p == 0.0:
            if q < 0.0:
                return None
            continue
        t = q / p
        if p < 0.0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return None
    return [(ax + t * (bx - ax), az + t * (bz - az)) for t in (t0, t1)]


def segment_touches_square(ax, az, bx, bz, x0, x1, z0, z1, tol=1e-12):
    """The closed segment meets the closed square [x0, x1] x [z0, z1] (Liang-Barsky clipping)."""
    return segment_clip_to_square(ax, az, bx, bz, x0, x1, z0, z1, tol) is not None


def cells_touched(ax, az, bx, bz, ox, oz, cell, n_rows, n_cols):
    """Cells (in the map) whose closed square the segment a-b meets: corners included, so a chain
    of them is 4-connected (the documented 'supercover')."""
    c_lo = int(math.floor((min(ax, bx) - ox) / cell)) - 1
    c_hi = int(math.floor((max(ax, bx) - ox) / cell)) + 1
    r_lo = int(math.floor((min(az, bz) - oz) / cell)) - 1
    r_hi = int(math.floor((max(az, bz) - oz) / cell)) + 1
    out = []
    for r in range(max(r_lo, 0), min(r_hi, n_rows - 1) + 1):
        for c in range(max(c_lo, 0), min(c_hi, n_cols - 1) + 1):
            if segment_touches_square(ax, az, bx, bz, ox + c * cell, ox + (c + 1) * cell, oz + r * cell,
                                      oz + (r + 1) * cell):
                out.append((r, c))
    return out


def cells_walked(ax, az, bx, bz, ox, oz, cell):
    """Grid walk (Amanatides & Woo) from the cell containing a to the cell containing b, by the grid's
    floor convention; a pass through a corner takes both side cells."""
    u0, v0, u1, v1 = (ax - ox) / cell, (az - oz) / cell, (bx - ox) / cell, (bz - oz) / cell
    c, r = math.floor(u0), math.floor(v0)
    c_end, r_end = math.floor(u1), math.floor(v1)
    du, dv = u1 - u0, v1 - v0
    step_c, step_r = (1 if du > 0 else -1), (1 if dv > 0 else -1)
    t_c = ((c + (du > 0)) - u0) / du if du != 0 else math.inf
    t_r = ((r + (dv > 0)) - v0) / dv if dv != 0 else math.inf
    dt_c = abs(1.0 / du) if du != 0 else math.inf
    dt_r = abs(1.0 / dv) if dv != 0 else math.inf
    out = [(r, c)]
    for _ in range(2 * (abs(c_end - c) + abs(r_end - r) + 2)):
        if (r, c) == (r_end, c_end) or (t_c > 1.0 and t_r > 1.0):
            break
        if abs(t_c - t_r) < 1e-9:
            out += [(r + step_r, c), (r, c + step_c)]
            r, c, t_c, t_r = r + step_r, c + step_c, t_c + dt_c, t_r + dt_r
        elif t_c < t_r:
            c, t_c = c + step_c, t_c + dt_c
        else:
            r, t_r = r + step_r, t_r + dt_r
        out.append((r, c))
    return out


def _minmod(forward, backward):
    """The one-sided difference of the smaller size, 0 where the two differ in sign (the documented slope)."""
    return 0.0 if forward * backward <= 0 else min(forward, backward, key=abs)


def octile_distance_map(seeds, cell):
    """Distance (m) from each cell centre to the nearest seed cell centre in the chamfer metric the
    runtime documents (steps of 1 and sqrt 2 cells: octile distance); inf without seeds."""
    n_rows, n_cols = seeds.shape
    out = np.full(seeds.shape, np.inf)
    pts = np.argwhere(seeds)
    if len(pts) == 0:
        return out
    rr, cc = np.mgrid[0:n_rows, 0:n_cols]
    dr = np.abs(rr[..., None] - pts[:, 0])
    dc = np.abs(cc[..., None] - pts[:, 1])
    octile = np.maximum(dr, dc) + (SQRT2 - 1.0) * np.minimum(dr, dc)
    return octile.min(axis=2) * cell


# ============================================================================ the oracle


class Oracle:
    """Every (footprint, slice) couple of one foot, scored from scratch.

    ``endpoint`` says which cell the footprint point T is in when a path is checked: ``"own"`` (the
    default, right) puts T in its own cell, the closed square whose point nearest the preferred
    footprint it is; ``"floor"`` (the runtime's) takes the grid's half-open convention, so a T on the
    high border of its cell is in the next cell. ``leg_over_size_increase`` (the runtime's) turns a
    size-increase cell under another leg into an other-leg cell: it then stops counting for the
    obstacle proximity, and it may take the foot when the preferred footprint lies in it. By default
    (paper §5.1) a size-increase cell never takes a foot and a leg hides no obstacle.
    """

    def __init__(self, maps: LocalMaps, query: FootQuery, weights: ScoringWeights, config: PlannerConfig,
                 slice_size: float, *, endpoint="own", leg_over_size_increase=False):
        self.maps, self.q, self.w, self.cfg = maps, query, weights, config
        self.endpoint = endpoint
        f = maps.frame
        self.ox, self.oz, self.cell = f.origin_x, f.origin_z, f.cell_size
        self.n_rows, self.n_cols = f.shape
        self.elev = np.asarray(maps.elevation, dtype=float)
        self.ground = np.asarray(maps.ground, dtype=float)
        self.forb = np.asarray(maps.forbidden).astype(bool)
        self.src_x, self.src_y, self.src_z = (float(v) for v in query.source)
        self.pref_x, self.pref_z = (float(v) for v in query.preferred)
        self.src_rc = cell_of(self.src_x, self.src_z, self.ox, self.oz, self.cell)
        self._maps(leg_over_size_increase)
        self._candidates()
        self._slices(slice_size)

    # ------------------------------------------------------------------ maps (§4, Fig. 12, §5.1)
    def _maps(self, leg_over_size_increase):
        q, cell = self.q, self.cell
        stencil = foot_stencil(q.foot_length, q.foot_width, q.foot_yaw, cell)
        n_rows, n_cols = self.n_rows, self.n_cols
        code = np.full((n_rows, n_cols), FREE)
        elev_dil = np.empty((n_rows, n_cols))
        boxh_dil = np.zeros((n_rows, n_cols))
        for r in range(n_rows):
            for c in range(n_cols):
                touches = False
                tops, heights = [], [0.0]
                for dr, dc in stencil:
                    r2, c2 = r + dr, c + dc
                    if not (0 <= r2 < n_rows and 0 <= c2 < n_cols):
                        touches = True  # the world's edge counts as forbidden
                        continue
                    tops.append(self.elev[r2, c2])
                    heights.append(self.elev[r2, c2] - self.ground[r2, c2])
                    touches |= bool(self.forb[r2, c2])
                elev_dil[r, c] = max(tops)
                boxh_dil[r, c] = max(heights)
                code[r, c] = FORBIDDEN if self.forb[r, c] else (SIZE_INCREASE if touches else FREE)
        # The other legs (hip -> foot) and the other feet block cells (§4: no leg crossing; §5.1).
        radius = q.feet_block_radius
        for hx, hz, fx, fz, foot in q.kernel_legs:
            cells = cells_touched(hx, hz, fx, fz, self.ox, self.oz, cell, n_rows, n_cols)
            if foot:  # (a segment of a leg as drawn blocks only the cells it passes: no foot ends it)
                for r in range(n_rows):
                    for c in range(n_cols):
                        x, z = cell_centre(r, c, self.ox, self.oz, cell)
                        if math.hypot(x - fx, z - fz) <= radius:
                            cells.append((r, c))
            for r, c in cells:
                if code[r, c] == FREE or (leg_over_size_increase and code[r, c] == SIZE_INCREASE):
                    code[r, c] = OTHER_LEG
        self.code, self.elev_dil, self.boxh_dil = code, elev_dil, boxh_dil
        # Obstacle proximity: distance to the cells where a foot would touch a forbidden box.
        self.proximity = octile_distance_map((code == FORBIDDEN) | (code == SIZE_INCREASE), cell)

    # ------------------------------------------------------------------ potential footprints (§5.1)
    def _candidates(self):
        q, w, cell = self.q, self.w, self.cell
        h = 0.5 * cell
        px, pz = self.pref_x, self.pref_z
        hip_x, hip_z = (float(v) for v in q.hip)
        legs = [(*map(float, leg[:4]), bool(leg[4])) for leg in q.kernel_legs]
        feet = [(fx, fz) for _, _, fx, fz, foot in legs if foot]
        radius = q.feet_block_radius
        weights = np.array([w.footprint_distance, w.footprint_elevation, w.footprint_slope, w.footprint_leg_spacing,
                            w.footprint_obstacle_proximity])
        cands = []
        for r in range(self.n_rows):
            for c in range(self.n_cols):
                if self.code[r, c] not in (FREE, OTHER_LEG) or (r, c) == self.src_rc:
                    continue
                cx, cz = cell_centre(r, c, self.ox, self.oz, cell)
                if math.hypot(cx - px, cz - pz) > self.cfg.search_radius_m:
                    continue  # the candidate disc is a set of cells (their centres in the disc)
                tx, tz = min(max(px, cx - h), cx + h), min(max(pz, cz - h), cz + h)
                other_leg_cell = self.code[r, c] == OTHER_LEG
                if other_leg_cell and (tx, tz) != (px, pz):
                    continue  # a cell under another leg: only the preferred footprint's own
                moved = pushed_out(tx, tz, cx, cz, h, legs, radius, other_leg_cell)
                if moved is None:
                    continue
                tx, tz = moved
                if math.hypot(tx - self.src_x, tz - self.src_z) < MIN_STEP_CELLS * cell:
                    continue
                if math.hypot(tx - hip_x, tz - hip_z) > q.reach_xz:
                    continue
                if any(proper_crossing((hip_x, hip_z), (tx, tz), (a, b), (fx, fz)) for a, b, fx, fz, _ in legs):
                    continue  # the leg would cross another (or a drawn segment of one): refused outright
                gap = min([point_segment_distance(tx, tz, a, b, fx, fz) for a, b, fx, fz, _ in legs]
                          + [point_segment_distance(fx, fz, hip_x, hip_z, tx, tz) for fx, fz in feet],
                          default=math.inf)
                if gap < 0.5 * radius:
                    continue  # half a foot's room from every other leg, both ways (LEG_CLEARANCE)
                if other_leg_cell:
                    # ... and with a foot's room from every leg and foot, both ways.
                    if gap < radius or any(math.hypot(tx - fx, tz - fz) <= radius for fx, fz in feet):
                        continue
                if any(math.hypot(tx - fx, tz - fz) <= radius for fx, fz in feet):
                    continue  # within a foot's room of another foot (whatever its cell)
                assert 0 < r < self.n_rows - 1 and 0 < c < self.n_cols - 1, "a footprint on the map's edge"
                e = self.elev_dil[r, c]
                rough = max(abs(self.elev[r + dr, c + dc] - e) for dr in (-1, 0, 1) for dc in (-1, 0, 1)
                            if (dr, dc) != (0, 0))
                gx = _minmod(self.elev_dil[r, c + 1] - self.elev_dil[r, c], self.elev_dil[r, c] - self.elev_dil[r, c - 1]) / cell
                gz = _minmod(self.elev_dil[r + 1, c] - self.elev_dil[r, c], self.elev_dil[r, c] - self.elev_dil[r - 1, c]) / cell
                slope = math.atan(math.hypot(gx, gz))
                dist = math.hypot(tx - px, tz - pz)
                prox = self.proximity[r, c]
                goodness = np.array([
                    max(0.0, 1.0 - dist / w.distance_scale_m),
                    max(0.0, 1.0 - rough / w.step_critical_m),
                    max(0.0, 1.0 - slope / w.slope_critical_rad),
                    min(1.0, gap / w.leg_spacing_ref_m),
                    min(1.0, prox / w.proximity_ref_m),
                ])
                cands.append(dict(cell=(r, c), point=(tx, tz), features=(dist, rough, slope, gap, prox),
                                  terms=goodness, score=float(weights @ goodness / weights.sum())))
        self.candidates = cands

    # ------------------------------------------------------------------ slices (§5.2)
    def _slices(self, slice_size):
        eps = self.cfg.slice_epsilon_m
        levels = [math.inf]
        heights = np.sort(self.boxh_dil[(self.code == FREE) & (self.boxh_dil > eps)])
        if slice_size > 0 and heights.size:
            last = 0
            k = int(math.ceil(heights[-1] / slice_size))
            while k >= 0 and len(levels) < MAX_SLICES:
                blocked = int((heights > k * slice_size + eps).sum())
                if blocked > last:
                    levels.append(k * slice_size)
                    last = blocked
                k -= 1
        self.levels = levels

    # ------------------------------------------------------------------ one slice: passable, distance, wavefront (§4)
    def _slice(self, level):
        eps, cell = self.cfg.slice_epsilon_m, self.cell
        ok = (self.code == FREE) & (self.boxh_dil <= level + eps)
        # A swing stays within its leg's reach of the hip it lands under (or as far as the source,
        # if further), grown by half a cell's diagonal: cells beyond are not passed, yet block nothing.
        hip_x, hip_z = (float(v) for v in self.q.hip)
        radius = max(self.q.reach_xz, math.hypot(self.src_x - hip_x, self.src_z - hip_z)) + 0.5 * SQRT2 * cell
        centres = np.array([[cell_centre(r, c, self.ox, self.oz, cell) for c in range(self.n_cols)]
                            for r in range(self.n_rows)])
        in_reach = np.hypot(centres[..., 0] - hip_x, centres[..., 1] - hip_z) <= radius
        passable = ok & in_reach
        passable[self.src_rc] = True
        clearance = octile_distance_map(~ok, cell)  # distance to the blocked cells of this slice
        rng = self.cfg.potential_range_m
        factor = np.where(clearance < rng, 1.0 + self.cfg.potential_gain * (1.0 - clearance / rng) ** 2, 1.0)
        goal_only = np.zeros_like(ok)
        for cand in self.candidates:
            if self.boxh_dil[cand["cell"]] <= level + eps and not passable[cand["cell"]]:
                goal_only[cand["cell"]] = True  # a footprint next to another leg: reached, never passed through
        n_rows, n_cols = ok.shape
        idx = np.arange(n_rows * n_cols).reshape(n_rows, n_cols)
        rows, cols, costs = [], [], []
        for r, c in itertools.product(range(n_rows), range(n_cols)):
            if not passable[r, c]:
                continue
            for dr, dc in itertools.product((-1, 0, 1), repeat=2):
                r2, c2 = r + dr, c + dc
                if (dr, dc) == (0, 0) or not (0 <= r2 < n_rows and 0 <= c2 < n_cols):
                    continue
                if not (passable[r2, c2] or goal_only[r2, c2]):
                    continue
                if dr and dc and not (passable[r + dr, c] and passable[r, c + dc]):
                    continue  # no corner cutting
                rows.append(idx[r, c])
                cols.append(idx[r2, c2])
                costs.append(cell * (SQRT2 if dr and dc else 1.0) * factor[r2, c2])
        graph = csr_matrix((costs, (rows, cols)), shape=(idx.size, idx.size))
        dist = dijkstra(graph, directed=True, indices=idx[self.src_rc]).reshape(n_rows, n_cols)
        return dict(level=level, passable=passable, clearance=clearance, dist=dist, graph=graph)

    def _shortest_paths(self, sl, target, cap=4000):
        """Every shortest naive path (list of cells) from the source to ``target`` (ties explicit)."""
        graph, dist = sl["graph"].tocsc(), sl["dist"].ravel()
        n_cols = self.n_cols
        src = self.src_rc[0] * n_cols + self.src_rc[1]
        preds = {}

        def pred(v):
            if v not in preds:
                lo, hi = graph.indptr[v], graph.indptr[v + 1]
                preds[v] = [int(u) for u, cost in zip(graph.indices[lo:hi], graph.data[lo:hi])
                            if abs(dist[u] + cost - dist[v]) <= PATH_TIE_TOL]
            return preds[v]

        paths = []
        stack = [(target[0] * n_cols + target[1], [])]
        while stack:
            v, tail = stack.pop()
            if v == src:
                paths.append([divmod(u, n_cols) for u in [v] + tail])
                if len(paths) > cap:
                    raise RuntimeError("too many tied shortest paths")
                continue
            for u in pred(v):
                stack.append((u, [v] + tail))
        return paths

    def _clear(self, ax, az, bx, bz, passable, to_target):
        """Line of sight a -> b through passable cells (the source cell is always allowed)."""
        if not to_target:
            cells = cells_touched(ax, az, bx, bz, self.ox, self.oz, self.cell, self.n_rows, self.n_cols)
        elif self.endpoint == "floor":
            # The walk ends in the cell that contains T by the grid's floor convention.
            cells = cells_walked(ax, az, bx, bz, self.ox, self.oz, self.cell)
        else:
            # T belongs to its own (closed) cell: cells the chord meets only at T do not count.
            d = math.hypot(bx - ax, bz - az)
            back = 1e-9 / d if d > 0 else 0.0
            cells = cells_touched(ax, az, bx - back * (bx - ax), bz - back * (bz - az), self.ox, self.oz, self.cell,
                                  self.n_rows, self.n_cols)
        out = 1
        for r, c in cells:
            if not (0 <= r < self.n_rows and 0 <= c < self.n_cols):
                return 0
            if (r, c) != self.src_rc and not passable[r, c]:
                if not self._in_source_grace(ax, az, bx, bz, r, c):
                    return 0
                out = 2
        return out

    def _in_source_grace(self, ax, az, bx, bz, r, c):
        """Cell (r, c) is another leg's or foot's, and the chord a-b meets its closed square only within the
        source's grace (SOURCE_GRACE x the foot's room: the standing foot's half-diagonal) of the source."""
        if self.code[r, c] != OTHER_LEG:
            return False
        x0, z0 = self.ox + c * self.cell, self.oz + r * self.cell
        clip = segment_clip_to_square(ax, az, bx, bz, x0, x0 + self.cell, z0, z0 + self.cell)
        grace = SOURCE_GRACE * self.q.feet_block_radius
        return clip is not None and all(math.hypot(x - self.src_x, z - self.src_z) <= grace for x, z in clip)

    def _kept(self, naive_cells, target_pt, passable):
        """Refine the naive cells by line of sight: from each kept point, the farthest visible one."""
        pts = [(self.src_x, self.src_z)]
        pts += [cell_centre(r, c, self.ox, self.oz, self.cell) for r, c in naive_cells[1:-1]]
        pts.append(target_pt)
        kept, i = [0], 0
        last = len(pts) - 1
        while i < last:
            j = last
            while j > i + 1 and not self._clear(*pts[i], *pts[j], passable, j == last):
                j -= 1
            kept.append(j)
            i = j
        return tuple(pts[k] for k in kept)

    def _sample_cell(self, x, z, is_target, target_cell):
        if is_target and self.endpoint == "own":
            return target_cell
        return cell_of(x, z, self.ox, self.oz, self.cell)

    def _path_2d(self, kept, passable, target_cell):
        """The Hermite path through the kept points: the first of tau = 1, 1/2, 0 (Catmull-Rom tangents
        times tau) whose samples stay in the map and whose chords are short and clear."""
        cell = self.cell
        kept = np.asarray(kept)
        nk = len(kept)
        for tau in (1.0, 0.5, 0.0):
            samples = []
            for i in range(nk - 1):
                p0, p1 = kept[i], kept[i + 1]
                t0 = (p1 - p0) if i == 0 else 0.5 * (p1 - kept[i - 1])
                t1 = (p1 - p0) if i == nk - 2 else 0.5 * (kept[i + 2] - p0)
                t0, t1 = tau * t0, tau * t1
                est = np.linalg.norm(p1 - p0) + (np.linalg.norm(t0) + np.linalg.norm(t1)) / 3.0
                m = max(1, math.ceil(est / (DENSE_SPACING * cell)))
                ts = np.arange(m + 1 if i == nk - 2 else m) / m
                basis = np.stack([2 * ts**3 - 3 * ts**2 + 1, ts**3 - 2 * ts**2 + ts, -2 * ts**3 + 3 * ts**2,
                                  ts**3 - ts**2], axis=1)
                samples.append(basis @ np.stack([p0, t0, p1, t1]))
            dense = np.concatenate(samples)
            dense[-1] = kept[-1]
            n = len(dense)
            cells = [self._sample_cell(x, z, i == n - 1, target_cell) for i, (x, z) in enumerate(dense)]
            if any(not (0 <= r < self.n_rows and 0 <= c < self.n_cols) for r, c in cells):
                continue
            chords = np.linalg.norm(np.diff(dense, axis=0), axis=1)
            if (chords > DENSE_SPACING_MAX * cell).any():
                continue
            clear = [self._clear(*dense[i - 1], *dense[i], passable, i == n - 1) for i in range(1, n)]
            if all(clear):
                return dense, cells, 2 in clear
        return None, None, False

    def _border_assignments(self, dense, cells):
        """Every assignment of the samples to cells, the documented one first: a sample within BORDER_TOL of
        a cell border lies in the cells on both sides (the last sample stays in the footprint's cell)."""
        choices = []
        for i, ((x, z), own) in enumerate(zip(dense, cells)):
            near = {own}
            if i < len(dense) - 1:
                for dx, dz in itertools.product((-BORDER_TOL, 0.0, BORDER_TOL), repeat=2):
                    r, c = cell_of(x + dx, z + dz, self.ox, self.oz, self.cell)
                    if 0 <= r < self.n_rows and 0 <= c < self.n_cols:
                        near.add((r, c))
            choices.append([own] + sorted(near - {own}))
        ambiguous = [i for i, ch in enumerate(choices) if len(ch) > 1]
        yield list(cells)
        for picks in itertools.islice(itertools.product(*(choices[i] for i in ambiguous)), 1, MAX_BORDER_VARIANTS):
            alt = list(cells)
            for i, rc in zip(ambiguous, picks):
                alt[i] = rc
            yield alt

    def _couple(self, cand, sl, kept):
        """The couple (cand, slice) along the path through ``kept``: one variant per assignment of its
        samples to cells (:meth:`_border_assignments`), [None] when no 2D path fits."""
        passable = sl["passable"].copy()
        passable[cand["cell"]] = True  # the path may end in its target (a goal-only cell too)
        dense, cells, graced = self._path_2d(kept, passable, cand["cell"])
        if dense is None or len(dense) < 2:
            return [None]
        last = len(kept) - 1
        graced |= any(self._clear(*kept[i], *kept[i + 1], passable, i + 1 == last) == 2 for i in range(last))
        legs = [leg[:4] for leg in self.q.kernel_legs]
        if graced and any(proper_crossing(dense[i], dense[i + 1], (hx, hz), (fx, fz))
                          for i in range(len(dense) - 1) for hx, hz, fx, fz in legs):
            return [None]  # a path clear only by its source's grace crosses no other leg
        return [self._couple_along(cand, sl, kept, passable, dense, alt)
                for alt in self._border_assignments(dense, cells)]

    def _couple_along(self, cand, sl, kept, passable, dense, cells):
        """Raw metrics and terms of the couple (cand, slice) along the 2D path ``dense``, its samples in ``cells``."""
        cell, cfg, q, w = self.cell, self.cfg, self.q, self.w
        n = len(dense)
        chords = np.linalg.norm(np.diff(dense, axis=0), axis=1)
        cum = np.concatenate([[0.0], np.cumsum(chords)])
        length2d = cum[-1]
        # Clearance: the least distance to a blocked cell over the interior samples, but for those in the
        # source's or the footprint's own cell when that cell is blocked (they are at 0 by definition).
        # The same for samples in a cell of another leg that the source's grace lets the path pass.
        own = {self.src_rc, cells[-1]}
        grace = SOURCE_GRACE * q.feet_block_radius

        def graced(i):
            return (self.code[cells[i]] == OTHER_LEG and not passable[cells[i]]
                    and math.hypot(dense[i][0] - self.src_x, dense[i][1] - self.src_z) <= grace)

        clear = min((sl["clearance"][cells[i]] for i in range(1, n - 1)
                     if not ((cells[i] in own or graced(i)) and sl["clearance"][cells[i]] == 0.0)),
                    default=sl["clearance"][cells[-1]])
        # Curvature energy E = L * integral kappa^2 ds, kappa = turning angle / mean adjacent chord.
        integral = 0.0
        for i in range(1, n - 1):
            if not (U_LO <= cum[i] / length2d <= U_HI):
                continue
            a, b = dense[i] - dense[i - 1], dense[i + 1] - dense[i]
            if chords[i - 1] <= 0 or chords[i] <= 0:
                continue
            theta = math.atan2(a[0] * b[1] - a[1] * b[0], a @ b)
            integral += theta**2 / (0.5 * (chords[i - 1] + chords[i]))
        curvature = length2d * integral
        # Ground under the path: the highest dilated elevation over the sample's cell and the passable cells
        # around it (every point of a chord lies in passable cells of both end samples' blocks).
        ground = np.empty(n)
        for i, (r, c) in enumerate(cells):
            g = self.elev_dil[r, c]
            for dr, dc in itertools.product((-1, 0, 1), repeat=2):
                r2, c2 = r + dr, c + dc
                if 0 <= r2 < self.n_rows and 0 <= c2 < self.n_cols and (passable[r2, c2] or (r2, c2) == self.src_rc):
                    g = max(g, self.elev_dil[r2, c2])
            ground[i] = g
        source_y, target_y = self.src_y, self.elev_dil[cand["cell"]]
        base = max(source_y, target_y) + q.step_height
        climb2 = max(0.0, ground[1:-1].max(initial=-np.inf) - base)
        # 3D: a shape-preserving (PCHIP) height profile through waypoints lifted over the ground + margin.
        total = length2d if length2d > 0 else 1.0
        u = cum / total
        n_wp = min(n, max(3, math.ceil(length2d / (2 * cell)) + 1)) if n >= 3 else n
        idx = [round(j * (n - 1) / (n_wp - 1)) for j in range(n_wp)]
        wy = []
        for j, i in enumerate(idx):
            if j == 0:
                wy.append(source_y)
            elif j == n_wp - 1:
                wy.append(target_y)
            else:
                y = source_y + (target_y - source_y) * u[i] + q.step_height * 4 * u[i] * (1 - u[i])
                lo, hi = max(1, idx[j - 1]), min(n - 2, idx[j + 1])
                wy.append(max(y, ground[lo:hi + 1].max() + cfg.obstacle_margin_m))
        y = PchipInterpolator(u[idx], wy)(u)
        y[1:-1] = np.maximum(y[1:-1], ground[1:-1] + cfg.obstacle_margin_m)
        top = y[1:-1].max(initial=-np.inf)
        y[0], y[-1] = source_y, target_y
        poly = np.column_stack([dense[:, 0], y, dense[:, 1]])
        climb3 = max(0.0, top - base)
        jerk = geometric_jerk(poly)
        # Directness: the ground path against the straight distance to the couple's own footprint.
        d_ref = max(math.hypot(cand["point"][0] - self.src_x, cand["point"][1] - self.src_z), cell)
        traj2 = np.array([d_ref / max(length2d, d_ref), 1 / (1 + curvature / w.curvature_energy_ref),
                          min(1.0, clear / w.clearance_ref_m), 1 / (1 + climb2 / w.climb_ref_m), 1.0])
        traj3 = np.array([d_ref / max(length2d, d_ref), 1 / (1 + curvature / w.curvature_energy_ref),
                          min(1.0, clear / w.clearance_ref_m), 1 / (1 + climb3 / w.climb_ref_m),
                          1 / (1 + jerk / w.jerk_ref)])
        weights = w.to_array()[:10]
        terms = np.concatenate([cand["terms"], traj3])
        return dict(raw=(length2d, curvature, clear, climb3, jerk), terms=terms,
                    score=float(weights @ terms / weights.sum()),
                    score_2d=float(weights @ np.concatenate([cand["terms"], traj2]) / weights.sum()), kept=kept)

    def couples(self):
        """[(candidate, slice index, variants)] for every (candidate, slice) whose target the slice's
        wavefront reaches. Ties are explicit: the variants are the couples of the distinct refined paths of
        all the tied shortest naive paths (and of each path's samples on a cell border, in the cells on either
        side), None for one that yields no valid 2D path."""
        out = []
        eps = self.cfg.slice_epsilon_m
        for s, level in enumerate(self.levels):
            sl = self._slice(level)
            for cand in self.candidates:
                if self.boxh_dil[cand["cell"]] > level + eps or not np.isfinite(sl["dist"][cand["cell"]]):
                    continue
                passable = sl["passable"].copy()
                passable[cand["cell"]] = True
                kepts = {self._kept(p, cand["point"], passable) for p in self._shortest_paths(sl, cand["cell"])}
                out.append((cand, s, [v for k in sorted(kepts) for v in self._couple(cand, sl, k)]))
        return out


def geometric_jerk(poly):
    """J = L^3 * integral over u in [U_LO, U_HI] of |d^3 x / ds^3|^2 ds, from JERK_SAMPLES samples at constant
    arc length (third differences)."""
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])
    length = cum[-1]
    if length <= 0:
        return 0.0
    s = length * np.arange(JERK_SAMPLES) / (JERK_SAMPLES - 1)
    x = np.column_stack([np.interp(s, cum, poly[:, d]) for d in range(3)])
    x[0], x[-1] = poly[0], poly[-1]
    h = length / (JERK_SAMPLES - 1)
    k = np.arange(1, JERK_SAMPLES - 2)
    u = k / (JERK_SAMPLES - 1)
    k = k[(u >= U_LO) & (u <= U_HI)]
    third = (x[k + 2] - 3 * x[k + 1] + 3 * x[k] - x[k - 1]) / h**3
    return float(length**3 * (third**2).sum() * h)


# ============================================================================ (a) random small cases

N = 14  # cells per side: with the default radius (4 cells) and margin (6 cells) the search's region of
CELL = 0.07  # interest is the whole map when the preferred footprint's cell is in rows/cols 3..10.
# Every seed that ever failed joins: 1580367954, a pushed point 1 ulp apart; 251713580 and 587286411, a path
# sample on a cell border (z 3.7e-16 m past it), in one cell for the runtime and in the next for the oracle,
# so the ground under it and the jerk differed (0.4 %): ties now, BORDER_TOL.
FIXED_SEEDS = tuple(range(40)) + (1580367954, 251713580, 587286411)
N_FRESH = 10


def random_case(rng):
    """A tiny map (terrain, forbidden and safe boxes as cell blocks), a foot on free ground near the
    middle, a preferred footprint (often behind a wall, so paths go around or over), up to two other
    legs (one often passing by the preferred footprint), and random weights (or the defaults)."""
    ox, oz = (float(v) for v in rng.uniform(-3.0, 3.0, size=2))
    frame = GridFrame(ox, oz, CELL, N, N)
    xs, zs = np.meshgrid(ox + (np.arange(N) + 0.5) * CELL, oz + (np.arange(N) + 0.5) * CELL)
    kind = rng.integers(3)
    if kind == 0:
        ground = np.zeros((N, N))
    elif kind == 1:
        ground = rng.uniform(-0.2, 0.2) * (xs - ox) + rng.uniform(-0.2, 0.2) * (zs - oz)
    else:
        ground = 0.03 * np.sin((xs - ox) * rng.uniform(3, 12)) * np.cos((zs - oz) * rng.uniform(3, 12))
    elevation = ground.copy()
    forbidden = np.zeros((N, N), np.uint8)

    def box(rows, cols):
        block = (slice(max(rows[0], 0), rows[1]), slice(max(cols[0], 0), cols[1]))
        top = ground[block].max() + rng.uniform(0.01, 0.3)
        elevation[block] = np.maximum(elevation[block], top)
        if rng.random() < 0.4:
            forbidden[block] = 1

    for _ in range(int(rng.integers(0, 3))):
        r0, c0 = (int(v) for v in rng.integers(1, N - 2, size=2))
        hr, hc = (int(v) for v in rng.integers(1, 4, size=2))
        box((r0, r0 + hr), (c0, c0 + hc))
    long_foot = rng.random() < 0.25
    foot_length = float(rng.uniform(0.02, 0.16 if long_foot else 0.08))
    foot_width = float(rng.uniform(0.02, 0.05))
    foot_yaw = float(rng.uniform(-math.pi, math.pi))

    def free_cells(rows, cols):
        probe = FootQuery(source=(ox + 0.5, 0.0, oz + 0.5), preferred=(0, 0), hip=(0, 0), reach_xz=1.0,
                          step_height=0.0, foot_length=foot_length, foot_width=foot_width, foot_yaw=foot_yaw)
        o = Oracle(LocalMaps(frame, elevation, ground, forbidden), probe, ScoringWeights(), PlannerConfig(), -1.0)
        return [(r, c) for r in rows for c in cols if o.code[r, c] == FREE and o.boxh_dil[r, c] <= 0.0], o

    free, _ = free_cells(range(5, 9), range(5, 9))
    if not free:
        return None
    r, c = free[rng.integers(len(free))]
    sx = ox + (c + rng.uniform(0.05, 0.95)) * CELL
    sz = oz + (r + rng.uniform(0.05, 0.95)) * CELL
    heading = rng.uniform(-math.pi, math.pi)
    d = rng.uniform(0.03, 0.21)
    px, pz = sx + d * math.cos(heading), sz + d * math.sin(heading)
    pr, pc = cell_of(px, pz, ox, oz, CELL)
    if not (3 <= pr <= 10 and 3 <= pc <= 10):
        return None
    if rng.random() < 0.5:
        # A wall across the way, half-way to the preferred footprint.
        mr, mc = cell_of(0.5 * (sx + px), 0.5 * (sz + pz), ox, oz, CELL)
        k = int(rng.integers(1, 3))
        if abs(math.cos(heading)) > abs(math.sin(heading)):
            box((mr - k, mr + k + 1), (mc, mc + 1))
        else:
            box((mr, mr + 1), (mc - k, mc + k + 1))
        free, _ = free_cells([r], [c])
        if not free:
            return None
    _, o = free_cells([], [])
    sy = float(o.elev_dil[r, c])
    hip = (sx - 0.2 * math.cos(heading + 0.5), sz - 0.2 * math.sin(heading + 0.5))
    radius = math.hypot(foot_length, foot_width)
    legs = []
    for i in range(int(rng.integers(0, 3))):
        for _try in range(20):
            if i == 0 and rng.random() < 0.6:
                # A leg passing the preferred footprint at about a foot's room, beyond it.
                ex, ez = px - hip[0], pz - hip[1]
                a = math.atan2(ez, ex) + rng.uniform(-1.2, 1.2)
                off = radius * rng.uniform(1.02, 1.5)
                qx, qz = px + off * math.cos(a), pz + off * math.sin(a)
                side = rng.choice([-1.0, 1.0])
                tx, tz = -side * math.sin(a), side * math.cos(a)
                fx, fz = qx + tx * rng.uniform(0.0, 0.06), qz + tz * rng.uniform(0.0, 0.06)
                hx, hz = qx - tx * rng.uniform(0.15, 0.35), qz - tz * rng.uniform(0.15, 0.35)
            else:
                hx, hz = hip[0] + rng.uniform(-0.1, 0.1), hip[1] + rng.uniform(-0.1, 0.1)
                fx, fz = hx + rng.uniform(-0.4, 0.4), hz + rng.uniform(-0.4, 0.4)
            # The source's own cell stays clear of the leg and of its foot's room.
            cx, cz = cell_centre(r, c, ox, oz, CELL)
            if ((r, c) not in cells_touched(hx, hz, fx, fz, ox, oz, CELL, N, N)
                    and math.hypot(cx - fx, cz - fz) > radius):
                legs.append((hx, hz, fx, fz))
                break
    query = FootQuery(source=(sx, sy, sz), preferred=(px, pz), hip=hip,
                      reach_xz=float(rng.choice([0.7, 0.7, 0.25])), step_height=float(rng.uniform(0.02, 0.1)),
                      foot_length=foot_length, foot_width=foot_width, foot_yaw=foot_yaw,
                      other_legs=np.array(legs).reshape(-1, 4))
    if rng.random() < 0.25:
        weights = ScoringWeights()
    else:
        names = ("footprint_distance", "footprint_elevation", "footprint_slope", "footprint_leg_spacing",
                 "footprint_obstacle_proximity", "trajectory_length", "trajectory_curvature", "trajectory_clearance",
                 "trajectory_climb", "trajectory_jerk")
        weights = ScoringWeights(**{n: float(v) for n, v in zip(names, rng.uniform(0.1, 3.0, size=10))})
    # Some legs are also drawn with a knee bowed off their straight line (a tilted body's legs:
    # planner._crowd.drawn_leg_segments), as two segments that end in no foot. (Drawn last: the
    # rest of the case is what it was before drawn segments existed.)
    drawn = []
    for hx, hz, fx, fz in legs:
        if rng.random() < 0.5:
            continue
        # bowed toward the preferred footprint mostly, where it can refuse a footprint
        ln = max(math.hypot(fx - hx, fz - hz), 1e-9)
        toward = math.copysign(1.0, (fx - hx) * (pz - hz) - (fz - hz) * (px - hx))
        t, bow = rng.uniform(0.3, 0.9), toward * rng.uniform(-0.02, 0.08)
        kx, kz = hx + t * (fx - hx) - bow * (fz - hz) / ln, hz + t * (fz - hz) + bow * (fx - hx) / ln
        if ((r, c) not in cells_touched(hx, hz, kx, kz, ox, oz, CELL, N, N) + cells_touched(kx, kz, fx, fz, ox, oz, CELL, N, N)):
            drawn += [(hx, hz, kx, kz), (kx, kz, fx, fz)]
    query = dataclasses.replace(query, drawn_segments=np.array(drawn).reshape(-1, 4))
    return LocalMaps(frame, elevation, ground, forbidden), query, weights


def draw_case(seed, border=False):
    """:func:`random_case` of ``seed``; with ``border``, turned by :func:`border_case` (its own stream)."""
    rng = np.random.default_rng(seed)
    while True:
        case = random_case(rng)
        if case is not None:
            return border_case(*case, np.random.default_rng([seed, 7])) if border else case


def border_case(maps, query, weights, rng):
    """The case with its foot moved 0.1 mm inside a border of its cell and, across that border, another
    foot whose room takes the neighbouring cell, so that a swing may graze that cell beside its source
    (planner._kernels_foot.SOURCE_GRACE; a foot planned onto a cell's border stands there next). The
    source's own cell stays clear of the new leg and of its foot's room, as in :func:`random_case`."""
    f = maps.frame
    ox, oz = f.origin_x, f.origin_z
    sx, sy, sz = (float(v) for v in query.source)
    r, c = cell_of(sx, sz, ox, oz, CELL)
    axis, side = int(rng.integers(2)), float(rng.choice([-1.0, 1.0]))
    if axis == 0:
        sx = ox + (c + (side > 0)) * CELL - side * 1e-3
        nr, nc = r, c + int(side)
    else:
        sz = oz + (r + (side > 0)) * CELL - side * 1e-3
        nr, nc = r + int(side), c
    query = dataclasses.replace(query, source=(sx, sy, sz))
    radius = query.feet_block_radius
    nx, nz = cell_centre(nr, nc, ox, oz, CELL)
    cx, cz = cell_centre(r, c, ox, oz, CELL)
    for _try in range(20):
        away, along = 0.7 * radius * rng.uniform(0.0, 1.0, size=2) * (1.0, rng.choice([-1.0, 1.0]))
        fx, fz = (nx + side * away, nz + along) if axis == 0 else (nx + along, nz + side * away)
        a = math.atan2(fz - sz, fx - sx) + rng.uniform(-0.8, 0.8)
        length = rng.uniform(0.15, 0.35)
        hx, hz = fx + length * math.cos(a), fz + length * math.sin(a)
        if ((r, c) not in cells_touched(hx, hz, fx, fz, ox, oz, CELL, N, N)
                and math.hypot(cx - fx, cz - fz) > radius):
            legs = np.vstack([query.other_legs.reshape(-1, 4), [[hx, hz, fx, fz]]])
            return maps, dataclasses.replace(query, other_legs=legs), weights
    return maps, query, weights


def _describe(couple):
    cand, s, variants = couple
    scores = ["none" if v is None else f"{v['score']:.12f}" for v in variants]
    return f"cell {cand['cell']} point {cand['point']} slice {s}: {' | '.join(scores)}"


def roi_is_the_map(maps, query, config):
    """The search's region of interest (the bounding box of the source and of the candidate disc, grown
    by roi_margin_cells: planner/_kernels_foot.py) covers the whole map, which the oracle works on."""
    f = maps.frame
    rad, margin = math.ceil(config.search_radius_m / f.cell_size), config.roi_margin_cells
    s = cell_of(query.source[0], query.source[2], f.origin_x, f.origin_z, f.cell_size)
    p = cell_of(query.preferred[0], query.preferred[1], f.origin_x, f.origin_z, f.cell_size)
    return all(min(s[i], p[i] - rad) - margin <= 0 and max(s[i], p[i] + rad) + margin >= f.shape[i] - 1
               for i in (0, 1))


@functools.lru_cache(maxsize=None)
def _search_and_oracle(seed, border=False):
    maps, query, weights = draw_case(seed, border)
    config = PlannerConfig()
    assert roi_is_the_map(maps, query, config), f"seed {seed}: the case is larger than the search's region"
    oracle = Oracle(maps, query, weights, config, EXHAUSTIVE.slice_size_m)
    result = plan_foot(maps, query, weights=weights, budget=EXHAUSTIVE, config=config)
    return maps, query, weights, oracle, oracle.couples(), result


@pytest.mark.parametrize("border", (False, True), ids=("plain", "border"))
@pytest.mark.parametrize("seed", fresh_seeds(FIXED_SEEDS, N_FRESH, salt=20))
def test_exhaustive_search_picks_the_oracles_best_couple(seed, border):
    """The exhaustive search's couple is the oracle's argmax: same cell, point, slice and score; its
    breakdown and raw metrics are the oracle's. Ties are explicit: couples within SCORE_TOL of the best
    are all acceptable, and a couple with tied shortest paths may score any of its paths' scores.
    ``border``: the case's foot on a border of its cell, another foot's room across it
    (:func:`border_case`; a quarter of them have a path that grazes that room beside its source)."""
    _, _, _, oracle, couples, result = _search_and_oracle(seed, border)
    where = f"seed {seed}" + (" (border case)" if border else "")

    def lo(variants):  # the couple's score whichever tied path the search follows (-inf: maybe no path)
        return min(-math.inf if v is None else v["score"] for v in variants)

    possible = [c for c in couples if any(v is not None for v in c[2])]
    if not possible:
        # No couple: the search agrees, or its boxed-in foot's way out found one (planner._kernels_foot.
        # BOXED_CELL_COST: a fallback through other feet's room, which the oracle does not model).
        assert not result.valid or result.counters["boxed_ways"] == 1, \
            f"{where}: the oracle has no couple, the search found {result.target_cell}"
        return
    best = max(lo(c[2]) for c in couples)
    if not result.valid:
        assert best == -math.inf, f"{where}: no couple found; the oracle's best is {best}"
        return
    mine = [c for c in couples if c[0]["cell"] == result.target_cell and c[1] == result.slice_index]
    assert len(mine) == 1, f"{where}: the search's couple {result.target_cell}, slice {result.slice_index} " \
                           f"is none of the oracle's"
    cand, s, variants = mine[0]
    matching = [v for v in variants if v is not None and abs(v["score"] - result.couple_score) <= SCORE_TOL]
    assert matching, f"{where}: the search scores {result.couple_score:.12f}, the oracle {_describe(mine[0])}"
    winners = [c for c in couples if max(-math.inf if v is None else v["score"] for v in c[2]) >= best - SCORE_TOL]
    assert result.couple_score >= best - SCORE_TOL, (
        f"{where}: the search picked {_describe(mine[0])} but the oracle's best is "
        + "; ".join(_describe(c) for c in winners))
    v = matching[0]
    # Same point (the continuous footprint), same slice level, same breakdown and raw metrics.
    assert (result.target[0], result.target[2]) == pytest.approx(cand["point"], rel=0, abs=POINT_TOL), where
    assert result.target[1] == oracle.elev_dil[cand["cell"]], where
    assert result.slice_level_m == oracle.levels[s], where
    assert abs(result.footprint_score - cand["score"]) <= SCORE_TOL, where
    np.testing.assert_allclose(list(result.breakdown.values()), v["terms"], rtol=0, atol=SCORE_TOL, err_msg=where)
    np.testing.assert_allclose(list(result.metrics.values()), v["raw"], rtol=METRIC_TOL, atol=METRIC_TOL,
                               err_msg=where)


@pytest.mark.parametrize("border", (False, True), ids=("plain", "border"))
@pytest.mark.parametrize("seed", fresh_seeds(FIXED_SEEDS, N_FRESH, salt=21))
def test_every_couple_scores_as_the_oracle_says(seed, border):
    """Not only the winner: every candidate (cell, point, features, goodnesses, footprint score), the
    slice levels, and every (candidate, slice) couple of the runtime's harvest (valid or not, its score)
    are the oracle's (``border``: as in the test above)."""
    maps, query, weights, oracle, couples, _ = _search_and_oracle(seed, border)
    where = f"seed {seed}" + (" (border case)" if border else "")
    h = harvest_foot(maps, query, weights=weights, budget=EXHAUSTIVE, config=PlannerConfig())
    mine = {c["cell"]: c for c in oracle.candidates}
    theirs = {(int(r), int(c)): k for k, (r, c) in enumerate(h.cand_cells)}
    assert set(theirs) == set(mine), f"{where}: candidates only the runtime has {sorted(set(theirs) - set(mine))}, " \
                                     f"only the oracle {sorted(set(mine) - set(theirs))}"
    for cell, k in theirs.items():
        cand = mine[cell]
        assert (h.cand_xyz[k, 0], h.cand_xyz[k, 2]) == pytest.approx(cand["point"], rel=0, abs=POINT_TOL), \
            f"{where}: point of {cell}"
        np.testing.assert_allclose(h.cand_features[k], cand["features"], rtol=METRIC_TOL, atol=METRIC_TOL,
                                   err_msg=f"{where}: features of {cell}")
        np.testing.assert_allclose(h.cand_terms[k], cand["terms"], rtol=0, atol=SCORE_TOL, err_msg=f"{where}: {cell}")
        assert abs(h.cand_scores[k] - cand["score"]) <= SCORE_TOL, f"{where}: footprint score of {cell}"
    assert list(h.levels) == oracle.levels, where
    by_key = {(c[0]["cell"], c[1]): c for c in couples}
    for cell, k in theirs.items():
        for s in range(len(oracle.levels)):
            couple = by_key.get((cell, s))
            if not h.couple_valid[k, s]:
                assert couple is None or None in couple[2], f"{where}: the runtime finds no path for " \
                                                            f"{_describe(couple)}"
                continue
            assert couple is not None, f"{where}: the runtime has a couple {cell} slice {s}, the oracle none"
            score = h.couple_scores[k, s, 0]
            assert any(v is not None and abs(v["score"] - score) <= SCORE_TOL for v in couple[2]), \
                f"{where}: the runtime scores {score:.12f}, the oracle {_describe(couple)}"


# ---------------------------------------------------------------------------- disagreements (fixed)


def _wall_scene(ox=0.0, mirror=False):
    """14 x 14 cells of 7 cm, flat; a forbidden wall in column 10 (rows 4..10) and, with the foot's
    3 x 3 stencil, size-increase cells in columns 9 and 11. The foot stands at the centre of cell (7, 5)
    and prefers (ox + 0.721, 0.525), inside the wall's cells; ``mirror`` flips the scene in x."""
    n, cell = 14, 0.07
    forbidden = np.zeros((n, n), np.uint8)
    forbidden[4:11, 10] = 1
    sx, sz, px = ox + 5.5 * cell, 7.5 * cell, ox + 10.3 * cell
    hip_x = sx - 0.2
    if mirror:
        forbidden = forbidden[:, ::-1].copy()
        width = 2 * ox + n * cell
        sx, px, hip_x = width - sx, width - px, width - hip_x
    flat = np.zeros((n, n))
    maps = LocalMaps(GridFrame(ox, 0.0, cell, n, n), flat, flat.copy(), forbidden)
    query = FootQuery(source=(sx, 0.0, sz), preferred=(px, sz), hip=(hip_x, sz), reach_xz=0.7, step_height=0.05,
                      foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    return maps, query


def _box_scene(preferred, legs):
    """14 x 14 cells of 7 cm, flat; a forbidden box in cell (7, 9) (x in [0.63, 0.70], z in [0.49, 0.56]),
    so with the foot's 3 x 3 stencil cells (6..8, 8..10) are its size increase. The foot (3 x 2 cm, yaw 0)
    stands at the centre of (7, 5) = (0.385, 0.525), hip (0.185, 0.525)."""
    n, cell = 14, 0.07
    forbidden = np.zeros((n, n), np.uint8)
    forbidden[7, 9] = 1
    flat = np.zeros((n, n))
    maps = LocalMaps(GridFrame(0.0, 0.0, cell, n, n), flat, flat.copy(), forbidden)
    query = FootQuery(source=(0.385, 0.0, 0.525), preferred=preferred, hip=(0.185, 0.525), reach_xz=0.7,
                      step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0,
                      other_legs=np.array(legs, dtype=float).reshape(-1, 4))
    return maps, query


def _oracle_best(maps, query, **kw):
    oracle = Oracle(maps, query, ScoringWeights(), PlannerConfig(), EXHAUSTIVE.slice_size_m, **kw)
    return max(oracle.couples(), key=lambda c: min(-math.inf if v is None else v["score"] for v in c[2]))


# Scenes where the runtime disagreed with the oracle (both fixed):
# * A footprint on the high border of its cell (x or z = centre + half a cell, where footprint_point puts it
#   when the preferred footprint lies beyond) was floored by cell_of into the neighbour cell; when that
#   neighbour was blocked (size increase, another leg, above the slice) the last chord's supercover ended in
#   it and segment_clear refused the couple, although a foot anywhere in its own (closed) cell is safe.
#   Whether a low-border footprint was refused depended on how (x - origin) / cell rounds.
# * prepare_foot turned a size-increase cell under another leg's projection (or within a foot's room of
#   another foot) into OTHER_LEG; footprint_candidates then accepted it as the preferred footprint's cell
#   and left it out of the obstacle-proximity seeds.


def test_a_footprint_on_its_cells_border_next_to_a_wall_is_reached():
    # Cell (7, 8) spans x in [0.56, 0.63]; the preferred footprint x = 0.721 lies beyond it, so its
    # footprint is (0.63, 0.525): the foot (3 x 2 cm) then spans x in [0.615, 0.645], 5.5 cm short of the
    # wall (x >= 0.70), and the straight swing from (0.385, 0.525) stays in row 7's free cells. The oracle
    # (T in its own cell) picks it with score 0.86372; the runtime floors 0.63 / 0.07 = 9.000000000000002
    # into column 9 (size increase), refuses the couple and lands a cell short, at x = 0.56 (0.82705).
    maps, query = _wall_scene()
    cand, s, variants = _oracle_best(maps, query)  # the oracle's own semantics: T in its own cell
    assert cand["cell"] == (7, 8) and cand["point"] == pytest.approx((0.63, 0.525), abs=1e-12)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    assert result.target_cell == cand["cell"] and abs(result.couple_score - variants[0]["score"]) <= SCORE_TOL


def test_moving_the_world_by_a_metre_moves_the_footprint_by_a_metre():
    # The mirror image of the wall scene: the border footprint is now on the low side, x = centre - half a
    # cell. At origin 0 the runtime refuses it (0.35 / 0.07 floors to 4, a size-increase cell) and picks
    # (7, 6); the same scene 1 m further in x is planned with (7, 5), the border footprint, 4.4 % better.
    picks = []
    for ox in (0.0, 1.0):
        maps, query = _wall_scene(ox, mirror=True)
        r = plan_foot(maps, query, budget=EXHAUSTIVE)
        picks.append((r.target_cell, round(r.target[0] - ox, 9), round(r.couple_score, 9)))
    assert picks[0] == picks[1]


def _graze_scene(source_z):
    """14 x 14 cells of 7 cm, flat, no box. The foot (3 x 2 cm: room hypot(0.03, 0.02) = 3.61 cm, grace
    1.80 cm) stands at (0.4199, ``source_z``), 0.1 mm inside cell (6, 5)'s east border x = 0.42, and
    prefers (0.60, 0.501) in cell (7, 8). Another leg, hip (0.55, 0.30) -> foot (0.47, 0.43): the only
    cell of its foot's room on the way is (6, 6), x in [0.42, 0.49], z in [0.42, 0.49] (its centre
    (0.455, 0.455) is 2.9 cm from that foot)."""
    n, cell = 14, 0.07
    flat = np.zeros((n, n))
    maps = LocalMaps(GridFrame(0.0, 0.0, cell, n, n), flat, flat.copy(), np.zeros((n, n), np.uint8))
    query = FootQuery(source=(0.4199, 0.0, source_z), preferred=(0.60, 0.501), hip=(0.50, 0.75), reach_xz=0.7,
                      step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0,
                      other_legs=np.array([[0.55, 0.30, 0.47, 0.43]]))
    return maps, query


def test_a_swing_grazing_another_legs_cell_beside_its_source_goes_straight():
    # Source z = 0.489: the straight way to (0.60, 0.501) rises 1.2 cm over 18 cm, so it leaves row 6 at
    # z = 0.49 after 1.5 cm, having met cell (6, 6) only within 1.50 cm of its source (< the grace, 1.80 cm).
    # It is the couple's path: 2D length = the straight distance. Without the grace that cell refused it;
    # the way ran through the centre of (7, 5), (0.385, 0.525), 3.5 cm back and 3.6 cm out, and the foot
    # took a 1 cm step to (0.42, 0.501) instead (score 0.850 against 0.961).
    maps, query = _graze_scene(0.489)
    h = harvest_foot(maps, query, budget=EXHAUSTIVE)
    k = [tuple(rc) for rc in h.cand_cells.tolist()].index((7, 8))
    straight = math.hypot(0.60 - 0.4199, 0.501 - 0.489)
    assert h.couple_valid[k, 0] and h.couple_raw[k, 0, 0] == pytest.approx(straight, abs=1e-12)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    assert result.target_cell == (7, 8)
    assert (result.target[0], result.target[2]) == pytest.approx((0.60, 0.501), abs=1e-12)
    way = result.trajectory[:, [0, 2]] - result.trajectory[0, [0, 2]]
    assert (way @ np.array([0.60 - 0.4199, 0.501 - 0.489]) / straight).min() >= -1e-12, "the swing starts backwards"
    cand, _, variants = _oracle_best(maps, query)
    assert cand["cell"] == (7, 8) and abs(result.couple_score - variants[0]["score"]) <= SCORE_TOL
    # Source z = 0.4865: the way leaves row 6 only after 4.3 cm (z rises 1.45 cm over 18 cm), so it meets
    # (6, 6) beyond the grace: refused, the couple's path bends round the cell (longer than straight).
    maps, query = _graze_scene(0.4865)
    h = harvest_foot(maps, query, budget=EXHAUSTIVE)
    k = [tuple(rc) for rc in h.cand_cells.tolist()].index((7, 8))
    assert h.couple_raw[k, 0, 0] > math.hypot(0.60 - 0.4199, 0.501 - 0.4865) + 0.005


def test_a_swing_clear_only_by_its_sources_grace_crosses_no_leg():
    # The first scene (source z = 0.489) with a leg drawn bent (planner._crowd.drawn_leg_segments: no foot at
    # its end) from (0.421, 0.43) to (0.428, 0.4897), in cell (6, 6) alone. The straight way to (0.60, 0.501)
    # is at z = 0.489 + 0.0081 x 0.012 / 0.1801 = 0.48954 at x = 0.428, below the segment's end: it crosses
    # the leg 0.8 cm from its source, inside the grace, so the cells let it pass and the geometry refuses it.
    # (7, 8) then has no couple, and the foot lands on (8, 8), (0.60, 0.56), as the oracle's; without the
    # check the runtime swung across the leg to (7, 8).
    maps, query = _graze_scene(0.489)
    query = dataclasses.replace(query, drawn_segments=np.array([[0.421, 0.43, 0.428, 0.4897]]))
    h = harvest_foot(maps, query, budget=EXHAUSTIVE)
    k = [tuple(rc) for rc in h.cand_cells.tolist()].index((7, 8))
    assert not h.couple_valid[k].any()
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    cand, _, variants = _oracle_best(maps, query)
    assert result.target_cell == cand["cell"] == (8, 8)
    assert abs(result.couple_score - variants[0]["score"]) <= SCORE_TOL


def test_a_leg_over_a_boxs_ring_does_not_let_the_foot_onto_the_box():
    # The preferred footprint (0.625, 0.51) lies in the size-increase cell (7, 8): a foot there
    # (x in [0.61, 0.64], z in [0.50, 0.52]) overlaps the forbidden cell (7, 9) by 1 cm in x. Without
    # other legs the search lands on the border of (7, 7) nearest P, (0.56, 0.51): the foot spans x in
    # [0.545, 0.575], 5.5 cm short of the box. Another leg, hip (0.585, 0.55) -> foot (0.70, 0.85), crosses
    # cell (7, 8); it stays 3.9 cm from the preferred footprint (more than a foot's room, hypot(0.03, 0.02)
    # = 3.6 cm) and does not cross this leg. The old runtime then put the foot in (7, 8), on the box.
    legs = [(0.585, 0.55, 0.70, 0.85)]
    maps, query = _box_scene((0.625, 0.51), legs)
    without_leg = plan_foot(maps, dataclasses.replace(query, other_legs=np.zeros((0, 4))), budget=EXHAUSTIVE)
    assert without_leg.target_cell == (7, 7)
    assert (without_leg.target[0], without_leg.target[2]) == pytest.approx((0.56, 0.51), abs=1e-12)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    x, z = result.target[0], result.target[2]
    assert x + 0.015 <= 0.63 or abs(z - 0.525) >= 0.035 + 0.01, f"the foot at {(x, z)} overlaps the box's cell"
    assert result.target_cell == _oracle_best(maps, query)[0]["cell"]
    # The old runtime's conventions (the border footprint floored into its neighbour, a size-increase cell
    # under a leg turned into another leg's) land on the box.
    assert _oracle_best(maps, query, endpoint="floor", leg_over_size_increase=True)[0]["cell"] == (7, 8)


def test_a_leg_over_a_boxs_ring_does_not_hide_the_box():
    # The foot prefers the centre of (7, 7) = (0.525, 0.525). Another leg lies along x = 0.60 (column 8),
    # over the ring's column 8, 7.5 cm from the preferred footprint.
    maps, query = _box_scene((0.525, 0.525), [(0.60, 0.15, 0.60, 0.85)])
    without_leg = plan_foot(maps, dataclasses.replace(query, other_legs=np.zeros((0, 4))), budget=EXHAUSTIVE)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    h = harvest_foot(maps, query, budget=EXHAUSTIVE)
    k = [tuple(rc) for rc in h.cand_cells.tolist()].index((7, 7))
    # Cell (7, 7) is one cell from the ring cell (7, 8): distance 0.07 m, goodness 0.07 / 0.10 = 0.7,
    # with the leg or without. The runtime measures 0.14 m (to the box itself), goodness 1.0.
    assert h.cand_features[k, 4] == pytest.approx(0.07, abs=METRIC_TOL)
    # P itself stays the pick, with the leg or without, as the oracle's.
    cand, _, _ = _oracle_best(maps, query)
    assert result.target_cell == cand["cell"] == without_leg.target_cell == (7, 7)
    # The old convention hides the ring under the leg: the oracle then measures 0.14 m too.
    old = Oracle(maps, query, ScoringWeights(), PlannerConfig(), EXHAUSTIVE.slice_size_m, leg_over_size_increase=True)
    assert [c["features"][4] for c in old.candidates if c["cell"] == (7, 7)] == [pytest.approx(0.14, abs=METRIC_TOL)]


# ============================================================================ (b) each term by hand, 5 x 5 cells
# Cells of 10 cm, origin (0, 0): cell (r, c) spans x in [0.1 c, 0.1 (c + 1)], z in [0.1 r, 0.1 (r + 1)]. The foot
# (4 x 2 cm, yaw 0) has the 3 x 3 stencil, so the outer ring (its stencil leaves the map) is size increase and
# only the inner 3 x 3 cells can be footprints. Tolerances: HAND_TOL on every hand number.
HAND_TOL = 1e-9
HAND_CONFIG = PlannerConfig(cell_size=0.1, obstacle_margin_m=0.0)
FOOT = dict(foot_length=0.04, foot_width=0.02, foot_yaw=0.0)


def _hand_maps(elevation, forbidden):
    frame = GridFrame(0.0, 0.0, 0.1, 5, 5)
    return LocalMaps(frame, np.asarray(elevation, float), np.zeros((5, 5)), np.asarray(forbidden, np.uint8))


def _row(h, cell):
    return [tuple(rc) for rc in h.cand_cells.tolist()].index(cell)


def test_hand_footprint_terms():
    # A safe box 3 cm high in cell (3, 3); a forbidden box in cell (1, 4), whose size increase takes (1, 3)
    # and (2, 3). Dilated elevation (3 x 3 max): 0.03 in rows 2..4 x cols 2..4, else 0.
    # The foot stands at the centre of (2, 1) = (0.15, 0.25), hip (0.05, 0.25); preferred footprint
    # P = (0.27, 0.33), in cell (3, 2). Another leg: hip (0.45, 0.55) -> foot (0.45, 0.38), in column 4 only.
    elevation = np.zeros((5, 5))
    elevation[3, 3] = 0.03
    forbidden = np.zeros((5, 5))
    forbidden[1, 4] = 1
    query = FootQuery(source=(0.15, 0.0, 0.25), preferred=(0.27, 0.33), hip=(0.05, 0.25), reach_xz=0.7,
                      step_height=0.05, other_legs=np.array([[0.45, 0.55, 0.45, 0.38]]), **FOOT)
    weights = ScoringWeights(leg_spacing_ref_m=0.25, proximity_ref_m=0.25)
    h = harvest_foot(_hand_maps(elevation, forbidden), query, weights=weights, budget=EXHAUSTIVE, config=HAND_CONFIG)
    # Footprints: the free inner cells but the source's: (1, 1), (1, 2), (2, 2), (3, 1), (3, 2), (3, 3).
    assert sorted(map(tuple, h.cand_cells.tolist())) == [(1, 1), (1, 2), (2, 2), (3, 1), (3, 2), (3, 3)]

    k = _row(h, (3, 2))  # P lies in (3, 2): the footprint is P itself.
    assert (h.cand_xyz[k, 0], h.cand_xyz[k, 2]) == (0.27, 0.33)
    # distance:   |P - P| = 0                                             -> 1 - 0 / 0.30 = 1
    # elevation:  dilated 0.03 here; raw neighbours 0 but (3, 3) = 0.03: max |dh| = 0.03 -> 1 - 0.03 / 0.12 = 0.75
    # slope:      one-sided differences (minmod): along x e(3, 3) - e(3, 2) = 0 and e(3, 2) - e(3, 1) = 0.03, so 0
    #             (the box's edge is beside the foot, not under it); along z 0 and 0          -> 0 rad -> 1
    # leg gap:    P to the other leg (its nearest point is its foot): hypot(0.18, 0.05) = sqrt(0.0349)
    #             = 0.18681541692269404 (the other foot to hip -> P: the same point) -> / 0.25 = 0.7472616676907762
    # proximity:  one cell to the size-increase ring cell (4, 2): 0.1 m  -> 0.1 / 0.25 = 0.4
    np.testing.assert_allclose(h.cand_features[k], [0.0, 0.03, 0.0, 0.18681541692269404, 0.1],
                               rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(h.cand_terms[k], [1.0, 0.75, 1.0, 0.7472616676907762, 0.4],
                               rtol=0, atol=HAND_TOL)
    # footprint score, weights 3, 1, 1, 1, 1: (3 * 1 + 0.75 + 1 + 0.74726166769 + 0.4) / 7
    assert h.cand_scores[k] == pytest.approx(0.8424659525384395, abs=HAND_TOL)

    k = _row(h, (1, 1))  # square [0.1, 0.2]^2, P beyond both edges: the footprint is the corner (0.2, 0.2).
    assert (h.cand_xyz[k, 0], h.cand_xyz[k, 2]) == (0.2, 0.2)
    # distance:   hypot(0.27 - 0.2, 0.33 - 0.2) = sqrt(0.0218) = 0.147648230602334
    #                                                                     -> 1 - 0.1476... / 0.3 = 0.5078392313255533
    # elevation, slope: no 0.03 within two cells of (1, 1): 0 and 0    -> 1, 1
    # leg gap:    hypot(0.45 - 0.2, 0.38 - 0.2) = sqrt(0.0949) = 0.30805843601498726 -> min(1, 1.23) = 1
    # proximity:  one cell to the ring (0, 1): 0.1 m                    -> 0.4
    np.testing.assert_allclose(h.cand_features[k], [0.147648230602334, 0.0, 0.0, 0.30805843601498726, 0.1],
                               rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(h.cand_terms[k], [0.5078392313255533, 1.0, 1.0, 1.0, 0.4], rtol=0, atol=HAND_TOL)
    # (3 * 0.50783923132555 + 1 + 1 + 1 + 0.4) / 7
    assert h.cand_scores[k] == pytest.approx(0.7033596705680943, abs=HAND_TOL)

    k = _row(h, (2, 2))  # square [0.2, 0.3]^2: the footprint is (0.27, 0.30), on its top edge.
    # distance:   0.33 - 0.30 = 0.03                                      -> 1 - 0.03 / 0.3 = 0.9
    # elevation:  dilated 0.03; raw neighbours 0 (but (3, 3)): 0.03   -> 0.75
    # slope:      minmod(e(2, 3) - e(2, 2), e(2, 2) - e(2, 1)) = minmod(0, 0.03) = 0, and along z
    #             minmod(e(3, 2) - e(2, 2), e(2, 2) - e(1, 2)) = minmod(0, 0.03) = 0     -> 0 rad -> 1
    # leg gap:    hypot(0.18, 0.08) = sqrt(0.0388) = 0.19697715603592209 -> / 0.25 = 0.7879086241436883
    # proximity:  one cell to the size increase (2, 3)                 -> 0.4
    np.testing.assert_allclose(h.cand_features[k], [0.03, 0.03, 0.0, 0.19697715603592209, 0.1],
                               rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(h.cand_terms[k], [0.9, 0.75, 1.0, 0.7879086241436883, 0.4],
                               rtol=0, atol=HAND_TOL)
    # (3 * 0.9 + 0.75 + 1 + 0.78790862414 + 0.4) / 7
    assert h.cand_scores[k] == pytest.approx(0.8054155177348126, abs=HAND_TOL)


def test_hand_a_leg_drawn_with_a_bowed_knee_is_kept_clear_of_as_drawn():
    # The scene of test_hand_footprint_terms without boxes: foot at (0.15, 0.25), hip (0.05, 0.25),
    # P = (0.27, 0.33) in cell (3, 2). Another leg, hip (0.45, 0.05) -> foot (0.45, 0.45), straight down
    # column 4; drawn, its knee bows to K = (0.32, 0.25): segments (0.45, 0.05) -> K -> (0.45, 0.45)
    # (a tilted body's leg: planner._crowd.drawn_leg_segments).
    flat = np.zeros((5, 5))
    straight = FootQuery(source=(0.15, 0.0, 0.25), preferred=(0.27, 0.33), hip=(0.05, 0.25), reach_xz=0.7,
                         step_height=0.05, other_legs=np.array([[0.45, 0.05, 0.45, 0.45]]), **FOOT)
    drawn = dataclasses.replace(straight, drawn_segments=np.array([[0.45, 0.05, 0.32, 0.25], [0.32, 0.25, 0.45, 0.45]]))
    h0, h1 = (harvest_foot(_hand_maps(flat, flat), q, budget=EXHAUSTIVE, config=HAND_CONFIG) for q in (straight, drawn))
    # leg gap at P, straight: P to the leg x = 0.45 is 0.18; the other foot to hip -> P is |(0.18, 0.12)|.
    assert h0.cand_features[_row(h0, (3, 2)), FEAT_LEG_GAP] == pytest.approx(0.18, abs=HAND_TOL)
    # drawn: P to K -> (0.45, 0.45), direction (0.13, 0.2): |(-0.05, 0.08) x (0.13, 0.2)| / |(0.13, 0.2)|
    # = 0.0204 / sqrt(0.0569) (the nearest point is inside the segment: t = 0.0095 / 0.0569)
    assert h1.cand_features[_row(h1, (3, 2)), FEAT_LEG_GAP] == pytest.approx(0.0204 / math.sqrt(0.0569), abs=HAND_TOL)
    # Cell (3, 3), x in [0.3, 0.4], z in [0.3, 0.4]: the knee's lower segment passes it (x 0.3525 at
    # z 0.3); its footprint (0.30, 0.33) is 0.15 from the straight leg. A candidate only straight.
    cells0 = set(map(tuple, h0.cand_cells.tolist()))
    cells1 = set(map(tuple, h1.cand_cells.tolist()))
    assert (3, 3) in cells0 and (3, 3) not in cells1
    assert cells1 < cells0


def test_hand_footprint_slope_is_the_ground_under_the_foot_not_a_step_beside_it():
    # The slope feature takes, per axis, the smaller of the dilated elevation's two one-sided differences
    # when they agree in sign, else 0 (minmod). On a ramp rising 2 cm a cell along x, the dilated
    # elevation (3 x 3 max) is 0.02 * min(c + 1, 4): at (2, 1) and (2, 2) both differences are 0.02, so
    # gx = 0.02 / 0.1 = 0.2 and the slope is atan(0.2), what a central difference gives too.
    # Beside a 3 cm step (columns 3 and 4), the dilated elevation is 0, 0, 0.03, 0.03, 0.03 along a row:
    # at (2, 1) and (2, 2) one difference is 0, so no slope; a central difference saw 0.15 there, and an
    # ant on stairs (4 cm cells, 7 cm strides) kept its feet three cells off every riser, a third of its
    # strides off the law next to each (stairs, 6 ants, p90 0.31-0.35). The step is the roughness's.
    query = FootQuery(source=(0.25, 0.0, 0.15), preferred=(0.25, 0.25), hip=(0.25, 0.15), reach_xz=0.7,
                      step_height=0.05, **FOOT)
    ramp = np.tile(0.02 * np.arange(5.0), (5, 1))
    h = harvest_foot(_hand_maps(ramp, np.zeros((5, 5))), query, budget=EXHAUSTIVE, config=HAND_CONFIG)
    for cell in ((2, 1), (2, 2)):
        assert h.cand_features[_row(h, cell), 2] == pytest.approx(math.atan(0.2), abs=HAND_TOL)
    step = np.zeros((5, 5))
    step[:, 3:] = 0.03
    h = harvest_foot(_hand_maps(step, np.zeros((5, 5))), query, budget=EXHAUSTIVE, config=HAND_CONFIG)
    assert h.cand_features[_row(h, (2, 1)), 2] == 0.0 and h.cand_features[_row(h, (2, 2)), 2] == 0.0
    assert h.cand_features[_row(h, (2, 2)), 1] == pytest.approx(0.03, abs=HAND_TOL)  # raw (2, 1) = 0 beside it


def test_hand_trajectory_terms():
    # Flat; a safe (not forbidden) box 2 cm high in cell (0, 2): dilated elevation 0.02 in rows 0..1 x cols
    # 1..3. Step height 0 and obstacle margin 0, so a swing that meets no raised cell stays flat. Slices
    # (5 cm): +inf (over everything) and 0 (around the raised cells (1, 1), (1, 2), (1, 3)).
    # The foot stands at the centre of (2, 1) = (0.15, 0.25); P = (0.27, 0.25), in (2, 2). d_ref of a candidate is
    # the straight distance from the source to its own footprint: |P - S| = 0.12 for the footprint P.
    elevation = np.zeros((5, 5))
    elevation[0, 2] = 0.02
    query = FootQuery(source=(0.15, 0.0, 0.25), preferred=(0.27, 0.25), hip=(0.0, 0.25), reach_xz=0.7,
                      step_height=0.0, **FOOT)
    weights = ScoringWeights(clearance_ref_m=0.25, proximity_ref_m=0.25)
    h = harvest_foot(_hand_maps(elevation, np.zeros((5, 5))), query, weights=weights, budget=EXHAUSTIVE,
                     config=HAND_CONFIG)
    assert list(h.levels) == [math.inf, 0.0]
    raw_names = ("length", "curvature", "clearance", "climb", "jerk")

    k = _row(h, (2, 2))  # footprint P itself, straight swing along z = 0.25
    assert h.d_ref[k] == pytest.approx(0.12, abs=HAND_TOL)
    raw = dict(zip(raw_names, h.couple_raw[k, 1]))  # slice 0: row 1 is blocked, nothing raised beside the swing
    # length:     |P - S| = 0.27 - 0.15 = 0.12 (flat)                     -> 0.12 / max(0.12, 0.12) = 1
    # curvature:  a straight line turns by 0                             -> 1 / (1 + 0) = 1
    # clearance:  the samples lie in (2, 1) and (2, 2), one cell from a blocked cell ((2, 0), (1, 2)): 0.1 m
    #                                                                     -> 0.1 / 0.25 = 0.4
    # climb:      nothing above max(source, target) + step = 0          -> 1
    # jerk:       a straight flat line: 0                                -> 1
    assert raw["length"] == pytest.approx(0.12, abs=HAND_TOL)
    assert abs(raw["curvature"]) <= HAND_TOL and abs(raw["jerk"]) <= HAND_TOL
    assert raw["clearance"] == pytest.approx(0.1, abs=HAND_TOL) and raw["climb"] == 0.0
    np.testing.assert_allclose(h.couple_terms[k, 1, 5:], [1.0, 1.0, 0.4, 1.0, 1.0], rtol=0, atol=HAND_TOL)
    # Footprint terms of (2, 2): distance 0 -> 1; flat around -> roughness 0 -> 1; slope: along z minmod(e(3, 2) -
    # e(2, 2), e(2, 2) - e(1, 2)) = minmod(0, -0.02) = 0 (the raised cells are beside the foot) -> 1; no other leg
    # -> 1; two cells to the ring (0.2 m) -> 0.8. Footprint score (3 + 1 + 1 + 1 + 0.8) / 7 = 0.9714285714285714;
    # trajectory score (weights 2, 1, 0.5, 1, 0.5): (2 + 1 + 0.5 * 0.4 + 1 + 0.5) / 5 = 0.94;
    # couple score (6.8 + 4.7) / 12 = 0.9583333333333334.
    np.testing.assert_allclose(h.couple_terms[k, 1, :5], [1.0, 1.0, 1.0, 1.0, 0.8], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(h.couple_scores[k, 1], [0.9583333333333334, 0.9714285714285714, 0.94], rtol=0,
                               atol=HAND_TOL)
    # Slice +inf: the raised cells of row 1 are passable, so every sample's 3 x 3 block reaches a 0.02 m cell:
    # climb = 0.02 - (max(0, 0) + 0) = 0.02 -> 1 / (1 + 0.02 / 0.10) = 0.8333333333333334. Clearance: the samples
    # in (2, 1) are one cell from the ring (2, 0): 0.1 m -> 0.4.
    assert h.couple_raw[k, 0, 3] == pytest.approx(0.02, abs=HAND_TOL)
    assert h.couple_terms[k, 0, 8] == pytest.approx(0.8333333333333334, abs=HAND_TOL)
    assert h.couple_raw[k, 0, 2] == pytest.approx(0.1, abs=HAND_TOL)

    k = _row(h, (2, 3))  # square [0.3, 0.4] x [0.2, 0.3]: footprint (0.3, 0.25), beyond P
    # length: 0.3 - 0.15 = 0.15, straight: d_ref 0.15 -> 0.15 / 0.15 = 1 (a longer step is no less direct;
    # closeness to P is the distance term's)
    assert h.couple_raw[k, 1, 0] == pytest.approx(0.15, abs=HAND_TOL)
    assert h.d_ref[k] == pytest.approx(0.15, abs=HAND_TOL)
    assert h.couple_terms[k, 1, 5] == pytest.approx(1.0, abs=HAND_TOL)
    k = _row(h, (3, 3))  # square [0.3, 0.4]^2: footprint the corner (0.3, 0.3)
    # length: hypot(0.15, 0.05) = 0.15811388300841897, still straight -> 1
    assert h.couple_raw[k, 1, 0] == pytest.approx(0.15811388300841897, abs=HAND_TOL)
    assert h.couple_terms[k, 1, 5] == pytest.approx(1.0, abs=HAND_TOL)
    assert abs(h.couple_raw[k, 1, 1]) <= HAND_TOL


def test_hand_geometric_jerk():
    # A zigzag of 48 vertices, x = 0.004 i, y = 0.003 (i mod 2): every segment is 0.005 long (3-4-5), so the
    # 48 constant-arc-length samples are the vertices: L = 47 * 0.005 = 0.235, h = 0.005. Third differences:
    # x is linear (0); y alternates 0, a, 0, a: a - 3 * 0 + 3 a - 0 = 4 a (or -4 a), a = 0.003. Samples
    # k = 1..45 with u = k / 47 in [0.05, 0.95]: k = 3..44, 42 of them. J = L^3 * sum (4 a / h^3)^2 h
    # = (47 h)^3 * 42 * 16 a^2 / h^5 = 47^3 * 672 * (a / h)^2 = 103823 * 672 * 0.36 = 25116860.16;
    # goodness 1 / (1 + J / 2000) = 7.962144728146773e-05.
    from footfall.planner._kernels_foot import JERK_SAMPLES as RUNTIME_JERK_SAMPLES
    from footfall.planner._kernels_foot import geometric_jerk as runtime_jerk
    from footfall.planner._kernels_foot import trajectory_goodness

    assert RUNTIME_JERK_SAMPLES == JERK_SAMPLES
    i = np.arange(48)
    poly = np.column_stack([0.004 * i, 0.003 * (i % 2), np.zeros(48)])
    j = runtime_jerk(poly, 48, np.empty((JERK_SAMPLES, 3)))
    assert j == pytest.approx(25116860.16, rel=HAND_TOL)
    assert geometric_jerk(poly) == pytest.approx(25116860.16, rel=HAND_TOL)  # the oracle's own
    terms = np.zeros(10)
    trajectory_goodness(ScoringWeights().to_array(), terms, 0.12, 0.12, 0.0, 0.07, 0.0, j)
    assert terms[9] == pytest.approx(7.962144728146773e-05, rel=HAND_TOL)


def test_hand_goodness_formulas():
    # The documented formulas (planner/_weights.py) on literal raw values, default references:
    # distance 0.06 m:       1 - 0.06 / 0.30 = 0.8          roughness 0.03 m:   1 - 0.03 / 0.12 = 0.75
    # slope 0.25 rad:        1 - 0.25 / 1.0 = 0.75          leg gap 0.02 m:     0.02 / 0.05 = 0.4
    # proximity 0.25 m:      min(1, 2.5) = 1                length 0.3, d_ref 0.2: 0.2 / 0.3 = 0.6666666666666666
    # curvature E = 0.5:     1 / (1 + 0.5 / 1.0) = 0.6666666666666666
    # clearance 0.035 m:     0.035 / 0.07 = 0.5             climb 0.05 m:  1 / (1 + 0.05 / 0.10) = 0.6666666666666666
    # jerk 6000:             1 / (1 + 6000 / 2000) = 0.25
    # couple score, weights 3 1 1 1 1 2 1 0.5 1 0.5:
    # (2.4 + 0.75 + 0.75 + 0.4 + 1 + 1.3333333 + 0.6666667 + 0.25 + 0.6666667 + 0.125) / 12
    #   = 8.3416667 / 12 = 0.6951388888888889
    from footfall.planner._kernels_foot import footprint_goodness, trajectory_goodness, weighted_mean

    w = ScoringWeights().to_array()
    terms = np.zeros(10)
    footprint_goodness(w, np.array([0.06, 0.03, 0.25, 0.02, 0.25]), terms)
    trajectory_goodness(w, terms, 0.2, 0.3, 0.5, 0.035, 0.05, 6000.0)
    np.testing.assert_allclose(terms, [0.8, 0.75, 0.75, 0.4, 1.0, 2 / 3, 2 / 3, 0.5, 2 / 3, 0.25], rtol=0,
                               atol=HAND_TOL)
    assert weighted_mean(w, terms, 0, 10) == pytest.approx(0.6951388888888889, abs=HAND_TOL)


# ----------------------------------------------------------------------------- a foot never climbs a forbidden box
def test_drawn_heights_keep_a_swing_under_a_ceiling_over_forbidden_cells_only():
    # Per sample: G, but no more than the ceiling where G came from a forbidden box's cells (G over the
    # others, g_free, is kept whatever the ceiling).
    from footfall.planner._kernels_foot import drawn_heights

    dense = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.4], [2.0, 0.0, 0.4], [3.0, 0.0, 0.3]])
    g_free = np.array([0.0, -math.inf, 0.25, 0.3])
    out = np.empty_like(dense)
    assert drawn_heights(dense, g_free, 4, 0.1, out)
    assert out.tolist() == [[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [2.0, 0.0, 0.25], [3.0, 0.0, 0.3]]
    assert not drawn_heights(dense, dense[:, 2].copy(), 4, 0.1, out)  # nothing from a forbidden box
    assert out.tolist() == dense.tolist()


def test_a_foot_beside_a_forbidden_wall_goes_around_it_not_through_it():
    # 16 x 16 cells of 7 cm, flat; a forbidden wall fills rows 4-11 of columns 7-8 (x in [0.49, 0.63],
    # z in [0.28, 0.84]). The foot stands at the centre of (7, 6) = (0.455, 0.525): its stencil touches
    # column 7, so its cell is a size-increase one (blocked) and the swing leaves through the blocked
    # region around it. Its footprint lies across the wall, near (0.805, 0.525). The way out is the
    # cells beside the wall; the wall's own cells were opened too, and the swing went straight through
    # it (a far spider's foot cut a static crate's corner: 1000 spiders, mixed, seed 1).
    n, cell = 16, 0.07
    forbidden = np.zeros((n, n), np.uint8)
    forbidden[4:12, 7:9] = 1
    elevation = np.where(forbidden == 1, 0.3, 0.0)
    maps = LocalMaps(GridFrame(0.0, 0.0, cell, n, n), elevation, np.zeros((n, n)), forbidden)
    query = FootQuery(source=(0.455, 0.0, 0.525), preferred=(0.805, 0.525), hip=(0.63, 0.525), reach_xz=0.7,
                      step_height=0.05, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    assert result.valid
    assert result.target[0] > 0.63
    rows = np.floor(result.trajectory[:, 2] / cell).astype(int)
    cols = np.floor(result.trajectory[:, 0] / cell).astype(int)
    assert not forbidden[rows, cols].any(), result.trajectory[forbidden[rows, cols] == 1]


@pytest.mark.parametrize("box_height", [0.25, 0.4])
def test_a_foot_stepping_away_from_a_tall_forbidden_box_beside_it_is_scored_climbing_it_and_drawn_low(box_height):
    # 14 x 14 cells of 7 cm, flat; a forbidden box of height box_height fills column 6 (x in [0.42, 0.49]).
    # The foot stands at the centre of (7, 5) = (0.385, 0.525): its 3 x 3 stencil touches column 6, so its
    # cell is a size increase one and the swing leaves through it (the foot of a box that moved next to it,
    # or where one is heading), to (0.175, 0.525), 3 cells away. The couple is scored climbing the box's
    # dilated top (climb = top + 1 cm margin - (0 + 5 cm step height)), which sends an escape far from
    # the box; the swing was drawn over it too (0.26, 0.41 m). Now it is drawn no higher than two step
    # heights + the margin: the box is forbidden at any height, and its top is no way out.
    n, cell, step, margin = 14, 0.07, 0.05, PlannerConfig().obstacle_margin_m
    forbidden = np.zeros((n, n), np.uint8)
    forbidden[:, 6] = 1
    elevation = np.zeros((n, n))
    elevation[:, 6] = box_height
    maps = LocalMaps(GridFrame(0.0, 0.0, cell, n, n), elevation, np.zeros((n, n)), forbidden)
    query = FootQuery(source=(0.385, 0.0, 0.525), preferred=(0.175, 0.525), hip=(0.385, 0.525), reach_xz=0.7,
                      step_height=step, foot_length=0.03, foot_width=0.02, foot_yaw=0.0)
    result = plan_foot(maps, query, budget=EXHAUSTIVE)
    assert result.valid
    assert result.target[0] < 0.385 - 2 * cell
    assert result.metrics["climb_m"] == pytest.approx(box_height + margin - step, abs=1e-9)
    assert result.trajectory[:, 1].max() <= 2 * step + margin + 1e-9
