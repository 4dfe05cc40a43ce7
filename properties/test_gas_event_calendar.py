"""The event calendar of the event-driven gas (engine/gas/event_queue.py) against a plain dictionary.

The calendar files one event time per sphere in a window heap, M bucket lists and an overflow list; whatever the
bucket width and count, ``calendar_top`` must name a sphere whose time is the smallest of all the times filed,
after any sequence of updates as the event loop makes them (every new time at or after the last time answered:
the same time, a time in the current bucket, a few buckets ahead, beyond the M buckets, or never). Also: times
earlier than the current bucket (after ``calendar_top`` has moved on past empty buckets), times beyond 2^52
bucket widths, and a calendar whose events are all infinite.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from engine.gas.event_queue import calendar_build, calendar_top, calendar_update, new_event_calendar


def _check_top(cal, model):
    i, t = calendar_top(cal)
    earliest = min(model)
    if earliest == math.inf:
        assert i == -1 and t == math.inf
        return None
    assert t == earliest and model[i] == earliest, (i, t, earliest)
    return int(i)


# a delay after the last time answered, in bucket widths: the same time, inside the bucket, a few buckets
# ahead, past the M buckets, far beyond (2^52 widths and more), or never
_DELAYS = st.one_of(st.just(0.0), st.floats(0.0, 1.0), st.floats(1.0, 12.0), st.floats(12.0, 1e4),
                    st.sampled_from([2.0**52, 2.0**60, 1e300]), st.just(math.inf))


@example(width=1.0, nbuckets=4, start=[0.5, 1.5], steps=[(True, 0, 3.0)])  # a bucket's event filed late
@example(width=1.0, nbuckets=3, start=[0.5, 5.5], steps=[(True, 0, 1.2)] * 8)  # the overflow's turn comes
@given(width=st.floats(1e-3, 1e3), nbuckets=st.integers(2, 10),
       start=st.lists(st.one_of(st.floats(0.0, 200.0), st.just(math.inf)), min_size=1, max_size=40),
       steps=st.lists(st.tuples(st.booleans(), st.integers(0, 10**6), _DELAYS), max_size=200))
def test_calendar_top_is_the_earliest_event(width, nbuckets, start, steps):
    n = len(start)
    cal = new_event_calendar(n, width, nbuckets)
    times = np.array(start, dtype=np.float64)
    calendar_build(cal, times)
    model = list(start)
    now = 0.0
    for top_sphere, pick, delay in steps:
        i = _check_top(cal, model)
        if i is not None:
            now = model[i]
        s = i if (top_sphere and i is not None) else pick % n
        t = now + delay * width  # at or after the last time answered (inf stays inf)
        calendar_update(cal, s, t)
        model[s] = t
    _check_top(cal, model)


@given(width=st.floats(1e-2, 10.0), nbuckets=st.integers(2, 8),
       times=st.lists(st.floats(0.0, 1e3), min_size=2, max_size=30), early=st.floats(0.0, 1.0))
def test_calendar_takes_times_before_its_current_bucket(width, nbuckets, times, early):
    """``calendar_top`` skips empty buckets up to the earliest event; a time filed after that, earlier than that
    bucket but after the last time answered, is still the next one out."""
    n = len(times)
    cal = new_event_calendar(n, width, nbuckets)
    calendar_build(cal, np.array(times))
    model = list(times)
    i = _check_top(cal, model)
    j = (i + 1) % n
    calendar_update(cal, i, math.inf)  # i answered; nothing new for it
    model[i] = math.inf
    k = _check_top(cal, model)  # the calendar moves on to k's bucket
    t = times[i] + early * (model[k] - times[i])
    calendar_update(cal, j, t)
    model[j] = t
    _check_top(cal, model)


def test_calendar_with_no_finite_event_is_empty():
    cal = new_event_calendar(5, 0.5, 4)
    calendar_build(cal, np.full(5, math.inf))
    assert calendar_top(cal) == (-1, math.inf)
    calendar_update(cal, 3, 7.25)
    assert calendar_top(cal) == (3, 7.25)


def test_calendar_whose_bucket_events_all_become_infinite_is_empty():
    """Events filed in the bucket lists (not in the window), then every one moved to "never": the calendar knows
    its buckets are empty and answers (-1, inf) instead of walking the empty buckets."""
    cal = new_event_calendar(3, 0.5, 4)
    calendar_build(cal, np.array([0.2, 1.25, 1.75]))
    assert calendar_top(cal) == (0, 0.2)
    for i in range(3):
        calendar_update(cal, i, math.inf)
    assert calendar_top(cal) == (-1, math.inf)


@pytest.mark.parametrize(("width", "nbuckets"), [(0.0, 4), (-1.0, 4), (math.inf, 4), (math.nan, 4), (1.0, 1)])
def test_calendar_rejects_bad_sizes(width, nbuckets):
    with pytest.raises(ValueError, match="width" if nbuckets > 1 else "nbuckets"):
        new_event_calendar(3, width, nbuckets)
