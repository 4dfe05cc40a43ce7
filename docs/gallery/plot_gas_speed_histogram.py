"""
The ideal gas: elastic spheres in a box and their speed histogram
=================================================================

The chapter's closing example: hard spheres in the box L = 10, specular walls, elastic collisions
(equal masses exchange the normal components of their velocities). The event-driven method jumps from one
collision to the next, so nothing tunnels and the energy is conserved to round-off. After equilibration the
speeds, scaled by sqrt(m / kT), follow the Maxwell–Boltzmann density whatever the start was (here every sphere
starts with the same speed in a random direction).
"""
import engine
from engine.gas import plot_speed_histogram, radius_for_packing

n = 500
radius = radius_for_packing(n, 0.2)
res = engine.simulate_gas(n, radius=radius, method="events", t_equilibrate=2.0, t_measure=4.0, seed=3)
fig = plot_speed_histogram(
    res.scaled_speeds,
    title=f"{n} spheres, packing 0.2: Z = {res.z_virial:.3f} ± {res.z_virial_err:.3f}\n"
    f"relative energy drift {res.energy_drift:.1e}",
)
fig
