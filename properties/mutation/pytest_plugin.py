"""pytest plugin loaded by the mutation run only (``-p properties.mutation.pytest_plugin``).

A test decorated with ``@settings(max_examples=60)`` ignores the profile's max_examples, and so does a stateful
machine with its own ``settings``. Under mutation (kernels interpreted, one run per mutant) every Hypothesis test
is capped at the loaded profile's max_examples (``mutation``: 25), and the shrink phase is skipped: the first
failing example already kills the mutant, and shrinking it with interpreted kernels costs minutes. Everything
else of the test is unchanged.
"""
from __future__ import annotations

from hypothesis import Phase, settings

NO_SHRINK = tuple(p for p in Phase if p is not Phase.shrink and p is not Phase.explain)


def _capped(current: settings | None) -> settings:
    current = settings.default if current is None else current
    return settings(current, max_examples=min(current.max_examples, settings.default.max_examples), phases=NO_SHRINK)


def pytest_collection_modifyitems(config, items):
    for item in items:
        fn = getattr(item, "obj", None)
        inner = getattr(fn, "hypothesis", None)
        if inner is not None and hasattr(fn, "_hypothesis_internal_use_settings"):
            fn._hypothesis_internal_use_settings = _capped(fn._hypothesis_internal_use_settings)
        cls = getattr(item, "cls", None)
        if cls is not None and isinstance(getattr(cls, "settings", None), settings):
            cls.settings = _capped(cls.settings)
