"""Exact event-driven simulation of the confined gas (the chapter's gas, without a time step).

Between events every sphere flies in a straight line (chapter 2.A, p(t + Δt) = p(t) + v Δt), so the next
sphere–sphere contact is a root of |r + v t|² = (r_i + r_j)² and the next wall contact a linear equation; the
simulation jumps from one event to the next and answers it with the chapter's elastic formulas
(engine/gas/elastic.py). Nothing can tunnel and no pair overlaps beyond round-off, whatever the speeds.

Data structures (Rapaport, *The Art of Molecular Dynamics Simulation*, ch. 14; Ericson, *Real-Time Collision
Detection* 7.1 for the grid):
- a uniform cell list of cells at least one largest diameter wide, as linked lists (head/next/prev): a sphere
  only meets spheres in its own or the 26 neighbouring cells, and leaving its cell is itself an event;
- one pending event per sphere (its earliest: pair, wall or cell crossing) in an indexed binary min-heap of the
  n spheres, so each event costs O(log n) plus a scan of the 27 cells;
- per-sphere collision counters for invalidation: a pair event remembers the partner's counter when it was
  predicted; if the partner collided since, the event is stale and the sphere is simply predicted again;
- lazy positions: each sphere stores its position at its own local time and is advanced only when touched.
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine._validate import as_count, as_float
from engine.gas.elastic import _pair_impulse
from engine.gas.initial import check_gas_state

__all__ = ["EventDrivenGas"]

_PAIR, _WALL, _CROSS, _NONE = 0, 1, 2, 3
_INF = math.inf

# counters of a run: collisions, events, wall hits, cell crossings, stale events
_C_COLLISIONS, _C_EVENTS, _C_WALLS, _C_CROSSINGS, _C_STALE = 0, 1, 2, 3, 4
# accumulators: Σ 2 m |v⊥| over wall hits, Σ m Δv_i · r_ij over collisions
_A_WALL_IMPULSE, _A_VIRIAL = 0, 1


# ------------------------------------------------------------------------------------------------------------
# indexed binary min-heap of the spheres, keyed by their next event time
# ------------------------------------------------------------------------------------------------------------
@njit
def _sift_up(hkey, hid, where, pos):
    k = hkey[pos]
    i = hid[pos]
    while pos > 0:
        parent = (pos - 1) >> 1
        if hkey[parent] <= k:
            break
        hkey[pos] = hkey[parent]
        hid[pos] = hid[parent]
        where[hid[pos]] = pos
        pos = parent
    hkey[pos] = k
    hid[pos] = i
    where[i] = pos
    return pos


@njit
def _sift_down(hkey, hid, where, pos):
    size = hkey.shape[0]
    k = hkey[pos]
    i = hid[pos]
    while True:
        c = 2 * pos + 1
        if c >= size:
            break
        if c + 1 < size and hkey[c + 1] < hkey[c]:
            c += 1
        if hkey[c] >= k:
            break
        hkey[pos] = hkey[c]
        hid[pos] = hid[c]
        where[hid[pos]] = pos
        pos = c
    hkey[pos] = k
    hid[pos] = i
    where[i] = pos


@njit
def _update_key(hkey, hid, where, i, t):
    """Give sphere i the event time t and restore the heap order (keys are stored in heap order, so a
    comparison reads one contiguous array)."""
    pos = where[i]
    hkey[pos] = t
    pos = _sift_up(hkey, hid, where, pos)
    _sift_down(hkey, hid, where, pos)


# ------------------------------------------------------------------------------------------------------------
# event times
# ------------------------------------------------------------------------------------------------------------
@njit
def _pair_time(rx, ry, rz, vx, vy, vz, sigma):
    """Time until |r + v t| = σ for an approaching pair (r = p_i − p_j, v = v_i − v_j), inf if never.

    The smaller root of vv t² + 2 b t + (rr − σ²) = 0, written (rr − σ²)/(−b + sqrt(b² − vv (rr − σ²))) so that
    it does not cancel for grazing pairs; a pair already touching (round-off) and approaching collides now.
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


@njit
def _advance(st, i, t):
    """Bring sphere i to time t along its straight line (chapter 2.A: p(t + Δt) = p(t) + v Δt)."""
    dt = t - st[i, 6]
    if dt != 0.0:
        st[i, 0] += st[i, 3] * dt
        st[i, 1] += st[i, 4] * dt
        st[i, 2] += st[i, 5] * dt
        st[i, 6] = t


@njit
def _scan_cells(i, t, st, cidx, head, nxt, count, geom, ncell, periodic, axis, side,
                best, bother, bcount):
    """Earliest contact of sphere i (at time t) with the spheres of its neighbouring cells.

    axis = -1 scans the 27 cells around i; otherwise only the layer of 9 cells at offset ``side`` (±1) along
    ``axis`` (the cells that became neighbours when i crossed into its cell). Starts from the candidate
    (best, bother, bcount) and returns the better of it and the scan: (time from t, partner, partner counter).
    Periodic neighbours across the box are met through their image, shifted by ±L.
    """
    box = geom[1]
    ri = st[i, 7]
    lo0, hi0, lo1, hi1, lo2, hi2 = -1, 1, -1, 1, -1, 1
    if axis == 0:
        lo0, hi0 = side, side
    elif axis == 1:
        lo1, hi1 = side, side
    elif axis == 2:
        lo2, hi2 = side, side
    cx0 = cidx[i, 0]
    cy0 = cidx[i, 1]
    cz0 = cidx[i, 2]
    for dx in range(lo0, hi0 + 1):
        cx = cx0 + dx
        sx = 0.0
        if cx < 0:
            if not periodic:
                continue
            cx += ncell
            sx = -box
        elif cx >= ncell:
            if not periodic:
                continue
            cx -= ncell
            sx = box
        for dy in range(lo1, hi1 + 1):
            cy = cy0 + dy
            sy = 0.0
            if cy < 0:
                if not periodic:
                    continue
                cy += ncell
                sy = -box
            elif cy >= ncell:
                if not periodic:
                    continue
                cy -= ncell
                sy = box
            for dz in range(lo2, hi2 + 1):
                cz = cz0 + dz
                sz = 0.0
                if cz < 0:
                    if not periodic:
                        continue
                    cz += ncell
                    sz = -box
                elif cz >= ncell:
                    if not periodic:
                        continue
                    cz -= ncell
                    sz = box
                j = head[(cx * ncell + cy) * ncell + cz]
                while j >= 0:
                    if j != i:
                        dtj = t - st[j, 6]
                        rx = st[i, 0] - (st[j, 0] + st[j, 3] * dtj + sx)
                        ry = st[i, 1] - (st[j, 1] + st[j, 4] * dtj + sy)
                        rz = st[i, 2] - (st[j, 2] + st[j, 5] * dtj + sz)
                        tp = _pair_time(rx, ry, rz, st[i, 3] - st[j, 3], st[i, 4] - st[j, 4],
                                        st[i, 5] - st[j, 5], ri + st[j, 7])
                        if tp < best:
                            best, bother, bcount = tp, j, count[j]
                    j = nxt[j]
    return best, bother, bcount


@njit
def _schedule(i, t, st, cidx, pc_time, pc_other, pc_count, ev_time, ev_type, ev_other, ev_count,
              geom, ncell, periodic):
    """Sphere i's event: the earliest of its pair candidate, its wall contacts and its cell crossings."""
    half = geom[0]
    width = geom[2]
    origin = -half
    best = _INF
    btype = _NONE
    bother = -1
    ri = st[i, 7]
    for k in range(3):
        v = st[i, 3 + k]
        x = st[i, k]
        c = cidx[i, k]
        if v > 0.0:
            if not periodic:
                tw = (half - ri - x) / v
                if tw < 0.0:
                    tw = 0.0
                if tw < best:
                    best, btype, bother = tw, _WALL, k
            if periodic or c < ncell - 1:
                tc = (origin + (c + 1) * width - x) / v
                if tc < 0.0:
                    tc = 0.0
                if tc < best:
                    best, btype, bother = tc, _CROSS, 2 * k + 1
        elif v < 0.0:
            if not periodic:
                tw = (-half + ri - x) / v
                if tw < 0.0:
                    tw = 0.0
                if tw < best:
                    best, btype, bother = tw, _WALL, k
            if periodic or c > 0:
                tc = (origin + c * width - x) / v
                if tc < 0.0:
                    tc = 0.0
                if tc < best:
                    best, btype, bother = tc, _CROSS, 2 * k
    if pc_other[i] >= 0 and pc_time[i] <= t + best:
        ev_time[i] = pc_time[i]
        ev_type[i] = _PAIR
        ev_other[i] = pc_other[i]
        ev_count[i] = pc_count[i]
    else:
        ev_time[i] = t + best
        ev_type[i] = btype
        ev_other[i] = bother
        ev_count[i] = 0


@njit
def _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count, ev_time, ev_type,
             ev_other, ev_count, geom, ncell, periodic, axis, side):
    """Predict sphere i's next event (i already advanced to time t).

    axis = -1: a full scan of the 27 cells (after i's velocity changed). After a cell crossing along ``axis``,
    when i's pair candidate is still valid (its partner has not collided since), only the 9 new cells are
    scanned and compared with it; a stale candidate forces the full scan.
    """
    if axis >= 0 and pc_other[i] >= 0 and count[pc_other[i]] != pc_count[i]:
        axis = -1
    if axis < 0:
        best, bother, bcount = _scan_cells(i, t, st, cidx, head, nxt, count, geom, ncell,
                                           periodic, -1, 0, _INF, -1, 0)
    else:
        best = pc_time[i] - t if pc_other[i] >= 0 else _INF
        if best < 0.0:
            best = 0.0
        best, bother, bcount = _scan_cells(i, t, st, cidx, head, nxt, count, geom, ncell,
                                           periodic, axis, side, best, pc_other[i], pc_count[i])
    pc_time[i] = t + best
    pc_other[i] = bother
    pc_count[i] = bcount
    _schedule(i, t, st, cidx, pc_time, pc_other, pc_count, ev_time, ev_type, ev_other, ev_count,
              geom, ncell, periodic)


@njit
def _cell_insert(i, cell, head, nxt, prv):
    h = head[cell]
    nxt[i] = h
    prv[i] = -1
    if h >= 0:
        prv[h] = i
    head[cell] = i


@njit
def _cell_remove(i, cell, head, nxt, prv):
    if prv[i] >= 0:
        nxt[prv[i]] = nxt[i]
    else:
        head[cell] = nxt[i]
    if nxt[i] >= 0:
        prv[nxt[i]] = prv[i]


@njit
def _init_kernel(st, cidx, head, nxt, prv, count, pc_time, pc_other, pc_count, ev_time, ev_type,
                 ev_other, ev_count, hkey, hid, where, geom, ncell, periodic):
    """Fill the cell lists, predict every sphere's first event and build the heap."""
    n = st.shape[0]
    half = geom[0]
    width = geom[2]
    head[:] = -1
    for i in range(n):
        for k in range(3):
            c = int(math.floor((st[i, k] + half) / width))
            cidx[i, k] = min(ncell - 1, max(0, c))
        _cell_insert(i, (cidx[i, 0] * ncell + cidx[i, 1]) * ncell + cidx[i, 2], head, nxt, prv)
    t = st[0, 6] if n else 0.0
    for i in range(n):
        _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count, ev_time,
                 ev_type, ev_other, ev_count, geom, ncell, periodic, -1, 0)
    for p in range(n):
        hid[p] = p
        hkey[p] = ev_time[p]
        where[p] = p
    for p in range(n // 2 - 1, -1, -1):
        _sift_down(hkey, hid, where, p)


@njit
def _run_kernel(t_stop, max_events, st, mass, cidx, head, nxt, prv, count, pc_time, pc_other,
                pc_count, ev_time, ev_type, ev_other, ev_count, hkey, hid, where, geom, ncell, periodic, counters, acc):
    """Process every event with time <= t_stop (at most max_events); returns the number processed.

    The event loop: pop the sphere with the earliest event; a stale pair event (partner's counter changed) is
    re-predicted; a pair contact gets the chapter's elastic response (1.B) and adds −2 μ b to the virial; a wall
    contact flips the normal velocity component (1.B, v − 2(v·n)n) and adds 2 m |v⊥| to the wall impulse; a
    cell crossing moves the sphere to the neighbouring cell (wrapping it, periodic).
    """
    half = geom[0]
    box = geom[1]
    done = 0
    while done < max_events:
        i = hid[0]
        t = hkey[0]
        if t > t_stop:
            break
        done += 1
        counters[_C_EVENTS] += 1
        kind = ev_type[i]
        other = ev_other[i]
        if kind == _PAIR:
            j = other
            _advance(st, i, t)
            if count[j] != ev_count[i]:
                counters[_C_STALE] += 1
                _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count,
                         ev_time, ev_type, ev_other, ev_count, geom, ncell, periodic, -1, 0)
                _update_key(hkey, hid, where, i, ev_time[i])
                continue
            _advance(st, j, t)
            rx = st[i, 0] - st[j, 0]
            ry = st[i, 1] - st[j, 1]
            rz = st[i, 2] - st[j, 2]
            if periodic:
                rx -= box * round(rx / box)
                ry -= box * round(ry / box)
                rz -= box * round(rz / box)
            w = _pair_impulse(st, mass, i, j, rx, ry, rz, 3)
            if w > 0.0:
                acc[_A_VIRIAL] += w
                counters[_C_COLLISIONS] += 1
            count[i] += 1
            count[j] += 1
            _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count,
                     ev_time, ev_type, ev_other, ev_count, geom, ncell, periodic, -1, 0)
            _update_key(hkey, hid, where, i, ev_time[i])
            _predict(j, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count,
                     ev_time, ev_type, ev_other, ev_count, geom, ncell, periodic, -1, 0)
            _update_key(hkey, hid, where, j, ev_time[j])
        elif kind == _WALL:
            _advance(st, i, t)
            k = other
            v = st[i, 3 + k]
            acc[_A_WALL_IMPULSE] += 2.0 * mass[i] * abs(v)
            counters[_C_WALLS] += 1
            # the centre is exactly on the wall of the reachable cube (round-off removed), velocity reflected
            st[i, k] = (half - st[i, 7]) if v > 0.0 else (-half + st[i, 7])
            st[i, 3 + k] = -v
            count[i] += 1
            _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count,
                     ev_time, ev_type, ev_other, ev_count, geom, ncell, periodic, -1, 0)
            _update_key(hkey, hid, where, i, ev_time[i])
        elif kind == _CROSS:
            _advance(st, i, t)
            k = other // 2
            up = other % 2
            old = (cidx[i, 0] * ncell + cidx[i, 1]) * ncell + cidx[i, 2]
            _cell_remove(i, old, head, nxt, prv)
            c = cidx[i, k] + (1 if up == 1 else -1)
            if c >= ncell:
                c = 0
                st[i, k] -= box
            elif c < 0:
                c = ncell - 1
                st[i, k] += box
            cidx[i, k] = c
            _cell_insert(i, (cidx[i, 0] * ncell + cidx[i, 1]) * ncell + cidx[i, 2], head, nxt, prv)
            counters[_C_CROSSINGS] += 1
            _predict(i, t, st, cidx, head, nxt, count, pc_time, pc_other, pc_count,
                     ev_time, ev_type, ev_other, ev_count, geom, ncell, periodic, k, 1 if up == 1 else -1)
            _update_key(hkey, hid, where, i, ev_time[i])
        else:  # a sphere at rest in an empty neighbourhood: nothing ever happens to it
            ev_time[i] = _INF
            _update_key(hkey, hid, where, i, ev_time[i])
    return done


@njit
def _kinetic_energy_kernel(st, mass):
    """Σ m (vx² + vy² + vz²)/2 with Kahan–Neumaier compensation."""
    total = 0.0
    comp = 0.0
    for i in range(st.shape[0]):
        e = 0.5 * mass[i] * (st[i, 3] * st[i, 3] + st[i, 4] * st[i, 4] + st[i, 5] * st[i, 5])
        s = total + e
        if abs(total) >= abs(e):
            comp += (total - s) + e
        else:
            comp += (e - s) + total
        total = s
    return total + comp


@njit
def _sync_kernel(st, t):
    for i in range(st.shape[0]):
        _advance(st, i, t)


class EventDrivenGas:
    """State of an event-driven gas of n spheres: positions and velocities (n, 3), radii and masses (n,).

    ``run(t_stop)`` processes every event up to ``t_stop`` and brings all spheres to that time; the counters
    (``collisions``, ``events``, ``wall_hits``, ``crossings``, ``stale``) and the sums ``wall_impulse``
    (Σ 2 m |v⊥|) and ``virial`` (Σ m_i Δv_i · r_ij) accumulate until ``reset_sums()``. Positions are wrapped
    into [−L/2, L/2) when periodic. The constructor validates its arguments (``check_gas_state``).

    Internally a sphere is one row of the packed state ``st`` (n, 8) = x, y, z, vx, vy, vz, local time, radius
    (one 64-byte cache line per neighbour visited), and spheres are renumbered in cell order; ``positions`` and
    ``velocities`` return arrays in the caller's order.
    """

    def __init__(self, positions, velocities, radii, masses, box, periodic):
        positions, velocities, radii, masses, box, periodic = check_gas_state(positions, velocities, radii, masses,
                                                                              box, periodic)
        n = positions.shape[0]
        self.n = n
        self.box = float(box)
        self.periodic = bool(periodic)
        rmax = float(radii.max())
        pos = np.array(positions, dtype=np.float64)
        if self.periodic:
            pos -= self.box * np.floor((pos + self.box / 2) / self.box)
        # cells at least one largest diameter wide (a contact is always between neighbouring cells), and not
        # much smaller than the mean spacing (V/n)^(1/3): in a dilute gas that trades cell crossings for a few
        # more spheres per scan (0.9 spacing measured best at η = 0.1 and 0.3, N = 32,000)
        width = max(2.0 * rmax * (1.0 + 1e-12), 0.9 * self.box / n ** (1.0 / 3.0))
        ncell = max(1, min(int(math.floor(self.box / width)), 128))
        if self.periodic:
            if self.box < 3.0 * 2.0 * rmax * (1.0 + 1e-12):
                raise ValueError(f"a periodic box must be at least 3 diameters wide: box = {self.box!r}, "
                                 f"largest diameter = {2.0 * rmax!r}")
            ncell = max(3, ncell)
        self.ncell = ncell
        self.geom = np.array([self.box / 2.0, self.box, self.box / ncell])
        cell = np.clip(np.floor((pos + self.box / 2.0) / self.geom[2]).astype(np.int64), 0, ncell - 1)
        self.order = np.lexsort((cell[:, 2], cell[:, 1], cell[:, 0]))
        self.st = np.zeros((n, 8))
        self.st[:, 0:3] = pos[self.order]
        self.st[:, 3:6] = np.asarray(velocities, dtype=np.float64)[self.order]
        self.st[:, 7] = np.asarray(radii, dtype=np.float64)[self.order]
        self.mass = np.ascontiguousarray(np.asarray(masses, dtype=np.float64)[self.order])
        self.time = 0.0
        self.processed = 0  # events processed by run() since construction (for the caller's event cap)
        self.cidx = np.zeros((n, 3), dtype=np.int64)
        self.head = np.empty(ncell**3, dtype=np.int64)
        self.nxt = -np.ones(n, dtype=np.int64)
        self.prv = -np.ones(n, dtype=np.int64)
        self.count = np.zeros(n, dtype=np.int64)
        self.pc_time = np.full(n, math.inf)
        self.pc_other = -np.ones(n, dtype=np.int64)
        self.pc_count = np.zeros(n, dtype=np.int64)
        self.ev_time = np.zeros(n)
        self.ev_type = np.zeros(n, dtype=np.int64)
        self.ev_other = np.zeros(n, dtype=np.int64)
        self.ev_count = np.zeros(n, dtype=np.int64)
        self.hkey = np.zeros(n)
        self.hid = np.zeros(n, dtype=np.int64)
        self.where = np.zeros(n, dtype=np.int64)
        self.counters = np.zeros(5, dtype=np.int64)
        self.acc = np.zeros(2)
        _init_kernel(self.st, self.cidx, self.head, self.nxt, self.prv, self.count, self.pc_time, self.pc_other,
                     self.pc_count, self.ev_time, self.ev_type, self.ev_other, self.ev_count, self.hkey, self.hid,
                     self.where, self.geom, ncell, self.periodic)

    def run(self, t_stop: float, max_events: int = 2**62) -> int:
        """Process the events up to time t_stop and synchronise every sphere to it; returns the event count.

        When ``max_events`` is reached first, the run stops there (spheres stay at their own local times)."""
        t_stop = as_float(t_stop, "t_stop")
        if t_stop < self.time:
            raise ValueError(f"t_stop must be >= the gas time {self.time!r}, got {t_stop!r}")
        max_events = as_count(max_events, "max_events", 1)
        done = _run_kernel(t_stop, max_events, self.st, self.mass, self.cidx, self.head, self.nxt,
                           self.prv, self.count, self.pc_time, self.pc_other, self.pc_count, self.ev_time,
                           self.ev_type, self.ev_other, self.ev_count, self.hkey, self.hid, self.where, self.geom,
                           self.ncell, self.periodic, self.counters, self.acc)
        self.processed += int(done)
        if done < max_events:
            _sync_kernel(self.st, float(t_stop))
            self.time = float(t_stop)
        return int(done)

    @property
    def positions(self) -> np.ndarray:
        """Centres (n, 3) at the current time, in the caller's order (a new array)."""
        out = np.empty((self.n, 3))
        out[self.order] = self.st[:, 0:3]
        return out

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (n, 3), in the caller's order (a new array)."""
        out = np.empty((self.n, 3))
        out[self.order] = self.st[:, 3:6]
        return out

    @property
    def masses(self) -> np.ndarray:
        out = np.empty(self.n)
        out[self.order] = self.mass
        return out

    def vel_view(self) -> np.ndarray:
        """The velocities (n, 3) in internal order (a view, aligned with ``mass``)."""
        return self.st[:, 3:6]

    def kinetic_energy(self) -> float:
        """K = Σ m v²/2 (compensated summation, so the drift measured is the dynamics', not the sum's)."""
        return _kinetic_energy_kernel(self.st, self.mass)

    def reset_sums(self) -> None:
        self.counters[:] = 0
        self.acc[:] = 0.0

    @property
    def collisions(self) -> int:
        return int(self.counters[_C_COLLISIONS])

    @property
    def events(self) -> int:
        return int(self.counters[_C_EVENTS])

    @property
    def wall_hits(self) -> int:
        return int(self.counters[_C_WALLS])

    @property
    def crossings(self) -> int:
        return int(self.counters[_C_CROSSINGS])

    @property
    def stale(self) -> int:
        return int(self.counters[_C_STALE])

    @property
    def wall_impulse(self) -> float:
        return float(self.acc[_A_WALL_IMPULSE])

    @property
    def virial(self) -> float:
        return float(self.acc[_A_VIRIAL])
