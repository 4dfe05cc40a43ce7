"""Fuzz every public callable with hostile arguments: the validation contract of README, as a property.

For each entry of ``properties/fuzz_registry.py`` Hypothesis draws VALID keyword arguments, then replaces one of
them with a hostile value. The contract (README "Validation contract"):

- NaN or ±inf anywhere in an array or scalar           -> ValueError naming the argument (and, for arrays, the
                                                           first offending index: ``points[3, 1]``);
- complex, object, string, None (unless optional)      -> TypeError or ValueError naming the argument;
- an unknown method name / a fractional count          -> ValueError or TypeError naming the argument;
- integer arrays, nested lists                          -> the same result as the float64 array;
- anything else (wrong rank, empty, huge or tiny
  magnitudes, negative values)                          -> a clean ValueError/TypeError naming the argument,
                                                           an iteration-cap error, or a result without NaN;
- never: another exception type (a crash), a hang (a watchdog kills the run), a NaN in an output, or a modified
  input array.
"""
from __future__ import annotations

import dataclasses
import faulthandler
import math
import numbers

import numpy as np
import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from engine.gas import GasEventCapReached
from engine.narrowphase import EPANotConverged, GJKNotConverged, TOINotConverged

from .fuzz_registry import NOT_CALLABLE_API, PUBLIC_MODULES, REGISTRY

#: the documented "cap reached" errors: a clean refusal, not a crash
CAP_ERRORS = (GJKNotConverged, EPANotConverged, TOINotConverged, GasEventCapReached)

ARRAY_STRICT = ("nan", "posinf", "neginf", "complex", "object", "string", "none")
ARRAY_SAME = ("int", "list")
ARRAY_WEAK = ("ravel", "add_axis", "empty", "huge", "tiny", "negate", "transpose", "fortran")
SCALAR_STRICT = ("nan", "posinf", "neginf", "string", "complex", "none")
SCALAR_WEAK = ("negative", "zero", "huge", "tiny", "array")
INT_STRICT = ("string", "none", "fraction")
INT_WEAK = ("negative", "zero", "huge")
STR_STRICT = ("unknown", "number", "none")


@pytest.fixture(autouse=True)
def watchdog():
    """A hang (a loop without its iteration cap) kills the run with a traceback instead of stalling CI."""
    faulthandler.dump_traceback_later(600, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def _kind(value) -> str:
    if isinstance(value, np.ndarray):
        return "int_array" if value.dtype.kind in "iu" else "array"
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, numbers.Integral):
        return "int"
    if isinstance(value, numbers.Real):
        return "scalar"
    if isinstance(value, str):
        return "str"
    return "other"


def _corrupt(kind: str, how: str, value, data):
    """The hostile replacement ``how`` of a valid ``value``; returns (new value, first bad index or None)."""
    if kind in ("array", "int_array"):
        arr = np.asarray(value)
        if how in ("nan", "posinf", "neginf"):
            if arr.size == 0:
                return None, None
            bad = np.array(arr, dtype=np.float64)
            flat = data.draw(st.integers(0, arr.size - 1), label="bad index")
            bad.flat[flat] = {"nan": np.nan, "posinf": np.inf, "neginf": -np.inf}[how]
            first = tuple(int(i) for i in np.unravel_index(flat, arr.shape))
            return bad, first
        table = {
            "complex": lambda: arr.astype(np.complex128) + 1j,
            "object": lambda: np.array([object()] * max(arr.size, 1), dtype=object),
            "string": lambda: "not an array",
            "none": lambda: None,
            "int": lambda: np.round(arr).astype(np.int64),
            "list": lambda: arr.tolist(),
            "ravel": lambda: arr.ravel(),
            "add_axis": lambda: arr[None, ...],
            "empty": lambda: arr[:0],
            "huge": lambda: np.array(arr, dtype=np.float64) * 1e300,
            "tiny": lambda: np.array(arr, dtype=np.float64) * 1e-300,
            "negate": lambda: -np.array(arr),
            "transpose": lambda: np.array(arr).T,
            "fortran": lambda: np.asfortranarray(arr),
        }
        return table[how](), None
    if kind == "scalar":
        table = {"nan": math.nan, "posinf": math.inf, "neginf": -math.inf, "string": "1.0", "complex": 1 + 1j,
                 "none": None, "negative": -abs(value) - 1.0, "zero": 0.0, "huge": 1e300, "tiny": 1e-300,
                 "array": np.array([value, value])}
        return table[how], None
    if kind == "int":
        table = {"string": "3", "none": None, "fraction": 2.5, "negative": -abs(value) - 1, "zero": 0,
                 "huge": 2**70}
        return table[how], None
    if kind == "str":
        return {"unknown": "no-such-choice", "number": 3, "none": None}[how], None
    raise AssertionError(kind)


def _walk(value, path="result"):
    """Yield (path, leaf) for every number or array reachable from a result."""
    if isinstance(value, np.ndarray):
        yield path, value
    elif isinstance(value, bool | str | type(None)):
        return
    elif isinstance(value, numbers.Number):
        yield path, value
    elif dataclasses.is_dataclass(value):
        for f in dataclasses.fields(value):
            yield from _walk(getattr(value, f.name), f"{path}.{f.name}")
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _walk(v, f"{path}[{k!r}]")
    elif isinstance(value, list | tuple):
        for i, v in enumerate(value):
            yield from _walk(v, f"{path}[{i}]")
    elif hasattr(value, "__dict__"):
        for k, v in vars(value).items():
            if not k.startswith("_"):
                yield from _walk(v, f"{path}.{k}")


def _assert_no_nan(result, nan_fields):
    for path, leaf in _walk(result):
        if path.split(".")[-1] in nan_fields:
            continue
        arr = np.asarray(leaf)
        if arr.dtype.kind in "fc":
            assert not np.isnan(arr).any(), f"NaN escaped in {path}"


def _same(x, y) -> bool:
    a, b = list(_walk(x)), list(_walk(y))
    if [p for p, _ in a] != [p for p, _ in b]:
        return False
    return all(np.array_equal(np.asarray(u), np.asarray(v), equal_nan=True) for (_, u), (_, v) in zip(a, b))


def _snapshot(kwargs):
    return {k: np.array(v, copy=True) for k, v in kwargs.items() if isinstance(v, np.ndarray)}


def _assert_untouched(kwargs, snap):
    for k, before in snap.items():
        numeric = before.dtype.kind in "biufc"
        assert np.array_equal(kwargs[k], before, equal_nan=numeric), f"the caller's array {k} was modified"


def _call(entry, kwargs):
    """(result, None) or (None, exception); the inputs are checked unmodified either way."""
    snap = _snapshot(kwargs)
    try:
        out = entry.call(**kwargs), None
    except (ValueError, TypeError, *CAP_ERRORS) as exc:
        out = None, exc
    _assert_untouched(kwargs, snap)
    return out


def _index_text(index) -> str:
    return str(index[0]) if len(index) == 1 else ", ".join(str(i) for i in index)


def _strategy_for(kind):
    return {
        "array": ARRAY_STRICT + ARRAY_SAME + ARRAY_WEAK,
        "int_array": ("posinf", "complex", "object", "string", "none", "list", "ravel", "add_axis", "empty",
                      "negate"),
        "scalar": SCALAR_STRICT + SCALAR_WEAK,
        "int": INT_STRICT + INT_WEAK,
        "str": STR_STRICT,
    }.get(kind, ())


def _settings(entry):
    base = settings()
    n = base.max_examples if entry.max_examples is None else min(base.max_examples, entry.max_examples)
    return settings(base, max_examples=n, suppress_health_check=[*base.suppress_health_check,
                                                                  HealthCheck.filter_too_much])


def test_every_public_name_is_fuzzed_or_exempt():
    fuzzed = {entry.name for entry in REGISTRY}
    for module in PUBLIC_MODULES:
        for name in module.__all__:
            assert name in fuzzed or name in NOT_CALLABLE_API, f"{module.__name__}.{name} is not fuzzed"
    assert not fuzzed & set(NOT_CALLABLE_API)


@pytest.mark.parametrize("entry", REGISTRY, ids=[e.name for e in REGISTRY])
def test_valid_arguments_give_a_result_without_nan(entry):
    @_settings(entry)
    @given(data=st.data())
    def run(data):
        kwargs = data.draw(entry.valid, label="kwargs")
        result, exc = _call(entry, kwargs)
        if exc is not None:  # valid draws may still be degenerate (e.g. coincident points): a clean refusal
            assert str(exc), "an error without a message"
            return
        _assert_no_nan(result, entry.nan_fields)
    run()


@pytest.mark.parametrize("entry", REGISTRY, ids=[e.name for e in REGISTRY])
def test_hostile_arguments_get_a_clean_answer(entry):
    @_settings(entry)
    @given(data=st.data())
    def run(data):
        kwargs = data.draw(entry.valid, label="kwargs")
        names = [k for k, v in kwargs.items() if _strategy_for(_kind(v))]
        if not names:
            return
        arg = data.draw(st.sampled_from(names), label="argument")
        kind = _kind(kwargs[arg])
        how = data.draw(st.sampled_from(_strategy_for(kind)), label="corruption")
        bad, first = _corrupt(kind, how, kwargs[arg], data)
        if how in ("nan", "posinf", "neginf") and bad is None:
            return  # an empty array has no element to poison
        hostile = dict(kwargs, **{arg: bad})
        label = entry.aliases.get(arg, arg)
        note(f"{entry.name}: {arg} <- {how}")
        result, exc = _call(entry, hostile)

        strict = how in ARRAY_STRICT + SCALAR_STRICT + INT_STRICT + STR_STRICT
        if how == "none" and arg in entry.optional:
            strict = False
        if strict:
            assert exc is not None and isinstance(exc, ValueError | TypeError), (
                f"{entry.name}({arg}={how}) must raise ValueError/TypeError, got {result!r:.200}")
            assert label in str(exc), f"the message does not name {label!r}: {exc}"
            if (how in ("nan", "posinf", "neginf") and first is not None and kind == "array" and entry.indexed
                    and np.ndim(kwargs[arg]) >= 1):
                assert f"{label}[{_index_text(first)}]" in str(exc), (
                    f"the message does not give the first offending index {label}[{_index_text(first)}]: {exc}")
            return
        if how in ARRAY_SAME:
            dtype = np.int64 if kind == "int_array" else np.float64
            converted = dict(kwargs, **{arg: np.asarray(bad, dtype=dtype)})
            expected, expected_exc = _call(entry, converted)
            if expected_exc is None:
                assert exc is None, f"{entry.name}: {how} input refused ({exc}) where float64 was accepted"
                assert _same(result, expected), f"{entry.name}: {how} input gives another result than float64"
            else:
                assert exc is not None and type(exc) is type(expected_exc)
            return
        if exc is not None:
            assert str(exc), "an error without a message"
            if isinstance(exc, ValueError | TypeError) and not isinstance(exc, CAP_ERRORS):
                # the message names an argument of the call (the corrupted one, or the one it conflicts with)
                named = {entry.aliases.get(k, k) for k in kwargs} | set(entry.aliases.values())
                assert any(n in str(exc) for n in named), f"the message names no argument: {exc}"
            return
        _assert_no_nan(result, entry.nan_fields)
    run()
