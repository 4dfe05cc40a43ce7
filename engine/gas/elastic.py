"""Elastic responses of the confined gas: sphere–wall (specular) and sphere–sphere (mass-weighted).

Chapter, "comportement des particules dans un volume confiné", 1.B "Modèle Mathématique des Collisions":
- wall:   v' = v − 2 (v·n) n                              (n the unit normal of the wall)
- pair:   n  = (p2 − p1)/|p2 − p1|
          v1' = v1 − (2 m2/(m1 + m2)) ((v1 − v2)·n) n
          v2' = v2 + (2 m1/(m1 + m2)) ((v1 − v2)·n) n
Only an approaching pair, (v1 − v2)·(p1 − p2) < 0, is answered: a receding or grazing pair,
or one whose centres coincide (no normal), is left unchanged, so overlapping spheres never stick and no NaN appears.

The kernels are shared by the stepped and the event-driven methods; each pair kernel returns the pair's
contribution m1 Δv1 · (p1 − p2) to the collision virial (0 when no impulse is applied).
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine._validate import as_float_array, as_positive
from engine.gas.kernels import state_kernel

__all__ = ["collide_elastic", "reflect_off_wall", "pair_impulse"]


@state_kernel  # no zero division: rr > 0 and m_i + m_j > 0 are checked or given
def pair_impulse(v, mi, mj, i, j, rx, ry, rz, off=0):
    """Kernel shared by both gas methods: answer the elastic collision of spheres i and j (masses mi, mj > 0) in
    place on the velocities v[:, off:off + 3] (v: (n, 3) float64, or a packed (n, k) state whose velocity
    columns start at ``off``); r = p_i − p_j (any periodic image).

    Chapter 1.B (and 2.C, the same formula written with <v_A − v_B, p_A − p_B>/|p_A − p_B|²): the normal
    components are exchanged with the weights 2 m_j/(m_i + m_j) and 2 m_i/(m_i + m_j). Returns the virial term
    m_i Δv_i · r = −2 μ b with μ the reduced mass and b = (v_i − v_j)·r < 0; 0.0 when nothing is done.
    """
    rr = rx * rx + ry * ry + rz * rz
    if not rr > 0.0:  # coincident centres: no contact normal, no impulse
        return 0.0
    b = (v[i, off] - v[j, off]) * rx + (v[i, off + 1] - v[j, off + 1]) * ry + (v[i, off + 2] - v[j, off + 2]) * rz
    if not b < 0.0:  # receding or grazing pair
        return 0.0
    total = mi + mj
    # (v_i − v_j)·n n = (b / rr) r ; the factors below are 2 m_j/(m_i+m_j) and 2 m_i/(m_i+m_j)
    s = b / rr
    ki = 2.0 * (mj / total) * s
    kj = 2.0 * (mi / total) * s
    v[i, off] -= ki * rx
    v[i, off + 1] -= ki * ry
    v[i, off + 2] -= ki * rz
    v[j, off] += kj * rx
    v[j, off + 1] += kj * ry
    v[j, off + 2] += kj * rz
    return -2.0 * (mi * (mj / total)) * b


@njit
def _collide_elastic_kernel(v1, v2, m1, m2, p1, p2):
    v = np.empty((2, 3))
    v[0] = v1
    v[1] = v2
    virial = pair_impulse(v, m1, m2, 0, 1, p1[0] - p2[0], p1[1] - p2[1], p1[2] - p2[2], 0)
    return v, virial


@njit
def _reflect_kernel(v, n):
    # Chapter 1.B, "Collision avec les Parois": v' = v − 2 (v·n) n, answered only when v moves into the wall
    # (v·n > 0 for the outward normal n).
    vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2]
    out = v.copy()
    if vn > 0.0:
        for k in range(3):
            out[k] = v[k] - 2.0 * vn * n[k]
    return out


def collide_elastic(v1, v2, m1, m2, p1, p2):
    """Velocities after the elastic collision of two spheres (the chapter's mass-weighted formulas, 1.B and 2.C).

    With r = p1 − p2 and b = (v1 − v2)·r < 0 (approaching), the normal components are exchanged with the weights
    2 m2/(m1 + m2) and 2 m1/(m1 + m2): ``v1' = v1 − 2 m2/(m1 + m2) (b/|r|²) r`` and
    ``v2' = v2 + 2 m1/(m1 + m2) (b/|r|²) r``.
    Momentum and kinetic energy are conserved.

    Parameters
    ----------
    v1, v2 : array_like, shape (3,)
        The velocities before the collision.
    m1, m2 : float
        The masses, > 0.
    p1, p2 : array_like, shape (3,)
        The centres at contact (only the direction p1 − p2 matters).

    Returns
    -------
    v1_new, v2_new : numpy.ndarray, shape (3,), float64
        New arrays; a receding, grazing (relative velocity perpendicular to p1 − p2) or coincident pair is
        returned unchanged. The inputs are never modified.
    virial : float
        The pair's virial term m1 Δv1 · (p1 − p2) >= 0 (0.0 when nothing is done).

    Raises
    ------
    ValueError
        For a vector not of shape (3,), NaN or ±inf, a mass <= 0, or a response that overflows float64.

    Examples
    --------
    Equal masses meeting head on exchange their velocities:

    >>> from engine.gas import collide_elastic
    >>> collide_elastic([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], 1.0, 1.0, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    (array([-1.,  0.,  0.]), array([1., 0., 0.]), 2.0)
    """
    v1 = as_float_array(v1, "v1", shape=(3,))
    v2 = as_float_array(v2, "v2", shape=(3,))
    p1 = as_float_array(p1, "p1", shape=(3,))
    p2 = as_float_array(p2, "p2", shape=(3,))
    m1 = as_positive(m1, "m1")
    m2 = as_positive(m2, "m2")
    v, virial = _collide_elastic_kernel(v1, v2, m1, m2, p1, p2)
    if not (np.isfinite(v).all() and math.isfinite(virial)):
        raise ValueError("collide_elastic: the response overflows float64 for these velocities and masses")
    return v[0].copy(), v[1].copy(), float(virial)


def reflect_off_wall(velocity, normal):
    """Specular reflection ``v − 2 (v·n) n`` off a wall of outward unit normal n.

    Applied only when the sphere moves into the wall (v·n > 0); otherwise the velocity comes back unchanged.

    Parameters
    ----------
    velocity : array_like, shape (3,)
        The sphere's velocity.
    normal : array_like, shape (3,)
        The wall's outward normal, of unit length within 1e-9.

    Returns
    -------
    numpy.ndarray, shape (3,), float64
        The velocity after the bounce (a new array).

    Raises
    ------
    ValueError
        For a normal that is not a unit vector, NaN or ±inf, or an overflowing result.
    """
    v = as_float_array(velocity, "velocity", shape=(3,))
    n = as_float_array(normal, "normal", shape=(3,))
    length = float(np.sqrt(n @ n))
    if abs(length - 1.0) > 1e-9:
        raise ValueError(f"normal must be a unit vector, got length {length!r}")
    out = _reflect_kernel(v, n)
    if not np.isfinite(out).all():
        raise ValueError("reflect_off_wall: the reflected velocity overflows float64")
    return out
