import numpy as np

from planner._lod import LodConfig, frame_crowd, lod_budgets, visibility


def test_zoomed_camera_shows_at_least_half_the_crowd_and_on_shows_all():
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(-8, 8, 400), np.zeros(400), rng.uniform(-8, 8, 400)])
    on, _ = visibility(frame_crowd(pts, 0.9, 1.0), pts)
    assert on.all()
    zoomed, _ = visibility(frame_crowd(pts, 0.9, 0.5, focus=0), pts)
    assert 0.5 <= zoomed.mean() < 0.75 and zoomed[0]


def test_budgets_fall_linearly_with_distance_and_are_minimal_off_screen():
    cfg = LodConfig(near_m=2.0, far_m=12.0, max_couples=8, near_slice_m=0.1, far_slice_m=0.3)
    couples, slices = lod_budgets(np.array([True, True, True, True, False]), np.array([1.0, 2.0, 7.0, 12.0, 1.0]), cfg)
    np.testing.assert_array_equal(couples, [8, 8, 4, 0, 0])
    np.testing.assert_allclose(slices, [0.1, 0.1, 0.2, -1.0, -1.0])
