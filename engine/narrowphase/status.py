"""Status codes of the narrow-phase kernels — GJK, EPA, the penetration chain, time of impact — in one numbering,
and the exceptions the public functions raise for them (from one place: ``raise_for_status``).

A kernel returns (or writes per pair, into an int64 array) one of these codes:

====================  =====  =====================================================================================
name                  value  meaning
====================  =====  =====================================================================================
``SEPARATED``         0      GJK: the hulls are apart (or touch without a full simplex); EPA / penetration: no
                             penetration (depth 0); time of impact: no contact in [0, t_max]
``OVERLAP``           1      GJK: the origin lies in the Minkowski difference (distance 0); EPA / penetration:
                             depth and normal found; time of impact: contact reached at the returned t
``GJK_NOT_CONVERGED`` 2      GJK reached its iteration cap before its stopping test
``INVALID_INPUT``     3      a coordinate is NaN, ±inf or above MAX_MAGNITUDE (found while the kernel read it)
``EPA_NOT_CONVERGED`` 4      the expanding polytope gave up (iteration cap, storage, a mesh folded by round-off);
                             the public functions then take the exact answer (``minkowski_fallback``)
``TOI_NOT_CONVERGED`` 5      conservative advancement reached its iteration cap before the contact distance
====================  =====  =====================================================================================

The codes are plain module-level ints, so numba compiles them as constants inside the kernels.
"""
from __future__ import annotations

import numpy as np

__all__ = ["SEPARATED", "OVERLAP", "GJK_NOT_CONVERGED", "INVALID_INPUT", "EPA_NOT_CONVERGED", "TOI_NOT_CONVERGED",
           "NotConverged", "GJKNotConverged", "EPANotConverged", "TOINotConverged", "raise_for_status"]

SEPARATED = 0
OVERLAP = 1
GJK_NOT_CONVERGED = 2
INVALID_INPUT = 3
EPA_NOT_CONVERGED = 4
TOI_NOT_CONVERGED = 5


class NotConverged(RuntimeError):
    """A narrow-phase iteration reached its cap before its stopping test.

    Attributes
    ----------
    status : int
        The code of the failure (a class attribute), one of this module's status codes.
    """

    status = -1


class GJKNotConverged(NotConverged):
    """GJK reached its iteration cap without meeting its stopping test.

    Raised by ``gjk_distance``, ``epa_penetration``, ``contact_feature`` and their batched forms (the message
    names the pair, ``pairs[p]``); ``status`` is ``GJK_NOT_CONVERGED``.
    """

    status = GJK_NOT_CONVERGED


class EPANotConverged(NotConverged):
    """EPA reached its iteration cap (or its polytope storage) before its stopping test.

    Raised by ``epa_penetration``, ``contact_feature`` and their batched forms only when the exact fallback on
    the Minkowski difference has no answer either; ``status`` is ``EPA_NOT_CONVERGED``.
    """

    status = EPA_NOT_CONVERGED


class TOINotConverged(NotConverged):
    """Conservative advancement hit its iteration cap before reaching the contact distance.

    Raised by ``time_of_impact`` and ``time_of_impact_pairs`` after ``max_iterations`` steps, or when the GJK
    a step runs on does not converge; ``status`` is ``TOI_NOT_CONVERGED``.
    """

    status = TOI_NOT_CONVERGED


_FAILURES = {GJK_NOT_CONVERGED: (GJKNotConverged, "GJK"), EPA_NOT_CONVERGED: (EPANotConverged, "EPA")}
#: _IS_FAILURE[code]: whether the code is a failure raise_for_status raises for (codes 0 to 5)
_IS_FAILURE = np.zeros(TOI_NOT_CONVERGED + 1, np.bool_)
_IS_FAILURE[[GJK_NOT_CONVERGED, EPA_NOT_CONVERGED, TOI_NOT_CONVERGED]] = True


def raise_for_status(status, max_iterations: int, where: str = "") -> None:
    """Raise the exception of the first failed pair of ``status`` (an int code or an int64 array of codes), if any.

    ``where`` names the batch argument (e.g. ``"pairs"``): the message then says which row failed. GJK and EPA
    failures say ``max_iterations``; a time-of-impact failure (its own or that of the GJK it runs on) raises
    ``TOINotConverged``. ``INVALID_INPUT`` is the caller's to explain (it knows the argument's name).
    """
    codes = np.atleast_1d(np.asarray(status))
    failed = _IS_FAILURE[codes]  # one table look-up (codes are 0..5): the common case costs one pass
    if not failed.any():
        return
    p = int(np.argmax(failed))
    at = f" for {where}[{p}]" if where else ""
    code = int(codes[p])
    if code == TOI_NOT_CONVERGED:
        raise TOINotConverged(f"conservative advancement did not reach contact in max_iterations={max_iterations} "
                              f"steps{at}; raise max_iterations or tol")
    cls, what = _FAILURES[code]
    raise cls(f"{what} did not converge in max_iterations={max_iterations} iterations{at}")
