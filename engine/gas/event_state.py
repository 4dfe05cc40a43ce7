"""The per-sphere state of the event-driven gas, and the kernels that move spheres and answer their contacts.

Shared by both partner searches of ``EventDrivenGas`` (engine/gas/events.py: cell lists; engine/gas/
neighbour_list.py: neighbour lists with a skin). Between events every sphere flies in a straight line (chapter
2.A, p(t + Δt) = p(t) + v Δt), each at its own local time, so the next sphere–sphere contact is a root of
|r + v t|² = (r_i + r_j)²; a contact is answered with the chapter's elastic formulas (engine/gas/elastic.py).
Per-sphere collision counters invalidate predictions: a pair event remembers the partner's counter when it was
predicted; if the partner's velocity changed since, the event is stale.

The state matrix
----------------
``EventGasState.st`` is an (n, ``STATE_COLUMNS``) float64 matrix, one row per sphere (one 64-byte cache line per
neighbour visited). This module owns its layout; the kernels (which read these module-level ints as compile-time
constants) and the tests address its columns by these names:

==============  ======  =========================================================================
name            column  meaning
==============  ======  =========================================================================
``X, Y, Z``     0 1 2   the centre at the sphere's local time (``X + k`` along axis k)
``VX, VY, VZ``  3 4 5   the velocity (``VX + k`` along axis k)
``T_LOCAL``     6       the sphere's local time: the time its centre was last brought to
``RADIUS``      7       the radius
==============  ======  =========================================================================

The centre comes first: ``cell_fill`` (engine/gas/cell_list.py) reads the first three columns as positions, and
``pair_impulse`` (engine/gas/elastic.py) is given ``VX`` as the offset of the velocity columns.

Event kinds
-----------
A sphere's scheduled event (``book["ev_type"]``, its subject in ``book["ev_other"]``) is of one of these kinds,
one enumeration for both partner searches:

==================  =====  ========================================================  ===============
name                value  the event (``ev_other``)                                  search
==================  =====  ========================================================  ===============
``EVENT_PAIR``      0      a contact with another sphere (the partner)               both
``EVENT_WALL``      1      a wall contact (its axis k)                               both, walls
``EVENT_CROSSING``  2      leaving its cell (2 · axis, + 1 through the upper face)   cells
``EVENT_NONE``      3      none: at rest, and nothing approaches it (−1)             both
``EVENT_REBUILD``   4      leaving the skin of its neighbour list (−1)               neighbour lists
==================  =====  ========================================================  ===============
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine.gas.elastic import pair_impulse
from engine.gas.kernels import state_kernel
from engine.gas.periodic import minimum_image
from engine.gas.tally import COLLISIONS, VIRIAL, WALL_HITS, WALL_IMPULSE, new_counters, new_sums

__all__ = ["BOOK", "EventGasState", "new_event_state", "pair_time", "advance_sphere", "collide_pair",
           "reflect_sphere", "sync_spheres", "X", "Y", "Z", "VX", "VY", "VZ", "T_LOCAL", "RADIUS", "STATE_COLUMNS",
           "EVENT_PAIR", "EVENT_WALL", "EVENT_CROSSING", "EVENT_NONE", "EVENT_REBUILD"]

#: the columns of the state matrix ``st`` (the table of the module docstring): centre, velocity, local time, radius
X, Y, Z, VX, VY, VZ, T_LOCAL, RADIUS = 0, 1, 2, 3, 4, 5, 6, 7
#: the width of the state matrix
STATE_COLUMNS = 8
#: the event kinds (``book["ev_type"]``; the table of the module docstring)
EVENT_PAIR, EVENT_WALL, EVENT_CROSSING, EVENT_NONE, EVENT_REBUILD = 0, 1, 2, 3, 4
_INF = math.inf

#: a sphere's bookkeeping in the event loop (one 48-byte record): its mass; its collision counter (velocity
#: changes, the invalidation counter); its pair candidate (the earliest contact found by its last scan: absolute
#: time, partner −1 if none, the partner's counter then); its scheduled event (time, kind: one of the ``EVENT_*``,
#: other: partner, wall axis or crossing 2·axis + up, −1 for the others; and the partner's counter)
BOOK = np.dtype([("cand_time", np.float64), ("ev_time", np.float64), ("mass", np.float64), ("count", np.int32),
                 ("cand_other", np.int32), ("cand_count", np.int32), ("ev_type", np.int32), ("ev_other", np.int32),
                 ("ev_count", np.int32)], align=True)


class EventGasState(NamedTuple):
    """The spheres of an event-driven gas and their pending events, in the gas's internal (cell) order.

    st: (n, STATE_COLUMNS) float64, one row per sphere: centre ``X, Y, Z``, velocity ``VX, VY, VZ``, local time
    ``T_LOCAL`` and ``RADIUS`` (the module docstring's table); book: (n,) BOOK records; counters, sums: the run's
    tallies (engine/gas/tally.py).
    """

    st: np.ndarray
    book: np.ndarray
    counters: np.ndarray
    sums: np.ndarray


def new_event_state(st, mass):
    book = np.zeros(st.shape[0], dtype=BOOK)
    book["mass"] = mass
    book["cand_time"] = math.inf
    book["cand_other"] = -1
    return EventGasState(st, book, new_counters(), new_sums())


# ------------------------------------------------------------------------------------------------------------
# Kernels. The event loop calls small kernels that take the state bundles; they are compiled by ``state_kernel``
# (engine/gas/kernels.py: no reference counting of the bundled arrays, and error_model="numpy": none of their
# divisions can be by zero, each is noted) and read a bundle's fields into locals once, before branching on them.
# ------------------------------------------------------------------------------------------------------------
@state_kernel
def pair_time(rx, ry, rz, vx, vy, vz, sigma):
    """Time until |r + v t| = σ for an approaching pair (r = p_i − p_j, v = v_i − v_j), inf if never.

    The smaller root of vv t² + 2 b t + (rr − σ²) = 0, written (rr − σ²)/(−b + sqrt(b² − vv (rr − σ²))) so that
    it does not cancel for grazing pairs (the denominator is >= −b > 0); a pair already touching (round-off) and
    approaching collides now.
    """
    b = rx * vx + ry * vy + rz * vz
    if b >= 0.0:
        return _INF
    c = rx * rx + ry * ry + rz * rz - sigma * sigma
    if c <= 0.0:
        return 0.0
    vv = vx * vx + vy * vy + vz * vz
    disc = b * b - vv * c
    if disc < 0.0:
        return _INF
    return c / (-b + math.sqrt(disc))


@state_kernel
def advance_sphere(st, i, t):
    """Bring sphere i to time t along its straight line (chapter 2.A: p(t + Δt) = p(t) + v Δt)."""
    dt = t - st[i, T_LOCAL]
    if dt != 0.0:
        st[i, X] += st[i, VX] * dt
        st[i, Y] += st[i, VY] * dt
        st[i, Z] += st[i, VZ] * dt
        st[i, T_LOCAL] = t




@state_kernel
def collide_pair(g, i, j, t, box, periodic):
    """Spheres i and j touch at time t: the chapter's elastic response (1.B), which adds −2 μ b to the virial."""
    st, book = g.st, g.book
    advance_sphere(st, i, t)
    advance_sphere(st, j, t)
    rx = st[i, X] - st[j, X]
    ry = st[i, Y] - st[j, Y]
    rz = st[i, Z] - st[j, Z]
    if periodic:
        rx, ry, rz = minimum_image(rx, ry, rz, box)
    w = pair_impulse(st, book[i]["mass"], book[j]["mass"], i, j, rx, ry, rz, VX)
    if w > 0.0:
        g.sums[VIRIAL] += w
        g.counters[COLLISIONS] += 1
    book[i]["count"] += 1
    book[j]["count"] += 1


@state_kernel
def reflect_sphere(g, i, t, half):
    """Sphere i reaches a wall: the normal velocity component flips (1.B, v − 2(v·n)n), 2 m |v⊥| is added to
    the wall impulse, and the centre is put exactly on the wall of the reachable cube (round-off removed)."""
    st, b = g.st, g.book[i]
    advance_sphere(st, i, t)
    k = b["ev_other"]
    v = st[i, VX + k]
    g.sums[WALL_IMPULSE] += 2.0 * b["mass"] * abs(v)
    g.counters[WALL_HITS] += 1
    st[i, X + k] = (half - st[i, RADIUS]) if v > 0.0 else (-half + st[i, RADIUS])
    st[i, VX + k] = -v
    b["count"] += 1




@state_kernel
def sync_spheres(st, t):
    for i in range(st.shape[0]):
        advance_sphere(st, i, t)


