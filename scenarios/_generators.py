"""Procedural terrains and crates.

Every generator is deterministic: randomness comes only from
``np.random.default_rng(seed)`` created inside the call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.scenarios._arrays import finite_float, invalid, positive_float
from footfall.scenarios._obstacles import STATIC, VELOCITY, WAYPOINTS, Obstacles
from footfall.scenarios._terrain import Heightfield

MAX_TERRAIN_CELLS = 4096 * 4096
"""Largest terrain grid (samples) a generator or loader will build."""

_WAVES_PER_OCTAVE = 6
_PLACEMENT_ATTEMPTS = 500


def _grid(size: tuple[float, float], cell_size: float) -> tuple[np.ndarray, np.ndarray]:
    """World x (C,) and z (R,) sample coordinates of a grid of ``size`` = (x extent, z extent) m centred on the origin.

    Each extent is rounded up to a whole number of cells (at least one).
    """
    cell_size = positive_float(cell_size, "cell_size")
    if len(size) != 2:
        raise invalid("size", "expected (x extent, z extent)")
    extents = [positive_float(extent, "size") for extent in size]
    cells = [max(1.0, math.ceil(extent / cell_size - 1e-9)) if extent / cell_size < 1e12 else math.inf
             for extent in extents]
    if (cells[0] + 1) * (cells[1] + 1) > MAX_TERRAIN_CELLS:
        raise invalid("cell_size", f"terrain grid would have more than {MAX_TERRAIN_CELLS} samples; "
                                   "use a larger cell_size or a smaller size")
    xs, zs = ((np.arange(int(n) + 1) - 0.5 * n) * cell_size for n in cells)
    return xs, zs


def flat_heightfield(size: tuple[float, float], cell_size: float, height: float = 0.0) -> Heightfield:
    """Flat ground at ``height`` m over ``size`` = (x, z) extent in m, centred on the origin.

    An extent that is not a whole number of cells is rounded up.

    Parameters
    ----------
    size : (float, float)
        Extent (m) along x and z, each > 0.
    cell_size : float
        Grid spacing (m), > 0.
    height : float, optional
        Ground height y (m); default 0.

    Returns
    -------
    Heightfield

    Examples
    --------
    >>> from footfall.scenarios import flat_heightfield
    >>> ground = flat_heightfield((2.0, 1.0), 0.5, height=0.2)
    >>> ground.heights.shape, ground.x_range, ground.z_range    # 3 rows along z, 5 columns along x
    ((3, 5), (-1.0, 1.0), (-0.5, 0.5))
    >>> float(ground.height_at(0.3, -0.1))
    0.2
    >>> flat_heightfield((1.2, 1.0), 0.5).x_range    # 1.2 m is 2.4 cells: 3 cells, 1.5 m
    (-0.75, 0.75)
    """
    xs, zs = _grid(size, cell_size)
    heights = np.full((zs.size, xs.size), finite_float(height, "height"))
    return Heightfield(heights, xs[0], zs[0], cell_size)


def hills_heightfield(
    size: tuple[float, float],
    cell_size: float,
    amplitude: float,
    wavelength: float,
    octaves: int = 3,
    persistence: float = 0.5,
    seed: int = 0,
) -> Heightfield:
    """Smooth rolling hills: a seeded sum of plane waves, rescaled to heights in [0, amplitude] m.

    Octave ``o`` (0-based) adds six sine waves of random direction and phase
    with wavelengths near ``wavelength / 2**o`` m (+-25 %) and weight
    ``persistence**o``. The sum is then shifted and scaled so the lowest point
    is at 0 m and the highest at ``amplitude`` m.

    Parameters
    ----------
    size : (float, float)
        Extent (m) along x and z, each > 0, centred on the origin; rounded up to whole cells.
    cell_size : float
        Grid spacing (m), > 0.
    amplitude : float
        Height span (m), >= 0.
    wavelength : float
        Main wavelength (m), > 0.
    octaves : int, optional
        Number of octaves, >= 1; default 3.
    persistence : float, optional
        Weight of each further octave, > 0; default 0.5.
    seed : int, optional
        Seed of ``np.random.default_rng``; default 0.

    Returns
    -------
    Heightfield

    Examples
    --------
    >>> import numpy as np
    >>> from footfall.scenarios import hills_heightfield
    >>> hills = hills_heightfield((4.0, 4.0), 0.1, amplitude=0.3, wavelength=2.0, seed=1)
    >>> hills.heights.shape, hills.x_range
    ((41, 41), (-2.0, 2.0))
    >>> round(float(hills.heights.min()), 3), round(float(hills.heights.max()), 3)
    (0.0, 0.3)
    >>> again = hills_heightfield((4.0, 4.0), 0.1, amplitude=0.3, wavelength=2.0, seed=1)
    >>> bool(np.array_equal(hills.heights, again.heights))    # the same seed gives the same hills
    True
    """
    amplitude = finite_float(amplitude, "amplitude")
    if amplitude < 0.0:
        raise invalid("amplitude", "must be >= 0")
    wavelength = positive_float(wavelength, "wavelength")
    if isinstance(octaves, bool) or int(octaves) != octaves or octaves < 1:
        raise invalid("octaves", "must be an integer >= 1")
    persistence = positive_float(persistence, "persistence")
    xs, zs = _grid(size, cell_size)
    rng = np.random.default_rng(seed)
    heights = np.zeros((zs.size, xs.size))
    for octave in range(int(octaves)):
        weight = persistence**octave
        for _ in range(_WAVES_PER_OCTAVE):
            direction = rng.uniform(0.0, 2.0 * math.pi)
            length = wavelength / 2**octave * rng.uniform(0.8, 1.25)
            phase = rng.uniform(0.0, 2.0 * math.pi)
            k = 2.0 * math.pi / length
            along_x = k * math.cos(direction) * xs + phase
            along_z = k * math.sin(direction) * zs
            # sin(a + b) = sin a cos b + cos a sin b, as outer products.
            heights += weight * (np.outer(np.cos(along_z), np.sin(along_x)) + np.outer(np.sin(along_z), np.cos(along_x)))
    span = heights.max() - heights.min()
    heights = (heights - heights.min()) * (amplitude / span if span > 0.0 else 0.0)
    return Heightfield(heights, xs[0], zs[0], cell_size)


def stairs_heightfield(
    size: tuple[float, float],
    cell_size: float,
    rise: float,
    run: float,
    steps: int,
    start: float = 0.0,
    direction: float = 0.0,
    landing: float | None = None,
) -> Heightfield:
    """A straight flight of ``steps`` stairs, each ``rise`` m high and ``run`` m deep.

    Distance along the stairs is ``d = x cos(direction) + z sin(direction)``
    (m); the stairs span the whole terrain across that direction. Ground is
    at 0 m for d < ``start``; risers are at ``d = start + k * run`` for
    k = 0 .. steps-1, so the top (``steps * rise`` m) begins at
    ``start + (steps - 1) * run``. Without ``landing`` the top continues to the
    terrain edge; with it, the top is ``landing`` m deep and a mirror flight
    descends back to 0 m.

    Parameters
    ----------
    size : (float, float)
        Extent (m) along x and z, each > 0, centred on the origin; rounded up to whole cells.
    cell_size : float
        Grid spacing (m), > 0.
    rise : float
        Step height (m), > 0.
    run : float
        Step depth (m), > 0.
    steps : int
        Number of steps, >= 1.
    start : float, optional
        Distance ``d`` (m) of the first riser; default 0.
    direction : float, optional
        Climbing direction (radians) about +y; default 0 (+x).
    landing : float, optional
        Depth (m) of the top before a mirror flight descends; None (default): no descent.

    Returns
    -------
    Heightfield

    Examples
    --------
    Three 0.1 m steps, 0.5 m deep, climbing along +x from x = 0:

    >>> from footfall.scenarios import stairs_heightfield
    >>> stairs = stairs_heightfield((6.0, 1.0), 0.1, rise=0.1, run=0.5, steps=3)
    >>> stairs.height_at([-1.0, 0.25, 0.75, 1.25, 2.9], 0.0).round(3)    # x in [-3, 3] m
    array([0. , 0.1, 0.2, 0.3, 0.3])

    With a 0.5 m landing (the top runs from x = 1 m to 1.5 m), then down again:

    >>> stairs = stairs_heightfield((6.0, 1.0), 0.1, rise=0.1, run=0.5, steps=3, landing=0.5)
    >>> stairs.height_at([1.25, 1.75, 2.25, 2.75], 0.0).round(3)
    array([0.3, 0.2, 0.1, 0. ])
    """
    rise = positive_float(rise, "rise")
    run = positive_float(run, "run")
    if isinstance(steps, bool) or int(steps) != steps or steps < 1:
        raise invalid("steps", "must be an integer >= 1")
    steps = int(steps)
    start = finite_float(start, "start")
    direction = finite_float(direction, "direction")
    xs, zs = _grid(size, cell_size)
    d = math.cos(direction) * xs[None, :] + math.sin(direction) * zs[:, None]
    up = np.clip(np.floor((d - start) / run) + 1.0, 0.0, steps)
    if landing is not None:
        landing = positive_float(landing, "landing")
        top_end = start + (steps - 1) * run + landing
        up -= np.clip(np.floor((d - top_end) / run) + 1.0, 0.0, steps)
    return Heightfield(rise * up, xs[0], zs[0], cell_size)


def resting_y(terrain: Heightfield, x: np.ndarray | float, z: np.ndarray | float, height: float, lift: float = 0.0) -> np.ndarray:
    """World y (m) of the centre of a box ``height`` m tall whose bottom centre rests ``lift`` m above the ground at (x, z)."""
    return terrain.height_at(x, z) + 0.5 * height + lift


def terrain_loop(terrain: Heightfield, points_xz: np.ndarray, height: float, lift: float = 0.0) -> np.ndarray:
    """A closed waypoint loop (k', 3) for a box ``height`` m tall resting ``lift`` m above the ground.

    ``points_xz`` (k, 2) are world (x, z). On uneven terrain every leg of the
    loop is subdivided (at most ``max(2 cells, 0.1 m)`` apart) so the box
    follows the ground; on flat terrain the points are kept as they are.
    """
    points_xz = np.asarray(points_xz, dtype=np.float64).reshape(-1, 2)
    if np.ptp(terrain.heights) > 0.0 and points_xz.shape[0] >= 2:
        points_xz = _densify_xz(points_xz, max(2.0 * terrain.cell_size, 0.1))
    y = resting_y(terrain, points_xz[:, 0], points_xz[:, 1], height, lift)
    return np.column_stack([points_xz[:, 0], y, points_xz[:, 1]])


@dataclass(frozen=True)
class CrateRecipe:
    """Parameters of :func:`random_crates` (the ``[obstacles_random]`` table of a scenario file).

    All lengths in m, speeds in m/s; ranges are (min, max) with 0 < min <= max.

    Attributes
    ----------
    count : int
        Number of crates, >= 0.
    region : (float, float, float, float)
        (x_min, z_min, x_max, z_max): crates (and their loops) stay inside.
    footprint_range : (float, float), default (0.1, 0.6)
        Range of each horizontal box extent (local x and z, drawn independently).
    height_range : (float, float), default (0.1, 0.6)
        Range of box height (local y).
    safe_height_range : (float, float) or None, default None
        Range of the height of safe crates (e.g. low enough to step on);
        ``None`` (default) uses ``height_range``.
    forbidden_fraction : float, default 0.5
        Share of the *static* crates that are forbidden (rounded); the rest are
        safe to step on. Moving crates are always forbidden.
    moving_fraction : float, default 0
        Share of all crates that move (rounded).
    velocity_fraction : float, default 0.5
        Share of the moving crates that move at constant velocity (rounded);
        the rest loop along waypoints. Constant-velocity crates move
        horizontally at their initial height and do not follow the terrain,
        so prefer 0 on uneven ground.
    speed_range : (float, float), default (0.1, 0.4)
        Range of crate speeds.
    loop_radius_range : (float, float), default (0.5, 1.5)
        Range of the radius of a waypoint loop (3 to 6 points around a circle
        through the crate's start).
    min_gap : float, default 0.1
        Minimum clearance between the bounding circles of crates at t = 0.

    The recipe stores the values as given; :func:`random_crates` checks them when it uses them.

    Examples
    --------
    >>> from footfall.scenarios import CrateRecipe
    >>> recipe = CrateRecipe(count=4, region=(-2.5, -2.5, 2.5, 2.5), moving_fraction=0.5)
    >>> recipe.forbidden_fraction, recipe.velocity_fraction, recipe.footprint_range
    (0.5, 0.5, (0.1, 0.6))
    """

    count: int
    region: tuple[float, float, float, float]
    footprint_range: tuple[float, float] = (0.1, 0.6)
    height_range: tuple[float, float] = (0.1, 0.6)
    safe_height_range: tuple[float, float] | None = None
    forbidden_fraction: float = 0.5
    moving_fraction: float = 0.0
    velocity_fraction: float = 0.5
    speed_range: tuple[float, float] = (0.1, 0.4)
    loop_radius_range: tuple[float, float] = (0.5, 1.5)
    min_gap: float = 0.1


def _check_range(value: tuple[float, float], field: str) -> tuple[float, float]:
    low, high = (finite_float(v, field) for v in value)
    if not 0.0 < low <= high:
        raise invalid(field, "expected [min, max] with 0 < min <= max")
    return low, high


def _check_fraction(value: float, field: str) -> float:
    value = finite_float(value, field)
    if not 0.0 <= value <= 1.0:
        raise invalid(field, "must be between 0 and 1")
    return value


def _clear_of(x: np.ndarray, z: np.ndarray, radius: float, circles: list[tuple[float, float, float]]) -> bool:
    """Whether the disks of ``radius`` m at every (x, z) keep clear of every (cx, cz, r) circle."""
    for cx, cz, r in circles:
        if np.any(np.hypot(x - cx, z - cz) < r + radius):
            return False
    return True


def random_crates(
    terrain: Heightfield,
    recipe: CrateRecipe,
    seed: int,
    keep_out: tuple[tuple[float, float, float], ...] = (),
    occupied: tuple[tuple[float, float, float], ...] = (),
) -> Obstacles:
    """Seeded random crates resting on ``terrain`` (see :class:`CrateRecipe`).

    ``keep_out`` and ``occupied`` are (x, z, radius) world disks (m). No crate
    overlaps a keep-out disk at t = 0, and no waypoint loop ever enters one
    (constant-velocity crates may cross them later). Crates keep
    ``recipe.min_gap`` clear of ``occupied`` disks and of each other at t = 0;
    waypoint loops also avoid static crates. Static crates are placed first,
    then constant-velocity ones, then waypoint loops; the returned boxes are in
    that order. Raises :class:`InputError` (field ``count``) if a crate cannot
    be placed.

    Parameters
    ----------
    terrain : Heightfield
        The ground the crates rest on.
    recipe : CrateRecipe
        How many crates, where, how large and how they move.
    seed : int
        Seed of ``np.random.default_rng``: the same arguments always give the same crates.
    keep_out : tuple of (x, z, radius), optional
        World disks (m) no crate may overlap at t = 0; default none.
    occupied : tuple of (x, z, radius), optional
        World disks (m) already taken (e.g. hand-placed boxes); default none.

    Returns
    -------
    Obstacles
        ``recipe.count`` boxes resting on ``terrain`` (no ``lift``): static, then constant-velocity,
        then waypoint loops.

    Examples
    --------
    Four crates on flat ground, half of them moving (one at constant velocity, one on a
    loop), none within 1 m of the origin:

    >>> import numpy as np
    >>> from footfall.scenarios import CrateRecipe, flat_heightfield, random_crates
    >>> ground = flat_heightfield((6.0, 6.0), 0.1)
    >>> recipe = CrateRecipe(count=4, region=(-2.5, -2.5, 2.5, 2.5), moving_fraction=0.5)
    >>> crates = random_crates(ground, recipe, seed=1, keep_out=((0.0, 0.0, 1.0),))
    >>> len(crates), crates.motion_kind.tolist()
    (4, [0, 0, 1, 2])
    >>> bool(np.all(np.hypot(crates.centres[:, 0], crates.centres[:, 2]) > 1.0))
    True
    >>> bool(np.allclose(crates.centres[:, 1], crates.sizes[:, 1] / 2))    # resting on the ground at y = 0
    True
    >>> again = random_crates(ground, recipe, seed=1, keep_out=((0.0, 0.0, 1.0),))
    >>> bool(np.array_equal(crates.centres, again.centres))
    True
    """
    count = recipe.count
    if isinstance(count, bool) or int(count) != count or count < 0:
        raise invalid("count", "must be an integer >= 0")
    count = int(count)
    x_min, z_min, x_max, z_max = (finite_float(v, "region") for v in recipe.region)
    if not (x_min < x_max and z_min < z_max):
        raise invalid("region", "expected x_min < x_max and z_min < z_max")
    footprint = _check_range(recipe.footprint_range, "footprint_range")
    box_height = _check_range(recipe.height_range, "height_range")
    safe_height = box_height if recipe.safe_height_range is None else _check_range(
        recipe.safe_height_range, "safe_height_range")
    speed = _check_range(recipe.speed_range, "speed_range")
    loop_radius = _check_range(recipe.loop_radius_range, "loop_radius_range")
    forbidden_fraction = _check_fraction(recipe.forbidden_fraction, "forbidden_fraction")
    moving_fraction = _check_fraction(recipe.moving_fraction, "moving_fraction")
    velocity_fraction = _check_fraction(recipe.velocity_fraction, "velocity_fraction")
    min_gap = finite_float(recipe.min_gap, "min_gap")
    if min_gap < 0.0:
        raise invalid("min_gap", "must be >= 0")

    rng = np.random.default_rng(seed)
    n_moving = round(count * moving_fraction)
    n_velocity = round(n_moving * velocity_fraction)
    n_static = count - n_moving
    kinds = np.array([STATIC] * n_static + [VELOCITY] * n_velocity + [WAYPOINTS] * (n_moving - n_velocity), np.int8)
    forbidden = kinds != STATIC
    forbidden[rng.permutation(n_static)[: round(n_static * forbidden_fraction)]] = True
    heights = np.where(forbidden, rng.uniform(*box_height, count), rng.uniform(*safe_height, count))
    sizes = np.column_stack([rng.uniform(*footprint, count), heights, rng.uniform(*footprint, count)])
    yaws = rng.uniform(0.0, math.pi, count)

    circles = list(occupied)
    static_circles = list(occupied)
    centres = np.zeros((count, 3))
    velocities = np.zeros((count, 3))
    speeds = np.zeros(count)
    waypoints: list[np.ndarray] = [np.zeros((0, 3))] * count
    for i in range(count):
        r = 0.5 * float(np.hypot(sizes[i, 0], sizes[i, 2]))
        if x_max - x_min <= 2.0 * r or z_max - z_min <= 2.0 * r:
            raise invalid("region", f"too small for a crate of radius {r:.2f} m")
        for _ in range(_PLACEMENT_ATTEMPTS):
            x = rng.uniform(x_min + r, x_max - r)
            z = rng.uniform(z_min + r, z_max - r)
            if not (_clear_of(x, z, r, list(keep_out)) and _clear_of(x, z, r + min_gap, circles)):
                continue
            if kinds[i] == WAYPOINTS:
                loop = _random_loop(rng, x, z, loop_radius)
                dense = _densify_xz(loop, 0.1)
                inside = (
                    np.all(dense[:, 0] >= x_min + r)
                    and np.all(dense[:, 0] <= x_max - r)
                    and np.all(dense[:, 1] >= z_min + r)
                    and np.all(dense[:, 1] <= z_max - r)
                )
                if not (inside and _clear_of(dense[:, 0], dense[:, 1], r, list(keep_out))
                        and _clear_of(dense[:, 0], dense[:, 1], r + min_gap, static_circles)):
                    continue
                waypoints[i] = terrain_loop(terrain, loop, sizes[i, 1])
                speeds[i] = rng.uniform(*speed)
            elif kinds[i] == VELOCITY:
                heading = rng.uniform(0.0, 2.0 * math.pi)
                velocities[i] = rng.uniform(*speed) * np.array([math.cos(heading), 0.0, math.sin(heading)])
            break
        else:
            raise invalid("count", f"could not place crate {i + 1} of {count} clear of the others and the crowd; "
                                   "lower count or enlarge region")
        centres[i] = (x, float(resting_y(terrain, x, z, sizes[i, 1])), z)
        circles.append((x, z, r))
        if kinds[i] == STATIC:
            static_circles.append((x, z, r))
        if kinds[i] == WAYPOINTS:
            waypoints[i][0] = centres[i]  # identical up to rounding; make it exact
    return Obstacles(centres, sizes, yaws, forbidden, kinds, velocities, tuple(waypoints), speeds)


def _random_loop(rng: np.random.Generator, x: float, z: float, radius_range: tuple[float, float]) -> np.ndarray:
    """(k, 2) closed loop of 3..6 points on a jittered circle through (x, z), starting at (x, z)."""
    k = int(rng.integers(3, 7))
    radius = rng.uniform(*radius_range)
    towards_centre = rng.uniform(0.0, 2.0 * math.pi)
    sense = 1.0 if rng.random() < 0.5 else -1.0
    cx = x + radius * math.cos(towards_centre)
    cz = z + radius * math.sin(towards_centre)
    angles = towards_centre + math.pi + sense * 2.0 * math.pi * np.arange(k) / k
    angles[1:] += rng.uniform(-0.25, 0.25, k - 1) * 2.0 * math.pi / k
    radii = np.full(k, radius)
    radii[1:] *= rng.uniform(0.8, 1.2, k - 1)
    loop = np.column_stack([cx + radii * np.cos(angles), cz + radii * np.sin(angles)])
    loop[0] = (x, z)
    return loop


def _densify_xz(loop: np.ndarray, spacing: float) -> np.ndarray:
    """Points along the closed loop (k, 2), at most ``spacing`` m apart."""
    dense = []
    for j in range(loop.shape[0]):
        a = loop[j]
        b = loop[(j + 1) % loop.shape[0]]
        n_sub = max(1, math.ceil(float(np.linalg.norm(b - a)) / spacing))
        dense.append(a + (np.arange(n_sub)[:, None] / n_sub) * (b - a))
    return np.vstack(dense)
