"""Shared behaviour of the flat parameter objects (:class:`ScoringWeights`, :class:`GaitTiming`).

Both are frozen dataclasses of named floats whose field metadata carry ``doc`` and
``unit``; tuning fits them as flat float vectors, so each has a lossless array
round trip in field order.
"""

from __future__ import annotations

import dataclasses

import numpy as np


class FlatParameters:
    """Mixin: array round trip, dict and a description of the fields, in field order."""

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    def to_array(self) -> np.ndarray:
        """float64 array in field order (lossless)."""
        return np.array([getattr(self, n) for n in self.field_names()], dtype=np.float64)

    @classmethod
    def from_array(cls, values):
        names = cls.field_names()
        values = np.asarray(values, dtype=np.float64)
        if values.shape != (len(names),):
            raise ValueError(f"{cls.__name__}.from_array: expected shape ({len(names)},), got {values.shape}")
        return cls(**{n: float(v) for n, v in zip(names, values)})

    def to_dict(self) -> dict[str, float]:
        return {n: getattr(self, n) for n in self.field_names()}

    @classmethod
    def describe(cls) -> list[tuple[str, str, str]]:
        """(name, unit, meaning) of every field, in array order."""
        return [(f.name, f.metadata["unit"], f.metadata["doc"]) for f in dataclasses.fields(cls)]
