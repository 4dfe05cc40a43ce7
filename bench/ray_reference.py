"""The exact answer of a batch of ray casts, by brute force over every body: the reference of the query benchmarks.

``ray_reference(scene, origins, directions, max_distance)`` tests every ray against every body of a scene made of
``Sphere``, ``Box`` and a ground ``Plane`` with closed forms, vectorised over chunks of rays in numpy:

- a sphere: the quadratic |o + t d − c|² = r² (the near root as c / q, the far root as q / a, Numerical Recipes'
  stable pair);
- a box: the slab test in the box frame (origin and direction turned by the box's rotation), the normal the face
  of the entering slab;
- the ground (solid below y = altitude): t = (o_y − altitude) / −d_y, normal +y.

It never uses the World's structures: a bounding sphere per body (the sphere itself, the box's circumscribed
sphere) only skips the closed forms for rays that cannot reach it, and that test is itself exact (every body
whose bounding sphere the ray segment meets is tested).

Directions need not be unit: distances are along the unit direction, as ``World.cast_rays``. A ray whose origin is
inside a body (or on its surface) is answered per ``inside``:

- ``"zero"`` (World's contract, Jolt's solid shapes): that body is hit at distance 0 with normal −direction;
- ``"skip"`` (Bullet: a convex shape that contains the origin is not reported): that body is ignored, the ray
  goes on to the other bodies;
- ``"exit"`` (MuJoCo: the far root of the quadratic / the exit face of the box): that body is hit where the ray
  leaves it, normal the outward normal there.

Returns ``(body, distance, point, normal)``: body (k,) int64 (−1 a miss; the ground is index n, after the n
bodies of the scene), distance (k,) (inf a miss), point (k, 3) and normal (k, 3) (NaN for a miss).
"""
from __future__ import annotations

import numpy as np

from engine.workloads import FrameScene, quaternion_matrices
from engine.world import Box, Sphere

INSIDE = ("zero", "skip", "exit")

#: rays per chunk: the chunk's ray × body arrays stay a few tens of MB at 1e4 bodies
CHUNK = 256


def _scene_arrays(scene: FrameScene):
    """(sphere indices, centres, radii), (box indices, centres, rotations (m, 3, 3), half extents) of a scene."""
    sph = np.array([i for i, s in enumerate(scene.shapes) if isinstance(s, Sphere)], np.int64)
    box = np.array([i for i, s in enumerate(scene.shapes) if isinstance(s, Box)], np.int64)
    if len(sph) + len(box) != len(scene.shapes):
        raise ValueError("the ray reference knows spheres, boxes and the ground plane only")
    radii = np.array([scene.shapes[i].radius for i in sph], float).reshape(-1)
    half = np.array([scene.shapes[i].half_extents for i in box], float).reshape(-1, 3)
    rot = quaternion_matrices(scene.quaternions[box]) if len(box) else np.empty((0, 3, 3))
    # a shape built at the origin with its own rotation keeps it in the body frame (the scenes' shapes have none)
    local = [scene.shapes[i].rotation for i in box]
    if local:
        rot = rot @ np.array(local)
    return (sph, scene.centers[sph], radii), (box, scene.centers[box], rot, half)


def _reaches(o, d, centers, radius, max_distance):
    """(ray, body) pairs of a chunk whose segment [0, max_distance] meets the body's bounding sphere."""
    oc = centers[None, :, :] - o[:, None, :]
    b = np.einsum("rbk,rk->rb", oc, d)
    perp2 = np.einsum("rbk,rbk->rb", oc, oc) - b * b
    near = (perp2 <= radius * radius * (1 + 1e-12) + 1e-12) & (b >= -radius - 1e-9) & (b <= max_distance + radius)
    return np.nonzero(near)


def _spheres(o, d, c, r, inside):
    """(t, normal) of rays o + t d (d unit) against spheres (c, r), row by row; t = inf for a miss."""
    oc = o - c
    b = np.einsum("ij,ij->i", oc, d)
    cc = np.einsum("ij,ij->i", oc, oc) - r * r
    disc = b * b - cc
    hit = disc >= 0.0
    root = np.sqrt(np.where(hit, disc, 0.0))
    q = -b - np.copysign(root, b)  # the stable pair: roots q and cc / q (a = 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r1, r2 = q, np.where(q != 0.0, cc / q, 0.0)
    t_near, t_far = np.minimum(r1, r2), np.maximum(r1, r2)
    is_in = cc <= 0.0
    t = np.where(hit & (t_near >= 0.0), t_near, np.inf)
    if inside == "zero":
        t = np.where(is_in, 0.0, t)
    elif inside == "skip":
        t = np.where(is_in, np.inf, t)
    else:
        t = np.where(is_in, np.where(hit, t_far, np.inf), t)
    with np.errstate(invalid="ignore"):  # inf × 0 on the misses, whose normals are never read
        normal = (o + t[:, None] * d - c) / r[:, None]
    if inside == "zero":
        normal = np.where(is_in[:, None], -d, normal)
    return t, normal


def _boxes(o, d, c, rot, half, inside):
    """(t, normal) of rays o + t d (d unit) against oriented boxes, row by row: the slab test in the box frame."""
    lo = np.einsum("ikj,ik->ij", rot, o - c)  # rot's columns are the box axes: local = rotᵀ (x − c)
    ld = np.einsum("ikj,ik->ij", rot, d)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - lo) / ld
        t2 = (half - lo) / ld
    parallel = ld == 0.0
    within = np.abs(lo) <= half
    t_in = np.where(parallel, np.where(within, -np.inf, np.inf), np.minimum(t1, t2))
    t_out = np.where(parallel, np.where(within, np.inf, -np.inf), np.maximum(t1, t2))
    axis_in = np.argmax(t_in, axis=1)
    axis_out = np.argmin(t_out, axis=1)
    rows = np.arange(len(o))
    t_near, t_far = t_in[rows, axis_in], t_out[rows, axis_out]
    crosses = (t_near <= t_far) & (t_far >= 0.0)
    is_in = within.all(axis=1)
    t = np.where(crosses & (t_near >= 0.0) & ~is_in, t_near, np.inf)
    # entering face: against the direction on that axis; leaving face: along it
    sign_in = -np.sign(ld[rows, axis_in])
    sign_out = np.sign(ld[rows, axis_out])
    normal = rot[rows, :, axis_in] * sign_in[:, None]
    if inside == "zero":
        t = np.where(is_in, 0.0, t)
        normal = np.where(is_in[:, None], -d, normal)
    elif inside == "exit":
        t = np.where(is_in, t_far, t)
        normal = np.where(is_in[:, None], rot[rows, :, axis_out] * sign_out[:, None], normal)
    return t, normal


def _ground(o, d, altitude, inside):
    """(t, normal) of rays against the half-space y <= altitude."""
    is_in = o[:, 1] <= altitude
    with np.errstate(divide="ignore", invalid="ignore"):
        t_cross = (o[:, 1] - altitude) / -d[:, 1]
    t = np.where(~is_in & (d[:, 1] < 0.0), t_cross, np.inf)
    normal = np.broadcast_to(np.array([0.0, 1.0, 0.0]), o.shape).copy()
    if inside == "zero":
        t = np.where(is_in, 0.0, t)
        normal = np.where(is_in[:, None], -d, normal)
    elif inside == "exit":  # leaving the ground upwards: the surface, its normal down
        t = np.where(is_in & (d[:, 1] > 0.0), t_cross, t)
        normal = np.where(is_in[:, None], -normal, normal)
    return t, normal


def ray_reference(scene: FrameScene, origins, directions, max_distance=np.inf, inside: str = "zero",
                  chunk: int = CHUNK):
    """The exact first hit of each ray of a scene of spheres, boxes and a ground plane (this module's summary).

    origins (k, 3) or (3,) (one origin for every ray), directions (k, 3), not necessarily unit;
    ``max_distance`` a float; ``inside`` one of ``INSIDE``. Returns ``(body, distance, point, normal)``.
    """
    if inside not in INSIDE:
        raise ValueError(f"inside must be one of {INSIDE}, got {inside!r}")
    d_all = np.asarray(directions, float).reshape(-1, 3)
    d_all = d_all / np.linalg.norm(d_all, axis=1, keepdims=True)
    o_all = np.broadcast_to(np.asarray(origins, float), d_all.shape)
    k, n = len(d_all), len(scene.shapes)
    (sph, sc, sr), (box, bc, brot, bhalf) = _scene_arrays(scene)
    body = np.full(k, -1, np.int64)
    dist = np.full(k, np.inf)
    normal = np.full((k, 3), np.nan)
    for start in range(0, k, chunk):
        o, d = o_all[start:start + chunk], d_all[start:start + chunk]
        best = np.full(len(o), np.inf)
        best_body = np.full(len(o), -1, np.int64)
        best_normal = np.full((len(o), 3), np.nan)

        def keep(rays, ids, t, nrm, best=best, best_body=best_body, best_normal=best_normal):
            # the nearest per ray, ties to the lower body index (np.lexsort: the last key is the primary one)
            ok = t <= max_distance
            rays, ids, t, nrm = rays[ok], ids[ok], t[ok], nrm[ok]
            order = np.lexsort((ids, t, rays))
            rays, ids, t, nrm = rays[order], ids[order], t[order], nrm[order]
            first = np.ones(len(rays), bool)
            first[1:] = rays[1:] != rays[:-1]
            rays, ids, t, nrm = rays[first], ids[first], t[first], nrm[first]
            better = (t < best[rays]) | ((t == best[rays]) & (ids < best_body[rays]))
            rays, ids, t, nrm = rays[better], ids[better], t[better], nrm[better]
            best[rays], best_body[rays], best_normal[rays] = t, ids, nrm

        if len(sph):
            r, b = _reaches(o, d, sc, sr[None, :], max_distance)
            t, nrm = _spheres(o[r], d[r], sc[b], sr[b], inside)
            keep(r, sph[b], t, nrm)
        if len(box):
            bound = np.linalg.norm(bhalf, axis=1)
            r, b = _reaches(o, d, bc, bound[None, :], max_distance)
            t, nrm = _boxes(o[r], d[r], bc[b], brot[b], bhalf[b], inside)
            keep(r, box[b], t, nrm)
        if scene.ground is not None:
            t, nrm = _ground(o, d, float(scene.ground), inside)
            keep(np.arange(len(o)), np.full(len(o), n, np.int64), t, nrm)
        body[start:start + chunk], dist[start:start + chunk], normal[start:start + chunk] = best_body, best, best_normal
    point = o_all + np.where(np.isfinite(dist), dist, np.nan)[:, None] * d_all
    return body, dist, point, normal


def agreement(reference, answer, scale: float, tolerance: float = 1e-9) -> dict:
    """How an engine's ``(body, distance, normal)`` agrees with the reference's: the fraction of rays whose hit
    or miss and distance agree within ``tolerance × scale``, and on the rays both hit, the median and max
    |distance error| and the max |n − n_ref| (NaN when the engine gives no normals)."""
    ref_body, ref_dist, _, ref_normal = reference
    body, dist, normal = answer
    body, dist = np.asarray(body), np.asarray(dist, float)
    ref_hit, hit = ref_body >= 0, body >= 0
    both = ref_hit & hit
    err = np.abs(dist[both] - ref_dist[both])
    close = np.abs(np.where(both, dist, 0.0) - np.where(both, ref_dist, 0.0)) <= tolerance * scale
    same = (ref_hit == hit) & (close | ~both)
    out = {"rays": int(len(body)), "agree": float(same.mean()) if len(body) else float("nan"),
           "hits_reference": int(ref_hit.sum()), "hits": int(hit.sum()),
           "only_reference": int((ref_hit & ~hit).sum()), "only_engine": int((hit & ~ref_hit).sum()),
           "same_body": float((body[both] == ref_body[both]).mean()) if both.any() else float("nan"),
           "distance_error_median": float(np.median(err)) if err.size else float("nan"),
           "distance_error_max": float(err.max()) if err.size else float("nan"),
           "normal_error_max": float("nan")}
    if normal is not None and both.any():
        out["normal_error_max"] = float(np.linalg.norm(np.asarray(normal)[both] - ref_normal[both], axis=1).max())
    return out


__all__ = ["ray_reference", "agreement", "INSIDE"]
