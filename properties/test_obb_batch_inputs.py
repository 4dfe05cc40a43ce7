"""The batched OBB argument check read in place (``as_obbs(..., copy=False)``, used by ``overlap_obb_obb_batch``).

For float64 C-contiguous arrays the check runs in one compiled pass and the arrays are used without a copy. That
pass must accept exactly what the copying check accepts: on boxes with one entry spoilt at a random place (NaN,
±inf, a magnitude over ``MAX_MAGNITUDE``, a negative or ``-0.0`` half extent, axes tilted around
``ORTHONORMAL_TOL``, a wrong shape or dtype, a non-contiguous view), ``copy=False`` raises the same exception with
the same message as ``copy=True``, or returns the same values; and the batch never writes to its arguments.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine._validate import MAX_MAGNITUDE
from engine.bounding.obb import ORTHONORMAL_TOL, as_obbs
from engine.narrowphase.sat import overlap_obb_obb_batch
from properties.strategies.narrow import obbs

NAMES = ("centers", "axes", "half_extents")
SPOILS = ["nan", "inf", "-inf", "huge", "negative_half", "minus_zero_half", "tilt", "float32", "strided",
          "short_axes", "none"]


def _outcome(call):
    """("ok", arrays) or (exception type, message)."""
    try:
        return "ok", call()
    except (ValueError, TypeError) as exc:
        return type(exc), str(exc)


@st.composite
def spoilt_boxes(draw):
    boxes = draw(st.lists(obbs(), min_size=1, max_size=6))
    c = np.array([b.center for b in boxes])
    r = np.array([b.axes for b in boxes])
    e = np.array([b.half_extents for b in boxes])
    spoil = draw(st.sampled_from(SPOILS))
    i = draw(st.integers(0, len(boxes) - 1))
    k = draw(st.integers(0, 2))
    target = draw(st.sampled_from(["c", "r", "e"]))
    arrays = {"c": c, "r": r, "e": e}
    value = {"nan": np.nan, "inf": np.inf, "-inf": -np.inf, "huge": MAX_MAGNITUDE * draw(st.floats(1.0, 1e6))}
    if spoil in value:
        if target == "r":
            r[i, k, draw(st.integers(0, 2))] = value[spoil]
        else:
            arrays[target][i, k] = value[spoil]
    elif spoil == "negative_half":
        e[i, k] = -draw(st.floats(1e-300, 1e3))
    elif spoil == "minus_zero_half":
        e[i, k] = -0.0  # accepted (a flat box), by both paths
    elif spoil == "tilt":
        # scale one axis by 1 + s: |A A^T - I| ~ 2 s, drawn on both sides of ORTHONORMAL_TOL and close to it
        s = ORTHONORMAL_TOL * draw(st.one_of(st.sampled_from([0.25, 0.45, 0.499, 0.501, 0.55, 0.75, 1.0, 1.5]),
                                             st.floats(0.1, 2.0)))
        r[i, k] *= 1.0 + s
    elif spoil == "float32":
        arrays[target] = arrays[target].astype(np.float32)
    elif spoil == "strided":
        arrays[target] = np.repeat(arrays[target], 2, axis=0)[::2]
    elif spoil == "short_axes":
        arrays["r"] = r[:-1]
    return arrays["c"], arrays["r"], arrays["e"]


@given(spoilt_boxes())
def test_in_place_check_accepts_and_rejects_as_the_copying_check(boxes):
    c, r, e = boxes
    before = [a.copy() for a in boxes]
    copied = _outcome(lambda: as_obbs(c, r, e, NAMES))
    in_place = _outcome(lambda: as_obbs(c, r, e, NAMES, copy=False))
    assert in_place[0] == copied[0]
    if copied[0] == "ok":
        for got, want in zip(in_place[1], copied[1]):
            assert got.dtype == np.float64 and got.flags.c_contiguous
            np.testing.assert_array_equal(got, want)
    else:
        assert in_place[1] == copied[1]
    for a, b in zip(boxes, before):
        np.testing.assert_array_equal(a, b)


@given(spoilt_boxes(), st.data())
def test_batch_raises_as_the_copying_check_and_never_writes(boxes, data):
    c, r, e = boxes
    before = [a.copy() for a in boxes]
    copied = _outcome(lambda: as_obbs(c, r, e, ("centers_b", "axes_b", "half_extents_b")))
    good = (np.zeros((1, 3)), np.eye(3)[None], np.ones((1, 3)))
    n = c.shape[0]
    ia = np.zeros(n, np.int64)
    got = _outcome(lambda: overlap_obb_obb_batch(*good, c, r, e, ia, np.arange(n)))
    if copied[0] == "ok":
        assert got[0] == "ok" and got[1].shape == (n,)
    else:
        assert got == copied
    for a, b in zip(boxes, before):
        np.testing.assert_array_equal(a, b)


def test_in_place_check_returns_the_arrays_themselves():
    c, r, e = np.zeros((2, 3)), np.stack([np.eye(3)] * 2), np.ones((2, 3))
    out = as_obbs(c, r, e, copy=False)
    assert all(a is b for a, b in zip(out, (c, r, e)))
    assert not any(a is b for a, b in zip(as_obbs(c, r, e), (c, r, e)))
    with pytest.raises(ValueError, match=r"half_extents\[1, 2\]"):
        as_obbs(c, r, np.array([[1.0, 1.0, 1.0], [1.0, 1.0, -1.0]]), copy=False)


def _no_name_prefixes_another(names) -> bool:
    return not any(a != b and a.startswith(b) for a in names for b in names) and len(set(names)) == 3


@given(st.lists(obbs(), min_size=1, max_size=4), st.sampled_from([0, 1, 2]),
       st.sampled_from(["shape", "nan", "value"]), st.booleans(),
       st.tuples(*[st.text("abcxyz_", min_size=1, max_size=8)] * 3).filter(_no_name_prefixes_another))
def test_each_refusal_starts_with_the_name_given_for_that_argument(boxes, which, spoil, copy, names):
    """The three names are the caller's (``overlap_obb_obb_batch`` passes ``centers_b`` ...): a refusal of the
    k-th argument starts with names[k], whichever path (copying or in place) checks it."""
    arrays = [np.array([b.center for b in boxes]), np.array([b.axes for b in boxes]),
              np.array([b.half_extents for b in boxes])]
    target = arrays[which]
    if spoil == "shape":  # one column too few (axes: one row of each box too few)
        arrays[which] = target[..., :2] if which != 1 else target[:, :2]
    elif spoil == "nan":
        target.reshape(-1)[-1] = np.nan
    elif which == 1:  # axes stretched well past ORTHONORMAL_TOL
        target[-1] *= 1.5
    elif which == 2:
        target[-1, 0] = -1.0
    else:  # a centre beyond MAX_MAGNITUDE
        target[-1, 0] = 2.0 * MAX_MAGNITUDE
    with pytest.raises(ValueError) as info:
        as_obbs(*arrays, names, copy=copy)
    assert str(info.value).startswith(names[which]), (names, which, str(info.value))
