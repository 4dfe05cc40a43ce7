"""Validation at the public boundary: the checks behind the validation contract (README, "Validation contract").

Every public function checks its arguments here before any kernel runs, and raises ``ValueError`` or
``TypeError`` naming the argument (and, for arrays, the first offending index). Inputs are never modified:
arrays are converted to fresh contiguous float64 copies when the kernels could write to them.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = [
    "MAX_MAGNITUDE",
    "MAX_STEPS",
    "as_float",
    "as_positive",
    "as_nonnegative",
    "as_fraction",
    "as_float_array",
    "as_choice",
    "as_count",
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


def as_choice(value, name: str, choices) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, one of {sorted(choices)}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"unknown {name} {value!r}; expected one of {sorted(choices)}")
    return value


def _shape_text(shape) -> str:
    return "(" + ", ".join("n" if s is None else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
