"""bvhkit.Scene's distance queries (closest pair, pairs within a threshold, the instance nearest a
posed mesh), collision and face contacts between two scenes, and saving, loading and pickling a scene. References:
bvhkit.distance / bvhkit.collide on every pair (no top-level tree), and boxes at known gaps."""

import pickle

import numpy as np
import pytest

import bvhkit
from reference import box_mesh
from test_instanced_scene import random_scene, random_rays, rotations


def pair_distances(m):
    """{(a, b): distance less the margins} for every pair the filter lets collide, by
    bvhkit.distance on the pair alone."""
    models = [bvhkit.CollisionModel(v, f, dtype=np.float64) for v, f in m.meshes]
    ids = sorted(m.poses, key=lambda i: i & 0xFFFFFFFF)
    out = {}
    for x, a in enumerate(ids):
        ga, ra, ta, groupa, maska, ma = m.poses[a]
        for b in ids[x + 1:]:
            gb, rb, tb, groupb, maskb, mb = m.poses[b]
            if not (groupa & maskb and groupb & maska):
                continue
            r, t = ra.T @ rb, ra.T @ (tb - ta)
            out[(a, b)] = bvhkit.distance(models[ga], models[gb], r, t[None]).distance[0] - ma - mb
    return out


def test_boxes_at_known_gaps():
    v, f = box_mesh([-1, -1, -1], [1, 1, 1])
    for offset, dtype in [(0.0, np.float64), (1e6, np.float64), (0.0, np.float32),
                          (2048.0, np.float32)]:
        s = bvhkit.Scene(dtype=dtype)
        g = s.add_mesh(v, f)
        a = s.add_instance(g, None, [offset, offset, offset])
        b = s.add_instance(g, None, [offset + 2.5, offset, offset])  # gap 0.5
        c = s.add_instance(g, None, [offset + 6.0, offset, offset], margin=0.25)  # gap 1.5
        d = s.closest_pair()
        assert len(d.distance) == 1 and tuple(d.pairs[0]) == (a, b)
        assert d.distance[0] == pytest.approx(0.5, abs=1e-6)
        assert d.point_a[0][0] == pytest.approx(offset + 1, abs=1e-3)
        assert d.point_b[0][0] == pytest.approx(offset + 1.5, abs=1e-3)
        w = s.pairs_within(1.25)
        assert [tuple(p) for p in w.pairs] == [(a, b), (b, c)]
        assert w.distance[1] == pytest.approx(1.25, abs=1e-5)  # 1.5 less c's margin
        assert len(s.pairs_within(0.4).distance) == 0
        assert [tuple(p) for p in s.closest_pair(ignore=[[b, a]]).pairs] == [(b, c)]
        near = s.closest_instance(g, None, [offset - 3, offset, offset])
        assert tuple(near.pairs[0]) == (-1, a) and near.distance[0] == pytest.approx(1, abs=1e-5)
        assert len(s.closest_instance(g, None, [offset, 0, 0], mask=0).distance) == 0
    empty = bvhkit.Scene()
    assert len(empty.closest_pair().distance) == 0
    with pytest.raises(ValueError, match="threshold"):
        s.pairs_within(float("nan"))
    with pytest.raises(ValueError, match="margin"):
        s.closest_instance(g, None, [0, 0, 0], margin=-1)


@pytest.mark.parametrize("dtype, offset, scale", [
    (np.float64, 0.0, 1.0), (np.float32, 0.0, 1.0), (np.float64, 1e5, 1.0),
    (np.float64, 0.0, 1e-3)])
def test_distances_match_every_pair(dtype, offset, scale):
    m, rng = random_scene(7, dtype, offset, scale, count=14)
    ids = list(m.poses)
    for i in ids[::3]:
        m.scene.set_options(i, margin=0.05 * scale)
        m.poses[i] = m.poses[i][:5] + (np.asarray(0.05 * scale, dtype).item(),)
    ref = pair_distances(m)
    tol = (1e-4 if dtype == np.float32 else 1e-9) * scale
    best = min(ref.values())
    d = m.scene.closest_pair()
    assert d.distance[0] == pytest.approx(best, abs=tol)
    assert ref[tuple(d.pairs[0])] == pytest.approx(best, abs=tol)
    for threshold in (0.0, 0.1 * scale, 0.5 * scale):
        w = m.scene.pairs_within(threshold)
        got = {tuple(p): x for p, x in zip(w.pairs, w.distance)}
        sure = {p for p, x in ref.items() if x <= threshold - tol}
        maybe = {p for p, x in ref.items() if x <= threshold + tol}
        assert sure <= set(got) <= maybe
        for p, x in got.items():
            assert x == pytest.approx(ref[p], abs=tol)


def test_two_scenes_collide_pair_by_pair():
    v, f = box_mesh([0, 0, 0], [1, 1, 1])
    s1, s2 = bvhkit.Scene(np.float64), bvhkit.Scene(np.float64)
    g1, g2 = s1.add_mesh(v, f), s2.add_mesh(v, f)
    a = s1.add_instance(g1, None, [0, 0, 0])
    b = s1.add_instance(g1, None, [5, 0, 0])
    c = s2.add_instance(g2, None, [0.5, 0.5, 0.5])  # overlaps a
    d = s2.add_instance(g2, None, [6.5, 0, 0], margin=0.6)  # 0.5 from b: with the margin
    e = s2.add_instance(g2, None, [5, 0, 0], group=2, mask=2)  # filtered out
    assert [tuple(p) for p in s1.colliding_pairs_with(s2)] == [(a, c), (b, d)]
    assert s1.any_collision_with(s2)
    assert [tuple(p) for p in s1.colliding_pairs_with(s2, ignore=[[a, c]])] == [(b, d)]
    assert not s1.any_collision_with(s2, ignore=[[a, c], [b, d]])
    assert [tuple(p) for p in s2.colliding_pairs_with(s1)] == [(c, a), (d, b)]
    assert e not in {int(x) for x in s1.colliding_pairs_with(s2).ravel()}
    # The closest pair across: (b, d) 0.5 apart less d's margin 0.6 beats (a, c) overlapping.
    near = s1.closest_pair_with(s2)
    assert [tuple(p) for p in near.pairs] == [(b, d)]
    assert near.distance[0] == pytest.approx(-0.1, abs=1e-9)
    near = s1.closest_pair_with(s2, ignore=[[b, d]])
    assert [tuple(p) for p in near.pairs] == [(a, c)] and near.distance[0] == 0
    assert len(s1.closest_pair_with(bvhkit.Scene(np.float64)).distance) == 0
    # Pairs within 0.2 across: (a, c) overlapping (0) and (b, d) at -0.1; e is filtered out.
    w = s1.pairs_within_with(s2, 0.2)
    assert [tuple(p) for p in w.pairs] == [(a, c), (b, d)]
    assert w.distance == pytest.approx([0.0, -0.1], abs=1e-9)
    assert len(s1.pairs_within_with(s2, -0.2).distance) == 0
    assert [tuple(p) for p in s1.pairs_within_with(s2, 0.2, ignore=[[a, c]]).pairs] == [(b, d)]
    with pytest.raises(ValueError, match="threshold"):
        s1.pairs_within_with(s2, float("nan"))
    # Face contacts across: (a, c) cross along segments on both unit boxes' surfaces (the
    # largest |coordinate - centre| is 1/2 on a box's surface); (b, d) within the margin only.
    fc = s1.colliding_faces_with(s2)
    crossing = ~fc.separated
    assert {tuple(p) for p in fc.pairs[crossing]} == {(a, c)}
    assert {tuple(p) for p in fc.pairs[fc.separated]} == {(b, d)}
    for end in (fc.p[crossing], fc.q[crossing]):
        assert np.abs(end - 0.5).max(axis=1) == pytest.approx(0.5, abs=1e-12)
        assert np.abs(end - 1.0).max(axis=1) == pytest.approx(0.5, abs=1e-12)
    sep = np.flatnonzero(fc.separated)[0]
    assert fc.p[sep][0] == pytest.approx(6.0, abs=1e-12)  # b's face x = 6
    assert fc.q[sep][0] == pytest.approx(6.5, abs=1e-12)  # d's face x = 6.5
    assert fc.coplanar.dtype == np.bool_ and fc.faces.shape == (len(fc.pairs), 2)
    assert len(s1.colliding_faces_with(s2, ignore=[[a, c], [b, d]]).pairs) == 0
    # Within one scene: a and c of one scene cross as they do across.
    s3 = bvhkit.Scene(np.float64)
    g3 = s3.add_mesh(v, f)
    x, y = s3.add_instance(g3, None, [0, 0, 0]), s3.add_instance(g3, None, [0.5, 0.5, 0.5])
    within = s3.colliding_faces()
    assert {tuple(p) for p in within.pairs} == {(x, y)} and not within.separated.any()
    assert sorted(map(tuple, within.faces)) == sorted(map(tuple, fc.faces[crossing]))
    with pytest.raises(TypeError, match="other"):
        s1.colliding_pairs_with(bvhkit.Scene(np.float32))
    with pytest.raises(TypeError, match="other"):
        s1.any_collision_with("scene")
    with pytest.raises(ValueError, match="ignore"):
        s1.colliding_pairs_with(s2, ignore=[[a, 7]])  # 7 names no instance of s2


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_save_load_pickle_answer_bit_for_bit(dtype, tmp_path):
    m, rng = random_scene(3, dtype, 100.0, 1.0, count=20)
    ids = list(m.poses)
    m.remove(ids[4:6])
    s = m.scene
    s.set_options(ids[7], margin=0.1, group=2, user_data=77)
    data = s.to_bytes()
    path = tmp_path / "scene.bvhkit"
    s.save(path)
    copies = [bvhkit.Scene.from_bytes(data), bvhkit.Scene.load(path),
              pickle.loads(pickle.dumps(s)), bvhkit.Scene.from_bytes(bytearray(data))]
    o, dirs = random_rays(rng, 300, 100.0, 1.0)
    points = 100.0 + rng.uniform(-3, 3, (200, 3))
    for c in copies:
        assert c.dtype == s.dtype and c.to_bytes() == data
        assert np.array_equal(c.ids(), s.ids()) and c.options(ids[7]) == s.options(ids[7])
        for x, y in zip(c.intersect(o, dirs), s.intersect(o, dirs)):
            assert np.array_equal(x, y)
        for x, y in zip(c.closest_point(points), s.closest_point(points)):
            assert np.array_equal(x, y)
        assert np.array_equal(c.colliding_pairs(), s.colliding_pairs())
        for x, y in zip(c.closest_pair(), s.closest_pair()):
            assert np.array_equal(x, y)
        with pytest.raises(ValueError, match="names no live"):
            c.set_pose(ids[4], None, [0, 0, 0])  # removed before saving: stale in the copy too
    # Damage: every truncation and a flipped byte are ValueErrors.
    for n in range(0, len(data), 97):
        with pytest.raises(ValueError):
            bvhkit.Scene.from_bytes(data[:n])
    bad = bytearray(data)
    bad[len(bad) // 2] ^= 0x40
    with pytest.raises(ValueError, match="checksum"):
        bvhkit.Scene.from_bytes(bytes(bad))
    with pytest.raises(TypeError):
        bvhkit.Scene.from_bytes("not bytes")
    with pytest.raises(ValueError, match="pickled"):
        bvhkit.Scene().__setstate__({"x": 1})
    with pytest.raises(ValueError):
        s.save(tmp_path)  # a directory


def test_dask_ships_a_scene():
    da = pytest.importorskip("dask.array")
    import bvhkit.dask as bd
    m, rng = random_scene(5, np.float64, 0.0, 1.0, count=10)
    s = m.scene
    o, d = random_rays(rng, 500, 0.0, 1.0)
    p = rng.uniform(-2, 2, (400, 3))
    for target in (s, bd.share(s)):
        got = bd.closest_point(target, da.from_array(p, chunks=(100, 3)))
        for x, y in zip(got, s.closest_point(p)):
            assert np.array_equal(x.compute(), y)
        hits = bd.intersect(target, da.from_array(o, chunks=(128, 3)),
                            da.from_array(d, chunks=(128, 3)))
        for x, y in zip(hits, s.intersect(o, d)):
            assert np.array_equal(x.compute(), y)
        occ = bd.occluded(target, da.from_array(o, chunks=(128, 3)),
                          da.from_array(d, chunks=(128, 3)), tmax=1.0)
        assert np.array_equal(occ.compute(), s.occluded(o, d, tmax=1.0))
        for sign in ("pseudonormal", "winding_number"):
            got = bd.signed_distance(target, da.from_array(p, chunks=(100, 3)), sign=sign)
            for x, y in zip(got, s.signed_distance(p, sign=sign)):
                assert np.array_equal(x.compute(), y)
        inside = bd.contains(target, da.from_array(p, chunks=(100, 3)))
        assert np.array_equal(inside.compute(), s.contains(p))
    with pytest.raises(TypeError, match="TriangleMesh query"):
        bd.winding_number(s, da.from_array(p, chunks=(100, 3)))
    with pytest.raises(ValueError, match="max_distance"):
        bd.closest_point(s, da.from_array(p, chunks=(100, 3)), max_distance=1.0)
