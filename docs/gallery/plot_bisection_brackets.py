"""
The falling particle: the collision time by bisection (Algorithme 3)
====================================================================

An RK4 step from t0 to t0 + Δt ends below the ground: the step is thrown away, and the collision time tc is
located by bisection on the re-integration from t0 (trial steps Δt/2, then Δt/4 or 3Δt/4, ...), the bracket
halving until it is narrower than the tolerance. The brackets after each halving are drawn below; ``bisect``
with a tolerance of (b − a)/2^k returns the bracket after k halvings.
"""
import matplotlib.pyplot as plt
import numpy as np

import engine

g, dt, height = 9.81, 0.25, 2.0


def fall(t, y):  # state (height, velocity) of a particle under gravity
    return np.array([y[1], -g])


t0, state = 0.0, np.array([height, 0.0])
while True:  # RK4 steps until one ends below the ground
    nxt = engine.rk4_step(fall, t0, state, dt)
    if nxt[0] < 0.0:
        break
    t0, state = t0 + dt, nxt


def height_after(tau):  # re-integrate from t0 by one RK4 step of length tau
    return engine.rk4_step(fall, t0, state, tau)[0]


brackets = []
for k in range(1, 11):
    res = engine.bisect(height_after, 0.0, dt, dt / 2**k, full_output=True)[1]
    brackets.append((t0 + res.a, t0 + res.b))

fig, (ax, zoom) = plt.subplots(2, 1, figsize=(7, 6))
ts = np.linspace(0.0, t0 + dt, 200)
ax.plot(ts, height - 0.5 * g * ts**2, color="0.6", label="exact y(t)")
ax.axhline(0.0, color="k", lw=0.8)
ax.axvspan(t0, t0 + dt, color="C1", alpha=0.15, label="the step that crosses the ground")
ax.set_ylabel("y (m)")
ax.legend()
for k, (a, b) in enumerate(brackets):
    zoom.plot([a, b], [k, k], lw=4, color="C0", solid_capstyle="butt")
zoom.axvline(np.sqrt(2 * height / g), color="crimson", lw=0.8, label="exact tc = sqrt(2h/g)")
zoom.set_xlabel("t (s)")
zoom.set_ylabel("halvings")
zoom.legend()
fig.tight_layout()
print(f"bracket after 10 halvings: [{brackets[-1][0]:.6f}, {brackets[-1][1]:.6f}] s")
