"""The narrow phase answers the same with numba's JIT disabled as compiled, bit for bit.

The mutation run (properties/MUTATION.md) interprets every kernel (``NUMBA_DISABLE_JIT=1``), so a kernel only
numba can run (an LLVM intrinsic such as the float bit casts of ``narrowphase.float_bits``) would stop the whole
narrow-phase area while the compiled suite stays green. A child process with the JIT disabled runs GJK (single,
batch, packed pairs), EPA with witnesses and the input check on a few hull pairs, touching, overlapping and apart,
at scales 1e-6, 1 and 1e6 (the power-of-two rescaling path), and every number must equal the compiled run's.
"""
from __future__ import annotations

import numba
import numpy as np

from engine.narrowphase import epa_penetration, gjk_distance, gjk_distance_batch, gjk_distance_pairs, pack_point_sets
from properties.jit_off import assert_same_bits, runs_in_child


def _hull_pairs():
    rng = np.random.default_rng(17)
    pairs = []
    for scale in (1e-6, 1.0, 1e6):
        for offset in (0.0, 1.2, 4.0):  # overlapping, near, apart
            a = rng.normal(size=(20, 3))
            b = rng.normal(size=(20, 3)) + np.array([offset, 0.3, -0.2])
            pairs.append((a * scale, b * scale))
    cube = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    pairs.append((cube, cube + [1.0, 0.0, 0.0]))  # face to face, touching
    return pairs


def narrowphase_runs() -> dict:
    """GJK, its batches and EPA over the pairs above: a name → what each returns."""
    runs: dict = {"jit_disabled": bool(numba.config.DISABLE_JIT)}
    pairs = _hull_pairs()
    for k, (a, b) in enumerate(pairs):
        runs[f"gjk/{k}"] = gjk_distance(a, b)
        if runs[f"gjk/{k}"][0] == 0.0:
            runs[f"epa/{k}"] = epa_penetration(a, b, witnesses=True)
    same_size = [p for p in pairs if p[0].shape == (20, 3)]
    runs["batch"] = gjk_distance_batch(np.stack([a for a, _ in same_size]), np.stack([b for _, b in same_size]))
    points, offsets = pack_point_sets([s for p in pairs for s in p])
    index = np.arange(len(pairs), dtype=np.int64)
    runs["pairs"] = gjk_distance_pairs(points, offsets, np.stack([2 * index, 2 * index + 1], axis=1))
    bad = pairs[0][0].copy()
    bad[3, 1] = np.nan
    try:
        gjk_distance(bad, pairs[0][1])
        runs["nan"] = "accepted"
    except ValueError as exc:
        runs["nan"] = str(exc)
    return runs


def _as_plain(value):
    """Tuples, lists and result objects as dicts, so that ``assert_same_bits`` walks every field."""
    if isinstance(value, dict):
        return {k: _as_plain(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return {str(i): _as_plain(v) for i, v in enumerate(value)}
    if hasattr(value, "__dict__") and not isinstance(value, np.ndarray):
        return {k: _as_plain(v) for k, v in vars(value).items()}
    if hasattr(value, "_fields"):
        return {k: _as_plain(getattr(value, k)) for k in value._fields}
    return value


def test_narrowphase_without_the_jit_equals_the_compiled_one_bit_for_bit():
    assert not numba.config.DISABLE_JIT
    compiled = narrowphase_runs()
    interpreted = runs_in_child("properties.test_narrowphase_without_jit", "narrowphase_runs")
    assert compiled.pop("jit_disabled") is False and interpreted.pop("jit_disabled") is True
    # not trivial: some pairs overlap (EPA ran), some are apart, the NaN was refused by name
    assert any(k.startswith("epa/") for k in compiled)
    assert any(v[0] > 0 for k, v in compiled.items() if k.startswith("gjk/"))
    assert compiled["nan"].startswith("points_a")
    assert_same_bits(_as_plain(compiled), _as_plain(interpreted), "runs")
