"""The horizon of a point seen from a convex triangle mesh, and the cone of new faces on it — the step that
quickhull (engine.bounding.hull) and EPA (engine.narrowphase.epa) both repeat to grow a convex polytope by one
point p.

    visible <- the faces whose plane p lies above (depth-first from one visible face, over face neighbours)
    horizon <- the edges between a visible face and a face that p does not see (in the visible face's winding)
    replace the visible faces by the triangles (a, b, p), one per horizon edge (a, b)

Barber, Dobkin & Huhdanpaa, "The quickhull algorithm for convex hulls" (1996); Ericson, *Real-Time Collision
Detection*, 12.4.2; van den Bergen, *Collision Detection in Interactive 3D Environments*, 4.3.3 (EPA).

The mesh is stored as index arrays, one row per face slot (slots are never reused; the caller marks dead faces):

- ``fv`` (F, 3) int64: the face's vertices, counter-clockwise seen from outside;
- ``fadj`` (F, 3) int64: the face across edge e = (fv[f, e], fv[f, (e + 1) % 3]);
- ``fn`` (F, 3) float64 unit outward normals and ``fd`` (F,) offsets: p is above face f iff
  fn[f]·p − fd[f] > eps; a face with offset +inf (a zero-area sliver that has no plane) counts as seen from
  every point, so that it leaves the mesh at the first chance;
- ``stamp`` (F,) int64: the visit mark of the search (a face is visible in search ``mark`` iff stamp == mark).

``visible_faces_and_horizon`` decides "p sees face h" by the face's floating-point plane (EPA's polytope);
``visible_faces_and_horizon_exact`` by the exact sign of orient3d (engine.bounding.predicates, Shewchuk 1997) on
the face's corners (quickhull's). With the exact test, a polytope that is exactly convex and a point strictly above
one of its faces give a connected visible region whose horizon is one simple loop, and the cone on it makes the
exact convex hull of the polytope and the point: no round-off can fold the mesh.
"""
from __future__ import annotations

import numpy as np

from .._config import njit
from .predicates import orient3d

__all__ = ["link_neighbours", "visible_faces_and_horizon", "visible_faces_and_horizon_exact", "stitch_cone"]


@njit
def link_neighbours(fv, n_faces, fadj):
    """Fill ``fadj[:n_faces]`` by brute force (the face holding each reversed edge, -1 where none does: the mesh is
    then not closed). For the initial simplex of a search; ``stitch_cone`` keeps the links up to date after."""
    for f in range(n_faces):
        for e in range(3):
            a = fv[f, e]
            b = fv[f, (e + 1) % 3]
            fadj[f, e] = -1
            for g in range(n_faces):
                for e2 in range(3):
                    if fv[g, e2] == b and fv[g, (e2 + 1) % 3] == a:
                        fadj[f, e] = g


@njit(inline="always")
def _visit(sees, g, e, h, fv, stamp, mark, stack, top, horizon, n_horizon):
    """One step of the search from visible face g across its edge e to face h: a face that p sees is stamped and
    pushed; else edge e of g is a horizon edge (its two vertices in g's winding, and h). Returns the new
    (top, n_horizon)."""
    if sees:
        stamp[h] = mark
        stack[top] = h
        return top + 1, n_horizon
    horizon[n_horizon, 0] = fv[g, e]
    horizon[n_horizon, 1] = fv[g, (e + 1) % 3]
    horizon[n_horizon, 2] = h
    return top, n_horizon + 1


@njit
def visible_faces_and_horizon(start, px, py, pz, eps, fv, fadj, fn, fd, stamp, mark, stack, visible, horizon):
    """The faces seen from p = (px, py, pz), found depth-first from face ``start`` (which p must see), into
    ``visible``, and the horizon edges (a, b, face beyond) into ``horizon`` (H, 3). Visible faces get
    ``stamp = mark``. Returns (number of visible faces, number of horizon edges)."""
    n_visible = 0
    n_horizon = 0
    top = 0
    stack[top] = start
    top += 1
    stamp[start] = mark
    while top > 0:
        top -= 1
        g = stack[top]
        visible[n_visible] = g
        n_visible += 1
        for e in range(3):
            h = fadj[g, e]
            if stamp[h] == mark:
                continue
            sees = fd[h] == np.inf or fn[h, 0] * px + fn[h, 1] * py + fn[h, 2] * pz - fd[h] > eps
            top, n_horizon = _visit(sees, g, e, h, fv, stamp, mark, stack, top, horizon, n_horizon)
    return n_visible, _drop_stale_edges(horizon, n_horizon, stamp, mark)


@njit
def visible_faces_and_horizon_exact(start, p, points, fv, fadj, stamp, mark, stack, visible, horizon):
    """``visible_faces_and_horizon`` for the point ``p`` (a row of ``points`` (n, 3) float64, the rows ``fv``
    indexes), where p sees face h iff orient3d(points, fv[h, 0], fv[h, 1], fv[h, 2], p) > 0 exactly."""
    n_visible = 0
    n_horizon = 0
    top = 0
    stack[top] = start
    top += 1
    stamp[start] = mark
    while top > 0:
        top -= 1
        g = stack[top]
        visible[n_visible] = g
        n_visible += 1
        for e in range(3):
            h = fadj[g, e]
            if stamp[h] == mark:
                continue
            sees = orient3d(points, fv[h, 0], fv[h, 1], fv[h, 2], p) > 0.0
            top, n_horizon = _visit(sees, g, e, h, fv, stamp, mark, stack, top, horizon, n_horizon)
    return n_visible, _drop_stale_edges(horizon, n_horizon, stamp, mark)


@njit
def _drop_stale_edges(horizon, n_horizon, stamp, mark):
    """Keep the horizon edges whose outer face is not visible (it may have turned visible after the edge was
    listed, later in the search); returns their count."""
    k = 0
    for t in range(n_horizon):
        if stamp[horizon[t, 2]] != mark:
            horizon[k, 0] = horizon[t, 0]
            horizon[k, 1] = horizon[t, 1]
            horizon[k, 2] = horizon[t, 2]
            k += 1
    return k


@njit
def stitch_cone(apex, horizon, n_horizon, fv, fadj, stamp, n_faces, start_face, end_face, new_faces):
    """The cone of new faces (a, b, apex), one per horizon edge (a, b, h), in slots ``n_faces``, ``n_faces + 1``
    …, linked to the faces h beyond the horizon and to each other; their slots are listed in ``new_faces`` and
    their stamps cleared. ``start_face``, ``end_face`` (V,) int64 are scratch, -1 everywhere on entry and on
    return. Returns False when the horizon is not one simple loop (round-off folded the mesh): the links are then
    left incomplete and the caller must give up."""
    for t in range(n_horizon):
        a = horizon[t, 0]
        b = horizon[t, 1]
        h = horizon[t, 2]
        nf = n_faces + t
        fv[nf, 0] = a
        fv[nf, 1] = b
        fv[nf, 2] = apex
        stamp[nf] = -1
        fadj[nf, 0] = h
        for e in range(3):
            if fv[h, e] == b and fv[h, (e + 1) % 3] == a:
                fadj[h, e] = nf
        if start_face[a] != -1 or end_face[b] != -1:
            _clear_ends(horizon, t, start_face, end_face)
            return False
        start_face[a] = nf
        end_face[b] = nf
        new_faces[t] = nf
    ok = True
    for t in range(n_horizon):
        nf = new_faces[t]
        fadj[nf, 1] = start_face[fv[nf, 1]]  # edge (b, apex) borders the face starting at b
        fadj[nf, 2] = end_face[fv[nf, 0]]  # edge (apex, a) borders the face ending at a
        if fadj[nf, 1] == -1 or fadj[nf, 2] == -1:
            ok = False
    _clear_ends(horizon, n_horizon, start_face, end_face)
    return ok


@njit
def _clear_ends(horizon, count, start_face, end_face):
    """Reset the scratch marks that the first ``count`` horizon edges set."""
    for t in range(count):
        start_face[horizon[t, 0]] = -1
        end_face[horizon[t, 1]] = -1
