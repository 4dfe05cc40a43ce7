"""The chapter's elastic formulas (engine/gas/elastic.py): conservation, no impulse for receding or grazing
pairs, no NaN for coincident centres, specular walls; against an independent centre-of-mass construction."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from engine.gas import collide_elastic, reflect_off_wall
from properties.strategies.gas import collisions, masses, unit_vectors, vectors


def centre_of_mass_collision(v1, v2, m1, m2, p1, p2):
    """Oracle: go to the centre-of-mass frame, reflect both velocities' components along the line of centres
    (a head-on elastic bounce there), come back. Independent of the chapter's weighted formula."""
    n = (p1 - p2) / np.linalg.norm(p1 - p2)
    vc = (m1 * v1 + m2 * v2) / (m1 + m2)
    u1, u2 = v1 - vc, v2 - vc
    return vc + u1 - 2 * (u1 @ n) * n, vc + u2 - 2 * (u2 @ n) * n


@given(collisions())
def test_momentum_and_energy_are_conserved(case):
    v1, v2, m1, m2, p1, p2 = case
    w1, w2, virial = collide_elastic(v1, v2, m1, m2, p1, p2)
    # relative to the momentum scale m1|v1| + m2|v2| (the total can cancel to zero)
    momentum_scale = m1 * np.linalg.norm(v1) + m2 * np.linalg.norm(v2)
    assert np.linalg.norm(m1 * w1 + m2 * w2 - (m1 * v1 + m2 * v2)) <= 1e-12 * momentum_scale
    e0 = 0.5 * (m1 * v1 @ v1 + m2 * v2 @ v2)
    e1 = 0.5 * (m1 * w1 @ w1 + m2 * w2 @ w2)
    assert abs(e1 - e0) <= 1e-12 * e0
    assert virial >= 0.0


@given(collisions())
def test_approaching_pairs_follow_the_centre_of_mass_oracle_and_then_recede(case):
    v1, v2, m1, m2, p1, p2 = case
    r = p1 - p2
    b = (v1 - v2) @ r
    assume(b < -1e-6 * np.linalg.norm(v1 - v2) * np.linalg.norm(r))  # clearly approaching
    w1, w2, virial = collide_elastic(v1, v2, m1, m2, p1, p2)
    o1, o2 = centre_of_mass_collision(v1, v2, m1, m2, p1, p2)
    speed = np.linalg.norm(v1) + np.linalg.norm(v2)
    np.testing.assert_allclose(w1, o1, rtol=0, atol=1e-9 * speed)
    np.testing.assert_allclose(w2, o2, rtol=0, atol=1e-9 * speed)
    # the normal relative velocity is reversed: the pair now recedes
    assert (w1 - w2) @ r > 0.0
    mu = m1 * m2 / (m1 + m2)
    assert virial == pytest.approx(-2 * mu * b, rel=1e-9)


@given(collisions(), st.booleans())
def test_receding_or_grazing_pairs_get_no_impulse(case, grazing):
    v1, v2, m1, m2, p1, p2 = case
    r = p1 - p2
    rel = v1 - v2
    if grazing:  # relative velocity exactly perpendicular to the line of centres (axis normals, integer data)
        n = r / np.linalg.norm(r)
        assume(np.count_nonzero(n) == 1)
        k = int(np.flatnonzero(n)[0])
        v2 = v2.copy()
        v2[k] = v1[k]
    else:
        assume(rel @ r > 0.0)
    w1, w2, virial = collide_elastic(v1, v2, m1, m2, p1, p2)
    np.testing.assert_array_equal(w1, v1)
    np.testing.assert_array_equal(w2, v2)
    assert virial == 0.0


@given(vectors(), vectors(), masses(), masses(), vectors(10.0))
def test_coincident_centres_never_produce_nan(v1, v2, m1, m2, p):
    w1, w2, virial = collide_elastic(v1, v2, m1, m2, p, p.copy())
    assert np.isfinite(w1).all() and np.isfinite(w2).all() and virial == 0.0
    np.testing.assert_array_equal(w1, v1)
    np.testing.assert_array_equal(w2, v2)


@given(collisions())
def test_inputs_are_not_modified(case):
    copies = [np.array(x, copy=True) for x in case]
    collide_elastic(*case)
    for before, after in zip(copies, case):
        np.testing.assert_array_equal(before, after)


@given(vectors(), unit_vectors())
def test_wall_reflection_flips_only_the_normal_component_and_keeps_the_speed(v, n):
    w = reflect_off_wall(v, n)
    vn = v @ n
    tangential_before = v - vn * n
    tangential_after = w - (w @ n) * n
    scale = np.linalg.norm(v) + 1e-300
    np.testing.assert_allclose(tangential_after, tangential_before, rtol=0, atol=1e-12 * scale)
    if vn > 0:  # moving into the wall: the normal component is reversed
        assert w @ n == pytest.approx(-vn, rel=1e-12, abs=1e-12 * scale)
    else:  # moving away (or along): untouched
        np.testing.assert_array_equal(w, v)
    assert abs(np.linalg.norm(w) - np.linalg.norm(v)) <= 1e-12 * scale


@given(vectors(), st.integers(0, 2), st.sampled_from([1.0, -1.0]))
def test_axis_walls_flip_exactly_one_component(v, k, sign):
    n = np.zeros(3)
    n[k] = sign
    w = reflect_off_wall(v, n)
    expected = v.copy()
    if v[k] * sign > 0:
        expected[k] = -v[k]
    np.testing.assert_array_equal(w, expected)


@pytest.mark.parametrize("bad", [
    dict(m1=0.0), dict(m2=-1.0), dict(v1=[np.nan, 0, 0]), dict(p2=[0, 0]), dict(m1=True), dict(v2="abc"),
])
def test_bad_arguments_name_the_argument(bad):
    args = dict(v1=[1.0, 0, 0], v2=[-1.0, 0, 0], m1=1.0, m2=1.0, p1=[0.0, 0, 0], p2=[1.0, 0, 0])
    args.update(bad)
    name = next(iter(bad))
    with pytest.raises((ValueError, TypeError), match=name):
        collide_elastic(**args)


def test_wall_normal_must_be_unit():
    with pytest.raises(ValueError, match="normal"):
        reflect_off_wall([1.0, 0, 0], [2.0, 0, 0])
