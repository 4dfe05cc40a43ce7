"""Collision response and resting contact for a body on the ground.

- Impact (slide "Application": "Traiter la collision: On prendra V_après = -e * V_avant"): the restart state
  Y(tc)+ keeps the position of Y(tc) and replaces the normal velocity by -e times itself.
- Resting contact (slide "Autre problème"): a body at rest on the ground receives a contact force that cancels
  the downward part of the external force, so the ODE solver goes on without stop/restart; the contact force is
  "just a part of the force returned by the routine that computes the external forces".
"""
from __future__ import annotations

from .._config import njit

# Layout of the parameter vector shared by the falling-body kernels (one float64 array, so kernels stay cacheable).
P_GRAVITY = 0  # g >= 0, pointing down (-y)
P_MASS = 1  # m > 0
P_LINEAR_DRAG = 2  # k >= 0 in F = -k v
P_QUADRATIC_DRAG = 3  # c >= 0 in F = -c |v| v
P_RESTITUTION = 4  # e in [0, 1]
P_GROUND = 5  # height of the reference point (the lowest point of the body) at contact: body y at y = P_GROUND
P_REST_SPEED = 6  # a bounce slower than this ends in resting contact (no Zeno cascade)
P_STOP_ON_CONTACT = 7  # 1.0: the body is stopped at the first contact (the falling cube of the slide)
N_PARAMS = 8


@njit
def external_force(v, params):
    """Vertical external force on the body: weight and drag, F = -m g - k v - c |v| v (scalar, newtons)."""
    return -params[P_MASS] * params[P_GRAVITY] - params[P_LINEAR_DRAG] * v - params[P_QUADRATIC_DRAG] * abs(v) * v


@njit
def resting_contact_force(v, params):
    """Normal force N >= 0 that keeps a resting body from accelerating into the ground (slide "Autre problème").

    The ground can push, never pull: N = max(0, -F_ext). With gravity alone, N = m g.
    """
    f = external_force(v, params)
    return -f if f < 0.0 else 0.0


@njit
def velocity_after_impact(v_before, params):
    """The slide's rule V_après = -e V_avant for the normal (vertical) velocity."""
    return -params[P_RESTITUTION] * v_before
