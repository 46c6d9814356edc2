"""Default gaits generated from the morphology (issue 13 item 4): any creature with 3 legs or more."""

from __future__ import annotations

import math

import numpy as np
import pytest

from footfall._errors import InputError
from footfall.scenarios import Creature, default_gait, default_gait_name, generate_gait, load_creature, load_gait
from footfall.scenarios._gaits import (
    DEFAULT_GAIT,
    check_support,
    leg_sides,
    min_stance_feet,
    required_stance_feet,
    ring_order,
    wave_latency,
)


def _creature(name, hips, rest_feet) -> Creature:
    n = len(hips)
    return Creature(
        name=name, leg_names=tuple(f"leg{i}" for i in range(n)), hips=hips,
        segment_lengths=[[0.06, 0.15, 0.15]] * n, joint_limits=[[[-1.0, 0.8], [-1.0, 1.4], [0.0, 2.4]]] * n,
        rest_feet=rest_feet, foot_length=0.02, foot_width=0.015, body_thickness=0.04,
        body_box=[0.2 + 0.1 * n, 0.12], standing_height=0.1)


def bilateral(n_left: int, n_right: int, shuffle: int = 0) -> Creature:
    """Legs listed in a scrambled order (so that the generator cannot rely on the listing)."""
    hips, feet = [], []
    for count, sign in ((n_left, 1.0), (n_right, -1.0)):
        xs = np.linspace(0.06 * (count - 1), -0.06 * (count - 1), count)
        for x in xs:
            hips.append([x, 0.0, sign * 0.05])
            feet.append([1.3 * x, sign * 0.22])
    order = np.random.default_rng(shuffle).permutation(len(hips))
    return _creature(f"bilateral{n_left}{n_right}", np.array(hips)[order], np.array(feet)[order])


def radial(n: int) -> Creature:
    angle = 2.0 * np.pi * np.arange(n) / n + 0.3
    hips = np.stack([0.08 * np.cos(angle), np.zeros(n), 0.08 * np.sin(angle)], axis=1)
    feet = np.stack([0.25 * np.cos(angle), 0.25 * np.sin(angle)], axis=1)
    return _creature(f"radial{n}", hips, feet)


CREATURES = {
    3: radial(3),
    5: radial(5),
    7: bilateral(4, 3),
    9: radial(9),
    12: bilateral(6, 6),
    16: bilateral(8, 8),
}
EXTRA = {"7-radial": radial(7), "12-radial": radial(12), "4-bilateral": bilateral(2, 2), "6-bilateral": bilateral(3, 3)}
ALL = {**{str(k): v for k, v in CREATURES.items()}, **EXTRA}


def _airborne(gait, phases):
    return np.mod(phases[:, None] - gait.swing_start[None, :], 1.0) < gait.swing_duration[None, :]


@pytest.mark.parametrize("key", sorted(ALL))
def test_support_rule_and_one_swing_per_leg(key):
    creature = ALL[key]
    gait = generate_gait(creature)
    assert gait.leg_names == creature.leg_names
    least, _ = min_stance_feet(gait.swing_start, gait.swing_duration)
    assert least >= required_stance_feet(creature.n_legs) == 2
    check_support(gait.leg_names, gait.swing_start, gait.swing_duration)
    phases = (np.arange(20000) + 0.5) / 20000  # the rule at every phase, sampled independently of the piece count
    air = _airborne(gait, phases)
    assert (creature.n_legs - air.sum(axis=1)).min() >= 2
    lifts = np.sum(air & ~np.roll(air, 1, axis=0), axis=0)  # lift-offs per leg over one cycle
    assert np.all(lifts == 1)
    assert np.all((gait.swing_duration >= 0.05) & (gait.swing_duration <= 1.0 - 0.72 + 1e-12))


@pytest.mark.parametrize("key", ["7", "12", "16", "4-bilateral", "6-bilateral"])
def test_bilateral_back_to_front_waves_half_a_cycle_apart(key):
    creature = ALL[key]
    gait = generate_gait(creature)
    sides = leg_sides(creature)
    assert sides is not None
    hips = creature.hips
    for side, sign in zip(sides, (1.0, -1.0)):
        assert np.all(np.sign(hips[list(side), 2]) == sign)
        assert np.all(np.diff(hips[list(side), 0]) > 0.0)  # back to front
        latency = wave_latency(len(side))
        steps = np.mod(np.diff(gait.swing_start[list(side)]), 1.0)
        np.testing.assert_allclose(steps, latency, atol=1e-9)  # each leg lifts after the one behind it
        assert 0.2 <= latency <= 0.5
    left, right = sides
    assert math.isclose((gait.swing_start[right[0]] - gait.swing_start[left[0]]) % 1.0, 0.5, abs_tol=1e-9)
    if len(left) == len(right):  # every opposite pair half a cycle apart
        np.testing.assert_allclose(np.mod(gait.swing_start[list(right)] - gait.swing_start[list(left)], 1.0), 0.5,
                                   atol=1e-9)


@pytest.mark.parametrize("key", sorted(ALL))
def test_neighbours_not_in_the_air_together(key):
    creature = ALL[key]
    gait = generate_gait(creature)
    sides = leg_sides(creature)
    pairs = []
    if sides is not None:
        for side in sides:
            pairs += list(zip(side[:-1], side[1:]))
        pairs += list(zip(sides[0], sides[1]))  # opposite legs
    else:
        ring = ring_order(creature)
        pairs += [(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
    phases = (np.arange(20000) + 0.5) / 20000
    air = _airborne(gait, phases)
    for a, b in pairs:
        assert not np.any(air[:, a] & air[:, b]), (creature.leg_names[a], creature.leg_names[b])


@pytest.mark.parametrize("n", [3, 5, 9])
def test_round_bodies_spread_swings_evenly(n):
    gait = generate_gait(CREATURES[n])
    assert leg_sides(CREATURES[n]) is None
    np.testing.assert_allclose(np.sort(gait.swing_start), np.arange(n) / n, atol=1e-9)


def test_ring_goes_round_the_body():
    creature = radial(5)
    ring = ring_order(creature)
    angles = np.mod(np.arctan2(creature.hips[list(ring), 2], creature.hips[list(ring), 0]), 2 * np.pi)
    assert np.all(np.diff(angles) > 0)


def test_deterministic_and_independent_of_the_listing():
    for creature in ALL.values():
        a, b = generate_gait(creature), generate_gait(creature)
        assert a.name == b.name and a.description == b.description
        np.testing.assert_array_equal(a.swing_start, b.swing_start)
        np.testing.assert_array_equal(a.swing_duration, b.swing_duration)
    one, other = bilateral(4, 3, shuffle=1), bilateral(4, 3, shuffle=2)  # same legs, listed differently
    by_hip = lambda c, g: sorted(zip(map(tuple, np.round(c.hips, 9)), g.swing_start))  # noqa: E731
    assert by_hip(one, generate_gait(one)) == by_hip(other, generate_gait(other))


def test_default_gait_builtin_or_generated():
    for name, gait in (("spider", "spider-metachronal-wave"), ("ant", "ant-tripod"), ("robot5", "robot5-wave")):
        creature = load_creature(name)
        assert default_gait(creature).name == gait == default_gait_name(creature)
    seven = CREATURES[7]
    assert default_gait(seven).name == "bilateral43-generated"
    assert default_gait_name(seven) == DEFAULT_GAIT
    np.testing.assert_array_equal(load_gait(DEFAULT_GAIT, seven).swing_start, generate_gait(seven).swing_start)
    # a user creature borrowing a built-in name with other legs gets a generated gait
    borrowed = _creature("spider", CREATURES[5].hips, CREATURES[5].rest_feet)
    assert default_gait(borrowed).name == "spider-generated"


def test_fewer_than_three_legs_refused():
    two = _creature("biped", [[0.0, 0.0, 0.05], [0.0, 0.0, -0.05]], [[0.0, 0.1], [0.0, -0.1]])
    with pytest.raises(InputError, match="biped: gait: cannot generate a gait for 2 legs"):
        generate_gait(two)
