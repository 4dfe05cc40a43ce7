"""Where the gas's lattice start puts its spheres (``place_spheres(..., initial="lattice")``, engine/gas/initial.py;
the sites are in its docstring): k³ cells of side a, k the smallest with 4k³ >= n, FCC sites lo + a (i + b + s).
With walls the lattice is shifted a/4 inside the reachable cube (s = ¼); periodic, its origin is the box corner
(s = 0). Every sphere must sit on one of those sites, the full lattice (n = 4k³) on all of them.
"""
from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.gas.initial import place_spheres, radius_for_packing

L = 10.0


def documented_sites(k, a, lo, s):
    """The FCC sites lo + a (i + b + s), (4k³, 3)."""
    basis = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]])
    cells = np.array([(x, y, z) for x in range(k) for y in range(k) for z in range(k)], dtype=float)
    return ((cells[:, None, :] + basis[None] + s) * a + lo).reshape(-1, 3)


@example(k=2, fill=1.0, eta=0.3, boundary="periodic", seed=0)
@example(k=2, fill=1.0, eta=0.3, boundary="walls", seed=0)
@given(st.integers(1, 4), st.floats(0.0, 1.0), st.floats(0.05, 0.4), st.sampled_from(["walls", "periodic"]),
       st.integers(0, 2**16))
def test_lattice_start_puts_every_sphere_on_a_documented_site(k, fill, eta, boundary, seed):
    n = max(2, math.ceil(0.61 * 4 * k**3 + fill * (4 * k**3 - math.ceil(0.61 * 4 * k**3))))
    r = radius_for_packing(n, eta, L, boundary)
    if boundary == "periodic" and 6 * r > L:
        return
    p = place_spheres(n, np.full(n, r), L, boundary, np.random.default_rng(seed), "lattice")
    k = min(j for j in range(1, 10) if 4 * j**3 >= n)  # the smallest lattice with >= n sites (k, by the choice of n)
    if boundary == "walls":
        a, lo, s = (L - 2.0 * r) / k, -L / 2.0 + r, 0.25
    else:
        a, lo, s = L / k, -L / 2.0, 0.0
        assert (p >= -L / 2.0).all() and (p < L / 2.0).all()
    sites = documented_sites(k, a, lo, s)
    # each sphere on a site (to round-off), and no two on the same one
    d = np.abs(p[:, None, :] - sites[None, :, :]).max(axis=2)
    nearest = d.argmin(axis=1)
    assert (d[np.arange(n), nearest] <= 1e-12 * L).all(), d[np.arange(n), nearest].max()
    assert np.unique(nearest).size == n
    if n == 4 * k**3:
        assert set(nearest.tolist()) == set(range(n))
