"""Benchmarks: pytest-benchmark suites. Kernels are compiled before timing (a warm-up call in each fixture or
``benchmark.pedantic(..., warmup_rounds=1)``); work counts go to ``benchmark.extra_info``.

``--quick`` (or ``BENCH_QUICK=1``) keeps only the small sizes, for the report's quick mode and smoke runs.
"""
from __future__ import annotations

import os

import pytest


def pytest_addoption(parser):
    parser.addoption("--quick", action="store_true", default=False, help="small sizes only")


@pytest.fixture(scope="session")
def quick(request) -> bool:
    return bool(request.config.getoption("--quick") or os.environ.get("BENCH_QUICK"))
