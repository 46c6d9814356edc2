"""The wavefront on grids small enough to check by hand (whole arrays asserted)."""

import math

import numpy as np
import pytest

from footfall.planner import wavefront_distances

R2 = math.sqrt(2.0)
INF = np.inf


def test_octile_distances_with_obstacles_and_no_corner_cutting():
    passable = np.array(
        [
            [1, 1, 1, 1, 1],
            [1, 0, 0, 1, 1],
            [1, 1, 0, 1, 1],
            [1, 1, 1, 1, 1],
        ],
        dtype=bool,
    )
    expected = np.array(
        [
            [0, 1, 2, 3, 4],
            [1, INF, INF, 4, 3 + R2],
            [2, 3, INF, 5, 4 + R2],
            [3, 2 + R2, 3 + R2, 4 + R2, 5 + R2],
        ]
    )
    np.testing.assert_allclose(wavefront_distances(passable, (0, 0)), expected, rtol=0, atol=1e-12)


def test_cell_size_scales_costs():
    passable = np.ones((2, 3), dtype=bool)
    got = wavefront_distances(passable, (0, 0), cell_size=0.07)
    expected = 0.07 * np.array([[0, 1, 2], [1, R2, 1 + R2]])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-15)


def test_potential_field_costs_are_paid_on_entering_a_cell():
    passable = np.ones((1, 5), dtype=bool)
    factor = np.array([[1.0, 2.0, 1.0, 3.0, 1.0]])
    got = wavefront_distances(passable, (0, 0), cost_factor=factor)
    np.testing.assert_allclose(got, [[0, 2, 3, 6, 7]], rtol=0, atol=0)


def test_potential_field_makes_the_path_detour():
    # Going straight through the middle row costs 10 per cell; around costs 1 per move.
    passable = np.ones((3, 3), dtype=bool)
    factor = np.ones((3, 3))
    factor[1, 1] = 10.0
    got = wavefront_distances(passable, (1, 0), cost_factor=factor)
    # (1, 2) is reached around the expensive centre: (1,0)->(0,1)->(1,2) = 2 sqrt 2.
    expected = np.array([[1, R2, 1 + R2], [0, 10, 2 * R2], [1, R2, 1 + R2]])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_walled_off_cells_are_unreached():
    passable = np.array([[1, 0, 1], [1, 0, 1], [1, 0, 1]], dtype=bool)
    got = wavefront_distances(passable, (1, 0))
    expected = np.array([[1, INF, INF], [0, INF, INF], [1, INF, INF]])
    np.testing.assert_array_equal(got, expected)


def test_diagonal_gap_between_two_blocked_cells_is_closed():
    # Two blocked cells touching at a corner: the 8-connected wavefront must not slip through.
    passable = np.array([[1, 0], [0, 1]], dtype=bool)
    got = wavefront_distances(passable, (0, 0))
    np.testing.assert_array_equal(got, [[0, INF], [INF, INF]])


def test_stopping_early_keeps_the_settled_distances_exact():
    rng = np.random.default_rng(7)
    for _ in range(50):
        passable = rng.random((9, 11)) > 0.25
        passable[4, 5] = True
        full = wavefront_distances(passable, (4, 5))
        reached = np.argwhere(np.isfinite(full))
        target = reached[rng.integers(len(reached))]
        partial = wavefront_distances(passable, (4, 5), targets=[target])
        assert partial[tuple(target)] == full[tuple(target)]
        # Everything settled before the target is exact; nothing is ever below the truth.
        assert (partial >= full - 1e-12).all()


def test_bad_arguments_name_the_argument():
    with pytest.raises(ValueError, match="source"):
        wavefront_distances(np.ones((2, 2), bool), (5, 0))
    with pytest.raises(ValueError, match="passable"):
        wavefront_distances(np.ones(3, bool), (0, 0))
    with pytest.raises(ValueError, match="cost_factor"):
        wavefront_distances(np.ones((2, 2), bool), (0, 0), cost_factor=np.zeros((2, 2)))
