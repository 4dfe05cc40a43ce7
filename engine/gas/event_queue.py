"""The event queue of the event-driven gas: an indexed binary min-heap of the spheres, keyed by their next event.

Each sphere has exactly one pending event (its earliest), so the queue holds n entries and a sphere's entry is
found through ``slot`` when its event changes (Rapaport, *The Art of Molecular Dynamics Simulation*, ch. 14;
Cormen et al., *Introduction to Algorithms*, 6.5 "Priority queues"). Keys are stored in heap order, so the
comparisons of a sift read one contiguous array.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from engine._config import njit

__all__ = ["EventHeap", "new_event_heap", "heap_build", "heap_update"]


class EventHeap(NamedTuple):
    """key: (n,) float64 event times in heap order; sphere: (n,) int64 the sphere at each heap position;
    slot: (n,) int64 the heap position of each sphere (slot[sphere[p]] == p)."""

    key: np.ndarray
    sphere: np.ndarray
    slot: np.ndarray


def new_event_heap(n: int) -> EventHeap:
    """An empty heap for n spheres (filled by ``heap_build``)."""
    return EventHeap(np.zeros(n), np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64))


@njit(error_model="numpy")
def _put(heap, pos, k, i):
    """Store sphere i with key k at heap position pos."""
    heap.key[pos] = k
    heap.sphere[pos] = i
    heap.slot[i] = pos


@njit(error_model="numpy")
def _sift_up(heap, pos):
    """Move the entry at pos up past every parent with a larger key; returns its final position."""
    k = heap.key[pos]
    i = heap.sphere[pos]
    while pos > 0:
        parent = (pos - 1) >> 1
        if heap.key[parent] <= k:
            break
        _put(heap, pos, heap.key[parent], heap.sphere[parent])
        pos = parent
    _put(heap, pos, k, i)
    return pos


@njit(error_model="numpy")
def _sift_down(heap, pos):
    """Move the entry at pos down past every child with a smaller key (the smaller child first)."""
    key = heap.key
    size = key.shape[0]
    k = key[pos]
    i = heap.sphere[pos]
    while True:
        c = 2 * pos + 1
        if c >= size:
            break
        if c + 1 < size and key[c + 1] < key[c]:
            c += 1
        if key[c] >= k:
            break
        _put(heap, pos, key[c], heap.sphere[c])
        pos = c
    _put(heap, pos, k, i)


@njit(error_model="numpy")
def heap_build(heap, times):
    """Fill the heap with sphere p keyed by times[p] ((n,) float64) and heapify it (Floyd's bottom-up build)."""
    n = times.shape[0]
    for p in range(n):
        heap.sphere[p] = p
        heap.key[p] = times[p]
        heap.slot[p] = p
    for p in range(n // 2 - 1, -1, -1):
        _sift_down(heap, p)


@njit(error_model="numpy")
def heap_update(heap, i, t):
    """Give sphere i the event time t and restore the heap order."""
    pos = heap.slot[i]
    heap.key[pos] = t
    pos = _sift_up(heap, pos)
    _sift_down(heap, pos)
