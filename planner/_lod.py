"""Level of detail (paper §6): a camera decides how hard each character searches.

* Off-screen: the first valid couple, no slices, no IK.
* On-screen: the couples evaluated after the first valid one and the slice size
  are interpolated linearly with the distance to the camera: at ``near_m`` the
  full budget (``max_couples`` couples after the first, ``near_slice_m`` slices),
  at ``far_m`` and beyond the first valid couple and no slices.

Modes of the paper's Table 1: ``on`` (the camera frames the whole crowd),
``zoomed`` (the camera follows character 0, zoomed so that about half the crowd
is on screen), ``off`` (no LOD: every character runs the paper's full search and IK).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner._params import SearchBudget

LOD_MODES = ("on", "zoomed", "off")


@dataclass(frozen=True)
class LodConfig:
    """Distances in m; ``max_couples`` couples after the first valid one up close."""

    near_m: float = 2.0
    far_m: float = 12.0
    max_couples: int = 8
    near_slice_m: float = 0.10
    far_slice_m: float = 0.30  # beyond this interpolated size: no slices

    def __post_init__(self) -> None:
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
    distance (found by bisection) that puts at least ``fraction`` of the points on screen."""
    pts = np.asarray(points, dtype=np.float64)
    target = pts[focus] if focus is not None else pts.mean(axis=0)
    direction = np.array([-math.cos(elevation), math.sin(elevation), -0.3])
    direction /= np.linalg.norm(direction)
    need = max(1, int(math.ceil(fraction * len(pts))))

    def enough(distance: float) -> bool:
        return int(visibility(look_at(target + distance * direction, target, fov), pts)[0].sum()) >= need

    lo, hi = 0.5, 1.0
    while not enough(hi) and hi < 1e4:
        lo, hi = hi, 2.0 * hi
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if enough(mid) else (mid, hi)
    return look_at(target + hi * direction, target, fov)


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
