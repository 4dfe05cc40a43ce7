"""Two edge cases of the box–box face contact (engine/narrowphase/box_box.py, ``_face_contact``).

- **The round-off allowance of the reference face.** A clipped point counts as below the reference face when it
  is at most ``FACE_SLOP`` × M above it, M the magnitude of the boxes' coordinates (box_box.py: the largest
  |centre coordinate| of each box plus all half extents). A cube resting on a long bar, tilted so that two of
  its bottom corners sink ``SINK`` below the bar's top face and the two others stand h above it: with h below
  the allowance the contact has the four corners, with h above it only the two sunk ones. The cube sits far out
  along the bar, where the bar's length and the cube's centre make most of M.
- **A corner touching an edge.** A box turned about the vertical whose lowest corner touches the top edge of
  another box (the rest of it outside, beyond the edge and above the top face), the scene turned by a random
  rotation: the boxes touch at that corner only, so every contact point is that corner. Round-off there may clip
  every point of the incident face, and the kernel then falls back on the incident face's deepest corner clamped
  onto the reference face; the pinned scenes below reach that fallback, on both sides of the reference box.
  With B turned about the vertical only, its incident face's corners tie in depth two by two and clamp to the
  same point; the tilted scenes make the touching corner strictly the deepest, so the fallback must pick it.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from engine.narrowphase.box_box import FACE_SLOP, contact_box_box_pair

SINK = 1e-9


def _tilted_cube_on_a_bar(length, along, half, h):
    """The bar (centre 0, axes x, y, z, half extents (1, length, 0.5)) and a cube of half edge ``half`` at
    y = along, turned about x so that its bottom corners at −y sink SINK below the bar's top face z = 0.5 and
    those at +y stand h above it."""
    angle = np.arcsin((h + SINK) / (2.0 * half))
    cz = 0.5 - SINK + half * (np.sin(angle) + np.cos(angle))
    return ((np.zeros(3), np.eye(3), [1.0, length, 0.5]),
            (np.array([0.0, along, cz]), Rotation.from_euler("x", angle).as_matrix(), [half, half, half]))


@pytest.mark.parametrize("fraction, corners", [(0.7, 4), (1.4, 2)])
@given(length=st.floats(20.0, 200.0), along=st.floats(0.3, 0.9), half=st.floats(0.1, 0.5))
def test_corners_within_the_round_off_allowance_of_the_top_face_touch_it(fraction, corners, length, along, half):
    centre = along * length
    # M as box_box.py defines it: max |centre coordinate| of each box plus all half extents
    magnitude = 0.0 + max(centre, 0.5 + half) + (1.0 + length + 0.5) + 3 * half
    h = fraction * FACE_SLOP * magnitude
    (ca, ra, ea), (cb, rb, eb) = _tilted_cube_on_a_bar(length, centre, half, h)
    magnitude = max(np.abs(cb)) + sum(ea) + sum(eb)  # the exact centre the kernel sees
    assert abs(fraction * FACE_SLOP * magnitude - h) <= 1e-3 * h
    cs = contact_box_box_pair(ca, ra, ea, cb, rb, eb)
    points = cs.points_of(0)
    assert points.shape[0] == corners, (points, h, FACE_SLOP * magnitude)
    # the points kept are corners of the cube's bottom face (each moved by half its depth along the normal)
    bottom = cb + (rb @ (np.array([[x, y, -1.0] for x in (-1, 1) for y in (-1, 1)]) * half).T).T
    for p in points:
        assert np.abs(bottom[:, :2] - p[:2]).max(axis=1).min() <= 1e-12, (p, bottom)
    assert np.allclose(cs.normal[0], [0.0, 0.0, 1.0]) and abs(cs.depth[0] - SINK) <= 1e-15


# (center_a, rotation_a, half_extents_a, center_b, rotation_b, half_extents_b), the touching corner: scenes
# whose clipped incident face is empty by round-off (the kernel's fallback), found by a random search
FALLBACK_SCENES = [
    # touching A's +x top edge
    ([[1.367052392665629, -2.90740513829698, 2.750100173971746],
      [[0.8581267917651245, -0.513001932439736, 0.021152460093129488],
       [-0.11023794210961971, -0.14385122071129003, 0.9834400959993995],
       [-0.5014638624809677, -0.8462480981443731, -0.17999486385089075]],
      [1.0, 1.0, 1.0],
      [3.20700878948388, -1.7012495432783605, 1.40028700476829],
      [[0.38229316842681343, -0.923798953672387, 0.021152460093129488],
       [-0.17430958793509385, -0.04961597660622963, 0.9834400959993995],
       [-0.9074514317185718, -0.37964950686022697, -0.17999486385089075]],
      [0.7536969030280134, 0.8680442449144317, 0.4680608160270355]],
     [2.107076609466366, -2.073251583479623, 1.8389263118430152]),
    # touching A's +x top edge
    ([[-2.1652889207486394, -1.2927936424562214, -2.6856494578937498],
      [[0.9190192060559814, -0.3898999906921305, 0.0581523529920315],
       [-0.3345121677069886, -0.8493597146039238, -0.4082764809095826],
       [0.20857926204732055, 0.35576125768022826, -0.9110041816465924]],
      [1.0, 1.0, 1.0],
      [-0.25171084196949356, -2.4008046131375194, -4.1492675863742035],
      [[0.6162906660568515, -0.7853687788374913, 0.0581523529920315],
       [-0.703220199008196, -0.582058130123582, -0.4082764809095826],
       [0.3544956510848556, 0.21072307511126284, -0.9110041816465924]],
      [0.8251171856890851, 0.2101771593560005, 0.8970161232134022]],
     [-0.977453039132379, -1.5766702798768737, -3.580293423746889]),
    # touching A's +x top edge
    ([[2.7753782494311716, 1.5824515526303458, -2.642040719914065],
      [[0.988682502696992, 0.1475348663813935, 0.027209778805364005],
       [0.1499925841831468, -0.9684340399898875, -0.1990922772960481],
       [-0.003022176512729919, 0.2009203160227687, -0.9796029262198213]],
      [1.0, 1.0, 1.0],
      [4.703462961506477, 1.1236578194593363, -4.455357234129116],
      [[0.9977765016560199, -0.06084143884259804, 0.027209778805364005],
       [-0.05423539433090425, -0.9784788128124413, -0.1990922772960481],
       [0.03873725267550277, 0.19717386286401548, -0.9796029262198213]],
      [0.7695113605164268, 0.434513488976973, 0.9201352111675354]],
     [3.884189506793061, 0.9234221433054997, -3.4981241416723896]),
    # touching A's -x top edge
    ([[2.8823685052835373, 0.09313601463762566, 0.12699677415734367],
      [[-0.046590492946377904, 0.8894201819078035, -0.4547098701173126],
       [-0.7996664458906443, -0.30600611506971676, -0.5166176853888806],
       [-0.5986341965538209, 0.33954675312102317, 0.7254964515153277]],
      [1.0, 1.0, 1.0],
      [2.5220511600337963, 0.5117195451119203, 2.234873317856311],
      [[0.2680835614855355, 0.8493351152985068, -0.4547098701173126],
       [-0.8561927607725691, -0.00633431480758957, -0.5166176853888806],
       [-0.4416618168484538, 0.5278160080717432, 0.7254964515153277]],
      [0.4905015604402813, 0.34352482205371726, 0.4768491512899828]],
     [2.5786068865725653, 0.34028035910149534, 1.4909672400863274]),
    # touching A's -x top edge
    ([[-2.286041669189685, 1.5000730851082533, -0.30493018461379773],
      [[0.8342190061179423, 0.40008658166977557, 0.37948567430060737],
       [-0.2747747162681315, 0.8982545417433083, -0.3429834304121514],
       [-0.4780977987100134, 0.1818502279495774, 0.8592746880150295]],
      [1.0, 1.0, 1.0],
      [-3.4181989301443627, 1.064517753810865, 2.0252366238542656],
      [[0.5738611325352881, -0.7257231039218263, 0.37948567430060737],
       [0.8157656048926852, 0.46571326407649627, -0.3429834304121514],
       [0.07217948766365617, 0.5063962204610989, 0.8592746880150295]],
      [0.2950708406791959, 0.8958622204953168, 0.7220041574443368]],
     [-2.872711566525505, 1.1356469404661242, 0.9724735463127214]),
    # touching A's -x top edge
    ([[2.5584078734346125, -1.18891720151586, -0.6287456113608298],
      [[-0.2965982940580378, 0.9519918142816487, -0.0757696344362085],
       [-0.9060265131011019, -0.25541915934465925, 0.33745667958647113],
       [0.30190298030943713, 0.16873837317102042, 0.938286710925758]],
      [1.0, 1.0, 1.0],
      [2.877359402635387, 1.3334592682959672, 0.607924650171801],
      [[0.883217467544898, 0.4628021904885287, -0.0757696344362085],
       [-0.4140351763284092, 0.8453980495394916, 0.33745667958647113],
       [0.22023119167429545, -0.26667633999633844, 0.938286710925758]],
      [0.6892519265798638, 0.89735902366217, 0.9873772195924808]],
     [3.145632232903359, -0.043737881023883984, 0.07258091960475466]),
]


def _check_touching_at(args, corner):
    cs = contact_box_box_pair(*args)
    scale = 1.0 + np.abs(np.asarray(corner)).max()
    if cs.separation[0] > 0.0:  # round-off may also call them apart, by no more than round-off
        assert cs.separation[0] <= 1e-14 * scale and cs.points_of(0).shape[0] == 0
        return
    points = cs.points_of(0)
    assert points.shape[0] >= 1 and abs(cs.separation[0]) <= 1e-14 * scale, cs
    assert np.abs(points - corner).max() <= 1e-12 * scale, (points, corner)


@pytest.mark.parametrize("args, corner", FALLBACK_SCENES)
def test_a_corner_on_an_edge_whose_clipped_face_is_empty_touches_at_that_corner(args, corner):
    _check_touching_at(args, np.array(corner))


@given(turn=st.floats(0.1, 1.4), halves=st.tuples(*[st.floats(0.2, 1.0)] * 3), side=st.sampled_from([-1.0, 1.0]),
       y=st.floats(-0.8, 0.8), seed=st.integers(0, 2**32 - 1), shift=st.tuples(*[st.floats(-3.0, 3.0)] * 3))
def test_a_corner_on_an_edge_touches_at_that_corner(turn, halves, side, y, seed, shift):
    rb = Rotation.from_euler("z", turn).as_matrix()
    hb = np.array(halves)
    # B's corner with the least side·x and the least z: its three edges run away from A (outward and upward)
    signs = -np.sign(rb[0, :]) * side
    signs[2] = -1.0
    corner = np.array([side, y, 1.0])  # on A's top edge x = side, z = 1 (A: the cube of half edge 1 at 0)
    cb = corner - rb @ (signs * hb)
    q = Rotation.random(random_state=seed).as_matrix()
    s = np.array(shift)
    _check_touching_at((s, q, np.ones(3), q @ cb + s, q @ rb, hb), q @ corner + s)


# scenes of the same kind with B tilted: its corner of least x (the touching one, corner 0 of its incident face)
# is strictly the deepest, so the fallback's choice of corner matters (the other corners clamp elsewhere on A's
# +x face); found by the random search of ``_tilted_corner_on_an_edge`` (about 1 in 6 of its scenes reaches it)
TILTED_FALLBACK_SCENES = [
    ([[2.41329047829593, -0.13707885696476207, -0.41702233362352104],
      [[0.4534561880121493, -0.18835964560423352, -0.871147593385494],
       [0.4923308165875077, 0.8676960301947612, 0.06865832959321169],
       [0.7429588498643571, -0.46002635043234186, 0.486197392337857]],
      [1.0, 1.0, 1.0],
      [2.4620958530525927, 1.367171313877804, 1.5672783657329095],
      [[-0.3232455984456886, -0.21890950571136525, 0.9206470069438637],
       [0.9153746750115317, -0.3190703872138973, 0.2455265613955175],
       [0.24000309879879023, 0.9221023350541847, 0.30352231590872997]],
      [0.8415209655886458, 0.33962225291522274, 0.8973082193501252]],
     [1.9823562142423194, 0.4849147356218525, 0.7797911850169059]),
    ([[1.2278871866400927, -2.4709837619425254, 0.8688901398075215],
      [[-0.2062478905665552, -0.5591859797904156, 0.8029774888766678],
       [0.6600647513888146, -0.685300795307658, -0.3076968376904673],
       [0.7223408694036829, 0.4665553128585338, 0.5104407981662585]],
      [1.0, 1.0, 1.0],
      [1.57180307950593, -1.376340773014247, 2.7230981569475485],
      [[0.6330130112637681, -0.11676953218764426, 0.7652838714643448],
       [0.6721936876755948, -0.40744057475777673, -0.6181810610898218],
       [0.38399241375300924, 0.9057356426649731, -0.17942344268909396]],
      [0.6047145553688051, 0.2571345776601732, 0.7600698564182509]],
     [1.8007055845026454, -2.147919810209775, 2.1216220529287115]),
    ([[0.7868991783336607, -2.950717077981335, -1.283201676746335],
      [[-0.43147311459980786, 0.3291928966008507, -0.8399184414007603],
       [-0.8782739423657017, -0.3659632018081984, 0.30774310241449704],
       [-0.2060723987800135, 0.8704613556900922, 0.44702482560951545]],
      [1.0, 1.0, 1.0],
      [-1.3125638664788775, -4.2202051308409, -0.8836015960451769],
      [[-0.04003755289403064, -0.806468025172699, -0.5899206037530003],
       [-0.9419699345945521, 0.22740099616956802, -0.24694418248062255],
       [0.33330112012741975, 0.5458004317652514, -0.7687732123368192]],
      [0.43355265787534325, 0.5322544344210264, 0.9256910794452715]],
     [-0.3198750559147876, -3.7042527238185627, -0.6069633778885356]),
    ([[-1.9897127751634172, 2.0371367903568816, -1.210255434988852],
      [[-0.9014450473534159, -0.40637029635120153, 0.14919788485576635],
       [-0.37700112968011074, 0.9063474506670846, 0.19079949394376575],
       [-0.21276036948153243, 0.1157474877166387, -0.9702244813780823]],
      [1.0, 1.0, 1.0],
      [-3.930875726975657, 2.429474556883791, -3.0115661365627866],
      [[-0.8778874220773244, -0.43447292903691187, 0.20136272766457233],
       [-0.36059652256619384, 0.3230948291121446, -0.8749742163710671],
       [0.31509335453417386, -0.8407395585644114, -0.4403103139756335]],
      [0.5908732806094612, 0.9464147842992559, 0.21566597994621475]],
     [-3.044390992455134, 2.5254618559478037, -2.3070980773400644]),
]


def _tilted_corner_on_an_edge(rotation, halves, y, q, shift):
    """A (the cube of half edge 1 at 0) and B (``rotation``, ``halves``) whose corner of least x touches A's top
    edge x = 1, z = 1 at height y; B's columns are flipped in pairs so that the touching corner is corner 0 of its
    face most anti-parallel to x (signs −1 on the other two axes), whose edges from that corner do not go down.
    The scene is turned by q and moved by ``shift``. Returns (arguments, the touching corner) or None."""
    r = np.array(rotation, dtype=float)
    a = int(np.argmax(np.abs(r[0])))
    b1, b2 = [m for m in range(3) if m != a]
    flips = np.where(r[0] < 0.0, -1.0, 1.0)
    flips[a] = 1.0 if flips[b1] * flips[b2] > 0.0 else -1.0
    r = r * flips
    if min(r[2, b1], r[2, b2]) < 0.02 or min(r[0, b1], r[0, b2]) < 0.02:
        return None
    hb = np.array(halves)
    corner = np.array([1.0, y, 1.0])
    cb = corner - r @ (-np.sign(r[0]) * hb)
    return (shift, q, np.ones(3), q @ cb + shift, q @ r, hb), q @ corner + shift


@pytest.mark.parametrize("args, corner", TILTED_FALLBACK_SCENES)
def test_a_tilted_corner_on_an_edge_whose_clipped_face_is_empty_touches_at_that_corner(args, corner):
    _check_touching_at(tuple(np.array(a) for a in args), np.array(corner))


@given(seed=st.integers(0, 2**32 - 1), halves=st.tuples(*[st.floats(0.2, 1.0)] * 3), y=st.floats(-0.8, 0.8),
       shift=st.tuples(*[st.floats(-3.0, 3.0)] * 3))
def test_a_tilted_corner_on_an_edge_touches_at_that_corner(seed, halves, y, shift):
    rotations = Rotation.random(2, random_state=seed).as_matrix()
    scene = _tilted_corner_on_an_edge(rotations[0], halves, y, rotations[1], np.array(shift))
    assume(scene is not None)
    _check_touching_at(*scene)


@pytest.mark.parametrize("args, corner", FALLBACK_SCENES + TILTED_FALLBACK_SCENES)
def test_the_fallback_scenes_with_the_boxes_exchanged_touch_at_that_corner(args, corner):
    """The same scenes with A and B exchanged: the reference face may now be the other box's (the touching
    axes tie to round-off), and the point must still be the corner, on both boxes. (The fallback once clamped the
    incident face's deepest corner onto the reference face: a point on the reference box, up to 0.65 outside the
    other.)"""
    a, b = tuple(np.array(x) for x in args[:3]), tuple(np.array(x) for x in args[3:])
    _check_touching_at(b + a, np.array(corner))
