"""Collision, contacts, distance and self-intersection against numpy brute force."""

import numpy as np
import pytest

import bvhkit
from reference import random_rotations, random_soup, triangle_distance, triangles_intersect

VOLUMES = ["obb", "rss", "obbrss", "aabb", "sphere", "kdop18", "hull"]


def setup(seed, k=40):
    rng = np.random.default_rng(seed)
    va, fa = random_soup(rng, 25, size=0.3)
    vb, fb = random_soup(rng, 20, size=0.3)
    rot = random_rotations(rng, k)
    trans = rng.uniform(-1.2, 1.2, (k, 3))
    return va, fa, vb, fb, rot, trans


def brute_pairs(va, fa, vb, fb, r, t):
    ta = va[fa]  # (m, 3, 3)
    tb = (vb @ r.T + t)[fb]
    hit, margin = triangles_intersect(ta[:, None], tb[None])
    return hit, margin


@pytest.mark.parametrize("volume", VOLUMES)
def test_collide_and_contacts_match_brute_force(volume):
    va, fa, vb, fb, rot, trans = setup(1)
    a = bvhkit.CollisionModel(va, fa, volume=volume, dtype=np.float64)
    b = bvhkit.CollisionModel(vb, fb, volume=volume, dtype=np.float64)
    yes = bvhkit.collide(a, b, rot, trans)
    pairs = bvhkit.collide(a, b, rot, trans, contacts=True)
    checked = 0
    for i in range(len(rot)):
        hit, margin = brute_pairs(va, fa, vb, fb, rot[i], trans[i])
        got = np.zeros_like(hit)
        got[pairs[i][:, 0], pairs[i][:, 1]] = True
        clear = margin > 1e-9
        np.testing.assert_array_equal(got[clear], hit[clear])
        if clear.all():
            assert yes[i] == hit.any()
            checked += 1
    assert checked > 30 and yes.sum() > 3 and (~yes).sum() > 3


@pytest.mark.parametrize("volume", ["rss", "obb", "hull"])
def test_distance_matches_brute_force(volume):
    va, fa, vb, fb, rot, trans = setup(2, k=25)
    trans *= 3  # mostly apart
    a = bvhkit.CollisionModel(va, fa, volume=volume, dtype=np.float64)
    b = bvhkit.CollisionModel(vb, fb, volume=volume, dtype=np.float64)
    r = bvhkit.distance(a, b, rot, trans)
    yes = bvhkit.collide(a, b, rot, trans)
    for i in range(len(rot)):
        ta = va[fa]
        tb = (vb @ rot[i].T + trans[i])[fb]
        if yes[i]:
            assert r.distance[i] == 0
            continue
        d = triangle_distance(ta[:, None], tb[None])
        assert r.distance[i] == pytest.approx(d.min(), rel=1e-9, abs=1e-12)
        # The points are on the faces reported, and as far apart as the distance.
        assert np.linalg.norm(r.point_a[i] - r.point_b[i]) == pytest.approx(r.distance[i],
                                                                            rel=1e-9)
        assert d[r.face_a[i], r.face_b[i]] == pytest.approx(d.min(), rel=1e-9, abs=1e-12)


def test_float32_models_and_identity_pose():
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    a = bvhkit.CollisionModel(v, f)
    assert list(bvhkit.collide(a, a, None, [[0, 0, 0], [1.5, 0, 0], [2.5, 0, 0]])) == [
        True, True, False]
    d = bvhkit.distance(a, a, None, [[3, 0, 0]]).distance[0]
    assert d == pytest.approx(1.0, rel=1e-3)


def test_float64_models_take_rotations_read_from_float32():
    # A rotation rounded to float32 is ~6e-8 from orthonormal: float64 models use it as given (the
    # same 1e-4 rule as float32 models); a 1e-3 scale is refused naming the argument.
    rng = np.random.default_rng(38)
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    a = bvhkit.CollisionModel(v, f, dtype=np.float64)
    r32 = random_rotations(rng, 4).astype(np.float32)
    t = [[1.5, 0, 0], [0, 2.5, 0], [0, 0, 1.9], [3, 3, 3]]
    assert list(bvhkit.collide(a, a, r32.astype(np.float64), t)) == [True, False, True, False]
    assert np.all(np.isfinite(bvhkit.distance(a, a, r32, t).distance))
    bad = r32.astype(np.float64)
    bad[1] *= 1 + 1e-3  # a scale: det R = 1.003
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.collide(a, a, bad, t)


def test_self_intersections():
    # Faces 0 and 1 cross; face 2 shares a vertex with face 0 and touches it there (left out);
    # face 3 is far away.
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0],
                  [0.5, 0.5, -1], [0.5, 0.5, 1], [1.5, 0.2, 0],
                  [0, 0, 1], [0, 1, 1],
                  [10, 10, 10], [11, 10, 10], [10, 11, 10]], float)
    f = np.array([[0, 1, 2], [3, 4, 5], [0, 6, 7], [8, 9, 10]])
    for volume in VOLUMES:
        m = bvhkit.CollisionModel(v, f, volume=volume)
        np.testing.assert_array_equal(bvhkit.self_intersections(m), [[0, 1]])


def test_refit_collision_model():
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    a = bvhkit.CollisionModel(v, f)
    b = bvhkit.CollisionModel(v, f)
    assert not bvhkit.collide(a, b, None, [[2.5, 0, 0]])[0]
    b.refit(v * 1.5)
    assert bvhkit.collide(a, b, None, [[2.5, 0, 0]])[0]


def test_the_extension_refuses_pose_arrays_of_the_wrong_shape():
    # The Python layer only hands over (k, 3) / (k, 3, 3) poses; the extension checks the shapes
    # itself too, so a direct call cannot make it read past an array.
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    m = bvhkit.CollisionModel(v, f)
    out = np.empty(1, np.bool_)
    for r, t in [
        (None, np.zeros(2)),
        (None, np.zeros((1, 4))),
        (np.zeros((1, 9)), np.zeros((1, 3))),
        (np.zeros((1, 3, 2)), np.zeros((1, 3))),
        (None, np.zeros((1, 1, 3))),
    ]:
        with pytest.raises(ValueError, match="rotations|translations"):
            m._impl.collides(m._impl, r, t, out, 1)
