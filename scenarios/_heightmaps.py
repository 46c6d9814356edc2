"""Reading height-map files: NumPy ``.npy`` arrays and 16-bit greyscale PNG images."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from footfall._errors import InputError
from footfall.scenarios._arrays import one_line

PNG_FULL_SCALE = 65535
"""A 16-bit PNG sample of this value maps to ``height_scale`` metres."""

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_COLOUR_TYPES = {0: "greyscale", 2: "RGB", 3: "palette", 4: "greyscale+alpha", 6: "RGBA"}


def read_heightmap(path: Path, file: str, field: str) -> np.ndarray:
    """Raw samples of the height map at ``path`` as an (R, C) float64 array.

    ``.npy``: the stored values (any real integer or float dtype).
    ``.png``: 16-bit greyscale samples divided by 65535 (so in [0, 1]).
    Row r of the array (image row r, top first, for PNG) is grid row r.
    Errors are :class:`InputError` (``file``, ``field``, reason).
    """
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".png"):
        raise InputError(file, field, f"unsupported height map format {path.suffix or '(none)'!r}; use .npy or 16-bit .png")
    try:
        found = path.is_file()
    except (OSError, ValueError):  # e.g. a NUL byte in the name
        found = False
    if not found:
        raise InputError(file, field, f"height map file not found: {path}")
    values = _read_npy(path, file, field) if suffix == ".npy" else _read_png(path, file, field)
    if values.ndim != 2 or values.shape[0] < 2 or values.shape[1] < 2:
        raise InputError(file, field, f"height map must be a 2-D array of at least 2x2 samples, got shape {values.shape}")
    if not np.all(np.isfinite(values)):
        raise InputError(file, field, "height map contains NaN or infinite values")
    return values


def _read_npy(path: Path, file: str, field: str) -> np.ndarray:
    try:
        loaded = np.load(path, allow_pickle=False)
    except Exception as error:  # numpy raises many kinds (ValueError, OSError, EOFError, ...)
        raise InputError(file, field, f"cannot read .npy height map {path}: {one_line(error)}") from None
    if not isinstance(loaded, np.ndarray):
        raise InputError(file, field, f"{path} is not a single .npy array")
    if loaded.dtype.kind not in "iuf":
        raise InputError(file, field, f"height map dtype must be integer or float, got {loaded.dtype}")
    return loaded.astype(np.float64)


def _read_png(path: Path, file: str, field: str) -> np.ndarray:
    from PIL import Image  # imported lazily: only PNG height maps need Pillow

    try:
        with open(path, "rb") as stream:
            header = stream.read(26)
    except OSError as error:
        raise InputError(file, field, f"cannot read {path}: {one_line(error.strerror)}") from None
    if len(header) < 26 or header[:8] != _PNG_SIGNATURE or header[12:16] != b"IHDR":
        raise InputError(file, field, f"{path} is not a PNG file")
    bit_depth, colour_type = header[24], header[25]
    if bit_depth != 16 or colour_type != 0:
        got = f"{bit_depth}-bit {_PNG_COLOUR_TYPES.get(colour_type, 'unknown colour type')}"
        raise InputError(file, field, f"PNG height map must be 16-bit greyscale, got {got}")
    try:
        with Image.open(path) as image:
            values = np.array(image, dtype=np.float64)
    except Exception as error:  # Pillow raises OSError, SyntaxError, ValueError, ...
        raise InputError(file, field, f"cannot decode PNG height map {path}: {one_line(error)}") from None
    return values / PNG_FULL_SCALE
