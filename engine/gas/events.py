"""Exact event-driven simulation of the confined gas (the chapter's gas, without a time step).

Between events every sphere flies in a straight line (chapter 2.A, p(t + Δt) = p(t) + v Δt), so the next
sphere–sphere contact is a root of |r + v t|² = (r_i + r_j)² and the next wall contact a linear equation; the
simulation jumps from one event to the next and answers it with the chapter's elastic formulas
(engine/gas/elastic.py). Nothing can tunnel and no pair overlaps beyond round-off, whatever the speeds.

Data structures (Rapaport, *The Art of Molecular Dynamics Simulation*, ch. 14; Ericson, *Real-Time Collision
Detection* 7.1 for the grid):
- a uniform cell list (engine/gas/cell_list.py) of cells at least one largest diameter wide: a sphere only
  meets spheres in its own or the 26 neighbouring cells, and leaving its cell is itself an event (or, with
  ``search="neighbour_lists"``, a neighbour list per sphere, remade when it leaves its skin:
  engine/gas/neighbour_list.py);
- one pending event per sphere (its earliest: pair, wall or cell crossing) filed in an event calendar
  (engine/gas/event_queue.py; G. Paul, "A complexity O(1) priority queue for event driven molecular dynamics
  simulations", J. Comput. Phys. 221, 615 (2007)): the events are filed by time into buckets and only the
  current bucket's few events are kept sorted, so filing or moving an event costs O(1), O(log k) within the
  current bucket of k events, instead of O(log n) in a heap of all n spheres; each prediction adds a scan of the
  27 cells;
- per-sphere collision counters for invalidation: a pair event remembers the partner's counter when it was
  predicted; if the partner collided since, the event is stale and the sphere is simply predicted again;
- lazy positions: each sphere stores its position at its own local time and is advanced only when touched.
"""
from __future__ import annotations

import math

import numpy as np

from engine._validate import as_choice, as_count, as_float, as_positive
from engine.gas.cell_list import CELL_MARGIN, cell_fill, cell_step, neighbour_cell, new_cell_list
from engine.gas.event_queue import calendar_build, calendar_top, calendar_update, sized_event_calendar
from engine.gas.event_state import (
    EVENT_CROSSING,
    EVENT_NONE,
    EVENT_PAIR,
    EVENT_WALL,
    RADIUS,
    STATE_COLUMNS,
    T_LOCAL,
    VX,
    VY,
    VZ,
    EventGasState,
    X,
    Y,
    Z,
    advance_sphere,
    collide_pair,
    new_event_state,
    pair_time,
    reflect_sphere,
    sync_spheres,
)
from engine.gas.initial import check_gas_state
from engine.gas.kernels import state_kernel
from engine.gas.neighbour_list import (
    SKIN,
    grown,
    list_cells_per_axis,
    neighbour_lists_init,
    neighbour_lists_run,
    new_neighbour_lists,
)
from engine.gas.observables import kinetic_energy_kernel
from engine.gas.periodic import check_periodic_box, wrapped_into_box
from engine.gas.tally import CROSSINGS, EVENTS, STALE, EventTally

__all__ = ["EventDrivenGas", "EventGasState", "EVENT_SEARCHES"]

#: the partner searches of ``EventDrivenGas``: cell lists with cell crossings, or neighbour lists with a skin
EVENT_SEARCHES = ("cells", "neighbour_lists")

_INF = math.inf


@state_kernel
def _earliest_in_cell(st, links, j, i, t, xi, yi, zi, vxi, vyi, vzi, ri, sx, sy, sz, shifted, best, bother):
    """The earliest contact (time from t, partner) of sphere i, whose position at t, velocity and radius are
    passed in locals, with the spheres j, links[j].next, … of one cell, met through their image shifted by
    (sx, sy, sz) when ``shifted`` (i lies in an edge cell of a periodic box: only there can a neighbour cell be
    across the box); (best, bother) is the earliest so far, kept on ties (the first found wins).

    Smallenburg's EDMD (EPJE 45, 22 (2022), mdCell.c ``findcollisioncell``; Rapaport ch. 14.3): the partner j
    is brought to t along its line, r = p_i − (p_j + v_j (t − t_j) + shift), and its contact time is the
    smaller root of |r + v t| = r_i + r_j (``pair_time``). A zero shift is not added: p + 0.0 == p exactly, so
    the result is the same bit for bit (EDMD's ``nearboxedge``).
    """
    while j >= 0:
        if j != i:
            dtj = t - st[j, T_LOCAL]
            px = st[j, X] + st[j, VX] * dtj
            py = st[j, Y] + st[j, VY] * dtj
            pz = st[j, Z] + st[j, VZ] * dtj
            if shifted:
                px += sx
                py += sy
                pz += sz
            tp = pair_time(xi - px, yi - py, zi - pz, vxi - st[j, VX], vyi - st[j, VY], vzi - st[j, VZ],
                           ri + st[j, RADIUS])
            if tp < best:
                best, bother = tp, j
        j = links[j]["next"]
    return best, bother


@state_kernel
def _find_partner(g, cells, i, t, axis, side):
    """Sphere i's pair candidate (at time t): its earliest contact with the spheres of the neighbouring cells.

    axis = -1: a full scan of the 27 cells around i (after its velocity changed). After a cell crossing along
    ``axis``, when i's candidate is still valid (its partner has not collided since), only the layer of 9 cells
    at offset ``side`` (±1) that became neighbours is scanned and compared with it (EDMD's cell crossing, EPJE
    45, 22 (2022); Rapaport ch. 14.3); a stale candidate forces the full scan. Periodic neighbours across the
    box are met through their image, shifted by ±L (only a sphere of an edge cell has such neighbours). Sphere i's
    fields are read once into locals, each row of 3 cells along z is one flat offset into ``head``, and the
    partner's counter is read once, after the scan (the counters do not change during it).
    """
    st, book, links, head = g.st, g.book, cells.links, cells.head
    b = book[i]
    other = b["cand_other"]
    if axis >= 0 and other >= 0 and book[other]["count"] != b["cand_count"]:
        axis = -1
    best, bother = _INF, -1
    if axis >= 0 and other >= 0:
        best = b["cand_time"] - t
        if best < 0.0:
            best = 0.0
        bother = other
    lo0, hi0, lo1, hi1, lo2, hi2 = -1, 1, -1, 1, -1, 1
    if axis == 0:
        lo0, hi0 = side, side
    elif axis == 1:
        lo1, hi1 = side, side
    elif axis == 2:
        lo2, hi2 = side, side
    n, box, periodic = cells.ncell, cells.box, cells.periodic
    c0, c1, c2 = np.int64(links[i]["cell"][0]), np.int64(links[i]["cell"][1]), np.int64(links[i]["cell"][2])
    xi, yi, zi, ri = st[i, X], st[i, Y], st[i, Z], st[i, RADIUS]
    vxi, vyi, vzi = st[i, VX], st[i, VY], st[i, VZ]
    edge = periodic and (c0 == 0 or c1 == 0 or c2 == 0 or c0 == n - 1 or c1 == n - 1 or c2 == n - 1)
    for dx in range(lo0, hi0 + 1):
        cx, sx = neighbour_cell(c0, dx, n, box, periodic)
        if cx < 0:
            continue
        for dy in range(lo1, hi1 + 1):
            cy, sy = neighbour_cell(c1, dy, n, box, periodic)
            if cy < 0:
                continue
            row = (cx * n + cy) * n
            for dz in range(lo2, hi2 + 1):
                cz, sz = neighbour_cell(c2, dz, n, box, periodic)
                if cz < 0:
                    continue
                best, bother = _earliest_in_cell(st, links, head[row + cz], i, t, xi, yi, zi, vxi, vyi, vzi, ri,
                                                 sx, sy, sz, edge, best, bother)
    b["cand_time"] = t + best
    b["cand_other"] = bother
    if bother >= 0:
        b["cand_count"] = book[bother]["count"]
    elif axis < 0:
        b["cand_count"] = 0


@state_kernel
def _schedule(g, cells, i, t):
    """Sphere i's event: the earliest of its pair candidate, its wall contacts and its cell crossings (each time
    a distance over v, v != 0)."""
    st, b, cell = g.st, g.book[i], cells.links[i]["cell"]
    half, width, ncell, periodic = cells.half, cells.width, cells.ncell, cells.periodic
    best = _INF
    btype = EVENT_NONE
    bother = -1
    for k in range(3):
        v = st[i, VX + k]
        if v == 0.0:
            continue
        up = v > 0.0
        x = st[i, X + k]
        c = cell[k]
        if not periodic:
            tw = ((half - st[i, RADIUS] if up else -half + st[i, RADIUS]) - x) / v
            if tw < 0.0:
                tw = 0.0
            if tw < best:
                best, btype, bother = tw, EVENT_WALL, k
        if periodic or (c < ncell - 1 if up else c > 0):
            tc = (-half + (c + 1 if up else c) * width - x) / v
            if tc < 0.0:
                tc = 0.0
            if tc < best:
                best, btype, bother = tc, EVENT_CROSSING, 2 * k + (1 if up else 0)
    if b["cand_other"] >= 0 and b["cand_time"] <= t + best:
        btype, bother, bcount = EVENT_PAIR, b["cand_other"], b["cand_count"]
    else:
        bcount = 0
    b["ev_time"] = b["cand_time"] if btype == EVENT_PAIR else t + best
    b["ev_type"] = btype
    b["ev_other"] = bother
    b["ev_count"] = bcount


@state_kernel
def _crossing(g, i, t):
    """Sphere i reaches a face of its cell at time t: returns the axis and side (±1) of the crossing."""
    advance_sphere(g.st, i, t)
    g.counters[CROSSINGS] += 1
    other = g.book[i]["ev_other"]
    return other // 2, 1 if other % 2 == 1 else -1


@state_kernel
def _init_kernel(g, cells):
    """Fill the cell lists and predict every sphere's first event."""
    n = g.st.shape[0]
    cell_fill(cells, g.st)
    t = g.st[0, T_LOCAL] if n else 0.0
    for i in range(n):
        _find_partner(g, cells, i, t, -1, 0)
        _schedule(g, cells, i, t)


@state_kernel
def _run_kernel(g, cells, queue, t_stop, max_events):
    """Process every event with time <= t_stop (at most max_events); returns the number processed.

    The event loop: pop the sphere with the earliest event, answer it (pair contact, wall contact or cell
    crossing), then predict again the spheres it changed (both of a collision; after a crossing only the 9 new
    neighbour cells) and file their new events in the calendar. A sphere at rest in an empty neighbourhood has no
    event, ever.
    """
    done = 0
    while done < max_events:
        i, t = calendar_top(queue)
        if i < 0 or t > t_stop:
            break
        done += 1
        g.counters[EVENTS] += 1
        book = g.book
        kind = book[i]["ev_type"]
        j, axis, side = -1, -1, 0
        if kind == EVENT_PAIR:
            j = book[i]["ev_other"]
            if book[j]["count"] == book[i]["ev_count"]:
                collide_pair(g, i, j, t, cells.box, cells.periodic)
            else:  # stale: j's velocity changed since the prediction; only i is predicted again
                advance_sphere(g.st, i, t)
                g.counters[STALE] += 1
                j = -1
        elif kind == EVENT_WALL:
            reflect_sphere(g, i, t, cells.half)
        elif kind == EVENT_CROSSING:  # into the neighbouring cell, wrapped to the opposite face when periodic
            axis, side = _crossing(g, i, t)
            shift = cell_step(cells, i, axis, side > 0)
            if shift != 0.0:
                g.st[i, X + axis] += shift
        else:
            book[i]["ev_time"] = _INF
            calendar_update(queue, i, _INF)
            continue
        for s in (i, j):
            if s >= 0:
                _find_partner(g, cells, s, t, axis, side)
                _schedule(g, cells, s, t)
                calendar_update(queue, s, book[s]["ev_time"])
    return done


def _cells_per_axis(n, box, rmax, periodic):
    """Cells at least one largest diameter wide (a contact is always between neighbouring cells), and at least
    c = 0.6 mean spacings s = (V/n)^(1/3) wide. In a dilute gas the width is a trade: a cell of width c s holds
    about c³ spheres, so a scan of the 27 cells tests about 27 c³ spheres, while a sphere crosses cell faces at a
    rate proportional to |v|/(c s); wider cells mean fewer crossing events but longer scans. The factor 0.6 is a
    compromise between the two, to be judged on bench/test_bench_gas.py (collisions per second, and events per
    collision in the periodic runs)."""
    width = max(2.0 * rmax * (1.0 + CELL_MARGIN), 0.6 * box / n ** (1.0 / 3.0))
    ncell = max(1, min(int(math.floor(box / width)), 128))
    if periodic:
        check_periodic_box(box, rmax, "radii")
        ncell = max(3, ncell)
    return ncell


class EventDrivenGas(EventTally):
    """An exact event-driven gas of n hard spheres: the state, and ``run(t_stop)`` that advances it.

    Every sphere flies in a straight line until its next event — a collision (the earliest root of
    ``|Δp + Δv t| = r_i + r_j``), a wall hit, a cell crossing or a list rebuild — kept in an event calendar
    (Paul's, engine/gas/event_queue.py); only the spheres of an event are moved and re-predicted (each keeps its
    own local time). Positions are wrapped into [−L/2, L/2) when periodic. Internally the spheres are renumbered
    in cell order (``order``) and packed into ``EventGasState``; ``positions``, ``velocities`` and ``masses``
    answer in the caller's order.

    Parameters
    ----------
    positions : array_like, shape (n, 3), float64
        Start centres, non-overlapping, inside the box (walls) or anywhere (periodic: wrapped).
    velocities : array_like, shape (n, 3), float64
        Start velocities.
    radii, masses : float or array_like, shape (n,)
        Positive, one for all or one per sphere.
    box : float
        The side L, > 0 (2r < L with walls, 6r (1 + 1e-12) <= L periodic: engine/gas/periodic.py).
    periodic : bool
        Periodic images instead of walls.
    search : {"cells", "neighbour_lists"}, default "cells"
        How a sphere's next contact is searched (``EVENT_SEARCHES``): "cells", the spheres of the 27 cells around
        it, leaving a cell being an event (cells about 0.6 mean spacings wide); "neighbour_lists", the spheres of
        its neighbour list, rebuilt when it has moved ``skin`` · r from where the list was made
        (engine/gas/neighbour_list.py). Both answer the same collisions; "cells" is the default as the faster of
        the two in bench/test_bench_gas.py (``test_events_periodic_against_c_code`` times both).
    skin : float, default 0.5
        α of the neighbour lists (> 0): neighbours within (1 + α)(r_i + r_j); unused by "cells".

    Attributes
    ----------
    n : int
        The number of spheres.
    time : float
        The gas time after the last ``run``.
    collisions, wall_hits, events, crossings, stale : int
        Counts since the last ``reset_sums()``: collisions, wall hits, events processed, cell crossings and stale
        pair events (the partner collided since the prediction).
    wall_impulse, virial : float
        ``Σ 2 m |v⊥|`` over the wall hits, and Σ m_i Δv_i · r_ij over the collisions, since ``reset_sums()``.

    Raises
    ------
    ValueError, TypeError
        From the checks of the start state (each argument named; overlapping spheres by their indices).
    """

    def __init__(self, positions, velocities, radii, masses, box, periodic, search="cells", skin=SKIN):
        positions, velocities, radii, masses, box, periodic = check_gas_state(positions, velocities, radii, masses,
                                                                              box, periodic)
        self.search = as_choice(search, "search", EVENT_SEARCHES)
        self.skin = as_positive(skin, "skin")
        n = positions.shape[0]
        self.n = n
        self.box = float(box)
        self.periodic = bool(periodic)
        pos = np.array(positions, dtype=np.float64)
        if self.periodic:
            pos -= self.box * np.floor((pos + self.box / 2) / self.box)
        lists = self.search == "neighbour_lists"
        if lists:
            self.ncell = list_cells_per_axis(n, self.box, float(radii.max()), self.periodic, self.skin)
        else:
            self.ncell = _cells_per_axis(n, self.box, float(radii.max()), self.periodic)
        self.cells = new_cell_list(n, self.box, self.ncell, self.periodic)
        cell = np.clip(np.floor((pos + self.box / 2.0) / self.cells.width).astype(np.int64), 0, self.ncell - 1)
        self.order = np.lexsort((cell[:, 2], cell[:, 1], cell[:, 0]))
        st = np.zeros((n, STATE_COLUMNS))
        st[:, X:Z + 1] = pos[self.order]
        st[:, VX:VZ + 1] = np.asarray(velocities, dtype=np.float64)[self.order]
        st[:, RADIUS] = np.asarray(radii, dtype=np.float64)[self.order]
        self.state = new_event_state(st, np.asarray(masses, dtype=np.float64)[self.order])
        self.st, self.mass = self.state.st, self.state.book["mass"]
        self.counters, self.sums = self.state.counters, self.state.sums
        self.time = 0.0
        self.processed = 0  # events processed by run() since construction (for the caller's event cap)
        self.lists = None
        if lists:
            self.lists = new_neighbour_lists(n, 16, self.skin)
            longest = neighbour_lists_init(self.state, self.lists, self.cells)
            if longest > self.lists.ids.shape[1]:
                self.lists = grown(self.lists, 2 * longest)
                neighbour_lists_init(self.state, self.lists, self.cells)
        else:
            _init_kernel(self.state, self.cells)
        times = np.ascontiguousarray(self.state.book["ev_time"])
        self.queue = sized_event_calendar(times)
        calendar_build(self.queue, times)

    def _run_events(self, t_stop: float, max_events: int) -> int:
        """The search's event loop up to t_stop; the neighbour lists grow (doubling) whenever a rebuild asks."""
        if self.lists is None:
            return int(_run_kernel(self.state, self.cells, self.queue, t_stop, max_events))
        done = 0
        while True:
            more, complete = neighbour_lists_run(self.state, self.lists, self.cells, self.queue, t_stop,
                                                 max_events - done)
            done += int(more)
            if complete:
                return done
            self.lists = grown(self.lists, 2 * self.lists.ids.shape[1])

    def run(self, t_stop: float, max_events: int = 2**62) -> int:
        """Process the events up to ``t_stop`` and bring every sphere to that time.

        Parameters
        ----------
        t_stop : float
            The time to reach, >= the gas's current ``time``.
        max_events : int, default 2**62
            Stop after this many events (>= 1); the spheres then stay at their own local times and ``time`` is not
            advanced.

        Returns
        -------
        int
            The number of events processed.

        Raises
        ------
        ValueError
            For ``t_stop`` before the gas time, or ``max_events < 1``.
        """
        t_stop = as_float(t_stop, "t_stop")
        if t_stop < self.time:
            raise ValueError(f"t_stop must be >= the gas time {float(self.time)!r}, got {t_stop!r}")
        max_events = as_count(max_events, "max_events", 1)
        done = self._run_events(t_stop, max_events)
        self.processed += done
        if done < max_events:
            sync_spheres(self.st, float(t_stop))
            self.time = float(t_stop)
        return int(done)

    def _in_caller_order(self, internal) -> np.ndarray:
        out = np.empty(internal.shape)
        out[self.order] = internal
        return out

    @property
    def positions(self) -> np.ndarray:
        """Centres (n, 3) at the current time, in the caller's order (a new array); wrapped into [−L/2, L/2)
        when periodic."""
        if self.lists is not None and self.periodic:  # the lists keep each centre unwrapped until its rebuild
            return self._in_caller_order(wrapped_into_box(self.st[:, X:Z + 1], self.box))
        return self._in_caller_order(self.st[:, X:Z + 1])

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (n, 3), in the caller's order (a new array)."""
        return self._in_caller_order(self.st[:, VX:VZ + 1])

    @property
    def masses(self) -> np.ndarray:
        """Masses (n,), in the caller's order (a new array)."""
        return self._in_caller_order(self.mass)

    def vel_view(self) -> np.ndarray:
        """The velocities (n, 3) in internal order (a view, aligned with ``mass``)."""
        return self.st[:, VX:VZ + 1]

    def kinetic_energy(self) -> float:
        """K = Σ m v²/2 (compensated summation, so the drift measured is the dynamics', not the sum's)."""
        return float(kinetic_energy_kernel(self.st[:, VX:VZ + 1], self.mass))
