"""Error messages print the offending value as a plain number, never numpy's repr.

With numpy 2 an array element formatted with ``!r`` prints as ``np.float64(-0.5)``; a user reads
``radii[2] = -0.5``. Each case provokes one argument check with a bad entry drawn at a random place and of a
random magnitude, and asserts that the message names the argument and the entry (``name[i] = value``, the value
as Python prints the float) and holds no ``np.`` text. The checks covered: the shared radius and half-extent checks
(``engine._validate``), the batched OBB check (SAT and the sphere–OBB test), the narrow phase's box and curve
arguments, the sphere–box and box–box contacts, the World's ``Box``, and the gas's start state and observables.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.broadphase import sphere_pairs
from engine.gas import EventDrivenGas, kinetic_temperature, maxwell_boltzmann_test, packing_fraction
from engine.narrowphase.box_box import contact_box_box_pair
from engine.narrowphase.primitives import max_on_intervals, overlap_aabb_aabb_batch, overlap_sphere_obb_batch
from engine.narrowphase.sat import overlap_obb_obb_batch
from engine.narrowphase.sphere_box import contact_sphere_box_pair
from engine.world import Box

NEGATIVE = st.floats(min_value=-1e100, max_value=-1e-300)  # refused by a ">= 0" check
NOT_POSITIVE = st.one_of(NEGATIVE, st.sampled_from([0.0, -0.0]))  # refused by a "> 0" check


def assert_plain(call, name: str, entry: str, value: float, exc=ValueError) -> None:
    """call() raises ``exc`` whose message starts with ``name``, quotes ``entry = value`` with the value as
    Python prints the float, and holds no numpy repr."""
    with pytest.raises(exc) as info:
        call()
    message = str(info.value)
    assert "np." not in message, message
    assert message.startswith(name), message
    assert f"{entry} = {float(value)!r}" in message, message


def boxes(n: int):
    """n unit boxes apart along x: centres (n, 3), axes (n, 3, 3) (rows), half extents (n, 3)."""
    centres = np.zeros((n, 3))
    centres[:, 0] = 3.0 * np.arange(n)
    return centres, np.tile(np.eye(3), (n, 1, 1)), np.full((n, 3), 0.5)


@given(n=st.integers(1, 6), data=st.data(), value=NEGATIVE)
def test_radii_checks_print_plain_numbers(n, data, value):
    i = data.draw(st.integers(0, n - 1))
    radii = np.full(n, 0.5)
    radii[i] = value
    centres = np.arange(3.0 * n).reshape(n, 3)
    assert_plain(lambda: sphere_pairs(centres, radii), "radii", f"radii[{i}]", value)
    c, a, e = boxes(1)
    assert_plain(lambda: overlap_sphere_obb_batch(centres, radii, c, a, e), "radii", f"radii[{i}]", value)


@given(n=st.integers(1, 4), data=st.data(), value=NEGATIVE)
def test_batched_obb_half_extents_print_plain_numbers(n, data, value):
    i = data.draw(st.integers(0, n - 1))
    k = data.draw(st.integers(0, 2))
    c, a, e = boxes(n)
    bad = e.copy()
    bad[i, k] = value
    assert_plain(lambda: overlap_obb_obb_batch(c, a, e, c, a, bad), "half_extents_b", f"half_extents_b[{i}, {k}]",
                 value)
    assert_plain(lambda: overlap_sphere_obb_batch(c, 1.0, c, a, bad), "box_half_extents",
                 f"box_half_extents[{i}, {k}]", value)


@given(n=st.integers(1, 4), data=st.data(), gap=st.floats(1e-12, 1e100))
def test_narrowphase_box_and_interval_order_print_plain_numbers(n, data, gap):
    i = data.draw(st.integers(0, n - 1))
    k = data.draw(st.integers(0, 2))
    lo = np.zeros((n, 3))
    hi = np.ones((n, 3))
    lo[i, k] = 1.0 + gap
    if lo[i, k] > hi[i, k]:
        assert_plain(lambda: overlap_aabb_aabb_batch(lo, hi, np.zeros((n, 3)), np.ones((n, 3))), "lo_a",
                     f"lo_a[{i}, {k}]", lo[i, k])
        assert_plain(lambda: max_on_intervals(np.sin, lo[:, k], hi[:, k]), "lo_x",
                     f"lo_x[{i}]", lo[i, k])


@given(x_bad=st.floats(0.05, 0.95), poison=st.sampled_from([np.nan, np.inf, -np.inf]))
def test_curve_values_print_plain_numbers(x_bad, poison):
    def f(x):
        return np.where(x >= x_bad, poison, np.sin(x))

    with pytest.raises(ValueError) as info:
        max_on_intervals(f, np.array([0.0]), np.array([1.0]))
    message = str(info.value)
    assert "np." not in message, message
    assert message.startswith(f"f returned a non-finite value {float(poison)!r} at x = "), message


@given(k=st.integers(0, 2), value=NOT_POSITIVE)
def test_box_contacts_and_world_box_print_plain_numbers(k, value):
    half = np.full(3, 0.5)
    half[k] = value
    entry = f"half_extents[{k}]"
    assert_plain(lambda: contact_sphere_box_pair(np.zeros(3), 1.0, np.ones(3), None, half), "half_extents", entry,
                 value)
    assert_plain(lambda: Box(np.zeros(3), half), "half_extents", entry, value)
    assert_plain(lambda: contact_box_box_pair(np.zeros(3), None, np.full(3, 0.5), np.ones(3), None, half),
                 "half_extents_b", f"half_extents_b[{k}]", value)


@given(n=st.integers(1, 5), data=st.data(), value=NOT_POSITIVE)
def test_gas_state_and_observables_print_plain_numbers(n, data, value):
    i = data.draw(st.integers(0, n - 1))
    positions = np.zeros((n, 3))
    positions[:, 0] = np.linspace(-3.0, 3.0, n)
    velocities = np.ones((n, 3))
    good = np.full(n, 0.25)
    bad = good.copy()
    bad[i] = value
    assert_plain(lambda: packing_fraction(bad, 10.0), "radii", f"radii[{i}]", value)
    assert_plain(lambda: EventDrivenGas(positions, velocities, bad, good, 10.0, False), "radii", f"radii[{i}]",
                 value)
    assert_plain(lambda: EventDrivenGas(positions, velocities, good, bad, 10.0, False), "masses", f"masses[{i}]",
                 value)
    assert_plain(lambda: kinetic_temperature(velocities, bad), "masses", f"masses[{i}]", value)
    if value < 0.0:
        assert_plain(lambda: maxwell_boltzmann_test(bad), "speeds", f"speeds[{i}]", value)


@given(n=st.integers(1, 5), data=st.data(), excess=st.floats(1e-3, 1e100))
def test_gas_start_outside_the_box_prints_plain_numbers(n, data, excess):
    i = data.draw(st.integers(0, n - 1))
    k = data.draw(st.integers(0, 2))
    positions = np.zeros((n, 3))
    positions[:, 0] = np.linspace(-3.0, 3.0, n)
    positions[i, k] = 5.0 - 0.25 + excess  # beyond the reachable half side L/2 - r
    with pytest.raises(ValueError) as info:
        EventDrivenGas(positions, np.ones((n, 3)), np.full(n, 0.25), np.ones(n), 10.0, False)
    message = str(info.value)
    assert "np." not in message, message
    assert message.startswith(f"positions[{i}] is outside the reachable box: coordinate {k} = "
                              f"{float(positions[i, k])!r}"), message
