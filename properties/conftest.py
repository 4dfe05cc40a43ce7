"""Hypothesis settings profiles for the property suite.

- ``dev`` (default): 100 examples, no deadline (the first call of a numba kernel compiles it).
- ``ci``: Hypothesis' built-in ``ci`` profile (loaded automatically when the ``CI`` variable is set),
  extended here rather than replaced: at least 200 examples, no deadline, derandomized as the built-in is.
- ``nightly``: 5,000 examples for long local or scheduled runs.
- ``mutation``: 25 derandomized examples, for ``tox -e mutation`` (one run per mutant).
Choose one with ``HYPOTHESIS_PROFILE=nightly pytest properties`` (or pytest's ``--hypothesis-profile``).
"""
from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large]

settings.register_profile("dev", max_examples=100, deadline=None, suppress_health_check=_SLOW_OK)
settings.register_profile(
    "ci",
    parent=settings.get_profile("ci"),
    max_examples=200,
    deadline=None,
    suppress_health_check=_SLOW_OK,
)
settings.register_profile("nightly", max_examples=5000, deadline=None, suppress_health_check=_SLOW_OK)
# mutation testing (tox -e mutation) runs the suite once per mutant, with kernels interpreted: few examples,
# derandomized so that a mutant's verdict does not depend on the run
settings.register_profile("mutation", max_examples=25, deadline=None, derandomize=True, database=None,
                          suppress_health_check=_SLOW_OK)

if os.environ.get("HYPOTHESIS_PROFILE"):
    settings.load_profile(os.environ["HYPOTHESIS_PROFILE"])
elif os.environ.get("CI"):
    settings.load_profile("ci")
else:
    settings.load_profile("dev")
