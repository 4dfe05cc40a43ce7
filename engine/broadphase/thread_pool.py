"""The worker threads of the broad phase: one call of a kernel per part, the parts run at once.

Every parallel stage of a broad phase (a sweep over ranges of columns, the histograms and the scatter of a
radix sort, the sort and the merge of the pair buffers) is a list of parts, each a call of a ``nogil`` kernel on
arrays that no other part writes. :func:`run_parts` runs the first part on the calling thread and the others on a
pool of threads kept for the life of the process (making threads at every stage would cost more than a small
stage), and returns the parts' results in the order of the parts, whatever order they finish in — so a stage's
result never depends on the scheduling.
"""
from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from typing import Any, TypeVar

from engine._config import MAX_THREADS

__all__ = ["run_parts"]

T = TypeVar("T")

_POOL: list[ThreadPoolExecutor] = []
_POOL_LOCK = threading.Lock()


def _pool() -> ThreadPoolExecutor:
    """The process's pool (made at its first use): idle threads are reused, at most MAX_THREADS of them."""
    with _POOL_LOCK:
        if not _POOL:
            _POOL.append(ThreadPoolExecutor(max_workers=MAX_THREADS, thread_name_prefix="engine-broad"))
        return _POOL[0]


def run_parts(work: Callable[[Any], T], parts: Sequence[Any]) -> list[T]:
    """``[work(part) for part in parts]``, the parts run at once: the first on this thread, the others on the
    pool's threads (``work`` must release the GIL to run in parallel, and the parts must not write the same
    memory). The results are in the order of ``parts``; an exception (the first failing part's, in part order)
    is raised once every part has finished, so no thread still writes the caller's arrays."""
    if len(parts) <= 1:
        return [work(part) for part in parts]
    pool = _pool()
    futures = [pool.submit(work, part) for part in parts[1:]]
    try:
        first = work(parts[0])
    finally:
        wait(futures)
    return [first, *(future.result() for future in futures)]
