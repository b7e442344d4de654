"""Solid and signed_distance_between: analytic depths of boxes and a cube into an L-shaped solid,
the separation property checked by collide (exact) on separate collision models, batches against
one-at-a-time calls, threads, and bad input."""

import numpy as np
import pytest

import bvhkit
from reference import box_mesh, random_rotations

I3 = np.eye(3)


def l_mesh():
    """The L: [0,3]x[0,1] joined with [0,1]x[0,3], z in [0,1], a prism over a counter-clockwise
    polygon, the caps fanned from the reflex corner (1, 1)."""
    poly = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]
    n = len(poly)
    v = np.array([(x, y, 0.0) for x, y in poly] + [(x, y, 1.0) for x, y in poly])
    f = []
    fan = 3
    for k in range(1, n - 1):
        i, j = (fan + k) % n, (fan + k + 1) % n
        f += [(n + fan, n + i, n + j), (fan, j, i)]
    for i in range(n):
        j = (i + 1) % n
        f += [(i, j, n + j), (i, n + j, n + i)]
    return v, np.array(f)


def solid(mesh, dtype=np.float64, volume="obb"):
    return bvhkit.Solid(*mesh, volume=volume, dtype=dtype)


def test_boxes_apart_and_into():
    a, b = solid(box_mesh([0, 0, 0], [2, 2, 2])), solid(box_mesh([0, 0, 0], [1, 1, 1]))
    assert a.convex and b.convex
    r = bvhkit.signed_distance_between(a, b, None, np.array([[2.5, 0.5, 0.5], [1.7, 0.5, 0.5]]))
    assert r.signed_distance[0] == pytest.approx(0.5, abs=1e-12)
    assert r.signed_distance[1] == pytest.approx(-0.3, abs=1e-6)
    assert np.allclose(r.normal, [[1, 0, 0], [1, 0, 0]], atol=1e-6)
    assert r.exact.all() and not r.contained.any()
    assert np.allclose(r.point_b - r.point_a, r.signed_distance[:, None] * r.normal, atol=1e-6)
    # Wholly inside: the least exit is -y by 1.2.
    r = bvhkit.signed_distance_between(a, b, I3, [0.6, 0.2, 0.7])
    assert r.contained[0]
    assert r.signed_distance[0] == pytest.approx(-1.2, abs=1e-6)


@pytest.mark.parametrize("volume", ["obb", "rss"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_cube_into_l(volume, dtype):
    l_solid = solid(l_mesh(), dtype, volume)
    cube = solid(box_mesh([0, 0, 0], [0.5, 0.5, 0.5]), dtype, volume)
    assert not l_solid.convex
    # Over the long arm: out through +y by 0.35; in the inner corner: (0.15, 0.2), 0.25.
    t = np.array([[1.75, 0.65, 0.25], [0.85, 0.8, 0.25]])
    r = bvhkit.signed_distance_between(l_solid, cube, None, t)
    tol = 1e-4 if dtype == np.float64 else 1e-3
    assert -r.signed_distance == pytest.approx([0.35, 0.25], abs=tol)
    assert r.normal[0] == pytest.approx([0, 1, 0], abs=1e-2)
    assert r.normal[1] == pytest.approx([0.6, 0.8, 0], abs=1e-2)
    assert not r.exact.any()


def test_separation_by_collide():
    """Moving b by (1 + 1e-6) of the translation leaves no intersecting face pair by collide on
    separate CollisionModels; by (1 - 1e-3) of it they intersect (poses with faces meeting)."""
    rng = np.random.default_rng(7)
    lm, bm = l_mesh(), box_mesh([-0.3, -0.3, -0.3], [0.3, 0.3, 0.3])
    a, b = solid(lm), solid(bm)
    ca, cb = (bvhkit.CollisionModel(*m, dtype=np.float64) for m in (lm, bm))
    k = 40
    rot = random_rotations(rng, k)
    t = rng.uniform([0, 0, 0], [3, 3, 1], size=(k, 3))
    r = bvhkit.signed_distance_between(a, b, rot, t)
    hit = bvhkit.collide(ca, cb, rot, t)
    checked = 0
    for i in range(k):
        if r.signed_distance[i] > 0:
            assert not hit[i]
            continue
        if r.contained[i]:
            continue
        move = -r.signed_distance[i] * r.normal[i]
        assert not bvhkit.collide(ca, cb, rot[i], t[i] + move * (1 + 1e-6))[0], i
        assert bvhkit.collide(ca, cb, rot[i], t[i] + move * (1 - 1e-3))[0], i
        checked += 1
    assert checked > 5


def test_batch_equals_single_and_threads():
    rng = np.random.default_rng(3)
    a, b = solid(l_mesh()), solid(box_mesh([0, 0, 0], [0.5, 0.5, 0.5]))
    rot = random_rotations(rng, 12)
    t = rng.uniform(0, 2, size=(12, 3))
    one = bvhkit.signed_distance_between(a, b, rot, t, threads=1)
    many = bvhkit.signed_distance_between(a, b, rot, t, threads=4)
    for x, y in zip(one, many):
        assert np.array_equal(x, y)
    for i in range(12):
        single = bvhkit.signed_distance_between(a, b, rot[i], t[i])
        assert single.signed_distance[0] == one.signed_distance[i]


def test_bad_input():
    v, f = box_mesh([0, 0, 0], [1, 1, 1])
    with pytest.raises(ValueError, match="not closed"):
        bvhkit.Solid(v, f[:-1])
    with pytest.raises(ValueError, match="volume"):
        bvhkit.Solid(v, f, volume="aabb")
    a = bvhkit.Solid(v, f)
    with pytest.raises(TypeError, match="b: must be a Solid"):
        bvhkit.signed_distance_between(a, bvhkit.CollisionModel(v, f), None, [0, 0, 0])
    with pytest.raises(TypeError, match="same volume and dtype"):
        bvhkit.signed_distance_between(a, bvhkit.Solid(v, f, dtype=np.float64), None, [0, 0, 0])
    with pytest.raises(ValueError, match="translations"):
        bvhkit.signed_distance_between(a, a, None, [[0, np.nan, 0]])
    with pytest.raises(ValueError, match="rotation"):
        bvhkit.signed_distance_between(a, a, 2 * I3, [0, 0, 0])
