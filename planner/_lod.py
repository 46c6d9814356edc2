"""Level of detail (paper §6): a camera decides how hard each character searches and how
much work its frame costs.

* Off-screen: the first valid couple, no slices, no IK.
* On-screen: the couples evaluated after the first valid one and the slice size
  are interpolated linearly with the distance to the camera: at ``near_m`` the
  full budget (``max_couples`` couples after the first, ``near_slice_m`` slices),
  at ``far_m`` and beyond the first valid couple and no slices.

The search budget alone saves little: the shared wavefront, the foot-shape dilation and
the IK cost the same for every budget (issue 15). So each character also gets a *level*
(:func:`lod_levels`) that removes work:

* ``LEVEL_FULL`` (on screen, nearer than ``far_m``): the paper's 70 x 70 maps of 7 cm, IK
  every frame.
* ``LEVEL_FAR`` (on screen, ``far_m`` and beyond): the far planning of
  :mod:`planner._far_planning` (compact maps, a first try in a small region around the
  preferred footprint), and the IK in closed form: the azimuth and two hinges from the last
  pose (``planner._ik.solve_legs(..., two_bone=True)``), exact wherever they reach.
* ``LEVEL_HIDDEN`` (off screen): the far planning and no IK.

A character moves to a farther level at ``far_m`` and back to a nearer one only
``hysteresis_m`` closer, so one walking along the boundary does not flip every frame. A
character near a moving box (within ``moving_box_margin_m`` of its reach, about what a crate
covers while a foot stands) plans on the paper's maps with at least ``moving_box_couples`` couples
after the first valid one, whatever its level (its IK keeps its level): with the first valid
couple, far feet stood in the crates' way more often (``planner._crowd.character_budgets``).

Modes of the paper's Table 1: ``on`` (the camera frames the whole crowd),
``zoomed`` (the camera follows character 0, zoomed so that about half the crowd
is on screen), ``off`` (no LOD: every character runs the paper's full search and IK).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.planner._params import SearchBudget

LOD_MODES = ("on", "zoomed", "off")
LEVEL_FULL, LEVEL_FAR, LEVEL_HIDDEN = 0, 1, 2
LEVEL_NAMES = ("full", "far", "hidden")


@dataclass(frozen=True)
class LodConfig:
    """Distances in m; ``max_couples`` couples after the first valid one up close.

    How these distances and counts are used is in the module docstring. Values out of range
    (``near_m >= far_m``, ``hysteresis_m`` not in ``[0, far_m)``, ``near_slice_m >= far_slice_m``,
    a negative count ...) raise ValueError naming the field.

    Attributes
    ----------
    near_m, far_m : float
        Camera distances (m) of the full budget and of the first valid couple with no slices;
        the budget is interpolated linearly in between, and ``far_m`` is where a character
        moves to ``LEVEL_FAR`` (defaults 2, 12).
    max_couples : int
        Couples evaluated after the first valid one at ``near_m`` and nearer (default 8).
    near_slice_m, far_slice_m : float
        Slice size (m) at ``near_m``, and the interpolated size beyond which there are no
        slices (defaults 0.10, 0.30).
    far_radius_cells, far_margin_cells : int
        Candidate disc radius and region-of-interest margin (cells) of a far foot's first try
        (defaults 1, 1).
    far_fallback_margin_cells : int
        Region-of-interest margin (cells) of a far foot's full first-valid search (default 6).
    hysteresis_m : float
        A character goes back from ``LEVEL_FAR`` to ``LEVEL_FULL`` only at ``far_m -
        hysteresis_m`` (m) (default 1).
    moving_box_margin_m : float
        A character this near (m) a moving box's reach plans on the paper's maps (default 0.3).
    moving_box_couples : int
        ... with at least this many couples after the first valid one (default 2).

    Examples
    --------
    >>> from footfall.planner import LodConfig
    >>> config = LodConfig(near_m=1.0, far_m=6.0)
    >>> config.far_m - config.hysteresis_m   # back to the full level nearer than this (m)
    5.0
    >>> LodConfig(near_m=6.0, far_m=6.0)
    Traceback (most recent call last):
        ...
    ValueError: LodConfig.near_m/far_m: expected 0 <= near < far, got 6.0, 6.0
    """

    near_m: float = 2.0
    far_m: float = 12.0
    max_couples: int = 8
    near_slice_m: float = 0.10
    far_slice_m: float = 0.30  # beyond this interpolated size: no slices
    far_radius_cells: int = 1  # cells: candidate disc of a far foot's first try (planner._far_planning)
    far_margin_cells: int = 1  # cells: region-of-interest margin of a far foot's first try
    far_fallback_margin_cells: int = 6  # cells: ... of its full first-valid search (at most the planner's)
    hysteresis_m: float = 1.0  # back from LEVEL_FAR to LEVEL_FULL only this much nearer than far_m
    moving_box_margin_m: float = 0.3  # m: a character this near a moving box's reach plans as a near one
    moving_box_couples: int = 2  # ... and weighs at least this many couples after the first valid one

    def __post_init__(self) -> None:
        integers = (("far_radius_cells", 1), ("far_margin_cells", 0), ("far_fallback_margin_cells", 0),
                    ("moving_box_couples", 0))
        for name, least in integers:
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < least:
                raise ValueError(f"LodConfig.{name}: expected an integer >= {least}, got {v!r}")
        if not (isinstance(self.moving_box_margin_m, (int, float)) and self.moving_box_margin_m >= 0.0):
            raise ValueError(f"LodConfig.moving_box_margin_m: expected a number >= 0, got {self.moving_box_margin_m!r}")
        if not (isinstance(self.hysteresis_m, (int, float)) and 0.0 <= self.hysteresis_m < self.far_m):
            raise ValueError(f"LodConfig.hysteresis_m: expected a number in [0, far_m), got {self.hysteresis_m!r}")
        if not (0 <= self.near_m < self.far_m):
            raise ValueError(f"LodConfig.near_m/far_m: expected 0 <= near < far, got {self.near_m}, {self.far_m}")
        if self.max_couples < 0:
            raise ValueError("LodConfig.max_couples: expected >= 0")
        if not (0 < self.near_slice_m < self.far_slice_m):
            raise ValueError("LodConfig.near_slice_m/far_slice_m: expected 0 < near < far")


# The paper's full search (Table 1, "No LOD"): no couple limit, 10 cm slices, §5.2 early stop.
FULL_SEARCH = SearchBudget(couples_after_first=None, slice_size_m=0.10, paper_early_stop=True)


@dataclass(frozen=True)
class CameraPose:
    position: np.ndarray  # (3,)
    forward: np.ndarray  # (3,) unit
    fov: float  # full cone angle, radians


def look_at(position, target, fov: float) -> CameraPose:
    position = np.asarray(position, dtype=np.float64)
    d = np.asarray(target, dtype=np.float64) - position
    n = float(np.linalg.norm(d))
    if n == 0:
        raise ValueError("camera: position and target coincide")
    return CameraPose(position, d / n, float(fov))


def frame_crowd(points: np.ndarray, fov: float, fraction: float = 1.0, focus: int | None = None,
                elevation: float = 0.9) -> CameraPose:
    """A camera above and behind, looking at ``focus`` (or the centroid), at the smallest
    distance that puts at least ``fraction`` of the points on screen.

    In closed form (it runs every frame, over the whole crowd): seen from a camera at distance D
    along the unit ``direction`` from the target, a point at offset q from the target, a = q .
    direction along it and b across it, is inside the cone of half-angle h exactly when
    D >= a + b / tan(h); the camera stands at the ``ceil(fraction n)``-th smallest of these
    distances (at least 0.5 m), a hair further so that round-off keeps that point on screen.
    """
    pts = np.asarray(points, dtype=np.float64)
    target = pts[focus] if focus is not None else pts.mean(axis=0)
    direction = np.array([-math.cos(elevation), math.sin(elevation), -0.3])
    direction /= np.linalg.norm(direction)
    need = max(1, int(math.ceil(fraction * len(pts))))
    q = pts - target
    along = q @ direction
    across = np.sqrt(np.maximum(np.einsum("ij,ij->i", q, q) - along**2, 0.0))
    needed = along + across / math.tan(0.5 * fov)
    distance = max(0.5, float(np.partition(needed, need - 1)[need - 1]))
    distance = distance * (1.0 + 1e-9) + 1e-9
    return look_at(target + distance * direction, target, fov)


def visibility(camera: CameraPose, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(on_screen (C,) bool, distance (C,) m) of points (C, 3) for a cone-shaped view."""
    d = np.asarray(points, dtype=np.float64) - camera.position
    dist = np.linalg.norm(d, axis=1)
    cosang = (d @ camera.forward) / np.maximum(dist, 1e-12)
    return cosang >= math.cos(0.5 * camera.fov), dist


def lod_budgets(on_screen: np.ndarray, distance: np.ndarray, config: LodConfig) -> tuple[np.ndarray, np.ndarray]:
    """Per character (couples_after_first (C,) int, slice_size (C,) m, -1 = no slices)."""
    a = np.clip((distance - config.near_m) / (config.far_m - config.near_m), 0.0, 1.0)
    couples = np.rint(config.max_couples * (1.0 - a)).astype(np.int64)
    slices = config.near_slice_m + a * (config.far_slice_m - config.near_slice_m)
    slices = np.where(a >= 1.0, -1.0, slices)
    couples = np.where(on_screen, couples, 0)
    slices = np.where(on_screen, slices, -1.0)
    return couples, slices


def lod_levels(on_screen: np.ndarray, distance: np.ndarray, previous: np.ndarray, config: LodConfig) -> np.ndarray:
    """(C,) int8 level of each character (module doc) from its visibility, its distance to the
    camera (m) and its ``previous`` level (the hysteresis).

    Examples
    --------
    >>> cfg = LodConfig(far_m=12.0, hysteresis_m=1.0)
    >>> lod_levels(np.array([True, True, True, False]), np.array([5.0, 11.5, 12.0, 5.0]),
    ...            np.array([0, 1, 0, 0]), cfg).tolist()
    [0, 1, 1, 2]
    """
    far = distance >= np.where(previous == LEVEL_FULL, config.far_m, config.far_m - config.hysteresis_m)
    level = np.where(far, LEVEL_FAR, LEVEL_FULL)
    return np.where(on_screen, level, LEVEL_HIDDEN).astype(np.int8)
