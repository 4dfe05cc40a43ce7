"""``threads=`` of ``find_pairs`` (every method) and ``sphere_pairs``: the same answer, bit for bit, as one thread.

Each method cuts its work (sweep columns, grid cells, tree nodes, octree objects, brute-force rows, sphere
columns) into contiguous ranges, one per thread, and merges the ranges' pairs into canonical form. A range is only
given to a thread when it holds enough work (``MIN_*_PER_THREAD``); here those minimums are lowered to 1 so that
the small Hypothesis scenes are really split, and a W1 scene checks the default minimums.
"""
from __future__ import annotations

import contextlib
from unittest import mock

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from engine.broadphase import (
    BROAD_PHASES,
    aabb_tree,
    brute_force,
    find_pairs,
    octree,
    sphere_pairs,
    spheres,
    sweep_and_prune,
    uniform_grid,
)
from engine.broadphase.pairs import split_work
from engine.workloads import clustered_spheres, w1_boxes
from properties.strategies.boxes import box_scenes, sphere_scenes

MINIMUMS = [(sweep_and_prune, "MIN_ENTRIES_PER_THREAD"), (uniform_grid, "MIN_ENTRIES_PER_THREAD"),
            (aabb_tree, "MIN_NODES_PER_THREAD"), (octree, "MIN_OBJECTS_PER_THREAD"),
            (brute_force, "MIN_TESTS_PER_THREAD"), (spheres, "MIN_SPHERES_PER_THREAD")]


@contextlib.contextmanager
def split_everything():
    """Every broad phase splits its work whatever its size."""
    with contextlib.ExitStack() as stack:
        for module, name in MINIMUMS:
            stack.enter_context(mock.patch.object(module, name, 1))
        yield


@given(box_scenes(max_n=60), st.sampled_from(BROAD_PHASES), st.integers(2, 6))
def test_find_pairs_with_threads_equals_one_thread_bit_for_bit(scene, method, threads):
    lo, hi = scene
    one, one_tests = find_pairs(lo, hi, method, return_tests=True)
    with split_everything():
        many, many_tests = find_pairs(lo, hi, method, return_tests=True, threads=threads)
    assert many.dtype == np.int64 and many.shape == one.shape
    np.testing.assert_array_equal(many, one)
    assert many_tests == one_tests  # the same work, only shared


@given(sphere_scenes(max_n=60), st.integers(2, 6))
def test_sphere_pairs_with_threads_equals_one_thread_bit_for_bit(scene, threads):
    centers, radii = scene
    one = sphere_pairs(centers, radii)
    with split_everything():
        many = sphere_pairs(centers, radii, threads=threads)
    assert many.dtype == np.int64
    np.testing.assert_array_equal(many, one)


@pytest.mark.parametrize("method", BROAD_PHASES)
def test_threads_with_the_default_minimums_on_w1(method):
    lo, hi = w1_boxes(4_000 if method == "brute" else 20_000)
    one = find_pairs(lo, hi, method, return_tests=True)
    many = find_pairs(lo, hi, method, return_tests=True, threads=2)
    np.testing.assert_array_equal(many[0], one[0])
    assert many[1] == one[1]


def test_sphere_threads_with_the_default_minimums_on_clusters():
    centres, radius = clustered_spheres(30_000, clusters=3, separation=1e5)
    np.testing.assert_array_equal(sphere_pairs(centres, radius, threads=2), sphere_pairs(centres, radius))


@given(st.lists(st.integers(0, 50), min_size=1, max_size=40), st.integers(1, 9), st.integers(1, 200))
def test_split_work_ranges_are_contiguous_cover_everything_and_respect_the_minimum(costs, threads, min_work):
    work = np.concatenate([[0], np.cumsum(costs)])
    ranges = split_work(work, threads, min_work)
    assert 1 <= len(ranges) <= threads
    assert ranges[0][0] == 0 and ranges[-1][1] == len(costs)
    for (a, b), (c, _) in zip(ranges, ranges[1:]):
        assert a < b == c
    if len(ranges) > 1:
        assert work[-1] >= len(ranges) * min_work


# three or more parts: with two, the one cut target total / 2 is the same for every formula total · t / parts
# with t = 1; the 25 derandomized examples of the mutation run drew no failing case of three parts or more
@example(costs=[1] * 30, threads=3, min_work=1)
@example(costs=[5, 0, 7, 7, 1, 3, 9, 2, 2, 8, 4, 6], threads=4, min_work=3)
@given(st.lists(st.integers(0, 50), min_size=1, max_size=40), st.integers(2, 9), st.integers(1, 200))
def test_split_work_ranges_carry_about_equal_work(costs, threads, min_work):
    """The cut targets are total · t / parts, so when no two targets fall in one item (as many ranges as parts),
    every range carries at most total / parts plus one item's work."""
    work = np.concatenate([[0], np.cumsum(costs)])
    ranges = split_work(work, threads, min_work)
    parts = min(threads, max(1, int(work[-1]) // min_work))
    if len(ranges) == parts > 1:
        for a, b in ranges:
            assert work[b] - work[a] <= work[-1] / parts + max(costs), (ranges, parts)


@pytest.mark.parametrize("threads", range(2, 10))
def test_split_work_cuts_equal_items_into_equal_ranges(threads):
    """Items of equal work: ``threads`` ranges (the minimum allows them all) whose sizes differ by at most one."""
    m = 12 * threads + 5
    ranges = split_work(np.arange(m + 1), threads, 1)
    sizes = [b - a for a, b in ranges]
    assert len(ranges) == threads and sum(sizes) == m
    assert max(sizes) - min(sizes) <= 1, ranges


@pytest.mark.parametrize("bad, error", [(0, ValueError), (257, ValueError), (1.5, TypeError), (True, TypeError)])
def test_bad_threads_are_refused_naming_the_argument(bad, error):
    lo, hi = w1_boxes(50)
    for call in (lambda: find_pairs(lo, hi, "grid", threads=bad), lambda: sphere_pairs(lo, 1.0, threads=bad)):
        with pytest.raises(error, match="threads"):
            call()
