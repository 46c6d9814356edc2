"""Rasterisation kernels on cases small enough to check by hand."""

import math

import numpy as np
import pytest

from conftest import fresh_seeds

from footfall.planner._kernels_geometry import (bowed_legs_onto_lines, foot_offsets, rasterise_boxes, segments_cross,
                                                supercover_visit)


def _cells(ax, az, bx, bz, cell=1.0):
    rows = np.empty(64, np.int64)
    cols = np.empty(64, np.int64)
    n = supercover_visit(ax, az, bx, bz, 0.0, 0.0, cell, rows, cols)
    return sorted(zip(rows[:n].tolist(), cols[:n].tolist()))


def test_supercover_of_a_row_segment():
    assert _cells(0.5, 0.5, 3.5, 0.5) == [(0, 0), (0, 1), (0, 2), (0, 3)]


def test_supercover_through_corners_marks_both_side_cells():
    # Diagonal through the corners of cells: the side cells are touched too.
    assert _cells(0.5, 0.5, 2.5, 2.5) == [(0, 0), (0, 1), (1, 0), (1, 1), (1, 2), (2, 1), (2, 2)]


def test_supercover_of_a_shallow_segment_is_4_connected():
    cells = _cells(0.2, 0.3, 4.7, 1.6)
    s = set(cells)
    # every cell except the last has a 4-neighbour in the set
    assert all(any((r + dr, c + dc) in s for dr, dc in ((0, 1), (1, 0), (0, -1), (-1, 0))) for r, c in cells)
    assert (0, 0) in s and (1, 4) in s


def test_small_foot_stencil_is_the_3x3_block():
    off = foot_offsets(0.03, 0.02, 0.4, 0.07)
    assert sorted(map(tuple, off.tolist())) == [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]


def test_long_foot_stencil_follows_its_orientation():
    along_x = {tuple(o) for o in foot_offsets(0.30, 0.02, 0.0, 0.07).tolist()}
    along_z = {tuple(o) for o in foot_offsets(0.30, 0.02, math.pi / 2, 0.07).tolist()}
    assert (0, 3) in along_x and (3, 0) not in along_x
    assert (3, 0) in along_z and (0, 3) not in along_z


def test_rotated_box_rasterisation():
    # A 2 x 0.2 box rotated 45 degrees, centred at (2.5, 2.5) on a 5 x 5 grid of 1 m cells:
    # it covers the cells of the diagonal and (being conservative) their corner neighbours.
    top = np.zeros((5, 5))
    forbidden = np.zeros((5, 5), np.uint8)
    rasterise_boxes(top, forbidden, 0.0, 0.0, 1.0, np.array([[2.5, 0.5, 2.5]]), np.array([[2.0, 1.0, 0.2]]),
                    np.array([math.pi / 4]), np.array([True]), np.array([True]))
    expected = np.zeros((5, 5), np.uint8)
    for r, c in [(1, 1), (1, 2), (2, 1), (2, 2), (2, 3), (3, 2), (3, 3)]:
        expected[r, c] = 1
    np.testing.assert_array_equal(forbidden, expected)
    np.testing.assert_array_equal(top, expected * 1.0)


def test_safe_box_raises_elevation_without_forbidding():
    top = np.full((3, 3), 0.1)
    forbidden = np.zeros((3, 3), np.uint8)
    rasterise_boxes(top, forbidden, 0.0, 0.0, 1.0, np.array([[1.5, 0.2, 1.5]]), np.array([[0.5, 0.4, 0.5]]),
                    np.array([0.0]), np.array([False]), np.array([True]))
    expected = np.full((3, 3), 0.1)
    expected[1, 1] = 0.4
    np.testing.assert_array_equal(top, expected)
    assert not forbidden.any()


def test_a_moving_box_drawn_over_a_static_one_leaves_its_cells_static():
    # Static 2 x 1 box over cells (1, 1), (1, 2); a moving 2 x 1 box over (1, 2), (1, 3) drawn after it:
    # the shared cell (1, 2) stays FORBIDDEN_STATIC (1), only (1, 3) is FORBIDDEN_MOVING (2). A static
    # box drawn after the moving one makes its cells static again.
    from footfall.planner.layout import FORBIDDEN_MOVING, FORBIDDEN_STATIC

    def draw(forbidden, centre_x, mark):
        rasterise_boxes(np.zeros((3, 5)), forbidden, 0.0, 0.0, 1.0, np.array([[centre_x, 0.5, 1.5]]),
                        np.array([[1.8, 1.0, 0.8]]), np.array([0.0]), np.array([True]), np.array([True]), mark)

    forbidden = np.zeros((3, 5), np.uint8)
    draw(forbidden, 2.0, FORBIDDEN_STATIC)
    draw(forbidden, 3.0, FORBIDDEN_MOVING)
    np.testing.assert_array_equal(forbidden, [[0, 0, 0, 0, 0], [0, 1, 1, 2, 0], [0, 0, 0, 0, 0]])
    draw(forbidden, 3.0, FORBIDDEN_STATIC)
    np.testing.assert_array_equal(forbidden, [[0, 0, 0, 0, 0], [0, 1, 1, 1, 0], [0, 0, 0, 0, 0]])


def test_segments_cross():
    assert segments_cross(0, 0, 2, 2, 0, 2, 2, 0)
    assert not segments_cross(0, 0, 1, 1, 2, 2, 3, 3)
    assert not segments_cross(0, 0, 2, 0, 0, 1, 2, 1)


# --------------------------------------------------------------------------- points near a query
def test_points_near_on_a_hand_made_grid():
    """Five feet of two characters, radius 1 m. A query of character 0 at the origin: character 1's
    feet 0.5, 1.0 (exactly: included) and 1.0 m away, not the one 1.5 m away, nor its own foot. A
    query of character 1 at (0, 1): character 0's foot 0.82 m away."""
    from footfall.planner._kernels_geometry import points_near

    points = np.array([[0.5, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.5], [-0.2, 0.2]])
    owner = np.array([1, 1, 1, 1, 0])
    start, index = points_near(points, owner, np.array([[0.0, 0.0], [0.0, 1.0]]), np.array([0, 1]), 1.0)
    assert start.tolist() == [0, 3, 4] and index.tolist() == [0, 1, 2, 4]


@pytest.mark.parametrize("seed", fresh_seeds([0, 1, 2], 3, salt=77))
def test_points_near_equals_brute_force_on_random_crowds(seed):
    """Against a plain distance matrix (no grid): random feet of random owners, queries inside and
    outside their box, radii from a tenth to twice the spread."""
    from footfall.planner._kernels_geometry import points_near

    rng = np.random.default_rng(seed)
    n, q = int(rng.integers(1, 300)), int(rng.integers(1, 60))
    points = rng.uniform(-5.0, 5.0, (n, 2))
    owner = rng.integers(0, 20, n)
    queries = rng.uniform(-7.0, 7.0, (q, 2))
    query_owner = rng.integers(0, 20, q)
    radius = float(rng.uniform(0.1, 20.0))
    start, index = points_near(points, owner, queries, query_owner, radius)
    d = np.hypot(*(queries[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    for k in range(q):
        expected = np.flatnonzero((d[k] <= radius) & (owner != query_owner[k]))
        assert index[start[k]:start[k + 1]].tolist() == expected.tolist(), f"seed {seed}, query {k}"


def test_legs_as_drawn_are_carried_onto_their_lines_where_they_leave_them():
    # Character 0, legs 1-3 (P = 3 points: hip, knee, foot) asked for by one planned foot.
    drawn = np.zeros((1, 4, 3, 3))
    drawn[0, 1, :, 0] = [0.0, 0.05, 0.1]           # along its line: no rows
    drawn[0, 2, :, 0] = [0.0, -0.05, 0.02]         # a quadruped's knee 5 cm before its hip, on the line
    drawn[0, 3, :, 0] = [0.0, 0.05, 0.1]
    drawn[0, 3, 1, 2] = 0.0015                     # a knee 1.5 mm off its line: under the tolerance
    straight = np.array([[[0.0, 0.0, 0.1, 0.0], [0.0, 1.0, 0.02, 1.0], [0.0, 0.0, 0.1, 0.0]]])
    rows, start = bowed_legs_onto_lines(drawn, np.array([0]), np.array([[1, 2, 3]]), straight, 0.002, 5)
    # Leg 2: hip and foot both move by (0, 1): the knee with them, to (-0.05, 1); two segment rows.
    np.testing.assert_allclose(rows, [[0.0, 1.0, -0.05, 1.0, 0.0], [-0.05, 1.0, 0.02, 1.0, 0.0]], rtol=0, atol=1e-15)
    assert start.tolist() == [0, 2]
    # The hip moves by (0, 1), the foot by (0.03, 0): the knee, 0.05 of the leg's 0.12 m from the hip,
    # moves by 7/12 (0, 1) + 5/12 (0.03, 0).
    straight[0, 1] = [0.0, 1.0, 0.05, 0.0]
    rows, _ = bowed_legs_onto_lines(drawn, np.array([0]), np.array([[1, 2, 3]]), straight, 0.002, 5)
    np.testing.assert_allclose(rows[0, 2:4], [-0.05 + 5 / 12 * 0.03, 7 / 12], rtol=0, atol=1e-15)
