"""World against MuJoCo and pybullet on small scenes of the benchmark's kinds: the same penetrating pairs.

Scenes of 12–40 bodies drawn like the frame benchmark's (spheres and rotated boxes; capsules and 12-vertex hulls;
boxes and spheres over a Plane), packed densely so that many pairs touch. A pair that World finds penetrating
by more than ``BAND`` is penetrating for MuJoCo and for pybullet, and a pair either peer finds penetrating by
more than ``BAND`` is penetrating for World — the pair sets agree outside a band of round-off and of the peers'
collision margins (Bullet's box margin puts its depths up to ~1e-3 off on box pairs). World's depths equal the
exact depth (distance from the origin to the boundary of the Minkowski difference, Qhull) on every penetrating
pair, within 1e-9.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.workloads import FrameScene, frame_scene, random_quaternions
from engine.world import Plane

pytest.importorskip("mujoco")
pytest.importorskip("pybullet")

from bench.world_peers import BulletFrame, EngineFrame, MuJoCoFrame, exact_depth  # noqa: E402

#: pairs penetrating by less than this (in the scenes' unit, bodies of size ~1) may be missed by one side
BAND = 5e-3


def _dense(scene: FrameScene, squeeze: float, seed: int) -> FrameScene:
    rng = np.random.default_rng(seed)
    n = len(scene.shapes)
    centers = scene.centers * squeeze
    if scene.ground is None:
        quats = random_quaternions(n, rng)
    else:
        quats = scene.quaternions
    return scene._replace(centers=centers, quaternions=quats)


@given(st.sampled_from(["mixed", "hulls", "pile"]), st.integers(12, 40), st.floats(0.55, 1.0),
       st.integers(0, 2**16))
@settings(max_examples=30)
def test_pair_sets_agree_with_mujoco_and_pybullet(name, n, squeeze, seed):
    scene = _dense(frame_scene(name, n, seed=seed), 1.0 if name == "pile" else squeeze, seed)
    world = EngineFrame(scene)
    world.detect()
    ours = dict(zip(map(tuple, world.penetrating(0.0)[0].tolist()), world.penetrating(0.0)[1].tolist()))
    for peer in (MuJoCoFrame(scene), BulletFrame(scene)):
        peer.detect()
        pairs, depth = peer.penetrating(0.0)
        theirs = dict(zip(map(tuple, pairs.tolist()), depth.tolist()))
        missed = {p for p, d in ours.items() if d > BAND and p not in theirs}
        extra = {p for p, d in theirs.items() if d > BAND and p not in ours}
        assert not missed and not extra, (peer.name, missed, extra)
        if isinstance(peer, BulletFrame):
            peer.close()
    centers, quats = scene.centers, scene.quaternions
    for (i, j), d in ours.items():
        shape_b = Plane(scene.ground) if j == n else scene.shapes[j]
        pose_b = None if j == n else (centers[j], quats[j])
        exact = exact_depth(scene.shapes[i], (centers[i], quats[i]), shape_b, pose_b)
        assert abs(d - exact) <= 1e-9, (i, j, d, exact)
