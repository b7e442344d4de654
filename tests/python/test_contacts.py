"""bvhkit.contacts: the contact manifold against analytic boxes and numpy's own plane tests."""

import numpy as np
import pytest

import bvhkit
from reference import box_mesh, random_rotations


def boxes(dtype=np.float64, delta=0.1):
    """A unit box (a) pushed delta into the top of a 4 x 4 box (b, identity pose)."""
    va, fa = box_mesh([-0.5, -0.5, -delta], [0.5, 0.5, 1 - delta])
    vb, fb = box_mesh([-2, -2, -3], [2, 2, 0])
    return (bvhkit.CollisionModel(va, fa, dtype=dtype), bvhkit.CollisionModel(vb, fb, dtype=dtype))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_box_into_box(dtype):
    a, b = boxes(dtype)
    (c,) = bvhkit.contacts(a, b, None, np.zeros(3))
    assert isinstance(c, bvhkit.Contacts)
    assert c.points.shape == (4, 3) and c.points.dtype == dtype
    assert c.normals.shape == (4, 3) and c.depths.shape == (4,) and c.faces.shape == (4, 2)
    tol = 1e-12 if dtype == np.float64 else 1e-6
    # The four bottom corners of a, at depth 0.1, pushed straight up.
    assert np.all(c.kinds == 1)
    np.testing.assert_allclose(c.depths, 0.1, atol=tol)
    np.testing.assert_allclose(c.normals, [[0, 0, 1]] * 4, atol=tol)
    np.testing.assert_allclose(np.sort(np.abs(c.points[:, :2]).ravel()), 0.5, atol=tol)
    np.testing.assert_array_equal(c.regions, 0)
    every = bvhkit.contacts(a, b, None, np.zeros(3), max_points=0)[0]
    assert len(every.depths) > 4
    assert np.all(every.depths <= 0.1 + tol) and np.all(every.normals[:, 2] >= -tol)


def test_apart_and_batches():
    a, b = boxes()
    rng = np.random.default_rng(3)
    k = 12
    rot = random_rotations(rng, k)
    trans = rng.uniform(-1.5, 1.5, (k, 3))
    trans[0] = [0, 0, 5]  # far above: nothing
    batch = bvhkit.contacts(a, b, rot, trans, threads=3)
    hit = bvhkit.collide(a, b, rot, trans)
    assert len(batch) == k
    assert len(batch[0].depths) == 0 and batch[0].points.shape == (0, 3)
    for i in range(k):
        one = bvhkit.contacts(a, b, rot[i], trans[i], threads=1)[0]
        for x, y in zip(batch[i], one):
            np.testing.assert_array_equal(x, y)
        assert (len(batch[i].depths) > 0) == hit[i]
        if hit[i]:
            np.testing.assert_allclose(np.linalg.norm(batch[i].normals, axis=1), 1, atol=1e-12)
            assert np.all(batch[i].depths >= 0)
            assert np.all(np.diff(batch[i].regions) >= 0)
            counts = np.bincount(batch[i].regions)
            assert np.all(counts <= 4) and np.all(counts >= 1)


def polytope_depth(points, vertices, faces):
    """Minus the largest face-plane value of a convex mesh at each point: > 0 inside, the depth."""
    t = vertices[faces]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    values = np.einsum("fk,pk->pf", n, points) - np.einsum("fk,fk->f", n, t[:, 0])[None]
    return -values.max(axis=1)


def test_spheres_against_the_polytope_planes():
    v, f = bvhkit.load_mesh("sphere:subdiv=3")
    v = np.asarray(v, np.float64)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    f = np.asarray(f, np.int64)
    a = bvhkit.CollisionModel(v, f, dtype=np.float64)
    t = np.array([1.7, 0.05, -0.02])
    c = bvhkit.contacts(a, a, None, t, max_points=0)[0]
    inside_b = polytope_depth(v, v + t, f)  # a's vertices against b (the same sphere, moved)
    inside_a = polytope_depth(v + t, v, f)
    clear = (np.abs(inside_b) > 1e-9).all() and (np.abs(inside_a) > 1e-9).all()
    assert clear
    assert (c.kinds == 1).sum() == (inside_b > 0).sum()
    assert (c.kinds == 2).sum() == (inside_a > 0).sum()
    np.testing.assert_allclose(np.sort(c.depths[c.kinds == 1]), np.sort(inside_b[inside_b > 0]),
                               atol=1e-12)
    assert np.all(c.normals[:, 0] < 0)  # pushing a away from b
    assert abs(c.depths.max() - 0.3) < 0.02
    four = bvhkit.contacts(a, a, None, t)[0]
    assert len(four.depths) == 4 and four.depths[0] == c.depths.max()
    local = bvhkit.contacts(a, a, None, t, max_points=0, walk_inside=False)[0]
    assert 0 < (local.kinds == 1).sum() < (c.kinds == 1).sum()
    assert local.depths.max() < c.depths.max()


def test_refit_and_open_meshes():
    a, b = boxes()
    before = bvhkit.contacts(a, b, None, np.zeros(3))[0]
    va, fa = box_mesh([-0.5, -0.5, -0.2], [0.5, 0.5, 0.8])
    a.refit(va)
    after = bvhkit.contacts(a, b, None, np.zeros(3))[0]
    np.testing.assert_allclose(before.depths, 0.1, atol=1e-12)
    np.testing.assert_allclose(after.depths, 0.2, atol=1e-12)
    curve = bvhkit.contacts(a, b, None, np.zeros(3), max_points=0, inside_vertices=False)[0]
    assert np.all(curve.kinds == 0) and np.all(curve.depths == 0)


def test_bad_arguments():
    a, b = boxes()
    c32 = boxes(np.float32)[0]
    z = np.zeros(3)
    with pytest.raises(ValueError, match="max_points"):
        bvhkit.contacts(a, b, None, z, max_points=-1)
    with pytest.raises(TypeError, match="max_points"):
        bvhkit.contacts(a, b, None, z, max_points=4.0)
    with pytest.raises(TypeError, match="inside_vertices"):
        bvhkit.contacts(a, b, None, z, inside_vertices="yes")
    with pytest.raises(TypeError, match="walk_inside"):
        bvhkit.contacts(a, b, None, z, walk_inside=None)
    with pytest.raises(TypeError, match="b:"):
        bvhkit.contacts(a, c32, None, z)
    with pytest.raises(TypeError, match="a:"):
        bvhkit.contacts("a", b, None, z)
    with pytest.raises(ValueError, match="translations"):
        bvhkit.contacts(a, b, None, [np.nan, 0, 0])
    with pytest.raises(ValueError):
        bvhkit.contacts(a, b, np.eye(3) * 2, z)
