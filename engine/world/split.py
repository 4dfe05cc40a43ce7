"""The work of a ``World(threads=N)`` query shared among threads, with answers the same bit for bit.

Every split here cuts a batch into contiguous ranges of rows, runs the same compiled (GIL-free) kernel on each
range, and puts the pieces back in range order — never in the order the threads finish —, so each row is
computed by the same arithmetic as on one thread and lands in the same place. A batch too small to repay the
hand-over to the pool (fewer than ``minimum`` rows per thread) stays on the calling thread.

The thresholds are module attributes read at each call: the properties lower them to make small worlds split.
"""
from __future__ import annotations

from collections.abc import Callable

from engine.broadphase.pairs import split_even
from engine.broadphase.thread_pool import run_parts

__all__ = ["MIN_CANDIDATES_PER_THREAD", "MIN_PAIRS_PER_THREAD", "MIN_RECORD_ROWS_PER_THREAD", "ranges", "run_ranges"]

#: candidate pairs per thread below which the AABB test and the filter (``classify_pairs``) stay on one thread
MIN_CANDIDATES_PER_THREAD = 8192
#: pairs per thread below which one kernel of the narrow phase stays on one thread
MIN_PAIRS_PER_THREAD = 256
#: touching rows per thread below which the contact record is assembled on one thread
MIN_RECORD_ROWS_PER_THREAD = 4096


def ranges(n: int, threads: int, minimum: int) -> list[tuple[int, int]]:
    """[first, last) ranges covering 0 .. n − 1 in order: as many as ``threads`` allows with at least ``minimum``
    rows each (one range, maybe empty, when n < 2 · minimum or threads is 1) — the broad phase's cut of equal
    items (``engine.broadphase.pairs.split_even``)."""
    return split_even(n, threads, minimum)


def run_ranges(work: Callable, spans: list[tuple[int, int]]) -> list:
    """``work(first, last)`` for each range, on the pool when there are several; the results in range order (an
    exception: the first failing range's, in range order, once every range has finished)."""
    return run_parts(lambda span: work(*span), spans)  # the engine's one pool of threads
