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
   (see reports/gas.md, "The stepped method's bias against Δt").

Pairs are canonical (sorted), so the result does not depend on the broad phase: same seed, same final state.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine._validate import as_choice, as_count, as_positive
from engine.broadphase import IncrementalSAP, find_pairs
from engine.broadphase.pairs import canonical_pairs
from engine.gas.elastic import pair_impulse
from engine.gas.initial import check_gas_state
from engine.gas.kernels import state_kernel
from engine.gas.observables import kinetic_energy_kernel
from engine.gas.periodic import minimum_image, wrap_coordinate
from engine.gas.tally import COLLISIONS, VIRIAL, WALL_HITS, WALL_IMPULSE, GasTally, new_counters, new_sums

__all__ = ["SteppedGas", "FrameState"]

#: passes of the overlap-removal loop before giving up for this frame (the next frame continues)
_MAX_PASSES = 64


class FrameState(NamedTuple):
    """What the frame kernels read and write: pos, vel (n, 3) float64; rad, mass (n,) float64; counters, sums
    (engine/gas/tally.py); half = L/2 and box = L (float), periodic (bool), dt (float)."""

    pos: np.ndarray
    vel: np.ndarray
    rad: np.ndarray
    mass: np.ndarray
    counters: np.ndarray
    sums: np.ndarray
    half: float
    box: float
    periodic: bool
    dt: float


@state_kernel
def _into_box(x, half, r, periodic):
    """Coordinate x of a sphere of radius r clamped into the reachable [−L/2 + r, L/2 − r] (periodic: wrapped
    into [−L/2, L/2))."""
    if periodic:
        return wrap_coordinate(x, half)
    lo = -half + r
    hi = half - r
    if x < lo:
        return lo
    if x > hi:
        return hi
    return x


@state_kernel
def _move_and_walls(s):
    """Steps 1 and 2 of the frame: p ← p + v Δt, then the walls (chapter 2.B: a sphere past a wall and moving
    outwards gets v_k reversed and travels the distance past the wall back) or the periodic wrap."""
    pos, vel, rad, mass, sums, counters = s.pos, s.vel, s.rad, s.mass, s.sums, s.counters
    dt, half, periodic = s.dt, s.half, s.periodic
    for i in range(pos.shape[0]):
        lo = -half + rad[i]
        hi = half - rad[i]
        for k in range(3):
            p = pos[i, k] + vel[i, k] * dt
            v = vel[i, k]
            if not periodic and (p <= lo and v < 0.0 or p >= hi and v > 0.0):
                sums[WALL_IMPULSE] += 2.0 * mass[i] * abs(v)
                counters[WALL_HITS] += 1
                vel[i, k] = -v
                p = lo + (lo - p) if v < 0.0 else hi - (p - hi)
            pos[i, k] = _into_box(p, half, rad[i], periodic)


@state_kernel
def _separation(s, i, j):
    """p_i − p_j (its nearest periodic image when periodic)."""
    pos = s.pos
    rx = pos[i, 0] - pos[j, 0]
    ry = pos[i, 1] - pos[j, 1]
    rz = pos[i, 2] - pos[j, 2]
    if s.periodic:
        return minimum_image(rx, ry, rz, s.box)
    return rx, ry, rz


@state_kernel
def _keep_inside(s, q):
    """Sphere q's centre into the reachable cube (periodic: wrapped into [−L/2, L/2)³)."""
    pos, half, r, periodic = s.pos, s.half, s.rad[q], s.periodic
    for k in range(3):
        pos[q, k] = _into_box(pos[q, k], half, r, periodic)


@state_kernel
def _answer_contacts(pairs, s):
    """The elastic response of every approaching contact among the candidate pairs (canonical order), at its
    contact instant: back to contact, the chapter's formulas (1.B / 2.C), forward again with the new velocities."""
    pos, vel, rad, mass, dt, sums, counters = s.pos, s.vel, s.rad, s.mass, s.dt, s.sums, s.counters
    for p in range(pairs.shape[0]):
        i = pairs[p, 0]
        j = pairs[p, 1]
        rx, ry, rz = _separation(s, i, j)
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
        old_i = (vel[i, 0], vel[i, 1], vel[i, 2])
        old_j = (vel[j, 0], vel[j, 1], vel[j, 2])
        w = pair_impulse(vel, mass[i], mass[j], i, j, rx - vx * tau, ry - vy * tau, rz - vz * tau, 0)
        if w > 0.0:
            sums[VIRIAL] += w
            counters[COLLISIONS] += 1
            for k in range(3):  # forward again from the contact with the new velocities
                pos[i, k] += (vel[i, k] - old_i[k]) * tau
                pos[j, k] += (vel[j, k] - old_j[k]) * tau


@state_kernel
def _remove_overlaps(pairs, s):
    """Push overlapping candidate pairs apart along their line of centres, mass-weighted (momentum kept), pass
    after pass until none overlaps (at most _MAX_PASSES). Returns the number of pairs still overlapping."""
    pos, rad, mass = s.pos, s.rad, s.mass
    remaining = 0
    for _ in range(_MAX_PASSES):
        remaining = 0
        for p in range(pairs.shape[0]):
            i = pairs[p, 0]
            j = pairs[p, 1]
            rx, ry, rz = _separation(s, i, j)
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
            _keep_inside(s, i)
            _keep_inside(s, j)
        if remaining == 0:
            break
    return remaining


@state_kernel
def _respond(pairs, s):
    """Step 4 of the frame on the candidate pairs: the elastic response of approaching contacts, every centre
    back into the reachable box (the moves to contact and back may cross a wall), then overlap removal.
    Returns the number of pairs still overlapping."""
    _answer_contacts(pairs, s)
    for q in range(s.pos.shape[0]):
        _keep_inside(s, q)
    return _remove_overlaps(pairs, s)


class SteppedGas(GasTally):
    """The chapter's fixed-step gas: ``run(steps)`` advances frames of ``dt``.

    A frame: move every sphere by v Δt; reflect off the walls (or wrap, periodic); find candidate pairs with the
    broad phase on boxes widened by the reach of a frame; test them exactly and answer each overlapping, approaching
    pair with the elastic response (``collide_elastic``'s formula), pushing the spheres apart. Overlaps at the start
    are allowed: the loop resolves them.

    Parameters
    ----------
    positions, velocities : array_like, shape (n, 3), float64
        The start state; centres inside the box (walls) or wrapped (periodic).
    radii, masses : float or array_like, shape (n,)
        Positive scalars or one per sphere.
    box : float
        The cube's side L, > 0.
    periodic : bool
        Periodic images instead of walls.
    dt : float
        The frame step Δt, > 0.
    broad_phase : str, default "sap"
        A name of ``BROAD_PHASES``; "sap" keeps an ``IncrementalSAP`` (sorted order kept between frames).

    Attributes
    ----------
    n : int
        Sphere count.
    time : float
        Frames run times ``dt``.
    overlapping : int
        Pairs still overlapping after the last frame's response.
    collisions, wall_hits : int
        Collisions answered and wall hits since ``reset_sums()``.
    wall_impulse, virial : float
        ``Σ 2 m |v⊥|`` (walls) and Σ m_i Δv_i · r_ij at contact, since ``reset_sums()``.

    Raises
    ------
    ValueError, TypeError
        From the checks of the state, ``dt`` or ``broad_phase`` (each named).
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
        self.sums = new_sums()
        self.counters = new_counters()
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
        """Advance ``steps`` frames: move, walls, pairs (broad phase and exact test), response.

        Parameters
        ----------
        steps : int
            Frames to run, >= 0.

        Returns
        -------
        None
        """
        steps = as_count(steps, "steps", 0)
        s = FrameState(self.pos, self.vel, self.rad, self.mass, self.counters, self.sums, self.half,
                       2.0 * self.half, self.periodic, self.dt)
        for _ in range(steps):
            _move_and_walls(s)
            pairs = self.candidate_pairs()
            self.overlapping = int(_respond(pairs, s))
            self.time += self.dt

    @property
    def positions(self) -> np.ndarray:
        """Centres (n, 3) after the last frame (a copy)."""
        return self.pos.copy()

    @property
    def velocities(self) -> np.ndarray:
        """Velocities (n, 3) after the last frame (a copy)."""
        return self.vel.copy()

    @property
    def masses(self) -> np.ndarray:
        """Masses (n,) (a copy)."""
        return self.mass.copy()

    def vel_view(self) -> np.ndarray:
        """The velocities (n, 3) in internal order (a view, aligned with ``mass``)."""
        return self.vel

    def kinetic_energy(self) -> float:
        """K = Σ m v²/2 (compensated summation)."""
        return float(kinetic_energy_kernel(self.vel, self.mass))
