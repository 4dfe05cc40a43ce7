"""Observables of the confined gas (kinetic theory of hard spheres), from the sums the simulations accumulate.

Notation: σ = 2r, kT = 2K/(3N); with walls at ±L/2 the centres live in a cube of side L' = L − 2r, V' = L'³,
A' = L'²; η = Nπσ³/(6V').
- wall pressure:   P = Σ 2m|v⊥| / (6 A' t)                      → Z_wall = P V'/(N kT)
- virial pressure: P V' = N kT + (1/(3t)) Σ_collisions m Δv_i · r_ij → Z_virial
- collision rate:  Γ = 2·collisions/(N t); in equilibrium Z − 1 = Γ σ sqrt(π m/kT)/6
- bulk equation of state (periodic boxes only): Carnahan–Starling Z = (1 + η + η² − η³)/(1 − η)³
- speeds: Maxwell–Boltzmann, |v| sqrt(m/kT) ~ scipy.stats.maxwell (Kolmogorov–Smirnov), ⟨v⁴⟩/⟨v²⟩² = 5/3.
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine._validate import as_count, as_float, as_float_array, as_fraction, as_nonnegative, as_positive

__all__ = [
    "compressibility_from_walls",
    "compressibility_from_virial",
    "collision_rate",
    "compressibility_from_collision_rate",
    "carnahan_starling",
    "kinetic_temperature",
    "scaled_speeds",
    "maxwell_boltzmann_test",
    "speed_moment_ratio",
    "mean_and_standard_error",
    "plot_speed_histogram",
    "kinetic_energy_kernel",
]


def compressibility_from_walls(wall_impulse, n, temperature, side, t) -> float:
    """Z = P V'/(N kT) with P = Σ 2m|v⊥|/(6 A' t), i.e. Z = Σ 2m|v⊥| · L'/(6 t N kT).

    wall_impulse: Σ 2m|v⊥| over the wall hits of the window; side: L' (reachable side); t: window length.
    """
    impulse = as_nonnegative(wall_impulse, "wall_impulse")
    n = as_count(n, "n", 1)
    kt = as_positive(temperature, "temperature")
    side = as_positive(side, "side")
    t = as_positive(t, "t")
    return impulse * side / (6.0 * t * n * kt)


def compressibility_from_virial(virial, n, temperature, t) -> float:
    """Z = 1 + Σ m Δv_i · r_ij / (3 t N kT) (the collision virial over a window of length t)."""
    w = as_nonnegative(virial, "virial")
    n = as_count(n, "n", 1)
    kt = as_positive(temperature, "temperature")
    t = as_positive(t, "t")
    return 1.0 + w / (3.0 * t * n * kt)


def collision_rate(collisions, n, t) -> float:
    """Γ = 2·collisions/(N t): collisions per particle per unit time."""
    c = as_count(collisions, "collisions", 0)
    n = as_count(n, "n", 1)
    t = as_positive(t, "t")
    return 2.0 * c / (n * t)


def compressibility_from_collision_rate(rate, sigma, mass, temperature) -> float:
    """Z = 1 + Γ σ sqrt(π m/kT)/6 (hard spheres: the virial written with the collision rate)."""
    rate = as_nonnegative(rate, "rate")
    sigma = as_positive(sigma, "sigma")
    mass = as_positive(mass, "mass")
    kt = as_positive(temperature, "temperature")
    return 1.0 + rate * sigma * math.sqrt(math.pi * mass / kt) / 6.0


def carnahan_starling(eta) -> float:
    """Carnahan–Starling compressibility of the bulk hard-sphere fluid, (1 + η + η² − η³)/(1 − η)³, η in [0, 1)."""
    eta = as_fraction(eta, "eta")
    if eta >= 1.0:
        raise ValueError("eta must be < 1")
    return (1.0 + eta + eta * eta - eta**3) / (1.0 - eta) ** 3


@njit
def kinetic_energy_kernel(velocities, masses):
    """Kernel shared by both gas methods: K = Σ m (vx² + vy² + vz²)/2 over velocities (n, 3) float64 (any
    strides) and masses (n,) float64, with Kahan–Neumaier compensation (so the energy drift a run reports is the
    dynamics', not the summation's)."""
    total = 0.0
    comp = 0.0
    for i in range(velocities.shape[0]):
        e = 0.5 * masses[i] * (velocities[i, 0] * velocities[i, 0] + velocities[i, 1] * velocities[i, 1]
                               + velocities[i, 2] * velocities[i, 2])
        s = total + e
        if abs(total) >= abs(e):
            comp += (total - s) + e
        else:
            comp += (e - s) + total
        total = s
    return total + comp


def _masses(masses, n):
    if np.ndim(masses) == 0:
        m = np.full(n, as_float(masses, "masses"))
    else:
        m = as_float_array(masses, "masses", shape=(n,))
    bad = np.flatnonzero(m <= 0.0)
    if bad.size:
        raise ValueError(f"masses must be > 0: masses[{bad[0]}] = {float(m[bad[0]])!r}")
    return m


def kinetic_temperature(velocities, masses=1.0) -> float:
    """kT = 2K/(3N) with K = Σ m v²/2; velocities (n, 3), masses a scalar or (n,)."""
    v = as_float_array(velocities, "velocities", shape=(None, 3), min_rows=1)
    m = _masses(masses, v.shape[0])
    return float(np.sum(m[:, None] * v * v) / (3.0 * v.shape[0]))


def scaled_speeds(velocities, masses=1.0, temperature=1.0) -> np.ndarray:
    """``|v_i| sqrt(m_i/kT)``, (n,): Maxwell-distributed with unit scale in equilibrium, whatever the masses."""
    v = as_float_array(velocities, "velocities", shape=(None, 3), min_rows=1)
    m = _masses(masses, v.shape[0])
    kt = as_positive(temperature, "temperature")
    return np.sqrt((v * v).sum(axis=1) * m / kt)


def _speeds(speeds) -> np.ndarray:
    u = as_float_array(speeds, "speeds", shape=(None,), min_rows=1)
    bad = np.flatnonzero(u < 0.0)
    if bad.size:
        raise ValueError(f"speeds must be >= 0: speeds[{bad[0]}] = {float(u[bad[0]])!r}")
    return u


def maxwell_boltzmann_test(speeds) -> tuple[float, float]:
    """Kolmogorov–Smirnov test of scaled speeds (n,) (see ``scaled_speeds``) against scipy.stats.maxwell
    (unit scale). Returns (statistic, p-value)."""
    from scipy import stats

    u = _speeds(speeds)
    res = stats.kstest(u, stats.maxwell.cdf)
    return float(res.statistic), float(res.pvalue)


def speed_moment_ratio(speeds) -> float:
    """⟨v⁴⟩/⟨v²⟩², 5/3 for a Maxwell–Boltzmann gas (1 when every speed is equal).

    The ratio does not depend on the unit of speed: it is computed on u / max(u), so that u⁴ neither underflows
    (speeds near 1e-80 gave ⟨v²⟩² = 0 and a ZeroDivisionError) nor overflows (speeds near 1e100 gave inf/inf).
    """
    u = _speeds(speeds)
    top = float(u.max())
    if top == 0.0:
        raise ValueError("speeds are all zero: the ratio is undefined")
    s = u / top
    s2 = float(np.mean(s * s))  # >= 1/n: the largest s is 1
    return float(np.mean(s**4)) / (s2 * s2)


def mean_and_standard_error(values) -> tuple[float, float]:
    """Mean of block values (k,) and its standard error s/sqrt(k) (k >= 2)."""
    x = as_float_array(values, "values", shape=(None,), min_rows=2)
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.shape[0]))


def plot_speed_histogram(speeds, path=None, title: str = ""):
    """Histogram of scaled speeds (n,) against the Maxwell–Boltzmann density; returns the matplotlib Figure.

    The figure is built without pyplot (the caller's matplotlib backend is left alone) and written as a PNG at
    ``path`` when one is given.
    """
    from matplotlib.figure import Figure
    from scipy import stats

    u = _speeds(speeds)
    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    ax.hist(u, bins=60, density=True, alpha=0.6, label=f"simulation ({u.shape[0]} speeds)")
    x = np.linspace(0.0, max(4.5, float(u.max())), 400)
    ax.plot(x, stats.maxwell.pdf(x), "k-", lw=2, label="Maxwell–Boltzmann")
    ax.set_xlabel("|v| sqrt(m / kT)")
    ax.set_ylabel("density")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig
