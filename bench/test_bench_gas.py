"""W3, the confined gas: event-driven collisions per second at N = 32,000 and η = 0.1, 0.3
(target >= 150,000 per second on one core), the same periodic against Smallenburg's EDMD "Cell" C code when
``EDMD_C_SOURCE`` names a local copy of it (bench/edmd_peer.py; otherwise the peer is skipped and said so), and the
stepped method's frames per second at N = 2,620 for every broad phase (the same scene, so the entries of a group
are comparable as ratios).

``--quick`` keeps N = 4,000 for the event-driven runs and fewer frames.
"""
from __future__ import annotations

import numpy as np
import pytest

from bench.edmd_peer import CODES, ENV, c_code_rate, peer_source
from engine.broadphase import BROAD_PHASES
from engine.gas import EventDrivenGas, SteppedGas, radius_for_packing
from engine.gas.events import EVENT_SEARCHES
from engine.gas.initial import draw_velocities, place_spheres

L = 10.0


def _scene(n, eta, seed=0, boundary="walls"):
    r = np.full(n, radius_for_packing(n, eta, L, boundary))
    m = np.ones(n)
    rng = np.random.default_rng(seed)
    p = place_spheres(n, r, L, boundary, rng)
    v = draw_velocities(m, 1.0, boundary, rng)
    return p, v, r, m


@pytest.mark.parametrize("eta", [0.1, 0.3])
@pytest.mark.benchmark(group="gas W3: event-driven collisions")
def test_events_collisions_per_second(benchmark, quick, eta):
    """N = 32,000 spheres (quick: 4,000), walls, after t = 1 of equilibration (the η = 0.3 lattice start has
    melted); each round runs 0.2 time units further (≈ 30,000 collisions at η = 0.1, ≈ 110,000 at η = 0.3)."""
    n = 4000 if quick else 32000
    p, v, r, m = _scene(n, eta)
    gas = EventDrivenGas(p, v, r, m, L, periodic=False)
    gas.run(1.0)  # compile + melt the lattice start
    state = {"t": gas.time, "collisions": 0}

    def advance():
        gas.reset_sums()
        state["t"] += 0.2
        gas.run(state["t"])
        state["collisions"] += gas.collisions
        return gas.collisions

    benchmark.pedantic(advance, rounds=3 if quick else 5, iterations=1, warmup_rounds=1)
    per_round = state["collisions"] / ((3 if quick else 5) + 1)
    rate = per_round / benchmark.stats.stats.mean
    benchmark.extra_info.update(n=n, eta=eta, collisions_per_round=per_round, work=per_round, unit="collisions",
                                collisions_per_second=rate, target_per_second=150_000)
    assert per_round > 0


@pytest.mark.parametrize("broad_phase", BROAD_PHASES)
@pytest.mark.benchmark(group="gas W3: stepped frames, N = 2,620")
def test_stepped_frames_per_second(benchmark, quick, broad_phase):
    """N = 2,620 spheres at η = 0.2, dt = 2e-3, walls: frames (move, walls, broad phase, response) per second."""
    n = 2620
    p, v, r, m = _scene(n, 0.2)
    gas = SteppedGas(p, v, r, m, L, periodic=False, dt=2e-3, broad_phase=broad_phase)
    gas.run(2)  # compile, build the incremental SAP
    frames = 5 if (quick or broad_phase == "brute") else 20

    benchmark.pedantic(gas.run, args=(frames,), rounds=3, iterations=1, warmup_rounds=0)
    benchmark.extra_info.update(n=n, frames=frames, work=frames, unit="frames",
                                frames_per_second=frames / benchmark.stats.stats.mean)


@pytest.mark.benchmark(group="gas W3: event-driven collisions")
def test_events_stepped_peer_collisions_per_second(benchmark, quick):
    """Peer in the same group: the stepped method's collisions per second on N = 4,000 at η = 0.1 (dt = 2e-3,
    incremental SAP), to compare both methods by the same unit."""
    p, v, r, m = _scene(4000, 0.1)
    gas = SteppedGas(p, v, r, m, L, periodic=False, dt=2e-3, broad_phase="sap")
    gas.run(2)
    state = {"collisions": 0, "rounds": 0}

    def advance():
        gas.reset_sums()
        gas.run(10)
        state["collisions"] += gas.collisions
        state["rounds"] += 1

    benchmark.pedantic(advance, rounds=3, iterations=1, warmup_rounds=0)
    per_round = state["collisions"] / state["rounds"]
    benchmark.extra_info.update(n=4000, eta=0.1, work=per_round, unit="collisions",
                                collisions_per_second=per_round / benchmark.stats.stats.mean)


@pytest.mark.parametrize("search", EVENT_SEARCHES)
@pytest.mark.parametrize("eta", [0.1, 0.3])
@pytest.mark.benchmark(group="gas W3: event-driven, periodic, against the EDMD C code")
def test_events_periodic_against_c_code(benchmark, quick, eta, search):
    """N = 32,000 (quick: 4,000) periodic, each partner search, rounds of 0.2 time units after t = 1; then, when
    EDMD_C_SOURCE is set, the three EDMD codes (Cell, Multi, Single) on the same N and η (FCC start, gcc -O3
    -march=native), collisions per CPU second as the difference of a short and a long run (bench/edmd_peer.py).
    Both rates are per second of processor time with ``--benchmark-timer=time.process_time``, the engine's from
    its fastest round; the ratio is against the fastest C code. ``-k cells`` keeps one search."""
    n = 4000 if quick else 32000
    p, v, r, m = _scene(n, eta, boundary="periodic")
    gas = EventDrivenGas(p, v, r, m, L, periodic=True, search=search)
    gas.run(1.0)
    state = {"t": gas.time, "best": 0.0, "collisions": 0, "events": 0}

    def advance():
        gas.reset_sums()
        state["t"] += 0.2
        gas.run(state["t"])
        state["collisions"] += gas.collisions
        state["events"] += gas.events
        return gas.collisions

    benchmark.pedantic(advance, rounds=3 if quick else 5, iterations=1, warmup_rounds=1)
    per_round = state["collisions"] / ((3 if quick else 5) + 1)
    rate = per_round / benchmark.stats.stats.min
    print(f"\nengine search={search} eta={eta}: {rate:,.0f} collisions/s, "
          f"{state['events'] / state['collisions']:.2f} events per collision")
    peers = {}
    for code in CODES:  # the C codes after the engine's rounds, alternating with them across the two η
        folder = peer_source(code)
        peers[code] = c_code_rate(folder, n, eta, code=code) if folder is not None else None
    measured = {code: c_rate for code, c_rate in peers.items() if c_rate}
    fastest = max(measured, key=measured.__getitem__) if measured else None
    benchmark.extra_info.update(n=n, eta=eta, collisions_per_round=per_round, work=per_round, unit="collisions",
                                search=search, events_per_collision=state["events"] / state["collisions"],
                                collisions_per_second=rate, **{f"c_code_{c}_collisions_per_second": peers[c]
                                                               for c in CODES},
                                fastest_c_code=fastest, ratio_to_fastest_c_code=rate / measured[fastest]
                                if fastest else None,
                                peer="EDMD Cell, Multi, Single (gcc -O3 -march=native)" if fastest
                                else f"skipped: {ENV} not set")
    print(f"C codes: {peers}; engine / fastest: {rate / measured[fastest]:.2f}x" if fastest else "C codes skipped")
    assert per_round > 0
