"""bvhkit.Scene (posed instances of shared meshes) against the same queries on the concatenated
world-space mesh: numpy brute force (reference.py) for rays and closest points, bvhkit.collide and
bvhkit.distance on each pair of instances for collision."""

import numpy as np
import pytest

import bvhkit
from reference import box_mesh, point_triangle, random_soup, ray_hits, triangles


def rotations(rng, k):
    """k random rotations (QR of Gaussian matrices, signs fixed to det +1)."""
    q, r = np.linalg.qr(rng.normal(size=(k, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


class Mirror:
    """A Scene and what it should hold, in float64: the world mesh its instances make."""

    def __init__(self, dtype, meshes):
        self.scene = bvhkit.Scene(dtype=dtype)
        self.dtype = dtype
        # What the scene holds: the meshes and poses rounded to its dtype.
        meshes = [(np.asarray(v, dtype).astype(float), f) for v, f in meshes]
        self.meshes = meshes
        self.geometry = [self.scene.add_mesh(v, f) for v, f in meshes]
        self.poses = {}  # id -> (geometry, R, t, group, mask, margin)

    def add(self, g, r, t, **options):
        i = self.scene.add_instance(g, r, t, **options)
        r, t = (np.asarray(x, self.dtype).astype(float) for x in (r, t))
        self.poses[i] = (g, r, t, options.get("group", 1),
                         options.get("mask", 0xFFFFFFFF), options.get("margin", 0.0))
        return i

    def set_poses(self, ids, r, t):
        self.scene.set_poses(ids, r, t)
        for i, ri, ti in zip(ids, r, t):
            g, _, _, *rest = self.poses[int(i)]
            ri, ti = (np.asarray(x, self.dtype).astype(float) for x in (ri, ti))
            self.poses[int(i)] = (g, ri, ti, *rest)

    def remove(self, ids):
        self.scene.remove(ids)
        for i in ids:
            del self.poses[int(i)]

    def world(self):
        """World vertices and faces of every live instance, in float64, and per face its
        (instance id, face index in its mesh)."""
        vs, fs, owner, n = [], [], [], 0
        for i, (g, r, t, *_) in self.poses.items():
            v, f = self.meshes[g]
            vs.append(np.asarray(v, float) @ r.T + t)
            fs.append(np.asarray(f) + n)
            owner += [(i, k) for k in range(len(f))]
            n += len(v)
        if not vs:
            return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 2), np.int64)
        return np.concatenate(vs), np.concatenate(fs), np.array(owner, np.int64)


def check_rays(m, origins, directions, tol, size):
    v, f, owner = m.world()
    hits = m.scene.intersect(origins, directions)
    occluded = m.scene.occluded(origins, directions)
    listed = m.scene.list_intersections(origins, directions)
    assert hits.t.dtype == m.scene.dtype and hits.instance.dtype == np.int64
    assert np.array_equal(listed.ray_splits[1:] - listed.ray_splits[:-1],
                          np.bincount(listed.ray_index, minlength=len(origins)))
    if len(f) == 0:
        assert np.isinf(hits.t).all() and (hits.instance == -1).all() and not occluded.any()
        assert len(listed.t) == 0
        return 0
    t, margin = ray_hits(v, f, origins, directions)
    checked = 0
    for r in range(len(origins)):
        if (margin[r] < 1e-4).any():
            continue  # grazes an edge or a tmin/tmax: either answer is right
        checked += 1
        order = np.argsort(t[r], kind="stable")
        finite = order[np.isfinite(t[r][order])]
        assert occluded[r] == (len(finite) > 0)
        mine = slice(listed.ray_splits[r], listed.ray_splits[r + 1])
        assert len(finite) == mine.stop - mine.start
        if not len(finite):
            assert hits.instance[r] == -1 and hits.face[r] == -1 and np.isinf(hits.t[r])
            assert np.array_equal(hits.normal[r], [0, 0, 0])
            continue
        best = finite[0]
        assert abs(hits.t[r] - t[r, best]) <= tol * max(1.0, t[r, best])
        np.testing.assert_allclose(listed.t[mine], t[r, finite], rtol=tol, atol=tol)
        assert sorted(map(tuple, owner[finite])) == sorted(
            zip(listed.instance[mine], listed.face[mine]))
        if len(finite) == 1 or t[r, finite[1]] - t[r, best] > 10 * tol * max(1.0, t[r, best]):
            assert (hits.instance[r], hits.face[r]) == tuple(owner[best])
            # The normal is the face's, under its instance's rotation: unit, and orthogonal to
            # the face's world edges.
            a, b, c = (x[best] for x in triangles(v, f))
            n = np.cross(b - a, c - a)
            np.testing.assert_allclose(hits.normal[r], n / np.linalg.norm(n), atol=100 * tol)
            g = m.poses[int(hits.instance[r])][0]
            assert hits.geometry[r] == m.geometry[g]
            w = hits.barycentric[r]
            np.testing.assert_allclose(w[0] * a + w[1] * b + w[2] * c,
                                       origins[r] + t[r, best] * directions[r],
                                       atol=10 * tol * size * max(1.0, t[r, best]))
    return checked


def check_closest(m, points, tol, size):
    v, f, owner = m.world()
    c = m.scene.closest_point(points)
    if len(f) == 0:
        assert np.isinf(c.distance).all() and np.isnan(c.point).all() and (c.instance == -1).all()
        return
    d, _ = point_triangle(points, v, f)
    np.testing.assert_allclose(c.distance, d.min(axis=1), rtol=tol, atol=tol * size)
    np.testing.assert_allclose(np.linalg.norm(c.point - points, axis=1), c.distance,
                               rtol=10 * tol, atol=10 * tol * size)
    # The face reported is at that distance (ties may name either face).
    lookup = {tuple(o): j for j, o in enumerate(owner)}
    rows = np.array([lookup[(i, k)] for i, k in zip(c.instance, c.face)])
    np.testing.assert_allclose(d[np.arange(len(points)), rows], c.distance, rtol=tol,
                               atol=tol * size)


def brute_pairs(m):
    """Colliding pairs by bvhkit.collide / bvhkit.distance on each pair, in the scene's order."""
    models = [bvhkit.CollisionModel(v, f, dtype=np.float64) for v, f in m.meshes]
    ids = sorted(m.poses, key=lambda i: i & 0xFFFFFFFF)
    out = []
    for x, a in enumerate(ids):
        ga, ra, ta, groupa, maska, ma = m.poses[a]
        for b in ids[x + 1:]:
            gb, rb, tb, groupb, maskb, mb = m.poses[b]
            if not (groupa & maskb and groupb & maska):
                continue
            r, t = ra.T @ rb, ra.T @ (tb - ta)
            if ma + mb == 0:
                hit = bvhkit.collide(models[ga], models[gb], r, t[None])[0]
            else:
                hit = bvhkit.distance(models[ga], models[gb], r, t[None]).distance[0] <= ma + mb
            if hit:
                out.append((a, b))
    return np.array(out, np.int64).reshape(-1, 2)


def random_scene(seed, dtype, offset=0.0, scale=1.0, count=16):
    rng = np.random.default_rng(seed)
    meshes = [random_soup(rng, n, size=0.3, scale=scale) for n in (10, 16, 7)]
    meshes.append(tuple(x * scale if i == 0 else x for i, x in enumerate(box_mesh([-.4] * 3,
                                                                                  [.4] * 3))))
    m = Mirror(dtype, meshes)
    for j in range(count):
        m.add(j % len(meshes), rotations(rng, 1)[0],
              offset + scale * rng.uniform(-1.5, 1.5, 3), user_data=1000 + j)
    return m, rng


def random_rays(rng, k, offset, scale):
    origins = offset + scale * rng.uniform(-6, 6, (k, 3))
    targets = offset + scale * rng.uniform(-1.5, 1.5, (k, 3))
    return origins, targets - origins


@pytest.mark.parametrize("dtype, offset, scale", [
    (np.float64, 0.0, 1.0), (np.float32, 0.0, 1.0), (np.float64, 1e5, 1.0),
    (np.float64, 0.0, 1e-3), (np.float64, 0.0, 1e3), (np.float32, 0.0, 1e-3),
])  # fmt: skip
def test_queries_match_the_world_mesh(dtype, offset, scale):
    m, rng = random_scene(7, dtype, offset, scale)
    eps = np.finfo(dtype).eps
    # Coordinates are rounded to the dtype once each way: the error scales with the largest one.
    tol = 1e3 * eps * (1 + abs(offset) / scale)
    o, d = random_rays(rng, 150, offset, scale)
    o, d = o.astype(dtype).astype(float), d.astype(dtype).astype(float)
    assert check_rays(m, o, d, tol, scale) > 100
    points = (offset + scale * rng.uniform(-4, 4, (60, 3))).astype(dtype).astype(float)
    check_closest(m, points, tol, scale)
    assert np.array_equal(m.scene.colliding_pairs(), brute_pairs(m))
    m.scene.validate()

    # New poses for half of them, in one call: no answer is stale.
    ids = np.array(sorted(m.poses))[::2]
    m.set_poses(ids, rotations(rng, len(ids)),
                offset + scale * rng.uniform(-1.5, 1.5, (len(ids), 3)))
    assert check_rays(m, o, d, tol, scale) > 100
    check_closest(m, points, tol, scale)
    assert np.array_equal(m.scene.colliding_pairs(), brute_pairs(m))
    assert m.scene.any_collision() == (len(brute_pairs(m)) > 0)

    # Removed instances are gone from every answer, and their ids are stale.
    gone = ids[:3]
    m.remove(gone)
    assert len(m.scene) == len(m.poses)
    assert check_rays(m, o, d, tol, scale) > 100
    check_closest(m, points, tol, scale)
    assert np.array_equal(m.scene.colliding_pairs(), brute_pairs(m))
    for i in gone:
        assert i not in m.scene
        with pytest.raises(ValueError, match="id"):
            m.scene.user_data(i)
    # A new instance reuses a slot, never an id.
    fresh = m.add(0, np.eye(3), np.full(3, offset))
    assert fresh not in set(int(i) for i in gone)
    with pytest.raises(ValueError, match=r"ids\[0\]"):
        m.scene.set_poses(gone[:1], np.eye(3)[None], np.zeros((1, 3)))
    with pytest.raises(ValueError, match=r"ids\[0\]"):
        m.scene.remove(gone[:1])
    with pytest.raises(ValueError, match="ignore"):
        m.scene.colliding_pairs([[fresh, gone[0]]])
    assert check_rays(m, o, d, tol, scale) > 100
    m.scene.validate()


def test_empty_scene():
    s = bvhkit.Scene()
    assert len(s) == 0 and s.geometry_count == 0
    lo, hi = s.bounds()
    assert np.isinf(lo).all() and (lo > 0).all() and (hi < 0).all()
    h = s.intersect([0, 0, 0], [1, 0, 0])
    assert h.instance[0] == -1 and np.isinf(h.t[0])
    assert not s.occluded([0, 0, 0], [1, 0, 0])[0]
    assert len(s.list_intersections([0, 0, 0], [1, 0, 0]).t) == 0
    c = s.closest_point([[1, 2, 3]])
    assert np.isinf(c.distance[0]) and c.instance[0] == -1
    assert s.colliding_pairs().shape == (0, 2) and not s.any_collision()
    g = s.add_mesh(*box_mesh([0, 0, 0], [1, 1, 1]))
    assert s.colliding_instances(g).shape == (0,) and not s.collides_with(g)
    s.validate()
    # Zero-row batches are fine.
    assert s.intersect(np.zeros((0, 3)), np.zeros((0, 3))).t.shape == (0,)
    assert s.closest_point(np.zeros((0, 3))).distance.shape == (0,)


def test_touching_overlapping_filters_and_margins():
    v, f = box_mesh([0, 0, 0], [1, 1, 1])
    m = Mirror(np.float64, [(v, f)])
    a = m.add(0, np.eye(3), [0, 0, 0])
    b = m.add(0, np.eye(3), [1, 0, 0])  # shares a face with a: touching collides
    c = m.add(0, np.eye(3), [0.5, 0.5, 0.5])  # overlaps both
    d = m.add(0, np.eye(3), [3, 0, 0], margin=0.6)  # 1 from b: collides only with a margin
    e = m.add(0, np.eye(3), [0, 0, 0.5], group=2, mask=2)  # overlaps a and c, filtered out
    pairs = m.scene.colliding_pairs()
    assert np.array_equal(pairs, brute_pairs(m))
    got = {tuple(p) for p in pairs}
    assert {(a, b), (a, c), (b, c)} <= got and (a, e) not in got and (b, d) not in got
    m.scene.set_poses([d], np.eye(3)[None], [[2.5, 0, 0]])
    m.poses[d] = (0, np.eye(3), np.array([2.5, 0, 0]), 1, 0xFFFFFFFF, 0.6)
    assert np.array_equal(m.scene.colliding_pairs(), brute_pairs(m))
    assert (b, d) in {tuple(p) for p in m.scene.colliding_pairs()}
    # ignore: either order, and then the rest.
    rest = m.scene.colliding_pairs(ignore=[[c, a], [b, a]])
    assert (a, c) not in {tuple(p) for p in rest} and (b, c) in {tuple(p) for p in rest}
    assert m.scene.any_collision() and not bvhkit.Scene().any_collision()
    # New options: e joins the rest; what was not given stays.
    m.scene.set_options([e], group=1, mask=0xFFFFFFFF)
    m.poses[e] = m.poses[e][:3] + (1, 0xFFFFFFFF, 0.0)
    assert np.array_equal(m.scene.colliding_pairs(), brute_pairs(m))
    assert {(a, e), (c, e)} <= {tuple(p) for p in m.scene.colliding_pairs()}
    m.scene.set_options(e, user_data=9)
    assert m.scene.options(e) == {"user_data": 9, "group": 1, "mask": 0xFFFFFFFF, "margin": 0}
    with pytest.raises(ValueError, match="margin"):
        m.scene.set_options([a, e], margin=[0.0, -1.0])
    assert m.scene.options(a)["margin"] == 0 and m.scene.options(e)["user_data"] == 9
    # One more posed mesh against the scene.
    assert list(m.scene.colliding_instances(0, None, [10, 0, 0])) == []
    assert list(m.scene.colliding_instances(0, None, [-1, 0, 0])) == [a, e]  # e touches too
    assert m.scene.collides_with(0, np.eye(3), [-1.2, 0, 0], margin=0.3)
    assert not m.scene.collides_with(0, np.eye(3), [-1.2, 0, 0])
    assert m.scene.user_data(a) == 0 and m.scene.geometry_of(e) == 0
    assert m.scene.options(e)["group"] == 1
    r, t = m.scene.pose(d)
    assert np.array_equal(r, np.eye(3)) and np.array_equal(t, [2.5, 0, 0])
    # Overlapping copies: a ray through them lists every face it crosses, nearest first.
    hits = m.scene.list_intersections([[0.7, 0.8, -5]], [[0, 0, 1]])
    assert np.all(np.diff(hits.t) >= 0) and set(hits.instance) == {a, c, e} and len(hits.t) == 6
    assert m.scene.intersect([[0.7, 0.8, -5]], [[0, 0, 1]]).t[0] == pytest.approx(5)


def test_threads_give_the_same_answers():
    m, rng = random_scene(3, np.float32, count=40)
    o, d = random_rays(rng, 3000, 0.0, 1.0)
    one = m.scene.intersect(o, d, threads=1)
    many = m.scene.intersect(o, d, threads=4)
    # One [tmin, tmax] for all (the one-ray fast path) or an array each: the same bits.
    o32, d32 = o.astype(np.float32), d.astype(np.float32)
    shared = m.scene.intersect(o32, d32, 0.0, np.inf)
    per_ray = m.scene.intersect(o32, d32, np.zeros(len(o)), np.full(len(o), np.inf))
    for x, y, z, w in zip(one, many, shared, per_ray):
        assert np.array_equal(x, y) and np.array_equal(x, z) and np.array_equal(x, w)
    with pytest.raises(ValueError, match="tmin"):
        m.scene.intersect(o32, d32, -1.0, np.inf)
    p = rng.uniform(-4, 4, (2000, 3))
    for x, y in zip(m.scene.closest_point(p, threads=1), m.scene.closest_point(p, threads=0)):
        assert np.array_equal(x, y, equal_nan=True)
    a, b = (m.scene.list_intersections(o, d, threads=n) for n in (1, 3))
    for x, y in zip(a, b):
        assert np.array_equal(x, y)


def test_queries_while_another_thread_changes_the_scene():
    """Queries hold a shared lock, changes an exclusive one: Python threads may mix them freely
    and every answer is of some whole state of the scene."""
    import threading

    m, rng = random_scene(5, np.float64, count=20)
    s, ids = m.scene, m.scene.ids()
    o, d = random_rays(rng, 400, 0.0, 1.0)
    errors, stop = [], threading.Event()

    def query():
        try:
            while not stop.is_set():
                h = s.intersect(o, d, threads=2)
                assert np.isfinite(h.t[h.instance >= 0]).all()
                s.closest_point(o[:50], threads=2)
                s.colliding_pairs()
        except Exception as e:  # reported by the main thread
            errors.append(e)

    def change():
        try:
            local = np.random.default_rng(1)
            for _ in range(20):
                k = len(ids)
                s.set_poses(ids, rotations(local, k), local.uniform(-1.5, 1.5, (k, 3)))
                s.remove(s.add_instances(0, None, local.uniform(-1, 1, (5, 3))))
        except Exception as e:
            errors.append(e)

    workers = [threading.Thread(target=query) for _ in range(2)]
    for w in workers:
        w.start()
    mover = threading.Thread(target=change)
    mover.start()
    mover.join()
    stop.set()
    for w in workers:
        w.join()
    assert not errors, errors
    s.validate()
    m.set_poses(ids, rotations(rng, len(ids)), rng.uniform(-1.5, 1.5, (len(ids), 3)))
    assert check_rays(m, o[:150], d[:150], 1e3 * np.finfo(float).eps, 1.0) > 100


def test_user_data_ids_and_batches():
    s = bvhkit.Scene(dtype=np.float64)
    g = s.add_mesh(*box_mesh([-1, -1, -1], [1, 1, 1]))
    along_x = np.stack([30.0 * np.arange(10), np.zeros(10), np.zeros(10)], axis=1)
    ids = s.add_instances(g, None, along_x,
                          user_data=np.arange(10, dtype=np.uint64) + 2**63)
    assert ids.dtype == np.int64 and len(s) == 10 and np.array_equal(np.sort(s.ids()), np.sort(ids))
    assert s.user_data(ids[3]) == 2**63 + 3 and isinstance(s.user_data(ids[3]), int)
    lo, hi = s.bounds()
    assert np.all(lo <= [-1, -1, -1]) and np.all(hi >= [271, 1, 1])
    assert np.all(lo > -1.01) and np.all(hi < [271.01, 1.01, 1.01])
    far = s.add_instance(g, translation=[500, 0, 0], user_data=2**64 - 1)
    assert far in s and s.user_data(far) == 2**64 - 1
    h = s.intersect([[0.3, -0.2, -5]], [[0, 0, 1]])
    assert h.instance[0] == ids[0] and h.t[0] == 4 and np.array_equal(h.normal[0], [0, 0, -1])
    rays = s.list_intersections([[0.3, -0.2, -5], [100, 100, 100]], [[0, 0, 1], [1, 0, 0]])
    assert list(rays.ray_index) == [0, 0] and list(rays.ray_splits) == [0, 2, 2]
    assert list(rays.t) == [4, 6] and list(rays.instance) == [ids[0]] * 2
    assert list(s.occluded([[0, 0, -5], [0, 0, -5]], [[0, 0, 1], [0, 0, 1]], tmax=[0.5, 4])) == [
        False, True]
    assert s.closest_point([[0, 0, 3]]).distance[0] == 2


def test_pinhole_rays():
    o, d = bvhkit.pinhole_rays(4, 3, 90, eye=[0, 0, 0], center=[0, 0, -1], up=[0, 1, 0])
    assert o.shape == d.shape == (12, 3) and o.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1, rtol=1e-6)
    # Row by row from the top left: x grows along a row, y falls down the rows.
    assert d[0, 0] < 0 < d[3, 0] and d[0, 1] > 0 > d[8, 1]
    # 90 degrees across 4 pixels: the image's edge at x/z = 1; pixel centres at 0.25 and 0.75.
    np.testing.assert_allclose(-d[3, 0] / d[3, 2], 0.75, rtol=1e-6)
    s = bvhkit.Scene()
    g = s.add_mesh(*box_mesh([-1, -1, -1], [1, 1, 1]))
    s.add_instance(g, translation=[0, 0, -10])
    o, d = bvhkit.pinhole_rays(32, 24, 40, [0, 0, 0], [0, 0, -1], [0, 1, 0])
    depth = s.intersect(o, d).t.reshape(24, 32)
    assert depth[12, 16] == pytest.approx(9, rel=1e-3) and np.isinf(depth[0, 0])
    for kwargs, match in [({"width": 0}, "width"), ({"fov_deg": 180}, "fov_deg"),
                          ({"center": [0, 0, 0]}, "center"), ({"up": [0, 0, 2]}, "up"),
                          ({"eye": [0, np.nan, 0]}, "eye")]:
        args = dict(width=4, height=3, fov_deg=60, eye=[0, 0, 0], center=[0, 0, -1], up=[0, 1, 0])
        args.update(kwargs)
        with pytest.raises(ValueError, match=match):
            bvhkit.pinhole_rays(**args)


def test_bad_arguments_are_named():
    s = bvhkit.Scene(dtype=np.float64)
    g = s.add_mesh(*box_mesh([0, 0, 0], [1, 1, 1]))
    i = s.add_instance(g)
    bad = np.diag([1.0, 1.0, 1.5])
    cases = [
        (lambda: bvhkit.Scene(dtype=np.int32), TypeError, "dtype"),
        (lambda: s.add_mesh(np.zeros((3, 2)), [[0, 1, 2]]), ValueError, "vertices"),
        (lambda: s.add_mesh(np.zeros((3, 3)), [[0, 1, 3]]), ValueError, "faces"),
        (lambda: s.add_mesh(np.zeros((3, 3)), [[0.0, 1, 2]]), TypeError, "faces"),
        (lambda: s.add_instance(5), ValueError, "geometry"),
        (lambda: s.add_instance(-1), ValueError, "geometry"),
        (lambda: s.add_instance("0"), TypeError, "geometry"),
        (lambda: s.add_instance(g, bad), ValueError, "rotation: rotation 0 is not a rotation"),
        (lambda: s.add_instance(g, -np.eye(3)), ValueError, "rotation"),
        (lambda: s.add_instance(g, np.eye(4)), ValueError, "rotation"),
        (lambda: s.add_instance(g, None, [0, np.nan, 0]), ValueError, "translation"),
        (lambda: s.add_instance(g, None, [0, 0]), ValueError, "translation"),
        (lambda: s.add_instance(g, margin=-1), ValueError, "margin"),
        (lambda: s.add_instance(g, margin=np.inf), ValueError, "margin"),
        (lambda: s.add_instance(g, group=2**32), ValueError, "group"),
        (lambda: s.add_instance(g, mask=True), TypeError, "mask"),
        (lambda: s.add_instance(g, user_data=-1), ValueError, "user_data"),
        (lambda: s.add_instances(g, np.stack([np.eye(3)] * 2), np.zeros((3, 3))), ValueError,
         "translations"),
        (lambda: s.add_instances(g), ValueError, "translations"),
        (lambda: s.set_poses([i], bad[None], [[0, 0, 0]]), ValueError, "rotations"),
        (lambda: s.set_poses([i], None, [[0, 0, np.inf]]), ValueError, "translations"),
        (lambda: s.set_poses([i, i], None, [[0, 0, 0]]), ValueError, "translations"),
        (lambda: s.set_poses([1.5], None, [[0, 0, 0]]), TypeError, "ids"),
        (lambda: s.set_poses([i + 7], None, [[0, 0, 0]]), ValueError, r"ids\[0\]"),
        (lambda: s.set_poses(np.array([i, -1]), None, np.zeros((2, 3))), ValueError, r"ids\[1\]"),
        (lambda: s.set_poses(np.array([2**64 - 1], np.uint64), None, [[0, 0, 0]]), ValueError,
         "ids"),
        (lambda: s.set_pose(-3), ValueError, "id"),
        (lambda: s.remove([i, i]), ValueError, "more than once"),
        (lambda: s.set_options([i + 7], group=3), ValueError, r"ids\[0\]"),
        (lambda: s.set_options([i], mask=-1), ValueError, "mask"),
        (lambda: s.set_options([i], user_data=[1, 2]), ValueError, "user_data"),
        (lambda: s.remove([[i]]), ValueError, "ids"),
        (lambda: s.user_data(i + 1), ValueError, "id"),
        (lambda: s.intersect([[0, 0, 0]], [[1, 0]]), ValueError, "directions"),
        (lambda: s.intersect([[0, 0, 0]], [[1, 0, 0], [1, 0, 0]]), ValueError, "directions"),
        (lambda: s.intersect([["a", 0, 0]], [[1, 0, 0]]), TypeError, "origins"),
        (lambda: s.intersect([[0, 0, 0]], [[1, 0, 0]], tmin=-1), ValueError, "tmin"),
        (lambda: s.intersect([[0, 0, 0]], [[1, 0, 0]], tmax="x"), TypeError, "tmax"),
        (lambda: s.occluded([[0, 0, 0]], [[1, 0, 0]], threads=-1), ValueError, "threads"),
        (lambda: s.list_intersections([[0, 0, 0]], [[1, 0, 0]], tmin=[0, 1]), ValueError, "tmin"),
        (lambda: s.closest_point([[0, 0]]), ValueError, "points"),
        (lambda: s.colliding_pairs([[i, i, i]]), ValueError, "ignore"),
        (lambda: s.colliding_pairs([[0.5, 1]]), TypeError, "ignore"),
        (lambda: s.colliding_instances(3), ValueError, "geometry"),
        (lambda: s.collides_with(g, bad), ValueError, "rotation"),
        (lambda: s.collides_with(g, margin=-0.1), ValueError, "margin"),
    ]
    for call, kind, match in cases:
        with pytest.raises(kind, match=match):
            call()
    # Nothing above changed the scene.
    assert len(s) == 1 and s.pose(i)[1].tolist() == [0, 0, 0]
    s.validate()
    # A strided int64 id array (not contiguous) is taken as any other.
    s.set_poses(np.array([i, i])[::2], None, [[0.0, 0.0, 1.0]])
    assert s.pose(i)[1][2] == 1
    s.set_pose(i)
    # NaN rays miss, NaN points find nothing: bad data in a batch is not an error.
    h = s.intersect([[np.nan, 0, 0], [0.5, 0.5, -1]], [[0, 0, 1], [0, 0, 1]])
    assert h.instance[0] == -1 and h.instance[1] == i
    assert np.isinf(s.closest_point([[np.nan, 0, 0]]).distance[0])


def test_docs_examples_run_as_written():
    """docs/scenes.md's Python examples, read from the file; the robot's printed pairs and its
    count of colliding configurations are the ones its comments show."""
    import contextlib
    import io
    import pathlib
    import re

    doc = pathlib.Path(__file__).resolve().parents[2] / "docs" / "scenes.md"
    section = doc.read_text(encoding="utf-8").split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    robot, renderer = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(robot, str(doc), "exec"), {})
    shown = [line[2:] for line in robot.splitlines()
             if line.startswith("# [") or re.match(r"# \d+ of ", line)]
    assert out.getvalue().splitlines() == shown
    namespace, out = {}, io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(renderer, str(doc), "exec"), namespace)
    assert out.getvalue().startswith("rock 44 at depth 39.0")  # the rock at (12, 0, 12)
    hits = namespace["hits"]
    assert (hits.instance >= 0).mean() > 0.2
    hit = hits.instance >= 0
    np.testing.assert_allclose(np.linalg.norm(hits.normal[hit], axis=1), 1, rtol=1e-5)
