"""Initial state of the confined gas: non-overlapping centres and velocities at the requested temperature.

Geometry: walls at ±L/2, so a sphere of radius r keeps its centre in the reachable cube
[−L/2 + r, L/2 − r]³ of side L' = L − 2r; periodic boxes use the whole cube [−L/2, L/2)³. The packing fraction
is η = Σ (π/6) σ_i³ / V' with σ = 2r and V' = L'³ (periodic: L³).

Placement: random sequential addition (a uniform random centre, rejected if it overlaps an earlier sphere, found
with a cell list) for dilute gases, and a face-centred cubic lattice (a random subset of its sites) that melts
during equilibration for dense fluids up to η = 0.45. Both stop after a bounded number of trials: an impossible
packing raises ValueError, it never hangs.
"""
from __future__ import annotations

import math

import numpy as np

from engine._config import njit
from engine._validate import as_choice, as_count, as_float_array, as_positive
from engine.gas.periodic import check_periodic_box

__all__ = ["reachable_side", "packing_fraction", "radius_for_packing", "place_spheres", "draw_velocities",
           "MAX_PACKING"]

#: the densest fluid the lattice start is documented for (the issue: "dense fluids up to η = 0.45")
MAX_PACKING = 0.45
#: random sequential addition is tried below this packing fraction (it jams near η ≈ 0.38)
_RANDOM_UP_TO = 0.25


def reachable_side(box: float, radius: float, boundary: str) -> float:
    """Side of the cube the centres can reach: L − 2r with walls, L when periodic."""
    return box - 2.0 * radius if boundary == "walls" else box


def packing_fraction(radii, box: float, boundary: str = "walls") -> float:
    """The packing fraction η = Σ π σ_i³/6 / V' of spheres in a cube of side ``box``.

    σ_i = 2 r_i; V' = (L − 2 r̄)³ with walls (r̄ the mean radius: the volume the centres can reach), L³ when
    periodic.

    Parameters
    ----------
    radii : float or array_like, shape (n,)
        The radii, > 0 (a scalar is one sphere).
    box : float
        The side L of the cube, > 0.
    boundary : {"walls", "periodic"}, default "walls"
        Hard walls at ±L/2, or periodic images.

    Returns
    -------
    float
        η, >= 0.

    Raises
    ------
    ValueError
        For an empty ``radii``, a radius <= 0, spheres too large for the box (L − 2r̄ <= 0), or an unknown
        ``boundary``.
    """
    boundary = as_choice(boundary, "boundary", ("walls", "periodic"))
    box = as_positive(box, "box")
    r = np.atleast_1d(as_float_array(radii, "radii"))
    if r.ndim != 1 or r.shape[0] == 0:
        raise ValueError(f"radii must be a positive scalar or a non-empty (n,) array, got shape {np.shape(radii)}")
    bad = np.flatnonzero(r <= 0.0)
    if bad.size:
        raise ValueError(f"radii must be > 0: radii[{bad[0]}] = {float(r[bad[0]])!r}")
    side = reachable_side(box, float(r.mean()), boundary)
    if side <= 0.0:
        raise ValueError(f"radii too large for the box: the centres' reachable side L - 2 r = {side!r} <= 0")
    return float(np.sum(math.pi / 6.0 * (2.0 * r) ** 3) / side / side / side)


def radius_for_packing(n: int, eta: float, box: float = 10.0, boundary: str = "walls") -> float:
    """The common radius of n spheres that fill a cube of side ``box`` at packing fraction η.

    With c = (6η/(nπ))^(1/3): σ = cL/(1 + c) with walls (the inverse of ``packing_fraction``), σ = cL periodic;
    the radius is σ/2.

    Parameters
    ----------
    n : int
        The number of spheres, >= 1.
    eta : float
        The packing fraction, in (0, 1).
    box : float, default 10.0
        The side L, > 0.
    boundary : {"walls", "periodic"}, default "walls"
        As for ``packing_fraction``.

    Returns
    -------
    float
        The radius r > 0.

    Raises
    ------
    ValueError
        For ``eta`` outside (0, 1), ``n < 1``, ``box <= 0``, or an unknown ``boundary``.
    """
    n = as_count(n, "n", 1)
    eta = as_positive(eta, "eta")
    if eta >= 1.0:
        raise ValueError(f"eta must be < 1, got {eta!r}")
    box = as_positive(box, "box")
    boundary = as_choice(boundary, "boundary", ("walls", "periodic"))
    c = (6.0 * eta / (n * math.pi)) ** (1.0 / 3.0)
    sigma = c * box / (1.0 + c) if boundary == "walls" else c * box
    return sigma / 2.0


@njit
def _overlaps_placed(p, ri, c, out, r, head, nxt, ncell, periodic, side):
    """Whether a sphere of radius ri at p (in cell c) overlaps one of the spheres placed in the 27 cells around
    c (periodic: minimum images over the period ``side``)."""
    for dx in range(-1, 2):
        for dy in range(-1, 2):
            for dz in range(-1, 2):
                cx, cy, cz = c[0] + dx, c[1] + dy, c[2] + dz
                if periodic:
                    cx %= ncell
                    cy %= ncell
                    cz %= ncell
                elif cx < 0 or cy < 0 or cz < 0 or cx >= ncell or cy >= ncell or cz >= ncell:
                    continue
                j = head[(cx * ncell + cy) * ncell + cz]
                while j >= 0:
                    d2 = 0.0
                    for k in range(3):
                        d = p[k] - out[j, k]
                        if periodic:
                            d -= side * np.round(d / side)
                        d2 += d * d
                    s = ri + r[j]
                    if d2 < s * s:
                        return True
                    j = nxt[j]
    return False


@njit
def _random_sequential_kernel(n, r, lo, side, periodic, max_trials, seed):
    """Random sequential addition with a cell list of cell side >= the largest diameter (Ericson 7.1).

    Returns (centres (n, 3), number placed): stops early when one sphere needs more than max_trials tries.
    """
    np.random.seed(seed)
    out = np.zeros((n, 3))
    rmax = 0.0
    for i in range(n):
        rmax = max(rmax, r[i])
    if periodic:
        # the cells tile the period exactly, so that wrapped neighbour cells are the true neighbours
        total = side
        origin = lo
    else:
        total = side + 2.0 * rmax
        origin = lo - rmax
    ncell = max(1, min(int(total / (2.0 * rmax)) if rmax > 0.0 else 1, 64))
    width = total / ncell
    head = -np.ones(ncell * ncell * ncell, dtype=np.int64)
    nxt = -np.ones(n, dtype=np.int64)
    for i in range(n):
        placed = False
        for _ in range(max_trials):
            p = np.empty(3)
            hi_r = r[i] if not periodic else 0.0
            for k in range(3):
                span = side - 2.0 * hi_r if not periodic else side
                p[k] = lo + hi_r + np.random.random() * span
            c = np.empty(3, dtype=np.int64)
            for k in range(3):
                c[k] = min(ncell - 1, max(0, int((p[k] - origin) / width)))
            if not _overlaps_placed(p, r[i], c, out, r, head, nxt, ncell, periodic, side):
                out[i] = p
                cell = (c[0] * ncell + c[1]) * ncell + c[2]
                nxt[i] = head[cell]
                head[cell] = i
                placed = True
                break
        if not placed:
            return out, i
    return out, n


def _fcc_sites(n, sigma, lo, side, periodic):
    """The smallest face-centred cubic lattice with >= n sites in the cube, nearest neighbours a/√2 apart."""
    k = max(1, math.ceil((n / 4.0) ** (1.0 / 3.0)))
    a = side / k
    basis = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]])
    cells = np.stack(np.meshgrid(np.arange(k), np.arange(k), np.arange(k), indexing="ij"), axis=-1).reshape(-1, 3)
    offset = 0.0 if periodic else 0.25
    sites = ((cells[:, None, :] + basis[None, :, :] + offset) * a).reshape(-1, 3) + lo
    # with walls the outermost sites sit a/4 inside the faces of the reachable cube; periodic images of the
    # lattice are a lattice again, so the nearest-neighbour distance a/√2 holds across the boundary too
    spacing = a / math.sqrt(2.0) if len(sites) > 1 else math.inf
    return sites, spacing


def place_spheres(n: int, radii: np.ndarray, box: float, boundary: str, rng: np.random.Generator,
                  initial: str = "auto") -> np.ndarray:
    """Non-overlapping centres (n, 3) in the reachable cube; ValueError when the packing is impossible.

    initial: "random" (random sequential addition), "lattice" (FCC sites, a random subset) or "auto" (random
    below η = 0.25, else the lattice; the other one when the first cannot place the spheres).

    The lattice: k³ cubic cells of side a, k the smallest with 4k³ >= n, and the sites lo + a (i + b + s) for i in
    {0 .. k − 1}³ and b in the FCC basis {(0, 0, 0), (½, ½, 0), (½, 0, ½), (0, ½, ½)}. With walls a = (L − 2r)/k,
    lo = −L/2 + r and s = ¼ (the outermost sites a/4 inside the faces of the reachable cube); periodic a = L/k,
    lo = −L/2 and s = 0 (the lattice origin at the box corner (−L/2, −L/2, −L/2), every site in [−L/2, L/2)).
    """
    periodic = boundary == "periodic"
    rmean = float(radii.mean())
    rmax = float(radii.max())
    eta = packing_fraction(radii, box, boundary)
    if not periodic and box - 2.0 * rmax <= 0.0:
        raise ValueError(f"radius {rmax!r} does not fit in a box of side {box!r} (need 2 r < box)")
    if eta > MAX_PACKING * (1.0 + 1e-9):
        raise ValueError(f"packing fraction {eta:.4g} is too dense: the gas is supported up to eta = {MAX_PACKING}")
    lo = -box / 2.0 + (0.0 if periodic else rmean)
    side = reachable_side(box, rmean, boundary)
    if initial == "auto":
        first = "random" if eta <= _RANDOM_UP_TO or np.ptp(radii) > 0.0 else "lattice"
        second = "lattice" if first == "random" else "random"
        try:
            return place_spheres(n, radii, box, boundary, rng, first)
        except ValueError as error:
            if second == "lattice" and np.ptp(radii) > 0.0:
                raise
            try:
                return place_spheres(n, radii, box, boundary, rng, second)
            except ValueError:
                raise error from None
    if initial == "random":
        seed = int(rng.integers(0, 2**31 - 1))
        # with unequal radii each sphere keeps its own reachable cube: sample in [−L/2 + r_i, L/2 − r_i]
        lo_r = -box / 2.0
        side_r = box
        out, placed = _random_sequential_kernel(n, radii, lo_r, side_r, periodic, 20_000, seed)
        if placed < n:
            raise ValueError(f"cannot place {n} spheres without overlap (packing fraction {eta:.4g}): random "
                             f"placement stopped after {placed}; use a smaller radius or initial='lattice'")
        return out
    # lattice
    if np.ptp(radii) > 0.0:
        raise ValueError("the lattice start needs equal radii; use initial='random' for unequal radii")
    sigma = 2.0 * rmax
    sites, spacing = _fcc_sites(n, sigma, lo, side, periodic)
    if spacing < sigma:
        raise ValueError(f"cannot place {n} spheres of radius {rmax!r} on a lattice in a box of side {box!r}: "
                         f"the packing (eta = {eta:.4g}) is impossible for this box")
    pick = np.sort(rng.choice(len(sites), size=n, replace=False))
    return np.ascontiguousarray(sites[pick])


def draw_velocities(masses: np.ndarray, temperature: float, boundary: str, rng: np.random.Generator) -> np.ndarray:
    """Maxwell–Boltzmann velocities (n, 3): each component normal with variance kT/m_i, then (periodic) the
    centre-of-mass velocity removed, then scaled so that 2K/(3n) = kT exactly."""
    n = masses.shape[0]
    v = rng.standard_normal((n, 3)) * np.sqrt(temperature / masses)[:, None]
    if boundary == "periodic":
        v -= (masses[:, None] * v).sum(axis=0) / masses.sum()
    kinetic = 0.5 * float(np.sum(masses[:, None] * v * v))
    if kinetic > 0.0:
        v *= math.sqrt(1.5 * n * temperature / kinetic)
    return v


def per_sphere(value, name, n):
    """A positive scalar or (n,) array as a fresh (n,) float64 array."""
    arr = np.asarray(value)
    if arr.ndim == 0:
        return np.full(n, as_positive(value, name))
    out = as_float_array(value, name, shape=(n,))
    bad = np.flatnonzero(out <= 0.0)
    if bad.size:
        raise ValueError(f"{name} must be > 0: {name}[{bad[0]}] = {float(out[bad[0]])!r}")
    return out


def check_start_positions(positions, radii, box, periodic):
    """Validated start positions (n, 3): inside the reachable box (walls) or wrapped (periodic), no overlap."""
    from engine.broadphase import sphere_pairs

    n = radii.shape[0]
    p = as_float_array(positions, "positions", shape=(n, 3))
    if not periodic:
        half = box / 2.0
        outside = (p < -half + radii[:, None]) | (p > half - radii[:, None])
        if outside.any():
            i, k = (int(x) for x in np.argwhere(outside)[0])
            raise ValueError(f"positions[{i}] is outside the reachable box: coordinate {k} = {float(p[i, k])!r}, "
                             f"limit ±{float(half - radii[i])!r}")
    else:
        p = p - box * np.floor((p + box / 2.0) / box)
    if periodic:
        # the pairs closer than the largest contact distance under minimum images (scipy's periodic k-d tree)
        from scipy.spatial import cKDTree

        tree = cKDTree(np.clip(p + box / 2.0, 0.0, np.nextafter(box, 0.0)), boxsize=box)
        for i, j in sorted(tree.query_pairs(2.0 * float(radii.max()))):
            d = p[i] - p[j]
            d -= box * np.round(d / box)
            if float(d @ d) < (radii[i] + radii[j]) ** 2:
                raise ValueError(f"positions overlap: spheres {i} and {j} are closer than r_{i} + r_{j}")
        return p
    pairs = sphere_pairs(p, radii)
    for i, j in pairs:
        d = p[i] - p[j]
        if float(d @ d) < (radii[i] + radii[j]) ** 2:
            raise ValueError(f"positions overlap: spheres {i} and {j} are closer than r_{i} + r_{j}")
    return p


def check_gas_state(positions, velocities, radii, masses, box, periodic, *, allow_overlap=False):
    """Validate a gas state for ``EventDrivenGas`` / ``SteppedGas``; returns fresh arrays
    (positions (n, 3), velocities (n, 3), radii (n,), masses (n,)), box and periodic.

    radii and masses: positive scalars or (n,) arrays; box > 0; periodic a bool; the spheres must fit (2 r < box
    with walls, ``check_periodic_box`` periodic), lie inside the reachable box and not overlap —
    unless ``allow_overlap``: the stepped method (the chapter's frame loop) starts from and resolves overlaps."""
    box = as_positive(box, "box")
    if not isinstance(periodic, bool | np.bool_):
        raise TypeError(f"periodic must be a bool, got {type(periodic).__name__}")
    p = as_float_array(positions, "positions", shape=(None, 3), min_rows=1)
    n = p.shape[0]
    r = per_sphere(radii, "radii", n)
    m = per_sphere(masses, "masses", n)
    v = as_float_array(velocities, "velocities", shape=(n, 3))
    rmax = float(r.max())
    if not periodic and 2.0 * rmax >= box:
        raise ValueError(f"radii must be < box/2: radius {rmax!r}, box {box!r}")
    if periodic:
        check_periodic_box(box, rmax, "radii")
    periodic = bool(periodic)
    if allow_overlap:
        p = check_start_positions(p, np.zeros(n), box, periodic)  # inside the box (walls) or wrapped, any overlap
        if not periodic:
            limit = box / 2.0 - r
            outside = np.abs(p) > limit[:, None]
            if outside.any():
                i, k = (int(x) for x in np.argwhere(outside)[0])
                raise ValueError(f"positions[{i}] is outside the reachable box: coordinate {k} = {float(p[i, k])!r}, "
                                 f"limit ±{float(limit[i])!r}")
        return p, v, r, m, box, periodic
    return check_start_positions(p, r, box, periodic), v, r, m, box, periodic
