"""Validation at the public boundary: the checks behind the validation contract (README, "Validation contract").

Every public function checks its arguments here before any kernel runs, and raises ``ValueError`` or
``TypeError`` naming the argument (and, for arrays, the first offending index). Inputs are never modified:
arrays are converted to fresh contiguous float64 copies when the kernels could write to them.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ._config import njit

__all__ = [
    "MAX_MAGNITUDE",
    "MAX_STEPS",
    "as_float",
    "as_positive",
    "as_nonnegative",
    "as_fraction",
    "as_float_array",
    "as_choice",
    "check_callable",
    "as_count",
    "as_max_iterations",
    "as_radii",
    "as_half_extents",
    "check_offsets",
    "check_pairs",
    "check_index",
    "pair_indices",
    "check_orthonormal_rows",
    "orthonormal_error",
    "unit_scale_exponent",
]


#: the largest magnitude any input value may have: squared distances and products of two inputs stay finite
#: (1e150² = 1e300 < 1.8e308), so no overflow can turn into inf − inf = NaN inside a kernel
MAX_MAGNITUDE = 1e150


#: the most time steps (t_end / dt) a public call may ask for: a typo in dt gets an error, not a hang
MAX_STEPS = 10**9


def _reject_non_real(value, name: str):
    if isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be a real number, got a bool")
    if isinstance(value, complex | np.complexfloating):
        raise TypeError(f"{name} must be a real number, got complex {value!r}")
    if not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")


def as_float(value, name: str) -> float:
    """A finite real scalar as a Python float; ValueError for NaN/inf, TypeError for non-reals."""
    if isinstance(value, np.ndarray):
        if value.ndim != 0:
            raise ValueError(f"{name} must be a scalar, got an array of shape {value.shape}")
        value = value[()]
    _reject_non_real(value, name)
    out = float(value)
    if not math.isfinite(out):
        raise ValueError(f"{name} must be finite, got {out!r}")
    if abs(out) > MAX_MAGNITUDE:
        raise ValueError(f"{name} must have magnitude <= {MAX_MAGNITUDE:g}, got {out!r}")
    return out


def as_positive(value, name: str) -> float:
    out = as_float(value, name)
    if out <= 0.0:
        raise ValueError(f"{name} must be > 0, got {out!r}")
    return out


def as_nonnegative(value, name: str) -> float:
    out = as_float(value, name)
    if out < 0.0:
        raise ValueError(f"{name} must be >= 0, got {out!r}")
    return out


def as_fraction(value, name: str) -> float:
    """A real number in the closed interval [0, 1]."""
    out = as_float(value, name)
    if not 0.0 <= out <= 1.0:
        raise ValueError(f"{name} must lie in [0, 1], got {out!r}")
    return out


def as_float_array(value, name: str, *, ndim: int | None = None, shape: tuple | None = None,
                   min_rows: int = 0) -> np.ndarray:
    """A finite float64 array (a fresh C-contiguous copy), checked for dtype, rank, shape and NaN/inf.

    ``shape`` may hold ``None`` for a free dimension, e.g. ``(None, 3)``.
    """
    try:
        arr = np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged nested lists
        raise ValueError(f"{name} must be a rectangular numeric array: {exc}") from None
    if arr.dtype == object or arr.dtype.kind not in "biuf":
        if arr.dtype.kind == "c":
            raise TypeError(f"{name} must hold real numbers, got complex dtype {arr.dtype}")
        raise TypeError(f"{name} must be a numeric array, got dtype {arr.dtype}")
    if arr.dtype.kind == "b":
        raise TypeError(f"{name} must hold real numbers, got booleans")
    if shape is not None:
        ndim = len(shape)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} dimension(s), got shape {arr.shape}")
    if shape is not None:
        for axis, (want, got) in enumerate(zip(shape, arr.shape)):
            if want is not None and want != got:
                raise ValueError(f"{name} must have shape {_shape_text(shape)}, got {arr.shape} (axis {axis})")
    if arr.ndim >= 1 and arr.shape[0] < min_rows:
        raise ValueError(f"{name} needs at least {min_rows} row(s), got {arr.shape[0]}")
    out = np.array(arr, dtype=np.float64, order="C", copy=True)
    bad = ~(np.abs(out) <= MAX_MAGNITUDE)  # one pass catches NaN, ±inf and overflow-prone magnitudes
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        value = out[index]
        where = f"{name}[{', '.join(str(i) for i in index)}] = {float(value)!r}" if index else repr(float(value))
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite: {where}")
        raise ValueError(f"{name} must have magnitude <= {MAX_MAGNITUDE:g}: {where}")
    return out


#: the largest count a public function accepts (indices and sizes stay far inside int64)
MAX_COUNT = 2**62


def as_count(value, name: str, minimum: int = 0, maximum: int | None = MAX_COUNT) -> int:
    """An integer (Python or numpy int, not a bool, not a float) in [minimum, maximum]."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, got {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{name} must be <= {maximum}, got {value}")
    return value


def as_max_iterations(value, name: str = "max_iterations") -> int:
    """An iteration cap: an int >= 1 (``as_count`` with minimum 1)."""
    return as_count(value, name, minimum=1)


def as_radii(value, name: str, n: int, *, scalar: bool = True) -> np.ndarray:
    """Radii (n,) >= 0 as a fresh float64 array; with ``scalar`` a single number stands for n equal radii."""
    if scalar and np.ndim(value) == 0:
        return np.full(n, as_nonnegative(value, name))
    arr = as_float_array(value, name, shape=(n,))
    if (arr < 0).any():
        i = int(np.argmax(arr < 0))
        raise ValueError(f"{name} must be >= 0: {name}[{i}] = {float(arr[i])!r}")
    return arr


def as_half_extents(value, name: str, shape: tuple = (3,), *, zero: bool = False) -> np.ndarray:
    """Box half extents of the given ``shape`` ((3,) for one box, ``(n, 3)`` for n boxes; ``None`` for any
    length) as a fresh float64 array, every entry > 0, or >= 0 with ``zero=True`` (a flat box);
    the ValueError names the first offending entry in row-major order, e.g. ``half_extents[1] = -0.5``."""
    arr = as_float_array(value, name, shape=shape)
    bad = arr < 0 if zero else arr <= 0
    if bad.any():
        at = tuple(int(i) for i in np.unravel_index(int(np.argmax(bad)), arr.shape))
        raise ValueError(f"{name} must be {'>=' if zero else '>'} 0: {name}[{', '.join(map(str, at))}] = "
                         f"{float(arr[at])!r}")
    return arr


def check_offsets(offsets, n_points: int, name: str = "offsets") -> np.ndarray:
    """Offsets (S + 1,) of S packed point sets over ``n_points`` rows: integers from 0 to n_points, strictly
    increasing (every set has a point); returned as int64."""
    off = np.asarray(offsets)
    if off.dtype.kind not in "iu":
        raise TypeError(f"{name} must be an integer array, got dtype {off.dtype}")
    if off.ndim != 1 or off.shape[0] < 1:
        raise ValueError(f"{name} must have shape (n_shapes + 1,), got {off.shape}")
    off = off.astype(np.int64)
    if off[0] != 0 or off[-1] != n_points:
        raise ValueError(f"{name} must start at 0 and end at len(points) = {n_points}, got {off[0]}..{off[-1]}")
    steps = np.diff(off)
    if (steps < 1).any():
        s = int(np.argmax(steps < 1))
        raise ValueError(f"{name} must be strictly increasing (every shape needs a point): {name}[{s}] = "
                         f"{off[s]} >= {name}[{s + 1}] = {off[s + 1]}")
    return off


def check_pairs(pairs, n_shapes: int, name: str = "pairs") -> np.ndarray:
    """A (k, 2) int64 array of shape indices in [0, n_shapes); ValueError naming the first bad row."""
    arr = np.asarray(pairs)
    if arr.size == 0:
        return np.empty((0, 2), np.int64)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"{name} must be an integer array, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape (k, 2), got {arr.shape}")
    arr = np.ascontiguousarray(arr, dtype=np.int64)
    bad = (arr < 0) | (arr >= n_shapes)
    if bad.any():
        r = int(np.argwhere(bad)[0][0])
        raise ValueError(f"{name}[{r}] = {arr[r].tolist()} holds an index outside [0, {n_shapes})")
    return arr


def check_index(index, n_items: int, k: int | None, name: str) -> np.ndarray:
    """An (k,) int64 index array into [0, n_items); ValueError naming the first index out of range."""
    arr = np.asarray(index)
    if arr.dtype.kind not in "iu":
        raise TypeError(f"{name} must be an integer array, got dtype {arr.dtype}")
    if arr.ndim != 1 or (k is not None and arr.shape[0] != k):
        raise ValueError(f"{name} must have shape ({'k' if k is None else k},), got {arr.shape}")
    arr = np.ascontiguousarray(arr, dtype=np.int64)
    bad = (arr < 0) | (arr >= n_items)
    if bad.any():
        p = int(np.argmax(bad))
        raise ValueError(f"{name}[{p}] = {arr[p]} is outside [0, {n_items})")
    return arr


def pair_indices(n_a: int, n_b: int, index_a, index_b):
    """Resolve the (index_a, index_b) convention of batched pair tests: both None means aligned arrays (pair p =
    row p of A against row p of B, which must have the same length); both given selects rows. Returns two (k,)
    int64 arrays."""
    if index_a is None and index_b is None:
        if n_a != n_b:
            raise ValueError(f"without index arrays the A and B arrays must have the same length, got {n_a} and "
                             f"{n_b}")
        idx = np.arange(n_a, dtype=np.int64)
        return idx, idx
    if index_a is None or index_b is None:
        raise ValueError("index_a and index_b must be given together")
    ia = check_index(index_a, n_a, None, "index_a")
    ib = check_index(index_b, n_b, ia.shape[0], "index_b")
    return ia, ib


@njit(inline="always")
def orthonormal_error(axes, n):
    """max |A A^T − I| of block A = ``axes[n]`` of ``axes`` (m, 3, 3) float64: the measure that
    ``check_orthonormal_rows`` compares with its tolerance (a compiled kernel, callable from other kernels)."""
    worst = 0.0
    for i in range(3):
        for j in range(3):
            d = axes[n, i, 0] * axes[n, j, 0] + axes[n, i, 1] * axes[n, j, 1] + axes[n, i, 2] * axes[n, j, 2]
            if i == j:
                d -= 1.0
            worst = max(worst, abs(d))
    return worst


@njit
def _orthonormal_errors(axes, err):
    """max |A A^T − I| of every (3, 3) block of ``axes`` (n, 3, 3), into err (n,)."""
    for n in range(axes.shape[0]):
        err[n] = orthonormal_error(axes, n)


def check_orthonormal_rows(axes: np.ndarray, name: str, tol: float) -> None:
    """ValueError naming the first (3, 3) block of ``axes`` (n, 3, 3) float64 whose rows are not orthonormal to
    ``tol`` (max |A A^T − I|)."""
    if axes.shape[0]:
        err = np.empty(axes.shape[0])
        _orthonormal_errors(axes, err)
        if (err > tol).any():
            i = int(np.argmax(err > tol))
            raise ValueError(f"{name}[{i}] must be orthonormal rows (max |A A^T - I| = {err[i]:.3g})")


def check_callable(value, name: str, expected: str = "a callable"):
    """``value`` itself when it is callable, else a TypeError "``name`` must be ``expected``, got <its type>"
    (``expected`` says what the caller wants, e.g. "a callable f(t, y)")."""
    if not callable(value):
        raise TypeError(f"{name} must be {expected}, got {type(value).__name__}")
    return value


def as_choice(value, name: str, choices) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, one of {sorted(choices)}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"unknown {name} {value!r}; expected one of {sorted(choices)}")
    return value


def _shape_text(shape) -> str:
    return "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


def unit_scale_exponent(values: np.ndarray, axis=None):
    """The exponent e (int, or an int array along ``axis``) with |values| / 2^e < 1, and e = 0 for all zeros.

    Scaling by 2^-e is exact on normal floats, so a kernel that squares coordinates (or multiplies squares) can
    work on ``np.ldexp(values, -e)``, where nothing underflows or overflows, and its answer scaled back by 2^e
    (lengths), 2^(2e) (areas) or 2^(3e) (volumes) is the unit-scale answer scaled bit for bit.
    """
    return np.frexp(np.abs(values).max(axis=axis, initial=0.0))[1]
