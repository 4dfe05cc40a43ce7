"""The shapes of engine.world refuse a bad argument with an error whose message starts with that argument's
name (the validation contract of the README), for a wrong shape and for a non-finite value alike."""
from __future__ import annotations

import re

import numpy as np
import pytest

from engine import Box, Capsule, Sphere

NAN3 = [np.nan, 0.0, 0.0]
CASES = [
    (lambda v: Sphere(v, 1.0), "center"),
    (lambda v: Box(v, [1.0, 1.0, 1.0]), "center"),
    (lambda v: Box(np.zeros(3), v), "half_extents"),
    (lambda v: Capsule(v, [0.0, 0.0, 1.0], 0.5), "p0"),
    (lambda v: Capsule(np.zeros(3), v, 0.5), "p1"),
]


@pytest.mark.parametrize("make, name", CASES)
@pytest.mark.parametrize("bad", [NAN3, [0.0, 0.0], [np.inf, 0.0, 0.0]])
def test_a_bad_vector_is_refused_by_its_name(make, name, bad):
    with pytest.raises(ValueError, match="^" + re.escape(name) + r"\b"):
        make(bad)
