"""bvhkit.Scene.colliding_pairs_at and any_collision_at: some instances at other poses, the scene
unchanged. References: bvhkit.collide on every pair with a moved instance (no scene, no top-level
tree), and a pickled copy moved by set_poses whose colliding_pairs are restricted to those pairs
(margins, groups and masks, the ignore list)."""

import pickle

import numpy as np
import pytest

import bvhkit
from reference import box_mesh
from test_instanced_scene import rotations


def make_scene(dtype, offset, margins, seed):
    rng = np.random.default_rng(seed)
    meshes = [box_mesh([-0.5, -0.3, -0.2], [0.5, 0.3, 0.2]), box_mesh([0, 0, 0], [1, 0.1, 0.1])]
    s = bvhkit.Scene(dtype=dtype)
    for v, f in meshes:
        s.add_mesh(v, f)
    poses = {}
    for k in range(16):
        g = k % 2
        r, t = rotations(rng, 1)[0], offset + rng.uniform(-1.5, 1.5, 3)
        options = {}
        if margins:
            options = {"margin": [0.0, 0.0, 0.05][k % 3], "group": 1 << (k % 2),
                       "mask": 0xFFFFFFFF if k % 4 else 1 << ((k + 1) % 2)}
        i = s.add_instance(g, r, t, **options)
        poses[i] = (g, r, t)
    return s, meshes, poses, rng


def pair_reference(s, meshes, poses, moved, r_new, t_new):
    """{(a, b)} colliding by bvhkit.collide on each pair with a moved instance (margins zero)."""
    models = [bvhkit.CollisionModel(v, f, dtype=np.float64) for v, f in meshes]
    now = dict(poses)
    for i, r, t in zip(moved, r_new, t_new):
        now[int(i)] = (now[int(i)][0], np.asarray(r, float), np.asarray(t, float))
    ids = sorted(now, key=lambda i: i & 0xFFFFFFFF)
    out = set()
    for x, a in enumerate(ids):
        for b in ids[x + 1:]:
            if a not in moved and b not in moved:
                continue
            ga, ra, ta = now[a]
            gb, rb, tb = now[b]
            r, t = ra.T @ rb, ra.T @ (tb - ta)
            if bvhkit.collide(models[ga], models[gb], r, t[None])[0]:
                out.add((a, b))
    return out


@pytest.mark.parametrize("offset", [0.0, 1e4])
def test_pairs_match_every_pair(offset):
    s, meshes, poses, rng = make_scene(np.float64, offset, False, 3)
    ids = list(poses)
    moved = [ids[1], ids[4], ids[9]]
    before = s.to_bytes()
    colliding = 0
    for _ in range(15):
        r, t = rotations(rng, 3), offset + rng.uniform(-1.5, 1.5, (3, 3))
        expected = pair_reference(s, meshes, poses, moved, r, t)
        found = {tuple(p) for p in s.colliding_pairs_at(moved, r, t)}
        assert found == expected
        assert s.any_collision_at(moved, r, t) == bool(expected)
        colliding += bool(expected)
    assert 0 < colliding < 15
    assert s.to_bytes() == before  # not changed


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_batch_matches_set_poses(dtype):
    s, _, poses, rng = make_scene(dtype, 0.0, True, 5)
    ids = list(poses)
    moved = np.array([ids[0], ids[3], ids[6], ids[7]])
    ignore = [[ids[2], ids[0]], [ids[3], ids[6]]]
    K = 40
    r = rotations(rng, K * 4).reshape(K, 4, 3, 3)
    t = rng.uniform(-1.5, 1.5, (K, 4, 3))
    copy = pickle.loads(pickle.dumps(s))
    expected = []
    for k in range(K):
        copy.set_poses(moved, r[k], t[k])
        pairs = [tuple(p) for p in copy.colliding_pairs(ignore=ignore)
                 if p[0] in moved or p[1] in moved]
        assert [tuple(p) for p in s.colliding_pairs_at(moved, r[k], t[k], ignore=ignore)] == pairs
        expected.append(bool(pairs))
    assert 5 < sum(expected) < K - 5
    for threads in (0, 1, 2):
        got = s.any_collision_at(moved, r, t, ignore=ignore, threads=threads)
        assert got.dtype == np.bool_ and got.tolist() == expected
    # Translations alone (rotations None: identities), many configurations.
    got = s.any_collision_at(moved, None, t)
    for k in range(K):
        assert got[k] == s.any_collision_at(moved, np.broadcast_to(np.eye(3), (4, 3, 3)), t[k])


def test_bad_arguments():
    s, _, poses, _ = make_scene(np.float64, 0.0, False, 7)
    ids = list(poses)
    two = [ids[0], ids[1]]
    eye = np.broadcast_to(np.eye(3), (2, 3, 3))
    sheared = np.array(eye)
    sheared[1, 0, 1] = 0.5
    cases = [
        (lambda: s.any_collision_at(two, eye, np.zeros((3, 3))), "translations"),
        (lambda: s.any_collision_at([ids[0], ids[0]], eye, np.zeros((2, 3))), "repeats"),
        (lambda: s.any_collision_at([ids[0], 12345], eye, np.zeros((2, 3))), "ids"),
        (lambda: s.any_collision_at(two, sheared, np.zeros((2, 3))), "rigid"),
        (lambda: s.any_collision_at(two, np.stack([eye, sheared]), np.zeros((2, 2, 3))),
         "configuration 1"),
        (lambda: s.any_collision_at(two, np.stack([eye] * 3), np.zeros((2, 2, 3))),
         "translations"),
        (lambda: s.colliding_pairs_at(two, np.stack([eye] * 2), np.zeros((2, 2, 3))), "one"),
        (lambda: s.any_collision_at(two, eye, np.zeros((2, 3)), threads=-1), "threads"),
    ]
    for call, match in cases:
        with pytest.raises(ValueError, match=match):
            call()
    assert s.any_collision_at([], None, np.zeros((0, 3))) is False
    assert s.any_collision_at([], None, np.zeros((4, 0, 3))).tolist() == [False] * 4
