"""What both gas methods count and sum while they run, in one layout shared by their kernels and their classes.

A run keeps two small arrays: ``counters`` (int64) and ``sums`` (float64), indexed by the constants below. The
kernels add to them; ``GasTally`` (the base class of ``SteppedGas`` and ``EventDrivenGas``) reads them back as
named properties and ``reset_sums()`` zeroes them between measurement blocks.

- ``sums[WALL_IMPULSE]``: Σ 2 m |v⊥| over the wall hits (the wall pressure's numerator);
- ``sums[VIRIAL]``: Σ m_i Δv_i · r_ij over the collisions (the collision virial).
"""
from __future__ import annotations

import numpy as np

__all__ = ["COLLISIONS", "WALL_HITS", "EVENTS", "CROSSINGS", "STALE", "N_COUNTERS", "WALL_IMPULSE", "VIRIAL",
           "N_SUMS", "GasTally", "EventTally", "new_counters", "new_sums"]

#: indices into ``counters``: collisions answered, wall hits, then (event-driven only) events processed, cell
#: crossings and stale events (a predicted pair contact whose partner collided since)
COLLISIONS, WALL_HITS, EVENTS, CROSSINGS, STALE = 0, 1, 2, 3, 4
N_COUNTERS = 5
#: indices into ``sums``
WALL_IMPULSE, VIRIAL = 0, 1
N_SUMS = 2


def new_counters() -> np.ndarray:
    """Zeroed counters, (N_COUNTERS,) int64."""
    return np.zeros(N_COUNTERS, dtype=np.int64)


def new_sums() -> np.ndarray:
    """Zeroed sums, (N_SUMS,) float64."""
    return np.zeros(N_SUMS)


def _counter(index: int, doc: str) -> property:
    return property(lambda self: int(self.counters[index]), doc=doc)


def _sum(index: int, doc: str) -> property:
    return property(lambda self: float(self.sums[index]), doc=doc)


class GasTally:
    """Named read access to a gas's ``counters`` and ``sums`` arrays (set by the subclass's constructor)."""

    counters: np.ndarray
    sums: np.ndarray

    collisions = _counter(COLLISIONS, "collisions answered since the last reset_sums()")
    wall_hits = _counter(WALL_HITS, "wall hits since the last reset_sums()")
    wall_impulse = _sum(WALL_IMPULSE, "Σ 2 m |v⊥| over the wall hits since the last reset_sums()")
    virial = _sum(VIRIAL, "Σ m_i Δv_i · r_ij over the collisions since the last reset_sums()")

    def reset_sums(self) -> None:
        """Zero the counters and the sums (the start of a measurement block)."""
        self.counters[:] = 0
        self.sums[:] = 0.0


class EventTally(GasTally):
    """GasTally plus the event-driven counters."""

    events = _counter(EVENTS, "events processed since the last reset_sums() (collisions, wall hits, cell "
                              "crossings, stale events)")
    crossings = _counter(CROSSINGS, "cell crossings since the last reset_sums()")
    stale = _counter(STALE, "stale pair events (the partner collided since the prediction) since reset_sums()")
