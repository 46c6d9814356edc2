"""Reading a simulation recording (``footfall simulate --record FILE.npz``) back, validated.

The recording format is written by :class:`planner._simulation.Recorder`: one ``.npz``
with a JSON ``header`` (format ``footfall-recording``, version
:data:`planner.RECORDING_VERSION`), per-frame arrays (F frames, C characters, L legs,
S segments) and the planning ``events`` table. Frame k holds the state after the k-th
step of 1/30 s, i.e. at time ``(k + 1) * dt``.

A file that is not such a recording, comes from another recording version or has
arrays of inconsistent shapes raises :class:`footfall._errors.InputError` naming the
file, the field and the reason (the CLI prints it as one line and exits with code 2).
"""

from __future__ import annotations

import json
import math
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from footfall._errors import InputError
from footfall.planner._simulation import RECORDING_FORMAT, RECORDING_VERSION

OPTIONAL_ARRAYS = ("foot_yaw", "speed", "lod_level")
"""Per-frame arrays a recording may lack (written before they were kept; ``lod_level`` with LOD off)."""


@dataclass(frozen=True, eq=False)
class Recording:
    """A loaded recording (arrays as in :class:`planner._simulation.Recorder`).

    pelvis:        (F, C, 3) world pelvis positions, m.
    orientation:   (F, C, 3) (heading, pitch, roll), rad (:func:`planner.body_rotation`).
    feet:          (F, C, L, 3) world feet: stance footholds, swing trajectory points, m.
    in_stance:     (F, C, L) bool.
    swing_phase:   (F, C, L) fraction of the swing done (0 in stance).
    joint_angles:  (F, C, L, S + 1) [azimuth, pitch_0, ..., pitch_{S-1}], rad (:mod:`planner._ik`).
    ik_on:         (F, C) bool: the IK solved this character's legs this frame (LOD off-screen: no).
    events:        (E, len(header["event_columns"])) planning events.
    foot_yaw:      (F, C, L) yaw of each foot's rectangle, rad, or None (recorded before it was kept).
    speed:         (F, C) commanded body speed, m/s, or None (likewise).
    lod_level:     (F, C) level of detail of each character (:data:`planner._lod.LEVEL_NAMES`), or
                   None (LOD off, or recorded before it was kept).
    """

    path: Path
    header: dict
    pelvis: np.ndarray
    orientation: np.ndarray
    feet: np.ndarray
    in_stance: np.ndarray
    swing_phase: np.ndarray
    joint_angles: np.ndarray
    ik_on: np.ndarray
    events: np.ndarray
    foot_yaw: np.ndarray | None = None
    speed: np.ndarray | None = None
    lod_level: np.ndarray | None = None

    @property
    def frames(self) -> int:
        return int(self.pelvis.shape[0])

    @property
    def characters(self) -> int:
        return int(self.pelvis.shape[1])

    @property
    def legs(self) -> int:
        return int(self.feet.shape[2])

    @property
    def segments(self) -> int:
        return int(self.joint_angles.shape[3]) - 1

    @property
    def dt(self) -> float:
        """Seconds per frame."""
        return float(self.header["dt"])

    @property
    def times(self) -> np.ndarray:
        """(F,) simulated time of each frame, s (frame k is the state after k + 1 steps)."""
        return (np.arange(self.frames) + 1.0) * self.dt

    @property
    def creature(self) -> str:
        return str(self.header["creature"])

    def load_creature(self):
        """The recorded creature: a built-in by name, or the user's creature file the recording carries."""
        from footfall.scenarios import load_creature, load_creature_text

        text = self.header.get("creature_toml")
        if isinstance(text, str):
            return load_creature_text(text, f"{self.path}:creature_toml")
        return load_creature(self.creature)

    @property
    def leg_names(self) -> tuple[str, ...]:
        return tuple(self.header["leg_names"])

    @property
    def scenario(self) -> str | None:
        name = self.header.get("scenario")
        return None if name is None else str(name)

    def load_scenario(self):
        """The recorded scenario: the user's scenario file it was run from, while that file is where
        it was (its height maps and creature files are found relative to it), else a built-in by name."""
        from footfall.scenarios import load_scenario

        file = self.header.get("scenario_file")
        if isinstance(file, str) and Path(file).is_file():
            return load_scenario(file)
        return load_scenario(self.scenario)

    def event_column(self, name: str) -> np.ndarray:
        """(E,) one column of the events table, by its header name."""
        return self.events[:, list(self.header["event_columns"]).index(name)]

    def touchdowns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(frame, character, leg) index arrays of the landings: a foot in stance at frame k
        that was swinging at frame k - 1 (the feet standing at frame 0 are not landings)."""
        landed = self.in_stance[1:] & ~self.in_stance[:-1]
        k, c, l = np.nonzero(landed)
        return k + 1, c, l

    def head(self, frames: int) -> Recording:
        """The first ``frames`` frames (and their events)."""
        if not 1 <= frames <= self.frames:
            raise InputError(self.path, "frames", f"expected 1 to {self.frames} frames, got {frames}")
        keep = self.event_column("frame") < frames if self.events.shape[0] else np.zeros(0, bool)
        return Recording(path=self.path, header=self.header, pelvis=self.pelvis[:frames],
                         orientation=self.orientation[:frames], feet=self.feet[:frames],
                         in_stance=self.in_stance[:frames], swing_phase=self.swing_phase[:frames],
                         joint_angles=self.joint_angles[:frames], ik_on=self.ik_on[:frames],
                         events=self.events[keep],
                         **{key: None if getattr(self, key) is None else getattr(self, key)[:frames]
                            for key in OPTIONAL_ARRAYS})


def load_recording(path: str | Path) -> Recording:
    """Load and validate a recording; raises InputError(file, field, reason) on anything amiss."""
    path = Path(path)
    if not path.is_file():
        raise InputError(path, "file", "no such recording file")
    if not zipfile.is_zipfile(path):
        raise InputError(path, "file", "not a footfall recording (not a .npz archive)")
    try:
        with np.load(path, allow_pickle=False) as data:
            contents = {key: np.array(data[key]) for key in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as e:
        raise InputError(path, "file", f"not a footfall recording (.npz): {e}") from None
    if "header" not in contents:
        raise InputError(path, "header", "missing: not a footfall recording")
    try:
        header = json.loads(str(contents["header"]))
    except (json.JSONDecodeError, TypeError) as e:
        raise InputError(path, "header", f"not valid JSON: {e}") from None
    if not isinstance(header, dict):
        raise InputError(path, "header", "expected a JSON object")
    if header.get("format") != RECORDING_FORMAT:
        raise InputError(path, "header.format", f"expected {RECORDING_FORMAT!r}, got {header.get('format')!r}")
    version = header.get("version")
    if version != RECORDING_VERSION:
        raise InputError(path, "header.version", f"recording version {version!r} is not the version this footfall "
                         f"reads ({RECORDING_VERSION}); record it again with this version")
    dt = header.get("dt")
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not (math.isfinite(dt) and dt > 0):
        raise InputError(path, "header.dt", f"expected a positive number of seconds, got {dt!r}")
    if not isinstance(header.get("creature"), str):
        raise InputError(path, "header.creature", "expected the creature's name")
    leg_names = header.get("leg_names")
    if not (isinstance(leg_names, list) and leg_names and all(isinstance(n, str) for n in leg_names)):
        raise InputError(path, "header.leg_names", "expected a non-empty list of leg names")
    columns = header.get("event_columns")
    if not (isinstance(columns, list) and "frame" in columns):
        raise InputError(path, "header.event_columns", "expected a list of column names including 'frame'")

    def array(key: str, trailing: tuple[int | None, ...], dtype, optional: bool = False) -> np.ndarray | None:
        if key not in contents:
            if optional:
                return None
            raise InputError(path, key, "missing array")
        a = contents[key]
        if a.ndim != 2 + len(trailing) or any(want is not None and got != want
                                              for got, want in zip(a.shape[2:], trailing)):
            raise InputError(path, key, f"unexpected shape {a.shape}")
        if dtype is bool:
            if a.dtype != np.bool_:
                raise InputError(path, key, f"expected booleans, got {a.dtype}")
            return a
        if dtype is int:
            if not np.issubdtype(a.dtype, np.integer):
                raise InputError(path, key, f"expected integers, got {a.dtype}")
            return a.astype(np.int64)
        if not np.issubdtype(a.dtype, np.number):
            raise InputError(path, key, f"expected numbers, got {a.dtype}")
        a = a.astype(np.float64)
        if not np.isfinite(a).all():
            raise InputError(path, key, "contains NaN or inf")
        return a

    n_legs = len(leg_names)
    pelvis = array("pelvis", (3,), float)
    frames, characters = pelvis.shape[:2]
    if frames < 1 or characters < 1:
        raise InputError(path, "pelvis", f"expected at least one frame and one character, got shape {pelvis.shape}")
    recording = Recording(
        path=path, header=header, pelvis=pelvis, orientation=array("orientation", (3,), float),
        feet=array("feet", (n_legs, 3), float), in_stance=array("in_stance", (n_legs,), bool),
        swing_phase=array("swing_phase", (n_legs,), float),
        joint_angles=array("joint_angles", (n_legs, None), float), ik_on=array("ik_on", (), bool),
        events=np.zeros((0, len(columns))) if "events" not in contents else contents["events"].astype(np.float64),
        foot_yaw=array("foot_yaw", (n_legs,), float, optional=True), speed=array("speed", (), float, optional=True),
        lod_level=array("lod_level", (), int, optional=True))
    for key in ("orientation", "feet", "in_stance", "swing_phase", "joint_angles", "ik_on") + OPTIONAL_ARRAYS:
        if getattr(recording, key) is not None and getattr(recording, key).shape[:2] != (frames, characters):
            raise InputError(path, key, f"expected {frames} frames x {characters} characters like 'pelvis', "
                             f"got shape {getattr(recording, key).shape}")
    if recording.joint_angles.shape[3] < 3:
        raise InputError(path, "joint_angles", "expected an azimuth and at least 2 pitches per leg")
    if recording.events.ndim != 2 or recording.events.shape[1] != len(columns):
        raise InputError(path, "events", f"expected {len(columns)} columns (header.event_columns), "
                         f"got shape {recording.events.shape}")
    return recording
