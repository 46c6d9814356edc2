"""A whole scenario: terrain, obstacles, the crowd to spawn and a camera."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from footfall.scenarios._arrays import finite_float, frozen_array, invalid, positive_float, readonly
from footfall.scenarios._obstacles import Obstacles
from footfall.scenarios._terrain import Heightfield

HEADING_MODES = ("fixed", "random")
_GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))


@dataclass(frozen=True, eq=False)
class CrowdSpawn:
    """Where and how to spawn a crowd of identical creatures, and where they walk.

    Attributes
    ----------
    creature : str
        Built-in creature name, or path to a creature ``.toml`` (loaders store
        it already resolved against the scenario file); pass to
        :func:`scenarios.load_creature`.
    count : int
        Number of creatures, >= 1.
    centre : (2,) ndarray
        World (x, z) of the spawn disk centre, m.
    radius : float
        Spawn disk radius (m), >= 0 (0 with one creature: spawn at ``centre``).
    heading : float
        Initial heading (radians) when ``heading_mode == "fixed"``; world
        forward is (cos heading, 0, sin heading).
    heading_mode : {"fixed", "random"}
        ``"fixed"``: every creature faces ``heading``; ``"random"``: each
        creature draws a heading uniformly in [-pi, pi) (see :meth:`initial_poses`).
    speed : float
        Desired walking speed (m/s), > 0.
    goal : (2,) ndarray
        World (x, z) of the final destination, m.
    waypoints : (k, 2) ndarray
        World (x, z) points visited in order before ``goal`` (k may be 0; None is stored as (0, 2)).
    feet_spacing : float
        Scale (> 0) applied to the creature's rest feet (forward, lateral); default 1.
    gait : str or None
        The gait the crowd walks with: a built-in gait name, ``"default"``, or a path to a
        gait ``.toml`` (loaders store it already resolved against the scenario file); pass to
        :func:`scenarios.load_gait` with the creature. None: the creature's gaits
        (its default, or its built-in schedule by speed).
    spawn_clear_s : float
        s, >= 0: creatures are spawned clear of where the boxes will be over this long (a moving box
        that would reach a creature in its first seconds runs it over while it turns to go); 0: of
        where they are at the start. Default 3.

    Examples
    --------
    Three ants spawned within 0.5 m of (1, 0), walking via (2, 1) to (5, 0):

    >>> from footfall.scenarios import CrowdSpawn
    >>> crowd = CrowdSpawn(creature="ant", count=3, centre=[1.0, 0.0], radius=0.5, heading=0.0,
    ...                    heading_mode="fixed", speed=0.3, goal=[5.0, 0.0], waypoints=[[2.0, 1.0]])
    >>> crowd.route.tolist()
    [[2.0, 1.0], [5.0, 0.0]]
    >>> crowd.feet_spacing, crowd.gait
    (1.0, None)
    >>> CrowdSpawn("ant", 1, [0.0, 0.0], 0.0, 0.0, "fixed", 0.3, [5.0, 0.0]).waypoints.shape
    (0, 2)
    """

    creature: str
    count: int
    centre: np.ndarray
    radius: float
    heading: float
    heading_mode: str
    speed: float
    goal: np.ndarray
    waypoints: np.ndarray | None = None
    feet_spacing: float = 1.0
    gait: str | None = None
    spawn_clear_s: float = 3.0

    def __post_init__(self) -> None:
        if not isinstance(self.creature, str) or not self.creature.strip():
            raise invalid("creature", "must be a non-empty string")
        if self.gait is not None and (not isinstance(self.gait, str) or not self.gait.strip()):
            raise invalid("gait", "must be a non-empty string or None")
        if isinstance(self.count, bool) or not isinstance(self.count, (int, np.integer)) or self.count < 1:
            raise invalid("count", "must be an integer >= 1")
        object.__setattr__(self, "count", int(self.count))
        object.__setattr__(self, "centre", frozen_array(self.centre, "centre", (2,)))
        radius = finite_float(self.radius, "radius")
        if radius < 0.0:
            raise invalid("radius", "must be >= 0")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "heading", finite_float(self.heading, "heading"))
        if self.heading_mode not in HEADING_MODES:
            raise invalid("heading_mode", f"must be one of {', '.join(HEADING_MODES)}")
        object.__setattr__(self, "speed", positive_float(self.speed, "speed"))
        object.__setattr__(self, "goal", frozen_array(self.goal, "goal", (2,)))
        waypoints = np.zeros((0, 2)) if self.waypoints is None or np.size(self.waypoints) == 0 else self.waypoints
        object.__setattr__(self, "waypoints", frozen_array(waypoints, "waypoints", (None, 2)))
        object.__setattr__(self, "feet_spacing", positive_float(self.feet_spacing, "feet_spacing"))
        spawn_clear_s = finite_float(self.spawn_clear_s, "spawn_clear_s")
        if spawn_clear_s < 0.0:
            raise invalid("spawn_clear_s", "must be >= 0")
        object.__setattr__(self, "spawn_clear_s", spawn_clear_s)

    @property
    def route(self) -> np.ndarray:
        """(k + 1, 2) world (x, z) points to walk through in order: the waypoints, then the goal.

        Examples
        --------
        >>> from footfall.scenarios import CrowdSpawn
        >>> CrowdSpawn("ant", 1, [0.0, 0.0], 0.0, 0.0, "fixed", 0.3, goal=[5.0, 0.0]).route.tolist()
        [[5.0, 0.0]]
        """
        return readonly(np.vstack([self.waypoints, self.goal[None, :]]))

    def initial_poses(self, seed: int) -> tuple[np.ndarray, np.ndarray]:
        """Deterministic start positions (count, 2) (world x, z, m) and headings (count,) (radians).

        Positions follow a sunflower spiral inside the spawn disk: creature 0 at
        the centre, the others spread evenly out to about ``radius``; adjacent
        creatures are roughly ``radius * sqrt(pi / count)`` apart. Headings are
        ``heading`` for ``"fixed"``, or drawn from ``np.random.default_rng(seed)``
        for ``"random"``.

        Parameters
        ----------
        seed : int
            Seed of the random headings; unused for ``"fixed"``.

        Returns
        -------
        positions : (count, 2) ndarray
            World (x, z) start positions, m.
        headings : (count,) ndarray
            Start headings, radians.

        Examples
        --------
        Creature i starts ``radius * sqrt(i / count)`` from the centre:

        >>> import numpy as np
        >>> from footfall.scenarios import CrowdSpawn
        >>> crowd = CrowdSpawn("ant", 3, [1.0, 0.0], 0.5, 0.0, "fixed", 0.3, [5.0, 0.0])
        >>> positions, headings = crowd.initial_poses(seed=0)
        >>> positions[0].tolist(), headings.tolist()
        ([1.0, 0.0], [0.0, 0.0, 0.0])
        >>> np.hypot(*(positions - crowd.centre).T).round(3)    # 0, 0.5 sqrt(1/3), 0.5 sqrt(2/3)
        array([0.   , 0.289, 0.408])
        >>> spread = CrowdSpawn("ant", 4, [0.0, 0.0], 1.0, 0.0, "random", 0.3, [5.0, 0.0])
        >>> bool(np.array_equal(spread.initial_poses(7)[1], spread.initial_poses(7)[1]))    # same seed, same headings
        True
        """
        i = np.arange(self.count)
        r = self.radius * np.sqrt(i / self.count)
        angle = i * _GOLDEN_ANGLE
        positions = self.centre + np.stack([r * np.cos(angle), r * np.sin(angle)], axis=1)
        if self.heading_mode == "random":
            headings = np.random.default_rng(seed).uniform(-math.pi, math.pi, self.count)
        else:
            headings = np.full(self.count, self.heading)
        return positions, headings


@dataclass(frozen=True, eq=False)
class Camera:
    """A pinhole camera looking from ``position`` at ``target``.

    Attributes
    ----------
    position, target : (3,) ndarray
        World points (x, y, z), m; they must differ.
    fov : float
        Vertical field of view (radians), 0 < fov < pi.

    Examples
    --------
    >>> from footfall.scenarios import Camera
    >>> camera = Camera(position=[0.0, 6.0, -9.0], target=[0.0, 0.0, 0.0], fov=0.9)
    >>> camera.position.tolist(), camera.fov
    ([0.0, 6.0, -9.0], 0.9)
    >>> round(float(camera.target[1] - camera.position[1]), 1)    # y is up: it looks down
    -6.0
    """

    position: np.ndarray
    target: np.ndarray
    fov: float

    def __post_init__(self) -> None:
        position = frozen_array(self.position, "position", (3,))
        target = frozen_array(self.target, "target", (3,))
        if np.allclose(position, target, rtol=0.0, atol=1e-9):
            raise invalid("target", "must differ from position")
        fov = finite_float(self.fov, "fov")
        if not 0.0 < fov < math.pi:
            raise invalid("fov", "must be between 0 and pi radians (exclusive)")
        object.__setattr__(self, "position", position)
        object.__setattr__(self, "target", target)
        object.__setattr__(self, "fov", fov)


@dataclass(frozen=True, eq=False)
class Scenario:
    """Everything the simulation needs to know about a scene.

    Attributes
    ----------
    name : str
        Scenario name.
    source : str
        Path of the scenario file as given, or ``"builtin:NAME"`` (a variant appends ``@key=value,...``).
    terrain : Heightfield
        The ground.
    obstacles : Obstacles
        The boxes (possibly none).
    crowd : CrowdSpawn
        The creatures to spawn and where they walk.
    camera : Camera
        The default view.
    seed : int
        Scenario seed (>= 0), for anything random left to the simulation,
        e.g. :meth:`CrowdSpawn.initial_poses`.
    description : str
        Free text.

    Examples
    --------
    Scenarios are usually loaded (:func:`load_scenario`):

    >>> from footfall.scenarios import load_scenario
    >>> scenario = load_scenario("flat")
    >>> scenario.name, scenario.source, scenario.seed
    ('flat', 'builtin:flat', 0)
    >>> scenario.terrain.heights.shape, len(scenario.obstacles)    # 20 m x 20 m at 0.05 m, no boxes
    ((401, 401), 0)
    >>> scenario.crowd.creature, scenario.crowd.centre.tolist(), scenario.crowd.goal.tolist()
    ('spider', [-5.0, 0.0], [5.0, 0.0])
    """

    name: str
    source: str
    terrain: Heightfield
    obstacles: Obstacles
    crowd: CrowdSpawn
    camera: Camera
    seed: int
    description: str = ""

    def __post_init__(self) -> None:
        checks = (
            ("terrain", Heightfield),
            ("obstacles", Obstacles),
            ("crowd", CrowdSpawn),
            ("camera", Camera),
        )
        for name, cls in checks:
            if not isinstance(getattr(self, name), cls):
                raise invalid(name, f"expected a {cls.__name__}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or self.seed < 0:
            raise invalid("seed", "must be an integer >= 0")
        object.__setattr__(self, "seed", int(self.seed))
