"""Exact orientation of four points and an accurately rounded triangle normal, on float64 coordinates.

Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", Discrete &
Computational Geometry 18 (1997): a floating-point value x = fl(a ∘ b) and its round-off error y are computed
exactly (error-free transformations, a ∘ b = x + y exactly):

- TwoSum (Knuth): x = a + b, y = (a − (x − (x − a))) + (b − (x − a));
- TwoProduct (Dekker, Veltkamp's split of a into two 26-bit halves with the splitter 2^27 + 1);

and a sum of such values (an *expansion*: nonoverlapping components, increasing magnitude) is grown and scaled
without any error (Shewchuk's Grow-Expansion and Scale-Expansion, with zero elimination).

``orient3d(points, a, b, c, p)`` is the sign-exact value of ((b − a) × (c − a)) · (p − a): positive when p lies
above the plane of the counter-clockwise triangle (a, b, c). It evaluates the floating-point determinant first
and returns it when its magnitude exceeds Shewchuk's a-priori error bound (stage A of his orient3d, error bound
(7 + 56 ε) ε × the permanent, ε = 2^-53); otherwise it evaluates the determinant exactly as an expansion (his
orient3dexact) and returns the expansion's largest component, which has the determinant's sign. The returned
value's sign is always exact; so is its zero. Assumption (Shewchuk's): no product of three coordinates underflows
— the engine calls it on clouds scaled by a power of two to |coordinates| < 1, whose nonzero coordinates are far
above 2^-300 in every practical input.

``accurate_cross(points, a, b, c, out)`` writes (b − a) × (c − a) with every component within a few ulps of its
exact value, even for a sliver triangle (the naive cross product loses the relative accuracy of a component
that cancels, ε |b − a| |c − a| / |(b − a) × (c − a)|): the differences are kept as double-doubles (TwoSum) and
each component's two products as TwoProducts; only terms of order ε² |b − a| |c − a| are dropped.
"""
from __future__ import annotations

import numpy as np

from .._config import njit

__all__ = ["orient3d", "accurate_cross"]

_EPSILON = 2.0 ** -53
#: Shewchuk's stage-A error bound of orient3d, times the permanent
_O3D_ERRBOUND_A = (7.0 + 56.0 * _EPSILON) * _EPSILON
#: Veltkamp's splitter for float64: 2^ceil(53/2) + 1
_SPLITTER = 134217729.0


@njit
def _two_sum(a, b):
    """x + y = a + b exactly, x = fl(a + b) (Knuth's TwoSum)."""
    x = a + b
    b_virtual = x - a
    a_virtual = x - b_virtual
    return x, (a - a_virtual) + (b - b_virtual)


@njit
def _split(a):
    """a = hi + lo exactly, each half with at most 26 significant bits (Veltkamp)."""
    c = _SPLITTER * a
    big = c - a
    hi = c - big
    return hi, a - hi


@njit
def _two_product(a, b):
    """x + y = a b exactly, x = fl(a b) (Dekker's TwoProduct)."""
    x = a * b
    ahi, alo = _split(a)
    bhi, blo = _split(b)
    err = x - ahi * bhi - alo * bhi - ahi * blo
    return x, alo * blo - err


@njit
def _grow(e, elen, b, h):
    """h = e + b exactly (Shewchuk's Grow-Expansion with zero elimination); h may be e. Returns h's length."""
    q = b
    hlen = 0
    for i in range(elen):
        q, err = _two_sum(q, e[i])
        if err != 0.0:
            h[hlen] = err
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@njit
def _add(e, elen, f, flen, sign, h):
    """h = e + sign f exactly (h holds elen + flen components and is not f). Returns h's length."""
    for i in range(elen):
        h[i] = e[i]
    hlen = elen
    for j in range(flen):
        hlen = _grow(h, hlen, sign * f[j], h)
    return hlen


@njit
def _scale(e, elen, b, h):
    """h = b e exactly (Shewchuk's Scale-Expansion with zero elimination; h holds 2 elen components)."""
    q, err = _two_product(e[0], b)
    hlen = 0
    if err != 0.0:
        h[hlen] = err
        hlen += 1
    for i in range(1, elen):
        p1, p0 = _two_product(e[i], b)
        s, err = _two_sum(q, p0)
        if err != 0.0:
            h[hlen] = err
            hlen += 1
        q = p1 + s  # Fast-Two-Sum: |p1| >= |s|
        err = s - (q - p1)
        if err != 0.0:
            h[hlen] = err
            hlen += 1
    if q != 0.0 or hlen == 0:
        h[hlen] = q
        hlen += 1
    return hlen


@njit
def _minor2(points, i, j, out):
    """out = x_i y_j − x_j y_i exactly (4 components). Returns its length."""
    p1, p0 = _two_product(points[i, 0], points[j, 1])
    q1, q0 = _two_product(points[j, 0], points[i, 1])
    out[0] = p0
    out[1] = p1
    return _add(out[:2], 2, np.array([q0, q1]), 2, -1.0, out)


@njit
def _orient3d_exact(points, a, b, c, d):
    """The exact det[a − d; b − d; c − d] as the largest component of its expansion (Shewchuk's orient3dexact:
    the 4 × 4 determinant of rows (x, y, z, 1) expanded along z into exact 2 × 2 minors of x, y)."""
    ab, bc, cd, da, ac, bd = (np.empty(4), np.empty(4), np.empty(4), np.empty(4), np.empty(4), np.empty(4))
    abn, bcn, cdn = _minor2(points, a, b, ab), _minor2(points, b, c, bc), _minor2(points, c, d, cd)
    dan, acn, bdn = _minor2(points, d, a, da), _minor2(points, a, c, ac), _minor2(points, b, d, bd)
    tmp = np.empty(8)
    cda, dab, abc, bcd = np.empty(12), np.empty(12), np.empty(12), np.empty(12)
    n = _add(cd, cdn, da, dan, 1.0, tmp)
    cdan = _add(tmp, n, ac, acn, 1.0, cda)  # cd + da + ac
    n = _add(da, dan, ab, abn, 1.0, tmp)
    dabn = _add(tmp, n, bd, bdn, 1.0, dab)  # da + ab + bd
    n = _add(ab, abn, bc, bcn, 1.0, tmp)
    abcn = _add(tmp, n, ac, acn, -1.0, abc)  # ab + bc − ac
    n = _add(bc, bcn, cd, cdn, 1.0, tmp)
    bcdn = _add(tmp, n, bd, bdn, -1.0, bcd)  # bc + cd − bd
    adet, bdet, cdet, ddet = np.empty(24), np.empty(24), np.empty(24), np.empty(24)
    an = _scale(bcd, bcdn, points[a, 2], adet)
    bn = _scale(cda, cdan, -points[b, 2], bdet)
    cn = _scale(dab, dabn, points[c, 2], cdet)
    dn = _scale(abc, abcn, -points[d, 2], ddet)
    half1, half2, total = np.empty(48), np.empty(48), np.empty(96)
    n1 = _add(adet, an, bdet, bn, 1.0, half1)
    n2 = _add(cdet, cn, ddet, dn, 1.0, half2)
    n = _add(half1, n1, half2, n2, 1.0, total)
    return total[n - 1]


@njit
def orient3d(points, a, b, c, p):
    """((b − a) × (c − a)) · (p − a) for rows a, b, c, p of ``points`` (n, 3) float64, with its sign exact: > 0
    when p is above the plane of the counter-clockwise triangle (a, b, c), 0 when the four points are coplanar.

    Shewchuk 1997, orient3d: the floating-point determinant with p as origin when it exceeds the stage-A error
    bound, else the exact determinant (only its sign and zero are then meaningful, not its magnitude)."""
    adx, ady, adz = points[a, 0] - points[p, 0], points[a, 1] - points[p, 1], points[a, 2] - points[p, 2]
    bdx, bdy, bdz = points[b, 0] - points[p, 0], points[b, 1] - points[p, 1], points[b, 2] - points[p, 2]
    cdx, cdy, cdz = points[c, 0] - points[p, 0], points[c, 1] - points[p, 1], points[c, 2] - points[p, 2]
    bdxcdy, cdxbdy = bdx * cdy, cdx * bdy
    cdxady, adxcdy = cdx * ady, adx * cdy
    adxbdy, bdxady = adx * bdy, bdx * ady
    det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady)
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz) + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    # det[a − p; b − p; c − p] = −((b − a) × (c − a)) · (p − a)
    if abs(det) > _O3D_ERRBOUND_A * permanent:
        return -det
    return -_orient3d_exact(points, a, b, c, p)


@njit
def _difference(points, i, j, k):
    """points[i, k] − points[j, k] as a double-double (hi, lo), exactly."""
    return _two_sum(points[i, k], -points[j, k])


@njit
def _cross_component(uy, uyl, uz, uzl, vy, vyl, vz, vzl):
    """(uy + uyl)(vz + vzl) − (uz + uzl)(vy + vyl) to a few ulps (terms of order ε² |u| |v| dropped)."""
    p1, p0 = _two_product(uy, vz)
    q1, q0 = _two_product(uz, vy)
    s, err = _two_sum(p1, -q1)
    low = err + p0 - q0 + (uy * vzl + uyl * vz) - (uz * vyl + uzl * vy)
    return s + low


@njit
def accurate_cross(points, a, b, c, out):
    """Write (b − a) × (c − a) for rows a, b, c of ``points`` (n, 3) float64 into ``out`` (3,), each component
    within a few ulps of its exact value (see the module docstring); returns ``out``."""
    ux, uxl = _difference(points, b, a, 0)
    uy, uyl = _difference(points, b, a, 1)
    uz, uzl = _difference(points, b, a, 2)
    vx, vxl = _difference(points, c, a, 0)
    vy, vyl = _difference(points, c, a, 1)
    vz, vzl = _difference(points, c, a, 2)
    out[0] = _cross_component(uy, uyl, uz, uzl, vy, vyl, vz, vzl)
    out[1] = _cross_component(uz, uzl, ux, uxl, vz, vzl, vx, vxl)
    out[2] = _cross_component(ux, uxl, uy, uyl, vx, vxl, vy, vyl)
    return out
