"""The falling scenes (``drop_particle``, ``drop_cube``) refuse a bad argument with a ValueError whose message starts
with the argument's own name, and refuse a bisection tolerance that is not smaller than the time step, equality
included (the bracket [t, t + dt] must hold more than one tolerance)."""
from __future__ import annotations

import pytest

from engine import drop_cube, drop_particle

BAD = [("height", -1.0), ("mass", 0.0), ("drag", -0.1), ("quadratic_drag", -0.1), ("gravity", -1.0), ("dt", 0.0),
       ("t_end", -1.0), ("tol", 0.0)]


@pytest.mark.parametrize("drop", [drop_particle, drop_cube])
@pytest.mark.parametrize("name, bad", BAD)
def test_a_bad_argument_is_refused_by_its_name(drop, name, bad):
    kwargs = {name: bad}
    height = kwargs.pop("height", 1.0)
    with pytest.raises(ValueError, match=rf"^{name} must be"):
        drop(height, **kwargs)


@pytest.mark.parametrize("drop", [drop_particle, drop_cube])
@pytest.mark.parametrize("dt", [0.01, 2.0**-7, 1e-3])
def test_a_tolerance_equal_to_the_step_is_refused(drop, dt):
    with pytest.raises(ValueError, match=r"^tol must be smaller than dt"):
        drop(1.0, dt=dt, tol=dt)
    drop(1.0, dt=dt, tol=dt / 2, t_end=0.5)  # just below the step: accepted
