"""Clipping in the contact plane: the intersection of the two features of a contact, projected on the plane
orthogonal to the normal (2-D coordinates). Face against face: Sutherland–Hodgman (Ericson, *Real-Time Collision
Detection*, 8.3.4; Box2D's ``b2ClipPolygons``); edge against face: Cyrus–Beck segment clipping; edge against edge:
their crossing or the overlap of parallel edges (Ericson 5.1.9); and the clean-up of the clipped polygon.

Polygons are (n, 2) float64 arrays of counter-clockwise vertices; every kernel writes into caller-given arrays and
returns a count.
"""
from __future__ import annotations

import math

from .._config import njit

__all__ = ["clip_polygon", "clip_segment", "closest_segments_2d", "drop_flat_vertices", "points_along_line"]


@njit
def clip_polygon(S, ns, C, nc, buf):
    """Sutherland–Hodgman (Ericson 8.3.4, Box2D's b2ClipPolygons): the part of the polygon S[:ns] inside the
    convex counter-clockwise polygon C[:nc]. Works in the two halves of buf (2, cap, 2); returns (half, count)."""
    cur = 0
    n = ns
    for i in range(ns):
        buf[0, i, 0] = S[i, 0]
        buf[0, i, 1] = S[i, 1]
    for e in range(nc):
        if n == 0:
            break
        ax = C[e, 0]
        ay = C[e, 1]
        ex = C[(e + 1) % nc, 0] - ax
        ey = C[(e + 1) % nc, 1] - ay
        nxt = 1 - cur
        m = 0
        for i in range(n):
            px, py = buf[cur, i, 0], buf[cur, i, 1]
            qx, qy = buf[cur, (i + 1) % n, 0], buf[cur, (i + 1) % n, 1]
            sp = ex * (py - ay) - ey * (px - ax)  # >= 0: p is inside the edge's half-plane
            sq = ex * (qy - ay) - ey * (qx - ax)
            if sp >= 0.0:
                buf[nxt, m, 0] = px
                buf[nxt, m, 1] = py
                m += 1
            if (sp >= 0.0) != (sq >= 0.0):
                t = sp / (sp - sq)
                buf[nxt, m, 0] = px + t * (qx - px)
                buf[nxt, m, 1] = py + t * (qy - py)
                m += 1
        cur = nxt
        n = m
    return cur, n


@njit
def points_along_line(px, py, dx, dy, s0, s1, out):
    """The two points p + s0·d and p + s1·d of a 2-D line into out[0], out[1]; returns 2 (their count)."""
    out[0, 0] = px + s0 * dx
    out[0, 1] = py + s0 * dy
    out[1, 0] = px + s1 * dx
    out[1, 1] = py + s1 * dy
    return 2


@njit
def clip_segment(px, py, qx, qy, C, nc, out):
    """Cyrus–Beck: the part of segment [p, q] inside the convex counter-clockwise polygon C[:nc] into out[:2];
    returns 2, or 0 when it is empty."""
    t0 = 0.0
    t1 = 1.0
    dx = qx - px
    dy = qy - py
    for e in range(nc):
        ax = C[e, 0]
        ay = C[e, 1]
        ex = C[(e + 1) % nc, 0] - ax
        ey = C[(e + 1) % nc, 1] - ay
        num = ex * (py - ay) - ey * (px - ax)  # >= 0 inside
        den = ex * dy - ey * dx
        if den == 0.0:
            if num < 0.0:
                return 0
            continue
        t = -num / den
        if den > 0.0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return 0
    return points_along_line(px, py, dx, dy, t0, t1, out)


@njit
def closest_segments_2d(A, B, tol, out):
    """Contact points of two projected edges A[:2], B[:2]: their crossing, or the overlap of parallel edges
    (Ericson 5.1.9). Writes out[:count]; returns count (1 or 2)."""
    p1x, p1y = A[0, 0], A[0, 1]
    d1x, d1y = A[1, 0] - p1x, A[1, 1] - p1y
    p2x, p2y = B[0, 0], B[0, 1]
    d2x, d2y = B[1, 0] - p2x, B[1, 1] - p2y
    den = d1x * d2y - d1y * d2x
    len1 = math.sqrt(d1x * d1x + d1y * d1y)
    scale = max(len1 * math.sqrt(d2x * d2x + d2y * d2y), 1e-300)
    if abs(den) > 1e-9 * scale:
        s = ((p2x - p1x) * d2y - (p2y - p1y) * d2x) / den
        s = min(max(s, 0.0), 1.0)
        out[0, 0] = p1x + s * d1x
        out[0, 1] = p1y + s * d1y
        return 1
    # parallel: the overlap of the two intervals along d1
    length = max(len1, 1e-300)
    ux = d1x / length
    uy = d1y / length
    a0 = 0.0
    a1 = d1x * ux + d1y * uy
    b0 = (p2x - p1x) * ux + (p2y - p1y) * uy
    b1 = (B[1, 0] - p1x) * ux + (B[1, 1] - p1y) * uy
    if b1 < b0:
        b0, b1 = b1, b0
    lo = max(a0, b0)
    hi = min(a1, b1)
    if lo > hi:  # should not happen for facing features; keep the nearest end
        lo = a1 if b0 > a1 else a0
        hi = lo
    if hi - lo <= tol:
        mid = 0.5 * (lo + hi)
        out[0, 0] = p1x + mid * ux
        out[0, 1] = p1y + mid * uy
        return 1
    return points_along_line(p1x, p1y, ux, uy, lo, hi, out)


@njit
def drop_flat_vertices(S, count, tol):
    """Remove from the convex polygon S[:count] every vertex within tol of the line through its two neighbours
    (clipping a face on a face that shares an edge leaves such points: they add nothing to the contact patch).
    Returns the new count."""
    while count >= 3:
        dropped = False
        for i in range(count):
            a = (i - 1) % count
            b = (i + 1) % count
            ex = S[b, 0] - S[a, 0]
            ey = S[b, 1] - S[a, 1]
            length = math.sqrt(ex * ex + ey * ey)
            dx = S[i, 0] - S[a, 0]
            dy = S[i, 1] - S[a, 1]
            off = abs(ex * dy - ey * dx) / length if length > 0.0 else math.sqrt(dx * dx + dy * dy)
            if off <= tol:
                for j in range(i, count - 1):
                    S[j, 0] = S[j + 1, 0]
                    S[j, 1] = S[j + 1, 1]
                count -= 1
                dropped = True
                break
        if not dropped:
            break
    return count
