"""Helpers shared by the scenario dataclasses: read-only arrays and field errors.

The dataclasses validate themselves in ``__post_init__``. They do not know
which file they came from, so they raise :class:`InputError` with the file
set to :data:`UNATTRIBUTED` and the field named after the dataclass field
(``rest_feet[2]``, ``sizes[0]``, ...). The file loaders catch these errors and
re-raise them with the real file and the field path of the file format.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from footfall._errors import InputError

UNATTRIBUTED = "argument"
"""``InputError.file`` of an error raised while constructing a value in code."""


def invalid(field: str, reason: str) -> InputError:
    """An :class:`InputError` about ``field`` of a value constructed in code."""
    return InputError(UNATTRIBUTED, field, reason)


def one_line(text: object) -> str:
    """``text`` with every run of whitespace (newlines included) folded to one space."""
    return " ".join(str(text).split())


def readonly(array: np.ndarray) -> np.ndarray:
    """Mark ``array`` read-only and return it."""
    array.flags.writeable = False
    return array


def frozen_array(
    value: Any,
    field: str,
    shape: tuple[int | None, ...],
    dtype: type | np.dtype = np.float64,
    finite: bool = True,
) -> np.ndarray:
    """A read-only copy of ``value`` as an array of ``dtype`` with the given shape.

    ``None`` in ``shape`` accepts any length along that axis. Float arrays must
    be finite unless ``finite`` is false. Raises :class:`InputError` naming
    ``field`` on any mismatch.
    """
    try:
        array = np.array(value, dtype=dtype, copy=True)
    except (TypeError, ValueError, OverflowError):
        raise invalid(field, "expected an array of numbers") from None
    if array.ndim != len(shape) or any(want is not None and got != want for got, want in zip(array.shape, shape)):
        wanted = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        raise invalid(field, f"expected shape {wanted}, got {array.shape}")
    if finite and array.dtype.kind == "f" and not np.all(np.isfinite(array)):
        raise invalid(field, "must be finite (no NaN or inf)")
    return readonly(array)


def finite_float(value: Any, field: str) -> float:
    """``value`` as a finite Python float, or :class:`InputError` naming ``field``."""
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise invalid(field, "expected a number") from None
    if not np.isfinite(number):
        raise invalid(field, "must be finite (no NaN or inf)")
    return number


def positive_float(value: Any, field: str) -> float:
    """``value`` as a finite float > 0, or :class:`InputError` naming ``field``."""
    number = finite_float(value, field)
    if number <= 0.0:
        raise invalid(field, "must be > 0")
    return number
