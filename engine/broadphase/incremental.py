"""The interface of the broad phases that keep their structure between frames.

:class:`~engine.broadphase.IncrementalSAP` (a sorted order repaired by insertion sort) and
:class:`~engine.broadphase.DynamicAABBTree` (a tree of fattened boxes) hold objects with integer ids, each with
a closed box; a frame moves the boxes and asks for the pairs. What they share is written here once: the id
check, ``remove``, ``update`` (every live object moved at once, then the pairs), ``ids``, ``len`` and ``dim``.
A subclass stores its boxes and implements ``ids``, ``pairs``, ``_is_live(i)``, ``_remove_object(id)`` and
``_set_boxes(ids, lo, hi)``.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine.broadphase.pairs import as_boxes, as_live_id, as_threads

__all__ = ["IncrementalBroadPhase"]


class IncrementalBroadPhase:
    """Objects with ids and closed boxes, kept between frames; see :ref:`broadphase-incremental`."""

    _d: int

    @property
    def dim(self) -> int:
        """The dimension d of the boxes (1, 2 or 3)."""
        return self._d

    def __len__(self) -> int:
        """The number of live objects.

        Returns
        -------
        int
        """
        return int(self.ids().shape[0])

    def ids(self) -> np.ndarray:
        """The live ids.

        Returns
        -------
        numpy.ndarray, shape (m,), int64
            Ascending: the row order ``update`` expects.
        """
        raise NotImplementedError

    def pairs(self, *, threads: int = 1) -> np.ndarray:
        """The pairs of live objects whose closed boxes overlap.

        Parameters
        ----------
        threads : int, optional
            How many threads may share the work, 1 to 256 (the same answer, bit for bit).

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            Canonical pairs of ids (:ref:`broadphase-pairs`), the same as :func:`~engine.broadphase.find_pairs`
            on the live boxes.
        """
        raise NotImplementedError

    def _is_live(self, obj_id: int) -> bool:
        raise NotImplementedError

    def _remove_object(self, obj_id: int) -> None:
        raise NotImplementedError

    def _set_boxes(self, ids: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
        raise NotImplementedError

    def _check_id(self, obj_id: int) -> int:
        return as_live_id(obj_id, self._is_live)

    def remove(self, obj_id: int) -> None:
        """Delete a live object; its id may be reused by a later insertion.

        Parameters
        ----------
        obj_id : int
            See :ref:`broadphase-incremental`.
        """
        obj_id = self._check_id(obj_id)
        self._remove_object(obj_id)

    def update(self, lo: ArrayLike, hi: ArrayLike, *, threads: int = 1) -> np.ndarray:
        """New boxes for every live object, then the pairs: one frame of a simulation.

        Parameters
        ----------
        lo, hi : array_like, shape (m, d)
            One row per live object, in ascending id order (the order of ``ids()``); the boxes as in
            :ref:`broadphase-boxes`. Another shape is a ValueError, and nothing is moved then.
        threads : int, optional
            As for ``pairs``.

        Returns
        -------
        numpy.ndarray, shape (k, 2), int64
            ``pairs()`` after the moves.
        """
        threads = as_threads(threads)
        lo_d, hi_d = as_boxes(lo, hi)
        ids = self.ids()
        if lo_d.shape != (ids.shape[0], self._d):
            raise ValueError(f"lo and hi must have shape ({ids.shape[0]}, {self._d}) (one row per live object), "
                             f"got {lo_d.shape}")
        self._set_boxes(ids, lo_d, hi_d)
        return self.pairs(threads=threads)
