"""Neighbour lists with a skin for the event-driven gas: one event per sphere, no cell crossings.

F. Smallenburg, "Efficient event-driven simulations of hard spheres", EPJE 45, 22 (2022), section 2.3 (neighbour
lists) and the "Single" variant of its code (one event per particle). Each sphere i keeps the list of the
spheres j whose centres were within (1 + α)(r_i + r_j) of its own when the list was made, measured between the
list centres x̂ (the positions at each sphere's last rebuild). Sphere i's event is the earliest of

- a contact with one of its neighbours (the pair equation of engine/gas/event_state.py);
- a wall contact (walls only);
- leaving its skin: |x_i − x̂_i| = α r_i (a *rebuild*: i's list is made again around its new position).

Two spheres that are not neighbours have |x̂_i − x̂_j| >= (1 + α)(r_i + r_j) and each stays within α r of its list
centre until its rebuild, so they are at least r_i + r_j apart: they cannot touch before one of them rebuilds,
and no contact is missed. A rebuild finds the new neighbours in a cell list of cells at least (1 + α) 2 r_max wide
(engine/gas/cell_list.py), and keeps the lists symmetric (i is taken out of its old neighbours' lists and put in
its new ones'). Compared with cell crossings, a rebuild happens only after a displacement of α r, and a
prediction tests a handful of neighbours instead of 27 cells.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine.gas.cell_list import CELL_MARGIN, cell_insert, cell_remove, neighbour_cell
from engine.gas.event_queue import calendar_top, calendar_update
from engine.gas.event_state import (
    EVENT_NONE,
    EVENT_PAIR,
    EVENT_REBUILD,
    EVENT_WALL,
    RADIUS,
    T_LOCAL,
    VX,
    VY,
    VZ,
    X,
    Y,
    Z,
    advance_sphere,
    collide_pair,
    pair_time,
    reflect_sphere,
)
from engine.gas.kernels import state_kernel
from engine.gas.periodic import wrap_coordinate
from engine.gas.tally import EVENTS, STALE

__all__ = ["NeighbourLists", "new_neighbour_lists", "SKIN", "REBUILDS", "neighbour_lists_init", "neighbour_lists_run",
           "grown", "list_cells_per_axis"]

#: α, the skin of the lists: neighbours within (1 + α)(r_i + r_j), rebuilt after a displacement of α r_i
#: (Smallenburg's default shell 1 + α = 1.5)
SKIN = 0.5
#: index of the rebuild count in the lists' ``tally``
REBUILDS = 0
# the skin a sphere may move through is α r (1 − 2^−30): the lists' guarantee then holds with a margin above
# round-off (two non-neighbours stay r_i + r_j (1 + 2^−31 α) apart)
_SKIN_MARGIN = 1.0 - 2.0**-30
_INF = math.inf


class NeighbourLists(NamedTuple):
    """centre: (n, 4) float64 list centres x̂ and the radius (the 32 bytes a rebuild reads per candidate); sizes:
    (n,) int32 neighbours of each sphere; ids: (n, cap) int32,
    row i's first sizes[i] entries its neighbours; found: (n,) int32 scratch of a rebuild; tally: (1,) int64
    rebuilds; skin: α (float)."""

    centre: np.ndarray
    sizes: np.ndarray
    ids: np.ndarray
    found: np.ndarray
    tally: np.ndarray
    skin: float


def new_neighbour_lists(n: int, capacity: int, skin: float = SKIN) -> NeighbourLists:
    """Empty lists of ``capacity`` neighbours per sphere for n spheres (filled by ``neighbour_lists_init``)."""
    return NeighbourLists(np.zeros((n, 4)), np.zeros(n, dtype=np.int32), np.full((n, capacity), -1, dtype=np.int32),
                          np.zeros(n, dtype=np.int32), np.zeros(1, dtype=np.int64), float(skin))


@state_kernel
def _separation(xi, yi, zi, xj, yj, zj, box, periodic):
    """x_i − x_j, its nearest image when periodic (both near the box, so one shift of ±L per axis suffices)."""
    rx, ry, rz = xi - xj, yi - yj, zi - zj
    if periodic:
        half = 0.5 * box
        if rx > half:
            rx -= box
        elif rx < -half:
            rx += box
        if ry > half:
            ry -= box
        elif ry < -half:
            ry += box
        if rz > half:
            rz -= box
        elif rz < -half:
            rz += box
    return rx, ry, rz


@state_kernel
def _skin_exit_time(st, nl, i):
    """Time from now until sphere i (up to date) is α r_i from its list centre: the larger root of
    |d + v s|² = δ², d = x_i − x̂_i (|d| <= δ, so the roots have opposite signs); inf at rest."""
    dx, dy, dz = st[i, X] - nl.centre[i, 0], st[i, Y] - nl.centre[i, 1], st[i, Z] - nl.centre[i, 2]
    vx, vy, vz = st[i, VX], st[i, VY], st[i, VZ]
    vv = vx * vx + vy * vy + vz * vz
    if vv == 0.0:
        return _INF
    delta = nl.skin * st[i, RADIUS] * _SKIN_MARGIN
    b = dx * vx + dy * vy + dz * vz
    room = delta * delta - (dx * dx + dy * dy + dz * dz)
    if room < 0.0:  # round-off just beyond the skin
        room = 0.0
    root = math.sqrt(b * b + vv * room)
    return room / (b + root) if b > 0.0 else (root - b) / vv  # both forms >= 0, the first without cancellation


@state_kernel
def _predict(g, nl, i, t, box, periodic):
    """Smallenburg's findcollisions: sphere i's next event (i at time t) — the earliest of its skin exit, its wall
    contacts and its contacts with its neighbours — stored in book[i]."""
    st, book = g.st, g.book
    best, kind, other, other_count = _skin_exit_time(st, nl, i), EVENT_REBUILD, -1, 0
    if not periodic:
        half = 0.5 * box
        for k in range(3):
            v = st[i, VX + k]
            if v != 0.0:
                tw = ((half - st[i, RADIUS] if v > 0.0 else -half + st[i, RADIUS]) - st[i, X + k]) / v
                tw = max(tw, 0.0)
                if tw < best:
                    best, kind, other = tw, EVENT_WALL, k
    xi, yi, zi = st[i, X], st[i, Y], st[i, Z]
    for m in range(nl.sizes[i]):
        j = nl.ids[i, m]
        dtj = t - st[j, T_LOCAL]
        rx, ry, rz = _separation(xi, yi, zi, st[j, X] + st[j, VX] * dtj, st[j, Y] + st[j, VY] * dtj,
                                 st[j, Z] + st[j, VZ] * dtj, box, periodic)
        tp = pair_time(rx, ry, rz, st[i, VX] - st[j, VX], st[i, VY] - st[j, VY], st[i, VZ] - st[j, VZ],
                       st[i, RADIUS] + st[j, RADIUS])
        if tp < best:
            best, kind, other, other_count = tp, EVENT_PAIR, j, book[j]["count"]
    if best == _INF:
        kind = EVENT_NONE
    b = book[i]
    b["ev_time"], b["ev_type"], b["ev_other"], b["ev_count"] = t + best, kind, other, other_count


@state_kernel
def _gather(g, nl, cells, i):
    """The spheres j of the 27 cells around i with |x̂_i − x̂_j| < (1 + α)(r_i + r_j), into nl.found; their
    number."""
    c, n, box, periodic, centre = cells.links[i]["cell"], cells.ncell, cells.box, cells.periodic, nl.centre
    shell = 1.0 + nl.skin
    found = 0
    for dx in range(-1, 2):
        cx, _ = neighbour_cell(c[0], dx, n, box, periodic)
        for dy in range(-1, 2):
            cy, _ = neighbour_cell(c[1], dy, n, box, periodic)
            for dz in range(-1, 2):
                cz, _ = neighbour_cell(c[2], dz, n, box, periodic)
                if cx < 0 or cy < 0 or cz < 0:
                    continue
                j = cells.head[(cx * n + cy) * n + cz]
                while j >= 0:
                    if j != i:
                        rx, ry, rz = _separation(centre[i, 0], centre[i, 1], centre[i, 2], centre[j, 0],
                                                 centre[j, 1], centre[j, 2], box, periodic)
                        reach = shell * (centre[i, 3] + centre[j, 3])
                        if rx * rx + ry * ry + rz * rz < reach * reach:
                            nl.found[found] = j
                            found += 1
                    j = cells.links[j]["next"]
    return found


@state_kernel
def _rebuild(g, nl, cells, i, t):
    """Smallenburg's makeneighborlist: sphere i is brought to t (and into the box when periodic), its list centre
    set there, its cell updated, and its list made again (symmetrically). Returns False, with the lists unchanged,
    when a list would outgrow its capacity (the caller grows ``ids`` and processes the event again)."""
    st, cells_half, width = g.st, cells.half, cells.width
    advance_sphere(st, i, t)
    cell_remove(cells, i)
    for k in range(3):
        if cells.periodic:
            st[i, X + k] = wrap_coordinate(st[i, X + k], cells_half)
        nl.centre[i, k] = st[i, X + k]
        cells.links[i]["cell"][k] = min(cells.ncell - 1, max(0, int(math.floor((st[i, X + k] + cells_half)
                                                                             / width))))
    cell_insert(cells, i)
    found = _gather(g, nl, cells, i)
    cap = nl.ids.shape[1]
    if found > cap:
        return False
    for m in range(found):
        if nl.sizes[nl.found[m]] >= cap:
            return False
    for m in range(nl.sizes[i]):  # out of the old neighbours' lists (swap with the last entry)
        j = nl.ids[i, m]
        last = nl.sizes[j] - 1
        for s in range(last + 1):
            if nl.ids[j, s] == i:
                nl.ids[j, s] = nl.ids[j, last]
                break
        nl.sizes[j] = last
    for m in range(found):
        j = nl.found[m]
        nl.ids[i, m] = j
        nl.ids[j, nl.sizes[j]] = i
        nl.sizes[j] += 1
    nl.sizes[i] = found
    nl.tally[REBUILDS] += 1
    return True


@state_kernel
def neighbour_lists_init(g, nl, cells):
    """Fill the cell list and every sphere's neighbour list (all spheres at one time t, inside the box), then
    predict each sphere's first event. Returns the longest list; when it exceeds the capacity of ``nl.ids``
    nothing is predicted (the caller grows ``ids`` and calls again)."""
    st = g.st
    n = st.shape[0]
    cells.head[:] = -1
    longest = 0
    for i in range(n):
        nl.centre[i, 3] = st[i, RADIUS]
        for k in range(3):
            nl.centre[i, k] = st[i, X + k]
            cells.links[i]["cell"][k] = min(cells.ncell - 1, max(0, int(math.floor((st[i, X + k] + cells.half)
                                                                                 / cells.width))))
        cell_insert(cells, i)
    cap = nl.ids.shape[1]
    for i in range(n):
        found = _gather(g, nl, cells, i)
        longest = max(longest, found)
        nl.sizes[i] = min(found, cap)
        for m in range(nl.sizes[i]):
            nl.ids[i, m] = nl.found[m]
    if longest > cap:
        return longest
    t = st[0, T_LOCAL] if n else 0.0
    for i in range(n):
        _predict(g, nl, i, t, cells.box, cells.periodic)
    return longest


@state_kernel
def neighbour_lists_run(g, nl, cells, queue, t_stop, max_events):
    """Process every event with time <= t_stop (at most max_events): (events processed, True), or (events
    processed, False) when a rebuild needs longer lists (that event is left at the head of the calendar).

    Smallenburg's event loop (section 2.3, "Single"): pop the sphere with the earliest event; answer it — a
    contact (when the partner has not changed velocity since the prediction; otherwise the event is stale), a wall
    hit, or a rebuild of its list; predict again the sphere(s) it changed and file their new events.
    """
    done = 0
    box, periodic, book, st = cells.box, cells.periodic, g.book, g.st
    while done < max_events:
        i, t = calendar_top(queue)
        if i < 0 or t > t_stop:
            break
        kind = book[i]["ev_type"]
        if kind == EVENT_REBUILD and not _rebuild(g, nl, cells, i, t):
            return done, False
        done += 1
        g.counters[EVENTS] += 1
        j = -1
        if kind == EVENT_PAIR:
            j = book[i]["ev_other"]
            if book[j]["count"] == book[i]["ev_count"]:
                collide_pair(g, i, j, t, box, periodic)
            else:  # stale: j's velocity changed since the prediction
                advance_sphere(st, i, t)
                g.counters[STALE] += 1
                j = -1
        elif kind == EVENT_WALL:
            reflect_sphere(g, i, t, cells.half)
        elif kind == EVENT_NONE:
            book[i]["ev_time"] = _INF
            calendar_update(queue, i, _INF)
            continue
        _predict(g, nl, i, t, box, periodic)
        calendar_update(queue, i, book[i]["ev_time"])
        if j >= 0:
            _predict(g, nl, j, t, box, periodic)
            calendar_update(queue, j, book[j]["ev_time"])
    return done, True


def grown(nl: NeighbourLists, capacity: int) -> NeighbourLists:
    """The same lists with room for ``capacity`` (>= the current) neighbours per sphere."""
    ids = np.full((nl.ids.shape[0], capacity), -1, dtype=np.int32)
    ids[:, :nl.ids.shape[1]] = nl.ids
    return nl._replace(ids=ids)


def list_cells_per_axis(n: int, box: float, rmax: float, periodic: bool, skin: float = SKIN) -> int:
    """Cells of the rebuilds' cell list: at least (1 + α) 2 r_max wide (every neighbour is in the 27 cells around),
    at most 128 and about 8 n cells in all (Smallenburg's cap); at least 3 when periodic."""
    width = (1.0 + skin) * 2.0 * rmax * (1.0 + CELL_MARGIN)
    ncell = max(1, min(int(math.floor(box / width)), 128, int(math.ceil((8.0 * n) ** (1.0 / 3.0)))))
    if periodic and ncell < 3:
        raise ValueError(f"search='neighbour_lists' needs a periodic box at least 3 list diameters wide: box = "
                         f"{float(box)!r}, (1 + α) · largest diameter = {float(width)!r}")
    return ncell
