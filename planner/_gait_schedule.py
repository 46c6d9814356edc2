"""Gait changes with speed (paper §3.3, "gaits interpolation/transition"; biomechanics notes).

Animals change gait as they speed up: quadrupeds walk below a Froude number of about 0.3 and
trot above about 0.5, insects move from tetrapod-like coordination to tripods, a spider's
metachronal wave shortens to alternating tetrapods. A :class:`GaitSchedule` is the list of
gaits a creature uses, slowest first, and the Froude numbers ``Fr = v^2 / (g h)`` at which it
moves up to the next one. The gait manager then interpolates the disks toward the new gait
(:func:`planner._gait.set_destination`), only while each foot is in stance.

Hysteresis: a character in gait k moves up to k + 1 when its Froude number exceeds
``froude_up[k]`` and back down when it falls below ``HYSTERESIS * froude_up[k]``, so a speed
that hovers at a boundary does not make the gait flicker.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall.planner._timing import GRAVITY

HYSTERESIS = 0.8
"""A character moves back down a gait below this fraction of the Froude number it moved up at."""


@dataclass(frozen=True, eq=False)
class GaitSchedule:
    """The gaits of one creature by speed.

    Attributes
    ----------
    gaits:
        Gait values (``scenarios.Gait``: ``name``, ``leg_names``, ``swing_start``,
        ``swing_duration``), slowest first, all with the creature's legs.
    froude_up:
        ``len(gaits) - 1`` increasing Froude numbers > 0: gait k + 1 takes over above
        ``froude_up[k]``.

    Examples
    --------
    >>> from types import SimpleNamespace as G
    >>> walk = G(name="walk", leg_names=("a", "b", "c"), swing_start=[0, 1/3, 2/3], swing_duration=[0.3] * 3)
    >>> trot = G(name="trot", leg_names=("a", "b", "c"), swing_start=[0, 0.5, 0.5], swing_duration=[0.4] * 3)
    >>> schedule = GaitSchedule((walk, trot), (0.35,))
    >>> schedule.names
    ('walk', 'trot')
    >>> schedule.select(np.array([0, 0, 1, 1]), np.array([0.1, 0.4, 0.3, 0.2]))
    array([0, 1, 1, 0])
    """

    gaits: tuple[Any, ...]
    froude_up: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        gaits = tuple(self.gaits)
        ups = tuple(float(f) for f in self.froude_up)
        if not gaits:
            raise ValueError("gaits: a schedule needs at least one gait")
        if len(ups) != len(gaits) - 1:
            raise ValueError(f"froude_up: expected {len(gaits) - 1} Froude numbers, got {len(ups)}")
        if any(not np.isfinite(f) or f <= 0.0 for f in ups) or any(b <= a for a, b in zip(ups, ups[1:])):
            raise ValueError(f"froude_up: expected increasing finite numbers > 0, got {ups}")
        legs = {tuple(g.leg_names) for g in gaits}
        if len(legs) != 1:
            raise ValueError("gaits: every gait of a schedule must name the same legs in the same order")
        object.__setattr__(self, "gaits", gaits)
        object.__setattr__(self, "froude_up", ups)

    @property
    def names(self) -> tuple[str, ...]:
        """The gaits' names, slowest first."""
        return tuple(g.name for g in self.gaits)

    @property
    def description(self) -> str:
        """The gaits' descriptions, with the Froude numbers of the changes."""
        parts = [getattr(self.gaits[0], "description", "") or self.gaits[0].name]
        for up, gait in zip(self.froude_up, self.gaits[1:]):
            parts.append(f"above Fr {up:g}: {getattr(gait, 'description', '') or gait.name}")
        return "; ".join(parts)

    @property
    def name(self) -> str:
        """One name for the schedule: the gait's name, or the names joined by ``+``."""
        return "+".join(self.names)

    def select(self, current: np.ndarray, froude: np.ndarray) -> np.ndarray:
        """(C,) gait index of each character at Froude numbers ``froude`` (C,), from ``current`` (C,)
        with hysteresis (module doc). Moves as many gaits as the speed asks in one call."""
        index = np.asarray(current, dtype=np.int64).copy()
        ups = np.asarray(self.froude_up, dtype=np.float64)
        for _ in range(len(ups)):
            can_up = index < len(ups)
            up = can_up & (froude > ups[np.minimum(index, len(ups) - 1)] if len(ups) else False)
            can_down = index > 0
            down = can_down & (froude < HYSTERESIS * ups[np.maximum(index - 1, 0)] if len(ups) else False)
            if not (np.any(up) or np.any(down)):
                break
            index = index + up.astype(np.int64) - down.astype(np.int64)
        return index

    def initial(self, speed: np.ndarray, leg_height: float) -> np.ndarray:
        """(C,) gait index for characters starting at ``speed`` (no hysteresis: the plain bands)."""
        froude = np.asarray(speed, dtype=np.float64) ** 2 / (GRAVITY * leg_height)
        return np.searchsorted(np.asarray(self.froude_up), froude, side="left").astype(np.int64)


def as_schedule(gait: Any) -> GaitSchedule:
    """A :class:`GaitSchedule` as it is, or one gait as a one-gait schedule."""
    return gait if isinstance(gait, GaitSchedule) else GaitSchedule((gait,), ())
