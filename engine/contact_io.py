"""``collide contact A.json B.json``: whether, where (point, normal, feature) and when two shapes collide.

JSON format of one shape file (one object; lengths in any unit, times in the unit of the velocities)::

    {
      "shape": "box" | "sphere" | "capsule" | "convex",
      "center": [x, y, z],              # box, sphere, capsule: required; convex: optional (rotation centre,
                                        #   default the mean of the points)
      "half_extents": [hx, hy, hz],     # box: required, >= 0
      "radius": r,                      # sphere, capsule: required, >= 0; box, convex: optional rounding (0)
      "half_height": h,                 # capsule: half length of its axis segment, along its local y axis
      "points": [[x, y, z], ...],       # convex: vertices in the shape's local frame (rotated about "center"
                                        #   and translated to it when "center" is given, else world coordinates)
      "rotation": [[...], [...], [...]] # optional 3x3 matrix (columns = the shape's local axes in the world,
                | [w, x, y, z],         #   world = center + rotation @ local) or a unit quaternion (w first)
      "velocity": [vx, vy, vz],         # optional, default 0: constant linear velocity
      "angular_velocity": [wx, wy, wz]  # optional, default 0: constant angular velocity about "center"
    }

Example: ``{"shape": "box", "center": [0, 0, 5], "half_extents": [1, 1, 1], "velocity": [0, 0, -2]}``.

``describe_contact(path_a, path_b, t_max=10.0)`` reads the two files and answers in plain text: at t = 0 whether
the shapes overlap (depth and normal) or how far apart they are; the first time of impact within [0, t_max]
(conservative advancement), and at that instant the contact feature (vertex-face, edge-edge, face-face ...), the
normal and the contact point(s). ``load_shape(path_or_dict)`` returns the parsed ``ShapeSpec``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine._validate import as_float_array, as_nonnegative, as_positive
from engine.bounding.aabb import as_rotation_matrix
from engine.narrowphase.contact_manifold import contact_feature
from engine.narrowphase.motion import pose_at
from engine.narrowphase.time_of_impact import time_of_impact

__all__ = ["ShapeSpec", "load_shape", "describe_contact", "SHAPE_KINDS"]

SHAPE_KINDS = ("box", "sphere", "capsule", "convex")


@dataclass(frozen=True)
class ShapeSpec:
    """A parsed shape: ``core`` (n, 3) world vertices at t = 0 swept by a ball of ``radius``; motion."""

    kind: str
    core: np.ndarray
    radius: float
    center: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray

    def at(self, t: float) -> np.ndarray:
        """The core vertices at time t, (n, 3)."""
        out = np.empty_like(self.core)
        pose_at(self.core, self.center, self.velocity, self.angular_velocity, float(t), out)
        return out


def load_shape(source, where: str = "shape") -> ShapeSpec:
    """Parse one shape of the ``collide contact`` JSON format (in this module's docstring).

    Parameters
    ----------
    source : str, os.PathLike or dict
        A path to a JSON file holding one object, or the already-loaded dict.
    where : str, default "shape"
        How error messages name a dict source (a file is named by its path).

    Returns
    -------
    ShapeSpec
        ``core`` (n, 3) float64 world vertices at t = 0 (a box's 8 corners, a sphere's centre, a capsule's two
        axis ends, a convex set's points), ``radius``, ``center``, ``velocity`` and ``angular_velocity`` (3,).

    Raises
    ------
    ValueError
        For invalid JSON, an unknown ``"shape"`` or key, a missing required key, a bad rotation, or a bad value
        (each message starts with the file or ``where``).
    OSError
        When the file cannot be read.
    """
    if isinstance(source, dict):
        spec = source
    else:
        path = Path(source)
        where = str(path)
        try:
            spec = json.loads(path.read_text())
        except json.JSONDecodeError as exc:
            raise ValueError(f"{where}: not valid JSON ({exc})") from exc
    if not isinstance(spec, dict):
        raise ValueError(f"{where}: a shape file holds one JSON object")
    kind = spec.get("shape")
    if kind not in SHAPE_KINDS:
        raise ValueError(f"{where}: 'shape' must be one of {list(SHAPE_KINDS)}, got {kind!r}")
    known = {"shape", "center", "half_extents", "radius", "half_height", "points", "rotation", "velocity",
             "angular_velocity"}
    unknown = sorted(set(spec) - known)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {unknown}")

    def need(key):
        if key not in spec:
            raise ValueError(f"{where}: a {kind} needs '{key}'")
        return spec[key]

    rot = as_rotation_matrix(spec.get("rotation"), f"{where}: rotation", tol=1e-6, normalise=True)
    radius = as_nonnegative(spec.get("radius", 0.0), f"{where}: radius")
    if kind == "box":
        center = as_float_array(need("center"), f"{where}: center", shape=(3,))
        half = as_float_array(need("half_extents"), f"{where}: half_extents", shape=(3,))
        if (half < 0).any():
            raise ValueError(f"{where}: half_extents must be >= 0, got {half.tolist()}")
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
        core = center + (signs * half) @ rot.T
    elif kind == "sphere":
        center = as_float_array(need("center"), f"{where}: center", shape=(3,))
        radius = as_nonnegative(need("radius"), f"{where}: radius")
        core = center[None, :].copy()
    elif kind == "capsule":
        center = as_float_array(need("center"), f"{where}: center", shape=(3,))
        radius = as_nonnegative(need("radius"), f"{where}: radius")
        h = as_nonnegative(need("half_height"), f"{where}: half_height")
        core = center + np.array([[0.0, -h, 0.0], [0.0, h, 0.0]]) @ rot.T
    else:
        local = as_float_array(need("points"), f"{where}: points", shape=(None, 3), min_rows=1)
        if "center" in spec:
            center = as_float_array(spec["center"], f"{where}: center", shape=(3,))
            core = center + local @ rot.T
        else:
            core = local @ rot.T
            center = core.mean(axis=0)
    velocity = as_float_array(spec.get("velocity", [0.0, 0.0, 0.0]), f"{where}: velocity", shape=(3,))
    spin = as_float_array(spec.get("angular_velocity", [0.0, 0.0, 0.0]), f"{where}: angular_velocity",
                          shape=(3,))
    return ShapeSpec(kind=kind, core=np.ascontiguousarray(core), radius=radius, center=center,
                     velocity=velocity, angular_velocity=spin)


def _fmt(v) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in np.asarray(v).ravel()) + ")"


def describe_contact(path_a, path_b, t_max: float = 10.0) -> str:
    """Whether, where and when the shapes of two JSON files collide, as readable text (``collide contact``).

    At t = 0: the overlap (depth, normal, feature and points) or the distance; otherwise the first time of impact
    in [0, t_max] (``time_of_impact``) and the contact feature, normal and points at that instant.

    Parameters
    ----------
    path_a, path_b : str, os.PathLike or dict
        The two shapes, as for ``load_shape`` (named "A" and "B" in messages about dicts).
    t_max : float, default 10.0
        The end of the time window, > 0.

    Returns
    -------
    str
        A few lines of text.

    Raises
    ------
    ValueError
        From ``load_shape``, or for ``t_max <= 0``.

    Examples
    --------
    >>> from engine.contact_io import describe_contact
    >>> ball = {"shape": "sphere", "center": [0, 3, 0], "radius": 0.5, "velocity": [0, -1, 0]}
    >>> box = {"shape": "box", "center": [0, 0, 0], "half_extents": [1, 1, 1]}
    >>> print(describe_contact(ball, box))
    A: sphere, B: box
    at t = 0: separated, distance 1.5
    time of impact: t = 1.5
    contact at t: sphere-face, normal (0, -1, 0) (A towards B), point(s): (0, 1, 0)
    """
    t_max = as_positive(t_max, "t_max")
    a = load_shape(path_a, "A")
    b = load_shape(path_b, "B")
    lines = [f"A: {a.kind}, B: {b.kind}"]
    now = contact_feature(a.core, b.core, radius_a=a.radius, radius_b=b.radius)
    if now.separation < 0.0:
        lines.append(f"at t = 0: overlapping, penetration depth {-now.separation:.6g} along normal "
                     f"{_fmt(now.normal)} (A towards B)")
        lines.append(f"contact: {now.kind}, point(s): " + ", ".join(_fmt(p) for p in now.points))
        lines.append("time of impact: t = 0 (already in contact)")
        return "\n".join(lines)
    lines.append(f"at t = 0: {'touching' if now.separation == 0.0 else 'separated'}, distance "
                 f"{now.separation:.6g}")
    t = time_of_impact(a.core, a.velocity, b.core, b.velocity, t_max=t_max, angular_velocity_a=a.angular_velocity,
                       angular_velocity_b=b.angular_velocity, center_a=a.center, center_b=b.center,
                       radius_a=a.radius, radius_b=b.radius)
    if t is None:
        lines.append(f"no collision for t in [0, {t_max:.6g}]")
        return "\n".join(lines)
    hit = contact_feature(a.at(t), b.at(t), radius_a=a.radius, radius_b=b.radius)
    lines.append(f"time of impact: t = {t:.9g}")
    lines.append(f"contact at t: {hit.kind}, normal {_fmt(hit.normal)} (A towards B), point(s): "
                 + ", ".join(_fmt(p) for p in hit.points))
    return "\n".join(lines)
