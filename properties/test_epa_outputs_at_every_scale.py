"""``epa_penetration``'s witness points of tiny and huge pairs.

Pairs whose largest coordinate lies outside [2^-160, 2^160] are solved on copies scaled by a power of two and
every length is scaled back (engine/narrowphase/rescale.py): the witness points too. Shapes scaled by 2^k
(exact) have witnesses 2^k times those of the unscaled pair, and still satisfy point_a − point_b = depth · normal
(overlap) or point_b − point_a = distance · normal (apart), in the pair's own units. (The depths and normals of such
pairs are checked by test_adversarial.py; the witnesses were not.)
"""
from __future__ import annotations

import numpy as np
from hypothesis import example, given
from hypothesis import strategies as st

from engine.narrowphase import epa_penetration, gjk_distance


@given(st.integers(0, 2**32 - 1), st.sampled_from([-1000, -700, -400, -200, -170, 170, 200, 400, 480]),
       st.booleans())
@example(seed=0, k=-1000, apart=False)
@example(seed=1, k=480, apart=True)
def test_witnesses_scale_with_the_shapes(seed, k, apart):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(int(rng.integers(4, 9)), 3))
    b = rng.normal(size=(int(rng.integers(4, 9)), 3)) + (rng.normal(size=3) * 4.0 if apart else 0.3)
    s = 2.0**k
    depth1, n1, pa1, pb1 = epa_penetration(a, b, witnesses=True)
    depth_s, n_s, pa_s, pb_s = epa_penetration(a * s, b * s, witnesses=True)
    scale = max(np.abs(a).max(), np.abs(b).max())
    assert np.all(np.isfinite(pa_s)) and np.all(np.isfinite(pb_s))
    # the scaled pair's witnesses, in its own units, are the unscaled ones times 2^k
    assert np.abs(pa_s / s - pa1).max() <= 1e-9 * scale, (pa_s / s, pa1)
    assert np.abs(pb_s / s - pb1).max() <= 1e-9 * scale, (pb_s / s, pb1)
    # and they differ by the signed distance along the normal
    if depth1 > 0.0:
        assert np.abs((pa_s - pb_s) / s - depth_s / s * n_s).max() <= 1e-9 * scale
    else:
        d1, _, _ = gjk_distance(a, b)
        assert np.abs((pb_s - pa_s) / s - d1 * n_s).max() <= 1e-9 * scale



@given(st.integers(0, 2**32 - 1), st.sampled_from([-1000, -400, -170, 170, 400, 480]), st.booleans())
def test_contact_closest_points_scale_with_the_shapes(seed, k, apart):
    """``contact_feature``'s closest (or deepest) points of a pair scaled by 2^k are 2^k times the unscaled ones."""
    from engine import contact_feature

    rng = np.random.default_rng(seed)
    a = rng.normal(size=(int(rng.integers(4, 9)), 3))
    b = rng.normal(size=(int(rng.integers(4, 9)), 3)) + (rng.normal(size=3) * 4.0 if apart else 0.3)
    s = 2.0**k
    c1, c_s = contact_feature(a, b), contact_feature(a * s, b * s)
    scale = max(np.abs(a).max(), np.abs(b).max())
    assert np.abs(c_s.closest_a / s - c1.closest_a).max() <= 1e-9 * scale, (c_s.closest_a / s, c1.closest_a)
    assert np.abs(c_s.closest_b / s - c1.closest_b).max() <= 1e-9 * scale, (c_s.closest_b / s, c1.closest_b)
