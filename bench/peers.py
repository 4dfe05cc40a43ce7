"""The peers of the broad-phase benchmarks, each run the way its users run it, and the machine's clock.

- ``ckdtree_pairs(centres, radius)`` — scipy's cKDTree: build + ``query_pairs`` (ndarray output);
- ``fcl_pairs(centres, radius)`` — python-fcl's DynamicAABBTreeCollisionManager: register + setup + collide, a
  Python callback collecting the pairs that fcl's narrow test confirms;
- ``coal_pairs(centres, radius)`` — coal's DynamicAABBTreeCollisionManager with the C++ CollisionCallBackCollect:
  its broad-phase pair count only (a lower bound on its time);
- ``cpu_mhz()`` — the nominal clock ("cpu MHz" of /proc/cpuinfo), for cycles per object.
"""
from __future__ import annotations

import math
import re
from pathlib import Path


def cpu_mhz() -> float:
    """Nominal clock from /proc/cpuinfo ("cpu MHz"), MHz; NaN when unavailable."""
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return math.nan
    found = re.findall(r"cpu MHz\s*:\s*([0-9.]+)", text)
    return float(found[0]) if found else math.nan


def ckdtree_pairs(centres, radius):
    from scipy.spatial import cKDTree

    return cKDTree(centres).query_pairs(2 * radius, output_type="ndarray")


def fcl_pairs(centres, radius):
    import fcl

    objects = [fcl.CollisionObject(fcl.Sphere(radius), fcl.Transform(c)) for c in centres]
    index = {tuple(c): i for i, c in enumerate(centres.tolist())}
    manager = fcl.DynamicAABBTreeCollisionManager()
    manager.registerObjects(objects)
    manager.setup()
    found = []

    def collect(o1, o2, _):
        # a fresh request/result per call (python-fcl: a reused result keeps a stale state)
        if fcl.collide(o1, o2, fcl.CollisionRequest(), fcl.CollisionResult()):
            found.append((index[tuple(o1.getTranslation())], index[tuple(o2.getTranslation())]))
        return False

    manager.collide(None, collect)
    return found


def coal_pairs(centres, radius):
    import coal

    manager = coal.DynamicAABBTreeCollisionManager()
    keep = []
    for c in centres:
        transform = coal.Transform3s()
        transform.setTranslation(c)
        obj = coal.CollisionObject(coal.Sphere(radius), transform)
        keep.append(obj)
        manager.registerObject(obj)
    manager.setup()
    callback = coal.CollisionCallBackCollect(max(16, 4 * len(centres)))
    manager.collide(callback)
    return callback.numCollisionPairs()
