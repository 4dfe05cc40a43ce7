"""Falling bodies: RK4 steps per second and impacts located per second, against scipy's solve_ivp with events."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from engine import drop_particle, rk4_step
from engine.dynamics import response as R
from engine.dynamics.events import simulate_fall

G = 9.81


def _params(drag=0.2):
    p = np.zeros(R.N_PARAMS)
    p[R.P_GRAVITY], p[R.P_MASS], p[R.P_LINEAR_DRAG], p[R.P_RESTITUTION] = G, 1.0, drag, 1.0
    p[R.P_REST_SPEED] = G * 1e-3
    return p


@pytest.mark.benchmark(group="dynamics: RK4 steps")
def test_rk4_kernel_steps(benchmark):
    """Free flight high above the ground: 100,000 RK4 steps of the compiled falling-body kernel."""
    params = _params()
    steps = 100_000
    simulate_fall(1e12, 0.0, 1.0, 1e-3, 1e-10, params)  # compile
    samples, _, _ = benchmark(simulate_fall, 1e12, 0.0, steps * 1e-3, 1e-3, 1e-10, params)
    benchmark.extra_info.update(steps=steps, work=steps, unit="RK4 steps")
    assert samples.shape[0] == steps + 1


@pytest.mark.benchmark(group="dynamics: RK4 steps")
def test_rk4_step_public_numpy(benchmark):
    """The public, callable-based rk4_step (any f), 1,000 steps: the price of generality."""
    def f(t, y):
        return np.array([y[1], -G - 0.2 * y[1]])

    def run():
        y = np.array([1e12, 0.0])
        for _ in range(1000):
            y = rk4_step(f, 0.0, y, 1e-3)
        return y

    benchmark(run)
    benchmark.extra_info.update(steps=1000, work=1000, unit="RK4 steps")


@pytest.mark.benchmark(group="dynamics: impacts")
def test_impacts_drop_particle(benchmark):
    """A ball bouncing (e = 1, linear drag 0.05 kg/s) for 200 s, dt = 1 ms: every impact located by bisection."""
    drop_particle(1.0, drag=0.2, restitution=1.0, t_end=1.0)
    res = benchmark(drop_particle, 10.0, drag=0.05, restitution=1.0, t_end=200.0, dt=1e-3)
    n = len(res.impacts)
    benchmark.extra_info.update(impacts=n, work=n, unit="impacts", bisection_iterations=res.bisection_iterations)
    assert n > 50


@pytest.mark.benchmark(group="dynamics: impacts")
def test_impacts_solve_ivp_peer(benchmark):
    """Peer: scipy solve_ivp (RK45, rtol = atol = 1e-10) with a terminal event, restarted at each impact."""
    def rhs(t, Y):
        return [Y[1], -G - 0.05 * Y[1]]

    def hit(t, Y):
        return Y[0]

    hit.terminal, hit.direction = True, -1

    def run(n_impacts=60):
        t0, state = 0.0, [10.0, 0.0]
        for _ in range(n_impacts):
            sol = solve_ivp(rhs, (t0, t0 + 1e3), state, events=hit, rtol=1e-10, atol=1e-10)
            t0, state = sol.t_events[0][0], [0.0, -sol.y_events[0][0][1]]
        return n_impacts

    n = benchmark.pedantic(run, rounds=3, iterations=1)
    benchmark.extra_info.update(impacts=n, work=n, unit="impacts")
