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
    """Z from the pressure on the walls: ``Z = Σ 2m|v⊥| · L' / (6 t N kT)``.

    ``P = Σ 2m|v⊥| / (6 A' t)`` over the six walls of area A' = L'², and Z = P V'/(N kT).

    Parameters
    ----------
    wall_impulse : float
        ``Σ 2 m |v⊥|`` over the wall hits of the window, >= 0.
    n, temperature, side, t : int, float, float, float
        N, kT, L' and the window length (:ref:`gas-notation`).

    Returns
    -------
    float
        Z measured on the walls.
    """
    impulse = as_nonnegative(wall_impulse, "wall_impulse")
    n = as_count(n, "n", 1)
    kt = as_positive(temperature, "temperature")
    side = as_positive(side, "side")
    t = as_positive(t, "t")
    return impulse * side / (6.0 * t * n * kt)


def compressibility_from_virial(virial, n, temperature, t) -> float:
    """Z from the collision virial: ``Z = 1 + Σ m Δv_i · r_ij / (3 t N kT)``.

    Parameters
    ----------
    virial : float
        Σ m_i Δv_i · r_ij over the collisions of the window, >= 0.
    n, temperature, t : int, float, float
        N, kT and the window length; see :ref:`gas-notation`.

    Returns
    -------
    float
        Z >= 1.
    """
    w = as_nonnegative(virial, "virial")
    n = as_count(n, "n", 1)
    kt = as_positive(temperature, "temperature")
    t = as_positive(t, "t")
    return 1.0 + w / (3.0 * t * n * kt)


def collision_rate(collisions, n, t) -> float:
    """The collision rate Γ = 2·collisions/(N t): collisions per particle per unit time (each involves two).

    Parameters
    ----------
    collisions : int
        Collisions counted in the window, >= 0.
    n, t : int, float
        The number of spheres and the window's length, as in :ref:`gas-notation`.

    Returns
    -------
    float
        Γ >= 0.
    """
    c = as_count(collisions, "collisions", 0)
    n = as_count(n, "n", 1)
    t = as_positive(t, "t")
    return 2.0 * c / (n * t)


def compressibility_from_collision_rate(rate, sigma, mass, temperature) -> float:
    """Z from the collision rate: ``Z = 1 + Γ σ sqrt(π m/kT) / 6`` (the hard-sphere virial written with Γ).

    Parameters
    ----------
    rate : float
        Γ, >= 0 (``collision_rate``).
    sigma : float
        The diameter σ, > 0.
    mass : float
        The sphere mass, > 0.
    temperature : float
        kT (:ref:`gas-notation`).

    Returns
    -------
    float
        Z >= 1.
    """
    rate = as_nonnegative(rate, "rate")
    sigma = as_positive(sigma, "sigma")
    mass = as_positive(mass, "mass")
    kt = as_positive(temperature, "temperature")
    return 1.0 + rate * sigma * math.sqrt(math.pi * mass / kt) / 6.0


def carnahan_starling(eta) -> float:
    """Carnahan–Starling compressibility of the bulk hard-sphere fluid, ``(1 + η + η² − η³) / (1 − η)³``.

    The reference a periodic gas's Z is compared with (a gas between walls adds a wall correction).

    Parameters
    ----------
    eta : float
        The packing fraction η, in [0, 1).

    Returns
    -------
    float
        Z >= 1 (1 at η = 0).

    Raises
    ------
    ValueError
        For η outside [0, 1).

    Examples
    --------
    >>> from engine.gas import carnahan_starling
    >>> carnahan_starling(0.0)
    1.0
    >>> round(carnahan_starling(0.2), 6)
    2.40625
    """
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
    """The kinetic temperature kT = 2K/(3N), with K = Σ m v²/2.

    Parameters
    ----------
    velocities : array_like, shape (n, 3), float64
        The velocities, n >= 1.
    masses : float or array_like, shape (n,), default 1.0
        The masses, > 0.

    Returns
    -------
    float
        kT >= 0.

    Raises
    ------
    ValueError
        For an empty or non-finite ``velocities``, or a mass <= 0 (named with its index).
    """
    v = as_float_array(velocities, "velocities", shape=(None, 3), min_rows=1)
    m = _masses(masses, v.shape[0])
    return float(np.sum(m[:, None] * v * v) / (3.0 * v.shape[0]))


def scaled_speeds(velocities, masses=1.0, temperature=1.0) -> np.ndarray:
    """The speeds in thermal units, ``|v_i| sqrt(m_i/kT)``: Maxwell-distributed with unit scale in equilibrium.

    Whatever the masses, these follow one distribution (scipy.stats.maxwell), so mixtures can be tested together.

    Parameters
    ----------
    velocities : array_like, shape (n, 3), float64
        One row per sphere, n >= 1.
    masses : float or array_like, shape (n,), default 1.0
        One mass for all, or one per sphere (> 0).
    temperature : float, default 1.0
        kT, > 0.

    Returns
    -------
    numpy.ndarray, shape (n,), float64
        The scaled speeds, >= 0.
    """
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
    """Kolmogorov–Smirnov test of scaled speeds against the unit Maxwell distribution (scipy.stats.maxwell).

    Parameters
    ----------
    speeds : array_like, shape (n,), float64
        Scaled speeds (``scaled_speeds``), >= 0, n >= 1.

    Returns
    -------
    statistic : float
        The KS statistic, in [0, 1].
    pvalue : float
        Its p-value; small values reject the Maxwell–Boltzmann distribution.

    Raises
    ------
    ValueError
        For an empty array, NaN or ±inf, or a negative speed (named with its index).
    """
    from scipy import stats

    u = _speeds(speeds)
    res = stats.kstest(u, stats.maxwell.cdf)
    return float(res.statistic), float(res.pvalue)


def speed_moment_ratio(speeds) -> float:
    """The moment ratio ⟨v⁴⟩/⟨v²⟩²: 5/3 for a Maxwell–Boltzmann gas, 1 when every speed is equal.

    The ratio does not depend on the unit of speed: it is computed on u / max(u), so that u⁴ neither underflows
    (speeds near 1e-80) nor overflows (near 1e100).

    Parameters
    ----------
    speeds : array_like, shape (n,), float64
        Speeds, >= 0, not all zero.

    Returns
    -------
    float
        The ratio, in [1, n].

    Raises
    ------
    ValueError
        For all-zero speeds, besides the checks of ``maxwell_boltzmann_test``.
    """
    u = _speeds(speeds)
    top = float(u.max())
    if top == 0.0:
        raise ValueError("speeds are all zero: the ratio is undefined")
    s = u / top
    s2 = float(np.mean(s * s))  # >= 1/n: the largest s is 1
    return float(np.mean(s**4)) / (s2 * s2)


def mean_and_standard_error(values) -> tuple[float, float]:
    """The mean of k block values and its standard error s/sqrt(k) (s the sample standard deviation).

    Parameters
    ----------
    values : array_like, shape (k,), float64
        One value per measurement block, k >= 2, finite.

    Returns
    -------
    mean : float
        The mean of the values.
    standard_error : float
        ``std(values, ddof=1) / sqrt(k)``.
    """
    x = as_float_array(values, "values", shape=(None,), min_rows=2)
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.shape[0]))


def plot_speed_histogram(speeds, path=None, title: str = ""):
    """Histogram of scaled speeds against the Maxwell–Boltzmann density, as a matplotlib Figure.

    The figure is built without pyplot, so the caller's matplotlib backend is left alone (notebooks included).

    Parameters
    ----------
    speeds : array_like, shape (n,), float64
        Scaled speeds (``scaled_speeds``), >= 0.
    path : str or os.PathLike, optional
        Where to write the figure as a PNG; nothing is written when omitted.
    title : str, default ""
        The axes' title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (6 × 4 inches, 60 bins).
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
