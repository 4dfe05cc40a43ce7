"""The dispatch of the narrow phase: (shape kind, shape kind, question) → the kernel that answers it, as one table.

As in Box2D (``s_registers[type][type]``, filled by ``b2AddType``) and parry (``DefaultQueryDispatcher``, with an
explicit GJK fallback and an explicit ``Unsupported``): every candidate pair of the broad phase is answered by
the kernel its two shapes' kinds select, and the table *is* the dispatch — a new kind or a new question adds
rows (engine/world/rows.py), never a branch here.

- A ``Kernel`` answers a batch: ``run(ctx, pairs, sel, out)`` fills rows ``sel`` of ``out`` for the pairs
  ``pairs[sel]`` (k, 2) of body-store rows; the kernel's A is the pair's shape of lower kind code (a pair whose
  first shape is its B is "flipped": normals and features are stored for the pair's own order). ``out`` is a
  ``ContactRows`` for "overlap" and "contact", a times array (k,) for "impact", a ``DistanceRows`` for
  "distance" (engine.narrowphase.signed_distance) — ``answer_rows(question, k)`` allocates it, in one place.
- ``unsupported(reason)`` is a cell no query may reach (ground against ground: two static shapes are never
  paired); reaching it raises ``UnsupportedQuery``.
- ``PARTS`` marks a composite kind's cells (``Compound``): its pairs are split into pairs of parts
  (``expand_parts``) before the table is read, and the answers are reported for the compound.

``DispatchTable(rows)`` turns the rows into one (kinds × kinds) index array per question (what the compiled
classification reads) and one list of kernels; ``answer(table, question, ctx, pairs)`` runs a question over
candidate pairs: parts first, then the AABB test (boxes grown by ``margin`` for "distance"), the filter and the
grouping by kernel (``classify_pairs``, or ``classify_unfiltered_pairs`` for a world without a filter;
``group_by_code``), then one batched call per kernel.
"""
from __future__ import annotations

from collections import namedtuple
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from engine._config import njit
from engine.narrowphase.contacts import contact_rows, kernel_scratch
from engine.narrowphase.signed_distance import distance_rows

from . import split
from .filters import pair_passes
from .kinds import KINDS, ShapeKind

__all__ = ["QUESTIONS", "Kernel", "UnsupportedQuery", "unsupported", "PARTS", "DispatchTable", "NarrowContext",
           "classify_pairs", "classify_unfiltered_pairs", "group_by_code", "expand_parts", "answer", "answer_rows",
           "Answer"]

#: the questions the table answers: do they overlap (touching counts), where do they touch, when do they touch,
#: how far apart (or how deep) are they
QUESTIONS = ("overlap", "contact", "impact", "distance")


@dataclass(frozen=True, eq=False)
class Kernel:
    """One answer of the table: ``name`` says what it computes, ``run(ctx, pairs, sel, out)`` computes it for a
    batch (see the module docstring)."""

    name: str
    run: Callable
    threaded: bool = True  # may run on several threads at once (compiled kernels); False: one thread only

    def __repr__(self) -> str:
        return f"Kernel({self.name!r})"


class UnsupportedQuery(NotImplementedError):
    """A (kind, kind, question) cell that has no kernel was reached."""


def unsupported(reason: str) -> Kernel:
    """A cell without a kernel: running it raises ``UnsupportedQuery`` with ``reason``."""
    def refuse(ctx, pairs, sel, out):
        raise UnsupportedQuery(reason)
    return Kernel(f"unsupported: {reason}", refuse)


def _split_first(ctx, pairs, sel, out):
    raise AssertionError("the pairs of a composite kind are split into parts before the table is read")


#: the cells of a composite kind: answered part by part
PARTS = Kernel("answered part by part", _split_first)

#: what every kernel reads: ``bodies`` (engine.world.bodies.BodyArrays), ``shapes`` ({row: Shape}, for kernels
#: that need the shape object: a HeightCurve's f), ``scratch`` (engine.narrowphase.contacts.kernel_scratch for
#: the store's points per body), ``dt`` (the time window of "impact"), ``has_parts`` (whether the store holds a
#: compound: only then are the pairs split into parts), ``threads`` (how many threads ``answer`` may use; 1 when
#: not given)
NarrowContext = namedtuple("NarrowContext", "bodies shapes scratch dt has_parts threads", defaults=(1,))


class DispatchTable:
    """The rows of engine/world/rows.py as arrays: ``index[question]`` (kinds × kinds) int16, symmetric, an index
    into ``kernels[question]``; ``cell(a, b, question)`` the kernel of a cell.

    ``rows`` maps (kind_a, kind_b) with ``kind_a.code <= kind_b.code`` to {question: Kernel}; every cell of
    every question must be given (ValueError naming the first missing one)."""

    def __init__(self, rows: dict):
        n = len(KINDS)
        self.kernels: dict[str, list[Kernel]] = {q: [] for q in QUESTIONS}
        self.index = {q: np.full((n, n), -1, np.int16) for q in QUESTIONS}
        for (a, b), answers in rows.items():
            if a.code > b.code:
                raise ValueError(f"row ({a.name}, {b.name}) must list the kind of lower code first")
            for q in QUESTIONS:
                kernel = answers[q]
                known = self.kernels[q]
                if kernel not in known:
                    known.append(kernel)
                self.index[q][a.code, b.code] = self.index[q][b.code, a.code] = known.index(kernel)
        for q in QUESTIONS:
            missing = np.argwhere(self.index[q] < 0)
            if missing.size:
                a, b = (KINDS[int(c)].name for c in missing[0])
                raise ValueError(f"the dispatch table has no {q!r} cell for ({a}, {b})")

    def cell(self, a: ShapeKind, b: ShapeKind, question: str) -> Kernel:
        return self.kernels[question][self.index[question][a.code, b.code]]


@njit(inline="always")
def boxes_within(lo, hi, i, j, margin):
    """Whether the AABBs of rows i and j are at most ``margin`` apart along every axis (closed; ``margin`` = 0: they
    overlap, as engine.broadphase.pairs.boxes_overlap, to the bit): a pair whose distance is <= margin passes."""
    for c in range(lo.shape[1]):
        if lo[i, c] > hi[j, c] + margin or lo[j, c] > hi[i, c] + margin:
            return False
    return True


@njit(inline="always")
def _every_pair_passes(sensor, category, mask, group, i, j, keys, no_sensors):
    """The filter of a world that has none (no filter, group, sensor or exclusion): every pair is tested."""
    return True


@njit(inline="always")
def _classify(bodies, pairs, index, counts, test_boxes, keys, no_sensors, margin, passes):
    """``classify_pairs`` with the filter ``passes`` (``pair_passes`` or ``_every_pair_passes``), inlined into each
    kernel below: a world without a filter compiles none."""
    kept = np.empty(pairs.shape[0], np.int64)
    codes = np.empty(pairs.shape[0], np.int64)
    lo, hi, bounded, owner, kind = bodies.lo, bodies.hi, bodies.bounded, bodies.owner, bodies.kind
    sensor, category, mask, group = bodies.sensor, bodies.category, bodies.mask, bodies.group
    m = filtered = 0
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        if test_boxes and bounded[i] and bounded[j] and not boxes_within(lo, hi, i, j, margin):
            continue
        bi = owner[i] if owner[i] >= 0 else i  # the bodies the rows answer for (a part: its compound)
        bj = owner[j] if owner[j] >= 0 else j
        if not passes(sensor, category, mask, group, bi, bj, keys, no_sensors):
            filtered += 1
            continue
        ki, kj = kind[i], kind[j]
        kept[m], codes[m] = p, index[ki, kj]
        counts[min(ki, kj), max(ki, kj)] += 1
        m += 1
    return kept[:m], codes[:m], filtered


@njit
def classify_pairs(bodies, pairs, index, counts, test_boxes, keys, no_sensors, margin):
    """Which candidate pairs of rows (k, 2) go to the narrow phase — their AABBs overlap (closed; grown by
    ``margin``: ``boxes_within``; a pair with an unbounded shape is kept: its own candidate test allowed for
    round-off; every pair when not ``test_boxes``) and the filter lets their bodies through
    (engine.world.filters.pair_passes, with ``keys`` and ``no_sensors``) —: their rows (k',) in order, each one's
    kernel index ``index[kind_i, kind_j]`` (k',), and how many the filter dropped; ``counts`` ((kinds, kinds)
    int64) += the pairs per (kind, kind), lower kind first."""
    return _classify(bodies, pairs, index, counts, test_boxes, keys, no_sensors, margin, pair_passes)


@njit
def classify_unfiltered_pairs(bodies, pairs, index, counts, test_boxes, margin):
    """``classify_pairs`` for a world without a filter: only the AABB test (the filter dropped 0 pairs)."""
    return _classify(bodies, pairs, index, counts, test_boxes, np.empty(0, np.int64), False, margin,
                     _every_pair_passes)


@njit
def group_by_code(codes, n_codes):
    """A counting sort of the kernel indices (k,): ``order`` (k,) lists the rows by code, stable, and code c's
    rows are ``order[bounds[c]:bounds[c + 1]]`` (bounds (n_codes + 1,))."""
    bounds = np.zeros(n_codes + 1, np.int64)
    for c in codes:
        bounds[c + 1] += 1
    for c in range(n_codes):
        bounds[c + 1] += bounds[c]
    fill = bounds[:-1].copy()
    order = np.empty(codes.shape[0], np.int64)
    for p in range(codes.shape[0]):
        order[fill[codes[p]]] = p
        fill[codes[p]] += 1
    return order, bounds


@njit(inline="always")
def _first_side(first_part, b):
    """The first row a body answers with: its first part (a compound), or itself."""
    return first_part[b] if first_part[b] >= 0 else b


@njit(inline="always")
def _next_side(first_part, next_part, b, s):
    return next_part[s] if first_part[b] >= 0 else -1


@njit
def expand_parts(bodies, pairs, test_boxes, margin=0.0):
    """Pairs of rows (m, 2) answering the pairs of bodies (k, 2), and the body pair each came from (m,): a pair
    without a compound stands for itself; a compound is replaced by each of its parts whose AABB overlaps the
    other side's, grown by ``margin`` (every part against an unbounded shape, every part when not ``test_boxes``),
    in the pair's
    order (Ericson 6.5: descend the hierarchy where the volumes overlap)."""
    first, after, bounded, lo, hi = bodies.first_part, bodies.next_part, bodies.bounded, bodies.lo, bodies.hi
    out = np.empty((2 * pairs.shape[0] + 16, 2), np.int64)
    origin = np.empty(out.shape[0], np.int64)
    m = 0
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        a = _first_side(first, i)
        while a >= 0:
            b = _first_side(first, j)
            while b >= 0:
                whole = a == i and b == j
                if whole or not (test_boxes and bounded[a] and bounded[b]) or boxes_within(lo, hi, a, b, margin):
                    if m == out.shape[0]:
                        out = np.concatenate((out, np.empty_like(out)))
                        origin = np.concatenate((origin, np.empty_like(origin)))
                    out[m, 0], out[m, 1], origin[m] = a, b, p
                    m += 1
                b = _next_side(first, after, j, b)
            a = _next_side(first, after, i, a)
    return out[:m], origin[:m]


#: what ``answer`` returns: ``pairs`` (m, 2) the rows tested (parts for a compound), ``origin`` (m,) the
#: candidate pair each came from, ``out`` their answers (``answer_rows``), ``counts`` the tests per
#: (kind, kind), ``filtered`` the pairs the filter dropped
Answer = namedtuple("Answer", "pairs origin out counts filtered")

def answer_rows(question: str, k: int):
    """The answers of ``question`` for k pairs, before any kernel writes them: ContactRows ("overlap", "contact"),
    times (k,) all inf ("impact"), DistanceRows ("distance")."""
    if question == "impact":
        return np.full(k, np.inf)
    if question == "distance":
        return distance_rows(k)
    return contact_rows(k)


def _classify_ranges(view, rows_pairs, index, test_boxes, keys, no_sensors, margin, threads):
    """``classify_pairs`` (``classify_unfiltered_pairs`` when ``keys`` is None: no filter) over contiguous ranges
    of the candidates (``split.ranges``), put back in range order: (kept (k',), codes (k',), counts, filtered) as
    one call over all of them gives."""

    def work(first, last):
        counts = np.zeros((len(KINDS), len(KINDS)), np.int64)
        rows = rows_pairs[first:last]
        if keys is None:
            kept, codes, filtered = classify_unfiltered_pairs(view, rows, index, counts, test_boxes, margin)
        else:
            kept, codes, filtered = classify_pairs(view, rows, index, counts, test_boxes, keys, no_sensors, margin)
        return kept + first if first else kept, codes, counts, filtered
    spans = split.ranges(rows_pairs.shape[0], threads, split.MIN_CANDIDATES_PER_THREAD)
    if len(spans) == 1:
        return work(0, rows_pairs.shape[0])
    kept, codes, counts, filtered = zip(*split.run_ranges(work, spans))
    return np.concatenate(kept), np.concatenate(codes), sum(counts), sum(filtered)


def _run_kernel(kernel: Kernel, ctx: NarrowContext, tested, sel, out) -> None:
    """One kernel over the rows ``sel`` (its rows of ``out``, disjoint from every other kernel's): on
    ``ctx.threads`` threads when the kernel allows it and there are enough rows, each contiguous range of ``sel``
    with scratch of its own."""
    spans = split.ranges(sel.shape[0], ctx.threads if kernel.threaded else 1, split.MIN_PAIRS_PER_THREAD)
    if len(spans) == 1:
        kernel.run(ctx, tested, sel, out)
        return
    m = ctx.bodies.points.shape[1]
    split.run_ranges(lambda first, last: kernel.run(ctx._replace(scratch=kernel_scratch(m)), tested,
                                                    sel[first:last], out), spans)


def answer(table: DispatchTable, question: str, ctx: NarrowContext, pairs: np.ndarray, keys=None,
           no_sensors: bool = False, margin: float = 0.0) -> Answer:
    """Run ``question`` over candidate pairs of bodies (k, 2): split compounds into parts, keep the pairs whose
    AABBs overlap (all of them for "impact": the bodies move; for "distance", boxes at most ``margin`` apart:
    ``margin`` = inf keeps every pair, every part of a compound) and, unless ``keys`` is None (a world with no
    filter, exclusion or sensor: nothing to drop), that the filter lets through (the sorted excluded ``keys``
    of engine.world.filters.Exclusions, ``no_sensors``), then one batched call per kernel of the table, each on
    ``ctx.threads`` threads when its batch is large enough (engine/world/split.py: the same answer, bit for
    bit)."""
    view = ctx.bodies
    test_boxes = question != "impact"
    margin = float(margin) if question == "distance" else 0.0
    if ctx.has_parts and pairs.shape[0]:
        rows_pairs, origin = expand_parts(view, pairs, test_boxes, margin)
    else:
        rows_pairs, origin = pairs, None
    kept, codes, counts, filtered = _classify_ranges(view, rows_pairs, table.index[question], test_boxes, keys,
                                                     no_sensors, margin, ctx.threads)
    tested = np.ascontiguousarray(rows_pairs[kept])
    out = answer_rows(question, tested.shape[0])
    order, bounds = group_by_code(codes, len(table.kernels[question]))
    for code, kernel in enumerate(table.kernels[question]):
        if bounds[code + 1] > bounds[code]:
            _run_kernel(kernel, ctx, tested, order[bounds[code]:bounds[code + 1]], out)
    return Answer(tested, kept if origin is None else origin[kept], out, counts, filtered)
