"""The chapter's frame loop for the confined gas: a fixed time step Δt (chapter 3, "Algorithme de Simulation").

Each frame:
1. **move**: p ← p + v Δt for every sphere (2.A);
2. **walls**: a sphere with p_k − r <= −L/2 moving outwards (or p_k + r >= L/2) has v_k reversed (2.B,
   v − 2(v·n)n) and its centre mirrored back into the reachable cube (periodic boxes wrap instead);
3. **pairs**: the broad phase (any of ``BROAD_PHASES``; by default the incremental sweep-and-prune of chapter 4,
   which keeps its sorted order between frames) proposes the pairs whose boxes overlap, and the exact test
   |p_A − p_B| <= r_A + r_B (2.C) keeps the contacts;
4. **response**: each approaching pair, (v_A − v_B)·(p_A − p_B) < 0, is moved back to its contact instant
   (a root of the same quadratic as the event-driven method), answered with the mass-weighted elastic formulas
   (1.B / 2.C), and moved forward again with its new velocities; then the remaining overlaps are removed by
   pushing each overlapping pair apart along its line of centres (mass-weighted, momentum kept), a few passes
   over the candidate pairs until none overlaps. Velocities only change in the elastic response, so energy is
   conserved to round-off; a finite Δt still misses or delays some collisions, which biases Z low
   (DESIGN.md section 6).

Pairs are canonical (sorted), so the result does not depend on the broad phase: same seed, same final state.
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine._validate import as_choice, as_count, as_positive
from engine.broadphase import IncrementalSAP, find_pairs
from engine.broadphase.pairs import canonical_pairs
from engine.gas.elastic import _pair_impulse
from engine.gas.events import _kinetic_energy_kernel
from engine.gas.initial import check_gas_state

__all__ = ["SteppedGas"]

#: passes of the overlap-removal loop before giving up for this frame (the next frame continues)
_MAX_PASSES = 64


@njit
def _move_and_walls(pos, vel, rad, mass, half, periodic, dt, acc, counters):
    """Steps 1 and 2 of the frame: p ← p + v Δt, then the walls (chapter 2.B) or the periodic wrap."""
    n = pos.shape[0]
    box = 2.0 * half
    for i in range(n):
        for k in range(3):
            p = pos[i, k] + vel[i, k] * dt
            if periodic:
                p -= box * math.floor((p + half) / box)
                if p >= half:  # round-off of the wrap
                    p -= box
            else:
                lo = -half + rad[i]
                hi = half - rad[i]
                v = vel[i, k]
                if p <= lo and v < 0.0:
                    acc[0] += 2.0 * mass[i] * (-v)
                    counters[1] += 1
                    vel[i, k] = -v
                    p = lo + (lo - p)  # mirror: the distance travelled past the wall is travelled back
                elif p >= hi and v > 0.0:
                    acc[0] += 2.0 * mass[i] * v
                    counters[1] += 1
                    vel[i, k] = -v
                    p = hi - (p - hi)
                if p < lo:
                    p = lo
                elif p > hi:
                    p = hi
            pos[i, k] = p


@njit
def _separation(pos, i, j, box, periodic):
    rx = pos[i, 0] - pos[j, 0]
    ry = pos[i, 1] - pos[j, 1]
    rz = pos[i, 2] - pos[j, 2]
    if periodic:
        rx -= box * round(rx / box)
        ry -= box * round(ry / box)
        rz -= box * round(rz / box)
    return rx, ry, rz


@njit
def _keep_inside(pos, rad, q, half, periodic):
    """Clamp sphere q's centre into the reachable cube [−L/2 + r, L/2 − r]³ (periodic: wrap into [−L/2, L/2))."""
    box = 2.0 * half
    for k in range(3):
        if periodic:
            pos[q, k] -= box * math.floor((pos[q, k] + half) / box)
            if pos[q, k] >= half:
                pos[q, k] -= box
        else:
            lo = -half + rad[q]
            hi = half - rad[q]
            if pos[q, k] < lo:
                pos[q, k] = lo
            elif pos[q, k] > hi:
                pos[q, k] = hi


@njit
def _respond(pairs, pos, vel, rad, mass, half, periodic, dt, acc, counters):
    """Step 4 of the frame on the candidate pairs (canonical order): elastic response of approaching contacts
    at their contact instant, then overlap removal. Returns the number of pairs still overlapping."""
    box = 2.0 * half
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        rx, ry, rz = _separation(pos, i, j, box, periodic)
        sigma = rad[i] + rad[j]
        c = rx * rx + ry * ry + rz * rz - sigma * sigma
        if c > 0.0:
            continue
        vx = vel[i, 0] - vel[j, 0]
        vy = vel[i, 1] - vel[j, 1]
        vz = vel[i, 2] - vel[j, 2]
        b = rx * vx + ry * vy + rz * vz
        if not b < 0.0:  # receding or grazing: not answered (chapter: only pairs that approach)
            continue
        # back to the contact instant: |r − v τ| = σ, τ = (b + sqrt(b² − vv c))/vv >= 0, at most one frame
        vv = vx * vx + vy * vy + vz * vz
        tau = (b + math.sqrt(b * b - vv * c)) / vv
        if not tau >= 0.0:
            tau = 0.0
        if tau > dt:
            tau = dt
        cx = rx - vx * tau
        cy = ry - vy * tau
        cz = rz - vz * tau
        old = np.empty(6)
        for k in range(3):
            old[k] = vel[i, k]
            old[3 + k] = vel[j, k]
        w = _pair_impulse(vel, mass, i, j, cx, cy, cz, 0)
        if w > 0.0:
            acc[1] += w
            counters[0] += 1
            # forward again from the contact with the new velocities
            for k in range(3):
                pos[i, k] += (vel[i, k] - old[k]) * tau
                pos[j, k] += (vel[j, k] - old[3 + k]) * tau
    # the moves back to contact and forward again may cross a wall: keep every centre in the reachable box
    for q in range(pos.shape[0]):
        _keep_inside(pos, rad, q, half, periodic)
    # overlap removal: push overlapping pairs apart along the line of centres, mass-weighted
    remaining = 0
    for _ in range(_MAX_PASSES):
        remaining = 0
        for p in range(pairs.shape[0]):
            i = pairs[p, 0]
            j = pairs[p, 1]
            rx, ry, rz = _separation(pos, i, j, box, periodic)
            sigma = rad[i] + rad[j]
            d2 = rx * rx + ry * ry + rz * rz
            if d2 >= sigma * sigma:
                continue
            remaining += 1
            d = math.sqrt(d2)
            if d > 0.0:
                ux, uy, uz = rx / d, ry / d, rz / d
            else:  # coincident centres: any direction will do
                ux, uy, uz = 1.0, 0.0, 0.0
            gap = (sigma - d) + 4.0 * sigma * 2.220446049250313e-16
            wi = mass[j] / (mass[i] + mass[j])
            wj = mass[i] / (mass[i] + mass[j])
            pos[i, 0] += wi * gap * ux
            pos[i, 1] += wi * gap * uy
            pos[i, 2] += wi * gap * uz
            pos[j, 0] -= wj * gap * ux
            pos[j, 1] -= wj * gap * uy
            pos[j, 2] -= wj * gap * uz
            _keep_inside(pos, rad, i, half, periodic)
            _keep_inside(pos, rad, j, half, periodic)
        if remaining == 0:
            break
    return remaining


class SteppedGas:
    """The chapter's fixed-step gas: positions/velocities (n, 3), radii/masses (n,), box side L, Δt.

    ``run(steps)`` advances ``steps`` frames of ``dt``; counters ``collisions``, ``wall_hits`` and the sums
    ``wall_impulse`` (Σ 2 m |v⊥|), ``virial`` (Σ m_i Δv_i · r_ij at contact) accumulate until ``reset_sums()``.
    ``broad_phase`` is a name of ``BROAD_PHASES``; "sap" uses ``IncrementalSAP`` (sorted order kept between
    frames). The constructor validates its arguments (``check_gas_state``, dt, broad_phase).
    """

    def __init__(self, positions, velocities, radii, masses, box, periodic, dt, broad_phase="sap"):
        from engine.broadphase import BROAD_PHASES

        positions, velocities, radii, masses, box, periodic = check_gas_state(positions, velocities, radii, masses,
                                                                              box, periodic, allow_overlap=True)
        dt = as_positive(dt, "dt")
        broad_phase = as_choice(broad_phase, "broad_phase", BROAD_PHASES)
        self.n = positions.shape[0]
        self.box = float(box)
        self.half = self.box / 2.0
        self.periodic = bool(periodic)
        self.dt = float(dt)
        self.broad_phase = broad_phase
        self.pos = np.array(positions, dtype=np.float64)
        if self.periodic:
            self.pos -= self.box * np.floor((self.pos + self.half) / self.box)
        self.vel = np.array(velocities, dtype=np.float64)
        self.rad = np.ascontiguousarray(radii, dtype=np.float64)
        self.mass = np.ascontiguousarray(masses, dtype=np.float64)
        self.time = 0.0
        self.acc = np.zeros(2)
        self.counters = np.zeros(2, dtype=np.int64)
        self.overlapping = 0
        self._sap = None

    # -- step 3: broad phase + (in the response) the exact test --------------------------------------------
    def _reach(self) -> np.ndarray:
        """Half-widths of the candidate boxes: radius plus how far a correction may still move a sphere."""
        vmax = float(np.sqrt((self.vel * self.vel).sum(axis=1).max())) if self.n else 0.0
        return self.rad + vmax * self.dt

    def _boxes_pairs(self, lo, hi, incremental):
        if self.broad_phase == "sap" and incremental:
            if self._sap is None or len(self._sap) != lo.shape[0]:
                self._sap = IncrementalSAP(lo, hi)
                return self._sap.pairs()
            return self._sap.update(lo, hi)
        return find_pairs(lo, hi, method=self.broad_phase)

    def candidate_pairs(self) -> np.ndarray:
        """Canonical pairs whose (slightly widened) boxes overlap, periodic images included."""
        reach = self._reach()
        lo = self.pos - reach[:, None]
        hi = self.pos + reach[:, None]
        pairs = self._boxes_pairs(lo, hi, incremental=True)
        if not self.periodic or self.n < 2:
            return pairs
        # pairs across the periodic boundary: the spheres near a face and their images shifted by ±L
        wide = float(2.0 * reach.max())
        near = np.abs(self.pos) >= self.half - wide  # (n, 3)
        border = np.flatnonzero(near.any(axis=1))
        ids = [border]
        shifted = [self.pos[border]]
        for sx in (-1, 0, 1):
            for sy in (-1, 0, 1):
                for sz in (-1, 0, 1):
                    shift = np.array([sx, sy, sz], dtype=float)
                    if not shift.any():
                        continue
                    # an image shifted by −L along k exists for spheres near the +L/2 face, and vice versa
                    ok = np.ones(self.n, dtype=bool)
                    for k in range(3):
                        if shift[k] != 0.0:
                            ok &= near[:, k] & (np.sign(self.pos[:, k]) == -shift[k])
                    if ok.any():
                        ids.append(np.flatnonzero(ok))
                        shifted.append(self.pos[ok] + shift * self.box)
        if len(ids) == 1:
            return pairs
        owner = np.concatenate(ids)
        p_all = np.concatenate(shifted)
        r_all = reach[owner]
        extra = find_pairs(p_all - r_all[:, None], p_all + r_all[:, None], method=self.broad_phase)
        a, b = owner[extra[:, 0]], owner[extra[:, 1]]
        cross = (extra[:, 1] >= border.shape[0]) & (a != b)  # at least one member is an image
        cross_pairs = np.stack([np.minimum(a[cross], b[cross]), np.maximum(a[cross], b[cross])], axis=1)
        if cross_pairs.shape[0] == 0:
            return pairs
        return canonical_pairs(np.concatenate([pairs, cross_pairs]), self.n)

    # -- the frame loop ---------------------------------------------------------------------------------------
    def run(self, steps: int) -> None:
        """Advance ``steps`` frames: move, walls, pairs (broad phase + exact test), response."""
        for _ in range(as_count(steps, "steps", 0)):
            _move_and_walls(self.pos, self.vel, self.rad, self.mass, self.half, self.periodic, self.dt, self.acc,
                            self.counters)
            pairs = self.candidate_pairs()
            self.overlapping = int(_respond(pairs, self.pos, self.vel, self.rad, self.mass, self.half,
                                            self.periodic, self.dt, self.acc, self.counters))
            self.time += self.dt

    @property
    def positions(self) -> np.ndarray:
        return self.pos.copy()

    @property
    def velocities(self) -> np.ndarray:
        return self.vel.copy()

    @property
    def masses(self) -> np.ndarray:
        return self.mass.copy()

    def vel_view(self) -> np.ndarray:
        """The velocities (n, 3) in internal order (a view, aligned with ``mass``)."""
        return self.vel

    def kinetic_energy(self) -> float:
        st = np.zeros((self.n, 8))
        st[:, 3:6] = self.vel
        return _kinetic_energy_kernel(st, self.mass)

    def reset_sums(self) -> None:
        self.acc[:] = 0.0
        self.counters[:] = 0

    @property
    def collisions(self) -> int:
        return int(self.counters[0])

    @property
    def wall_hits(self) -> int:
        return int(self.counters[1])

    @property
    def wall_impulse(self) -> float:
        return float(self.acc[0])

    @property
    def virial(self) -> float:
        return float(self.acc[1])
