"""Kinematic culling: the chapter's "méthode cinématique".

Chapter slide "Phase Large : Méthode cinématique": take the motion into account — objects moving apart cannot
collide — and compare the face normals of an object with its velocity: faces turned away are dropped from the
computation.

- :func:`cull_separating_sphere_pairs`: a candidate pair of spheres is dropped when it does not overlap and its
  relative velocity points away, (v_j − v_i)·(c_j − c_i) > 0. With constant velocities over the step the squared
  distance ``|p + v t|² = |p|² + 2 (p·v) t + |v|² t²`` then grows for all t >= 0, so the pair cannot collide
  during the whole step (Ericson, *Real-Time Collision Detection* 5.5.8: moving sphere against sphere).
- :func:`cull_separating_box_pairs`: a pair of axis-aligned boxes is dropped when on some axis the boxes are
  apart and their relative velocity along that axis widens (or keeps) the gap — the gap then never closes.
- :func:`front_faces`: the faces of a convex polyhedron moving with velocity v (relative to the other object)
  whose outward normal n has n·v >= 0; faces with n·v < 0 are turned away and culled. The first contact point of
  a translating convex polyhedron always lies on a kept face: its normal cone contains a direction m with
  m·v > 0, and that cone is spanned by the normals of the faces around the point.

The two culls share their ``pairs`` argument and their result: ``pairs`` (m, 2) are candidate pairs of indices
in [0, n), integers in any order, put in canonical form first (a ``ValueError`` names an index outside [0, n), a
``TypeError`` non-integers); the result is the int64 (k, 2) canonical pairs that are kept, a subset of
``pairs``. The other arrays are finite (NaN, ±inf or a wrong shape is a ``ValueError`` naming the argument).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine._config import njit
from engine._validate import as_float_array, as_radii
from engine.broadphase.pairs import as_boxes_3d, canonical_pairs

__all__ = ["cull_separating_sphere_pairs", "cull_separating_box_pairs", "front_faces"]


@njit
def _spheres_may_collide(c, r, v, i, j):
    # Chapter "méthode cinématique": drop (i, j) if apart and separating: p = c_j − c_i, w = v_j − v_i, p·w > 0.
    dist2 = 0.0
    approach = 0.0
    for k in range(c.shape[1]):
        p = c[j, k] - c[i, k]
        dist2 += p * p
        approach += p * (v[j, k] - v[i, k])
    s = r[i] + r[j]
    return dist2 <= s * s or approach <= 0.0


@njit
def _boxes_may_collide(lo, hi, v, i, j):
    # Per axis k: if box j lies above box i (lo_j > hi_i) and v_j − v_i >= 0 along k, the gap never closes;
    # symmetrically below. One such axis suffices to drop the pair.
    for k in range(lo.shape[1]):
        w = v[j, k] - v[i, k]
        if (lo[j, k] > hi[i, k] and w >= 0.0) or (lo[i, k] > hi[j, k] and w <= 0.0):
            return False
    return True


@njit
def _sphere_keep_kernel(pairs, c, r, v):
    keep = np.empty(pairs.shape[0], dtype=np.bool_)
    for t in range(pairs.shape[0]):
        keep[t] = _spheres_may_collide(c, r, v, pairs[t, 0], pairs[t, 1])
    return keep


@njit
def _box_keep_kernel(pairs, lo, hi, v):
    keep = np.empty(pairs.shape[0], dtype=np.bool_)
    for t in range(pairs.shape[0]):
        keep[t] = _boxes_may_collide(lo, hi, v, pairs[t, 0], pairs[t, 1])
    return keep


def _velocities(velocities: ArrayLike, n: int, d: int) -> np.ndarray:
    return as_float_array(velocities, "velocities", shape=(n, d))


def cull_separating_sphere_pairs(pairs: ArrayLike, centers: ArrayLike, radii: ArrayLike,
                                 velocities: ArrayLike) -> np.ndarray:
    """The candidate sphere pairs that may still collide: those not both apart and moving apart.

    A pair (i, j) is dropped when the spheres do not overlap and (v_j − v_i)·(c_j − c_i) > 0: with constant
    velocities their distance then grows for all t >= 0 (the chapter's kinematic method).

    Parameters
    ----------
    pairs : array_like of int, shape (m, 2)
        Candidate pairs, see the module's description.
    centers : array_like, shape (n, d)
        The spheres' centres, finite.
    radii : float or array_like, shape (n,)
        The radii, >= 0 (a negative one is a ValueError naming its index); a scalar for equal spheres.
    velocities : array_like, shape (n, d)
        The spheres' velocities, constant over the step.

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        The canonical pairs kept, see the module's description.
    """
    c = as_float_array(centers, "centers", ndim=2)
    n, d = c.shape
    r = as_radii(radii, "radii", n)
    v = _velocities(velocities, n, d)
    p = canonical_pairs(pairs, n=n)
    return p[_sphere_keep_kernel(p, c, r, v)]


def cull_separating_box_pairs(pairs: ArrayLike, lo: ArrayLike, hi: ArrayLike, velocities: ArrayLike) -> np.ndarray:
    """The candidate pairs of moving axis-aligned boxes that may still collide.

    A pair is dropped when, along some axis, the boxes are apart and their relative velocity does not close the
    gap (it then never closes, with constant velocities).

    Parameters
    ----------
    pairs : array_like of int, shape (m, 2)
        Candidate pairs, see the module's description.
    lo, hi : array_like, shape (n, d)
        The boxes, see :ref:`broadphase-boxes`.
    velocities : array_like, shape (n, d)
        The boxes' velocities.

    Returns
    -------
    numpy.ndarray, shape (k, 2), int64
        The canonical pairs kept, see the module's description.
    """
    lo3, hi3 = as_boxes_3d(lo, hi)
    n = lo3.shape[0]
    d = np.shape(lo)[1]
    v = np.zeros((n, 3))
    v[:, :d] = _velocities(velocities, n, d)
    p = canonical_pairs(pairs, n=n)
    return p[_box_keep_kernel(p, lo3, hi3, v)]


def front_faces(normals: ArrayLike, velocity: ArrayLike) -> np.ndarray:
    """The faces of a moving convex polyhedron to keep: those not turned away from its motion.

    The first contact point of a translating convex polyhedron always lies on a kept face.

    Parameters
    ----------
    normals : array_like, shape (m, d)
        The faces' outward normals (any length), finite.
    velocity : array_like, shape (d,)
        The polyhedron's velocity relative to the other object.

    Returns
    -------
    numpy.ndarray, shape (m,), bool
        True for the faces with n·v >= 0 (kept); False for those turned away (culled).

    Raises
    ------
    ValueError
        When ``normals`` is not 2-D, ``velocity`` does not have shape (d,), or either is not finite.
    TypeError
        For non-numeric arrays.
    """
    nrm = as_float_array(normals, "normals", ndim=2)
    v = as_float_array(velocity, "velocity", shape=(nrm.shape[1],))
    return nrm @ v >= 0.0
