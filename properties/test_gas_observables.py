"""The gas observables (engine/gas/observables.py) against independent oracles: the textbook formulas written
out here, the Carnahan–Starling virial series, the Kolmogorov–Smirnov statistic computed from the empirical CDF,
``statistics.stdev``; and the contract of every function (the argument named in each error, inputs kept).

Each property runs in milliseconds (numpy only), so that it also runs under mutation testing.
"""
from __future__ import annotations

import math
import statistics
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from scipy import stats

from engine.gas import (
    carnahan_starling,
    collision_rate,
    compressibility_from_collision_rate,
    compressibility_from_virial,
    compressibility_from_walls,
    kinetic_temperature,
    maxwell_boltzmann_test,
    mean_and_standard_error,
    plot_speed_histogram,
    scaled_speeds,
    speed_moment_ratio,
)

finite = dict(allow_nan=False, allow_infinity=False, allow_subnormal=False)
positive = st.floats(1e-3, 1e3, **finite)
counts = st.integers(1, 10**6)
# velocity components 0 or of magnitude >= 1e-100: squares that do not underflow (a gas, not the float format's corners)
component = st.floats(-1e3, 1e3, **finite).filter(lambda x: x == 0.0 or abs(x) >= 1e-100)


@given(st.floats(0.0, 1e6, **finite), counts, positive, positive, positive)
def test_wall_compressibility_is_pressure_times_volume_over_n_kt(impulse, n, kt, side, t):
    """P = Σ 2m|v⊥| / (6 A' t) over the six walls of area A' = L'², and Z = P V'/(N kT) with V' = L'³."""
    pressure = impulse / (6.0 * side * side * t)
    z = pressure * side**3 / (n * kt)
    assert compressibility_from_walls(impulse, n, kt, side, t) == pytest.approx(z, rel=1e-12, abs=1e-300)


@given(st.floats(0.0, 1e6, **finite), counts, positive, positive)
def test_virial_compressibility_is_one_plus_the_collision_virial(virial, n, kt, t):
    """P V' = N kT + (1/(3t)) Σ m Δv·r: an ideal gas (no collision) gives exactly Z = 1."""
    z = (n * kt + virial / (3.0 * t)) / (n * kt)
    assert compressibility_from_virial(virial, n, kt, t) == pytest.approx(z, rel=1e-12)
    assert compressibility_from_virial(0.0, n, kt, t) == 1.0


@given(st.integers(0, 10**6), counts, positive)
def test_collision_rate_counts_two_spheres_per_collision(collisions, n, t):
    assert collision_rate(collisions, n, t) == pytest.approx(2.0 * collisions / n / t, rel=1e-12)


@given(st.floats(0.0, 1e3, **finite), positive, positive, positive)
def test_compressibility_from_collision_rate_is_the_hard_sphere_virial(rate, sigma, mass, kt):
    """Z − 1 = Γ σ ⟨|v_rel|⟩ ... written Γ σ sqrt(π m/kT)/6; Z = 1 when nothing collides."""
    z = 1.0 + rate * sigma * math.sqrt(math.pi) * math.sqrt(mass) / math.sqrt(kt) / 6.0
    assert compressibility_from_collision_rate(rate, sigma, mass, kt) == pytest.approx(z, rel=1e-12)
    assert compressibility_from_collision_rate(0.0, sigma, mass, kt) == 1.0


@given(st.floats(0.0, 0.6, **finite))
def test_carnahan_starling_sums_its_virial_series(eta):
    """Z_CS = 1 + Σ_{k>=1} (k² + 3k) η^k (the Carnahan–Starling virial coefficients 4, 10, 18, 28, ...)."""
    series = 1.0 + sum((k * k + 3 * k) * eta**k for k in range(1, 400))
    assert carnahan_starling(eta) == pytest.approx(series, rel=1e-12)


def test_carnahan_starling_domain():
    assert carnahan_starling(0.0) == 1.0
    for bad in (1.0, -0.1, 1.5, math.nan):
        with pytest.raises(ValueError, match="eta"):
            carnahan_starling(bad)


def _velocity_sets():
    return st.integers(1, 30).flatmap(lambda n: st.tuples(
        arrays(np.float64, (n, 3), elements=component),
        st.one_of(positive, arrays(np.float64, (n,), elements=positive))))


@given(_velocity_sets())
def test_kinetic_temperature_is_two_thirds_of_the_mean_kinetic_energy(case):
    v, m = case
    v0 = v.copy()
    m_arr = np.broadcast_to(m, (v.shape[0],))
    kinetic = sum(0.5 * m_arr[i] * sum(v[i, k] ** 2 for k in range(3)) for i in range(v.shape[0]))
    assert kinetic_temperature(v, m) == pytest.approx(2.0 * kinetic / (3.0 * v.shape[0]), rel=1e-12, abs=1e-300)
    np.testing.assert_array_equal(v, v0)


@given(_velocity_sets(), positive)
def test_scaled_speeds_are_speeds_in_units_of_the_thermal_speed(case, kt):
    v, m = case
    m_arr = np.broadcast_to(m, (v.shape[0],))
    u = scaled_speeds(v, m, kt)
    assert u.shape == (v.shape[0],)
    for i in range(v.shape[0]):
        assert u[i] == pytest.approx(math.hypot(*v[i]) / math.sqrt(kt / m_arr[i]), rel=1e-12, abs=1e-300)


def test_temperature_and_speeds_use_each_sphere_s_own_mass():
    v = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    m = np.array([4.0, 1.0])
    assert kinetic_temperature(v, m) == pytest.approx((4.0 + 4.0) / 6.0)
    np.testing.assert_allclose(scaled_speeds(v, m, 2.0), [math.sqrt(2.0), math.sqrt(2.0)], rtol=1e-15)


@given(st.integers(20, 400), st.integers(0, 2**32 - 1))
def test_maxwell_test_statistic_is_the_largest_gap_between_the_cdfs(n, seed):
    """D = sup |F_n − F| with F the unit-scale Maxwell CDF, written out: F(u) = erf(u/√2) − sqrt(2/π) u e^(−u²/2)."""
    u = np.sort(np.abs(np.random.default_rng(seed).normal(size=(n, 3))).sum(axis=1) / 1.5)
    cdf = np.array([math.erf(x / math.sqrt(2.0)) - math.sqrt(2.0 / math.pi) * x * math.exp(-x * x / 2.0) for x in u])
    d = max(float((np.arange(1, n + 1) / n - cdf).max()), float((cdf - np.arange(n) / n).max()))
    statistic, pvalue = maxwell_boltzmann_test(u[::-1].copy())
    assert statistic == pytest.approx(d, rel=1e-9)
    assert 0.0 <= pvalue <= 1.0


def test_maxwell_test_accepts_maxwell_speeds_and_rejects_equal_speeds():
    rng = np.random.default_rng(7)
    maxwell = np.linalg.norm(rng.normal(size=(2000, 3)), axis=1)  # |N(0, 1)³| is Maxwell with unit scale
    _, p_ok = maxwell_boltzmann_test(maxwell)
    _, p_equal = maxwell_boltzmann_test(np.full(2000, math.sqrt(3.0)))
    _, p_hot = maxwell_boltzmann_test(2.0 * maxwell)
    assert p_ok > 1e-3
    assert p_equal < 1e-10 and p_hot < 1e-10
    assert stats.kstest(maxwell, stats.maxwell.cdf).pvalue == pytest.approx(p_ok, rel=1e-12)


@given(arrays(np.float64, st.integers(1, 50), elements=st.floats(0.0, 1e3, **finite)).filter(lambda u: u.any()))
def test_speed_moment_ratio_is_the_fourth_over_the_squared_second_moment(u):
    exact = [Fraction(float(x)) for x in u]  # exact rationals: no underflow of x⁴ in the oracle
    m2 = sum(x * x for x in exact) / len(exact)
    m4 = sum(x**4 for x in exact) / len(exact)
    ratio = speed_moment_ratio(u)
    assert ratio == pytest.approx(float(m4 / (m2 * m2)), rel=1e-9)
    assert ratio >= 1.0 - 1e-12  # Cauchy–Schwarz, equality for equal speeds


@given(arrays(np.float64, st.integers(1, 50), elements=st.floats(1e-3, 1e3, **finite)),
       st.integers(-140, 140))
def test_speed_moment_ratio_does_not_depend_on_the_unit_of_speed(u, decades):
    """A dimensionless ratio: the same for speeds in any unit, however small or large (no under/overflow)."""
    scaled = speed_moment_ratio(u * 10.0**decades)
    assert math.isfinite(scaled)
    assert scaled == pytest.approx(speed_moment_ratio(u), rel=1e-12)


def test_speed_moment_ratio_of_maxwell_and_of_equal_speeds():
    assert speed_moment_ratio(np.full(10, 2.5)) == pytest.approx(1.0, rel=1e-15)
    u = np.linalg.norm(np.random.default_rng(3).normal(size=(200_000, 3)), axis=1)
    assert speed_moment_ratio(u) == pytest.approx(5.0 / 3.0, rel=0.02)
    with pytest.raises(ValueError, match="zero"):
        speed_moment_ratio(np.zeros(4))


@given(arrays(np.float64, st.integers(2, 40), elements=st.floats(-1e6, 1e6, **finite)))
def test_block_mean_and_its_standard_error(x):
    mean, err = mean_and_standard_error(x)
    assert mean == pytest.approx(statistics.fmean(x), rel=1e-9, abs=1e-6)
    assert err == pytest.approx(statistics.stdev(x.tolist()) / math.sqrt(len(x)), rel=1e-6, abs=1e-6)


def test_standard_error_of_two_blocks():
    assert mean_and_standard_error([1.0, 3.0]) == (2.0, 1.0)  # s = sqrt(2), s/sqrt(2) = 1
    with pytest.raises(ValueError, match="values"):
        mean_and_standard_error([1.0])


def test_speed_histogram_is_written_as_a_png(tmp_path):
    path = tmp_path / "speeds.png"
    u = np.linalg.norm(np.random.default_rng(1).normal(size=(300, 3)), axis=1)
    plot_speed_histogram(u, path, "title")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match=r"speeds\[1\]"):
        plot_speed_histogram([1.0, -1.0], tmp_path / "bad.png")
    assert not (tmp_path / "bad.png").exists()


def test_speed_histogram_returns_its_figure_and_leaves_the_backend_alone(tmp_path, monkeypatch):
    """The plot is a Figure built without pyplot: the caller's backend stays as it was, no pyplot figure is left
    open, nothing is written without a path, and the returned figure holds the histogram and the density."""
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    monkeypatch.chdir(tmp_path)
    before = matplotlib.get_backend()
    open_figures = plt.get_fignums()
    u = np.linalg.norm(np.random.default_rng(2).normal(size=(200, 3)), axis=1)
    try:
        matplotlib.use("pdf")
        fig = plot_speed_histogram(u, title="no file")
        assert matplotlib.get_backend() == "pdf"
    finally:
        matplotlib.use(before)
    assert isinstance(fig, Figure)
    assert plt.get_fignums() == open_figures
    assert list(tmp_path.iterdir()) == []
    (ax,) = fig.axes
    assert ax.get_title() == "no file"
    assert len(ax.patches) == 60 and len(ax.lines) == 1  # the 60 bars and the Maxwell–Boltzmann curve
    heights = np.array([bar.get_height() for bar in ax.patches])
    widths = np.array([bar.get_width() for bar in ax.patches])
    assert float((heights * widths).sum()) == pytest.approx(1.0, rel=1e-12)  # a density
    assert plot_speed_histogram(u, tmp_path / "a.png") is not None
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_zero_impulse_and_zero_speed_are_allowed():
    assert compressibility_from_walls(0.0, 3, 1.0, 1.0, 1.0) == 0.0
    assert collision_rate(0, 3, 1.0) == 0.0
    np.testing.assert_array_equal(scaled_speeds(np.zeros((2, 3))), [0.0, 0.0])
    _, p = maxwell_boltzmann_test([0.0, 1.0, 2.0])
    assert 0.0 <= p <= 1.0


@pytest.mark.parametrize("top", [2.0, 7.5])
def test_speed_histogram_draws_the_maxwell_density_with_its_legend(top):
    """The curve is the Maxwell–Boltzmann density of the scaled speed, 4πu² e^{−u²/2}/(2π)^{3/2} (written out
    here), over [0, max(4.5, the largest speed)]; the legend names both; the figure is 6 × 4 inches (the
    docstring's contract)."""
    u = np.linspace(0.0, top, 50)
    fig = plot_speed_histogram(u)
    (ax,) = fig.axes
    (line,) = ax.lines
    x, y = line.get_xdata(), line.get_ydata()
    assert x[0] == 0.0 and x[-1] == max(4.5, top) and len(x) == 400
    np.testing.assert_allclose(y, 4.0 * np.pi * x**2 * np.exp(-(x**2) / 2.0) / (2.0 * np.pi) ** 1.5,
                               rtol=1e-12, atol=1e-300)
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["simulation (50 speeds)", "Maxwell–Boltzmann"]
    assert tuple(fig.get_size_inches()) == (6.0, 4.0)
    assert ax.get_ylabel() == "density"
