"""Strategies aimed at degenerate configurations of two convex shapes.

Random pairs almost never produce the cases where round-off decides: axes parallel or nearly so, faces sharing
a plane, a vertex or an edge lying exactly on a face, rotations by multiples of 90° ± 1e-9, and shapes whose size
is far from 1. Here they are built on purpose:

- ``degenerate_rotations``: the identity, a product of quarter turns about the coordinate axes (± 1e-9 about a
  random axis), a turn about one coordinate axis (two boxes sharing it keep parallel faces), or a uniform one;
- ``placed_pairs``: box A (half extents such as 0.025 and 0.245, not representable in binary) and B (a box or a
  convex cloud) turned relative to A by a degenerate rotation, B's lowest vertex along one of A's face normals
  put on a point of that face (inside it, or on its edges and corners), then moved off the face by a signed gap:
  0 (touching: face on face, edge on face, vertex on face), a small gap, a small or a real overlap. The scene is
  then turned by another degenerate rotation, scaled by 10^k (k in -6..6) and shifted.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

__all__ = ["SIGNS", "scales", "degenerate_rotations", "placed_pairs", "PlacedPair", "box_vertices"]

SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)

#: 10^k, k = -6..6: shapes from a micrometre to a thousand kilometres in metres
scales = st.integers(-6, 6).map(lambda k: 10.0 ** k)
#: half extents: values that are not binary fractions (0.025, 0.245, 0.105 ...) and any float in [0.01, 0.5]
half_lengths = st.one_of(st.sampled_from([0.025, 0.245, 0.105, 0.1, 0.3, 0.02, 0.06, 0.015]), st.floats(0.01, 0.5))
halves = st.tuples(half_lengths, half_lengths, half_lengths).map(np.array)
_seeds = st.integers(0, 2**32 - 1)


def _about(axis: int, angle: float) -> np.ndarray:
    return Rotation.from_rotvec(angle * np.eye(3)[axis]).as_matrix()


@st.composite
def degenerate_rotations(draw) -> np.ndarray:
    """A rotation matrix (3, 3): identity, quarter turns (± 1e-9), a turn about a coordinate axis, or uniform."""
    kind = draw(st.sampled_from(["identity", "quarter", "axis", "uniform"]))
    if kind == "identity":
        return np.eye(3)
    if kind == "uniform":
        return Rotation.random(random_state=draw(_seeds)).as_matrix()
    if kind == "axis":
        return _about(draw(st.integers(0, 2)), draw(st.floats(-np.pi, np.pi)))
    m = np.eye(3)
    for axis in range(3):
        m = _about(axis, draw(st.integers(0, 3)) * np.pi / 2) @ m
    tilt = draw(st.sampled_from([0.0, 1e-9, -1e-9]))
    if tilt:
        direction = np.random.default_rng(draw(_seeds)).normal(size=3)
        m = Rotation.from_rotvec(tilt * direction / np.linalg.norm(direction)).as_matrix() @ m
    return m


def box_vertices(half: np.ndarray, rotation: np.ndarray, center) -> np.ndarray:
    """The 8 corners (8, 3) of a box: center + rotation @ (± half)."""
    return (SIGNS * half) @ rotation.T + np.asarray(center, float)


class PlacedPair(NamedTuple):
    """Two convex shapes (vertex arrays) and how they were built: ``gap`` is the signed distance along ``normal``
    (A's face normal, world frame, unit) between A's face plane and B's lowest vertex, in world units (0:
    touching; > 0: apart by exactly gap when that vertex lands inside the face; < 0: overlapping)."""

    a: np.ndarray
    b: np.ndarray
    gap: float
    normal: np.ndarray
    scale: float
    #: (center (3,), half extents (3,), rotation (3, 3)) of each shape in world units; None for B when a cloud
    box_a: tuple
    box_b: tuple | None


@st.composite
def placed_pairs(draw, gaps=None) -> PlacedPair:
    """Box A and a box or cloud B placed on one of A's faces (see the module docstring). ``gaps``: a strategy of
    gaps relative to A's size (default: 0, ±1e-6, ±1e-3, -0.3)."""
    gaps = st.sampled_from([0.0, 0.0, 1e-6, -1e-6, 1e-3, -1e-3, -0.3]) if gaps is None else gaps
    ha = draw(halves)
    hb, rot_b = None, None
    if draw(st.booleans()):
        hb, rot_b = draw(halves), draw(degenerate_rotations())
        b0 = (SIGNS * hb) @ rot_b.T
    else:  # a convex cloud of 4 to 12 points, sized as a box
        rng = np.random.default_rng(draw(_seeds))
        b0 = rng.normal(size=(draw(st.integers(4, 12)), 3)) * draw(halves)
    k = draw(st.integers(0, 2))
    sign = draw(st.sampled_from([-1.0, 1.0]))
    n = sign * np.eye(3)[k]
    # the touching point: on A's face k, inside it or on its border (fractions ±1: A's edges and corners)
    where = np.array([draw(st.one_of(st.sampled_from([-1.0, 0.0, 1.0]), st.floats(-1.0, 1.0))) for _ in range(3)])
    q = where * ha
    q[k] = sign * ha[k]
    v = b0[np.argmin(b0 @ n)]
    # an overlap no deeper than A's half thickness along n: B's lowest vertex stays in A, wherever q is on the face
    gap = max(draw(gaps) * float(ha.max()), -float(ha[k]))
    b = b0 + (q - v + gap * n)  # translation rounded once, then added: the touching is not exact in binary
    a = SIGNS * ha
    turn = draw(degenerate_rotations())
    scale = draw(scales)
    shift = np.array(draw(st.tuples(*[st.sampled_from([0.0, 0.5, -1.5, 3.0])] * 3)))
    move = q - v + gap * n
    box_b = None if hb is None else ((turn @ move + shift) * scale, hb * scale, turn @ rot_b)
    return PlacedPair(a=(a @ turn.T + shift) * scale, b=(b @ turn.T + shift) * scale, gap=gap * scale,
                      normal=turn @ n, scale=scale, box_a=(shift * scale, ha * scale, turn), box_b=box_b)
