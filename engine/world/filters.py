"""Which pairs a ``World`` tests: collision filtering as Box2D's ``b2Filter``, single-pair exclusions as MuJoCo's
``<exclude>`` and pybullet's ``setCollisionFilterPair``, and the sensor rules — applied to the broad phase's
candidates, so that a filtered pair never reaches the narrow phase.

A pair (i, j) is tested iff it is not excluded, the two are not both sensors, and
- when ``group_i == group_j != 0``: the group decides alone (> 0 always, < 0 never);
- otherwise: ``category_i & mask_j`` and ``category_j & mask_i`` are both non-zero.
``category`` and ``mask`` are 64-bit sets (``ALL`` = every bit), ``group`` a signed 64-bit integer; by default a
body is in category 1, collides with every category (``mask = ALL``) and is in no group (0). The queries that
answer where and when (``contacts``, ``time_of_impact``) also drop every pair with a sensor.
"""
from __future__ import annotations

import numpy as np

from engine._config import njit

__all__ = ["ALL", "as_bits", "as_group", "Exclusions", "pair_passes"]

#: every category bit: the default mask (collide with everything)
ALL = (1 << 64) - 1


def as_bits(value, name: str) -> int:
    """A 64-bit set as an int in [0, 2^64): TypeError naming ``name`` for a bool, a float or a non-integer,
    ValueError for a negative value or one beyond 64 bits."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an int (a 64-bit set of categories), got {type(value).__name__}")
    v = int(value)
    if v < 0:
        raise ValueError(f"{name} must be >= 0 (a set of category bits), got {v}")
    if v > ALL:
        raise ValueError(f"{name} must fit in 64 bits (at most engine.ALL = 2**64 - 1), got {v}")
    return v


def as_group(value, name: str = "group") -> int:
    """A group index as an int in the int64 range (TypeError / ValueError naming ``name``)."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an int, got {type(value).__name__}")
    v = int(value)
    if not -(1 << 63) <= v < (1 << 63):
        raise ValueError(f"{name} must be a signed 64-bit integer, got {v}")
    return v


class Exclusions:
    """The excluded pairs of a world: a set of canonical (i, j), and its keys i · 2^32 + j as a sorted int64
    array for the compiled filter (rebuilt after a change)."""

    def __init__(self):
        self.pairs: set[tuple[int, int]] = set()
        self._keys: np.ndarray | None = np.empty(0, np.int64)

    def exclude(self, i: int, j: int) -> None:
        self.pairs.add((min(i, j), max(i, j)))
        self._keys = None

    def include(self, i: int, j: int) -> None:
        self.pairs.discard((min(i, j), max(i, j)))
        self._keys = None

    def forget(self, body: int) -> None:
        """Drop the exclusions of a removed body (a later body under its id starts with none)."""
        gone = {p for p in self.pairs if body in p}
        if gone:
            self.pairs -= gone
            self._keys = None

    def keys(self) -> np.ndarray:
        if self._keys is None:
            self._keys = np.array(sorted((i << 32) | j for i, j in self.pairs), np.int64)
        return self._keys


@njit(inline="always")
def _excluded(keys, i, j):
    key = (np.int64(min(i, j)) << 32) | np.int64(max(i, j))
    at = np.searchsorted(keys, key)
    return at < keys.shape[0] and keys[at] == key


@njit(inline="always")
def pair_passes(sensor, category, mask, group, i, j, keys, no_sensors):
    """Whether the pair of bodies (i, j) is tested, by the rule of the module docstring (the body store's
    ``sensor``, ``category``, ``mask``, ``group`` arrays); ``keys``: the sorted excluded keys
    (``Exclusions.keys``); ``no_sensors``: drop every pair with a sensor as well."""
    si, sj = sensor[i], sensor[j]
    if (si and sj) or (no_sensors and (si or sj)) or (keys.shape[0] > 0 and _excluded(keys, i, j)):
        return False
    if group[i] == group[j] and group[i] != 0:
        return group[i] > 0
    return (category[i] & mask[j]) != 0 and (category[j] & mask[i]) != 0
