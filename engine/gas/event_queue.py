"""The event queue of the event-driven gas: an event calendar (Paul's bucket queue) with one event per sphere.

G. Paul, "A complexity O(1) priority queue for event driven molecular dynamics simulations", J. Comput. Phys.
221, 615 (2007), as Smallenburg uses it (EPJE 45, 22 (2022)): time is cut into buckets of width Δ; the events of
the current bucket are kept sorted (here in a small indexed binary min-heap, the *window*), those of the next M
buckets in unsorted doubly linked lists, and the ones beyond in an overflow list that is redistributed each time
the calendar has gone round once. Inserting or removing an event is O(1) outside the window and O(log k) inside
it (k: the events of one bucket, a few dozen), instead of O(log n) in a heap of all n spheres; the arrays the
queue touches stay small enough for the processor's second-level cache.

Each sphere i has at most one event, filed in its 24-byte record ``entries[i]`` (``ENTRY``): its time ``key``;
``where``: −1 in the window heap (at position ``slot``), 0 … M−1 in a bucket list, M in the overflow list, −2
nowhere; ``qnext`` and ``qprev``: its neighbours in that list.
"""
from __future__ import annotations

import math
import sys
from typing import NamedTuple

import numpy as np

from engine.gas.kernels import state_kernel

__all__ = ["ENTRY", "EventCalendar", "new_event_calendar", "sized_event_calendar", "BUCKET_EVENTS",
           "calendar_build", "calendar_update", "calendar_top"]

#: a sphere's place in the calendar
ENTRY = np.dtype([("key", np.float64), ("where", np.int32), ("slot", np.int32), ("qnext", np.int32),
                  ("qprev", np.int32)], align=True)

_IN_WINDOW, _NOWHERE = -1, -2
# fields of the calendar's counters: window size, the absolute number of the current bucket, events in buckets
_SIZE, _BASE, _IN_BUCKETS = 0, 1, 2
#: bucket numbers floor(t/Δ) are exact integers below 2^52
_MAX_BUCKET = 2.0**52


class EventCalendar(NamedTuple):
    """entries: (n,) ENTRY records; win_key (n,) float64 and win_sphere (n,) int32: the window heap (its first
    ``count[0]`` entries); head: (M + 1,) int32 first sphere of each bucket list (−1: empty; head[M]: the overflow
    list); count: (3,) int64 window size, current bucket number, events in the M buckets; width: Δ (float);
    nbuckets: M (int)."""

    entries: np.ndarray
    win_key: np.ndarray
    win_sphere: np.ndarray
    head: np.ndarray
    # a public field name that shadows tuple.count (the method); the field is what the kernels read
    count: np.ndarray  # type: ignore[assignment]
    width: float
    nbuckets: int


def new_event_calendar(n: int, width: float, nbuckets: int) -> EventCalendar:
    """An empty calendar for n < 2^31 spheres, buckets of width Δ = ``width`` > 0, M = ``nbuckets`` >= 2."""
    if not (math.isfinite(width) and width > 0.0):
        raise ValueError(f"width must be finite and > 0, got {width!r}")
    if nbuckets < 2:
        raise ValueError(f"nbuckets must be >= 2, got {nbuckets!r}")
    entries = np.zeros(n, dtype=ENTRY)
    entries["key"] = math.inf
    entries["where"] = _NOWHERE
    entries["qnext"] = entries["qprev"] = -1
    return EventCalendar(entries, np.zeros(n), np.zeros(n, dtype=np.int32), np.full(nbuckets + 1, -1, dtype=np.int32),
                         np.zeros(3, dtype=np.int64), float(width), int(nbuckets))


#: events per bucket of a sized calendar
BUCKET_EVENTS = 16


def sized_event_calendar(times, per_bucket=BUCKET_EVENTS, turns=4.0):
    """An event calendar for n = len(times) spheres ((n,) float64 first event times), sized from them: with H
    the median time to a sphere's next event, events arrive at about n/H per unit time, so buckets of width
    Δ = per_bucket · H/n hold about ``per_bucket`` events, and M buckets cover ``turns`` · H."""
    n = times.shape[0]
    ahead = np.sort(times[np.isfinite(times)]) - (times.min() if n else 0.0)
    horizon = float(ahead[ahead.shape[0] // 2]) if ahead.shape[0] and ahead[ahead.shape[0] // 2] > 0 else 1.0
    width = max(per_bucket * horizon / max(n, 1), sys.float_info.min)  # > 0 even if H/n underflows
    return new_event_calendar(n, width, max(2, int(math.ceil(turns * horizon / width))))



# ------------------------------------------------------------------------------------------------------------
# the window: an indexed binary min-heap of the current bucket's events (Cormen et al. 6.5)
# ------------------------------------------------------------------------------------------------------------
@state_kernel
def _put(cal, pos, k, i):
    cal.win_key[pos] = k
    cal.win_sphere[pos] = i
    cal.entries[i]["slot"] = pos


@state_kernel
def _sift_up(cal, pos):
    key, sphere = cal.win_key, cal.win_sphere
    k = key[pos]
    i = sphere[pos]
    while pos > 0:
        parent = (pos - 1) >> 1
        if key[parent] <= k:
            break
        _put(cal, pos, key[parent], sphere[parent])
        pos = parent
    _put(cal, pos, k, i)
    return pos


@state_kernel
def _sift_down(cal, pos):
    key, sphere = cal.win_key, cal.win_sphere
    size = cal.count[_SIZE]
    k = key[pos]
    i = sphere[pos]
    while True:
        c = 2 * pos + 1
        if c >= size:
            break
        if c + 1 < size and key[c + 1] < key[c]:
            c += 1
        if key[c] >= k:
            break
        _put(cal, pos, key[c], sphere[c])
        pos = c
    _put(cal, pos, k, i)


@state_kernel
def _window_push(cal, i, t):
    pos = cal.count[_SIZE]
    cal.count[_SIZE] = pos + 1
    cal.entries[i]["where"] = _IN_WINDOW
    _put(cal, pos, t, i)
    _sift_up(cal, pos)


@state_kernel
def _window_remove(cal, i):
    """Take sphere i out of the window: the last entry fills its place and is sifted up or down."""
    pos = cal.entries[i]["slot"]
    last = cal.count[_SIZE] - 1
    cal.count[_SIZE] = last
    if pos != last:
        _put(cal, pos, cal.win_key[last], cal.win_sphere[last])
        _sift_down(cal, _sift_up(cal, pos))


# ------------------------------------------------------------------------------------------------------------
# the buckets: doubly linked lists of spheres
# ------------------------------------------------------------------------------------------------------------
@state_kernel
def _link(cal, i, b):
    """Push sphere i at the head of list b (a bucket, or M: the overflow list)."""
    e, head = cal.entries, cal.head
    h = head[b]
    e[i]["qnext"] = h
    e[i]["qprev"] = -1
    if h >= 0:
        e[h]["qprev"] = i
    head[b] = i
    e[i]["where"] = b
    if b < cal.nbuckets:
        cal.count[_IN_BUCKETS] += 1


@state_kernel
def _unlink(cal, i):
    e = cal.entries
    b, nxt, prv = e[i]["where"], e[i]["qnext"], e[i]["qprev"]
    if prv >= 0:
        e[prv]["qnext"] = nxt
    else:
        cal.head[b] = nxt
    if nxt >= 0:
        e[nxt]["qprev"] = prv
    if b < cal.nbuckets:
        cal.count[_IN_BUCKETS] -= 1


@state_kernel
def _insert(cal, i, t):
    """File sphere i's event at time t by its bucket number floor(t/Δ) (monotone in t, so the buckets keep
    their order): into the window if that is the current bucket (or earlier), into its bucket's list if it is
    less than M buckets ahead, else into the overflow list (infinite times and times beyond 2^52 Δ included)."""
    cal.entries[i]["key"] = t
    q = t / cal.width
    base = cal.count[_BASE]
    if q < base + 1.0:
        _window_push(cal, i, t)
    elif q < base + cal.nbuckets and q < _MAX_BUCKET:
        _link(cal, i, int(q) % cal.nbuckets)
    else:
        _link(cal, i, cal.nbuckets)


@state_kernel
def calendar_update(cal, i, t):
    """Give sphere i the event time t (a later or earlier one), wherever its previous event was filed."""
    w = cal.entries[i]["where"]
    if w == _IN_WINDOW:
        if t / cal.width < cal.count[_BASE] + 1.0:  # stays in the window: the heap's key update
            cal.entries[i]["key"] = t
            pos = cal.entries[i]["slot"]
            cal.win_key[pos] = t
            _sift_down(cal, _sift_up(cal, pos))
            return
        _window_remove(cal, i)
    elif w >= 0:
        _unlink(cal, i)
    _insert(cal, i, t)


@state_kernel
def _drain(cal, b):
    """Move every event of list b into the calendar again (into the window, a bucket or the overflow list)."""
    i = cal.head[b]
    while i >= 0:
        after = cal.entries[i]["qnext"]
        _unlink(cal, i)
        _insert(cal, i, cal.entries[i]["key"])
        i = after


@state_kernel
def _earliest_in_overflow(cal):
    """The sphere of the overflow list with the earliest event (−1 when the list is empty)."""
    best, t = -1, math.inf
    i = cal.head[cal.nbuckets]
    while i >= 0:
        if cal.entries[i]["key"] < t or best < 0:
            best, t = i, cal.entries[i]["key"]
        i = cal.entries[i]["qnext"]
    return best


@state_kernel
def calendar_top(cal):
    """The sphere with the earliest event and its time, (i, t); (−1, inf) when no event is finite.

    While the window is empty the calendar moves on by one bucket and sorts that bucket's events into the window;
    after a full turn of M buckets the overflow list is redistributed. When every bucket is empty it jumps to the
    bucket of the earliest overflow event (beyond 2^52 buckets, where bucket numbers are no longer exact, that
    event alone is moved into the window).
    """
    m = cal.nbuckets
    while cal.count[_SIZE] == 0:
        if cal.count[_IN_BUCKETS] == 0:
            i = _earliest_in_overflow(cal)
            if i < 0 or cal.entries[i]["key"] == math.inf:
                return -1, math.inf
            q = cal.entries[i]["key"] / cal.width
            if q < _MAX_BUCKET:
                cal.count[_BASE] = int(q)
                _drain(cal, m)
            else:
                _unlink(cal, i)
                _window_push(cal, i, cal.entries[i]["key"])
            continue
        cal.count[_BASE] += 1
        b = cal.count[_BASE] % m
        if b == 0:
            _drain(cal, m)
        _drain(cal, b)
    return cal.win_sphere[0], cal.win_key[0]


@state_kernel
def calendar_build(cal, times):
    """File the events times[i] ((n,) float64) of every sphere, the current bucket being that of the earliest."""
    t0 = math.inf
    for i in range(times.shape[0]):
        t0 = min(t0, times[i])
    cal.count[_SIZE] = 0
    cal.count[_IN_BUCKETS] = 0
    cal.count[_BASE] = int(t0 / cal.width) if t0 / cal.width < _MAX_BUCKET else 0
    cal.head[:] = -1
    for i in range(times.shape[0]):
        _insert(cal, i, times[i])
