"""Every dtype and layout gives the same answers; bad input raises naming the argument."""

import numpy as np
import pytest

import bvhkit
from reference import random_soup


@pytest.fixture(scope="module")
def mesh():
    rng = np.random.default_rng(21)
    v, f = random_soup(rng, 40)
    return v, f


def layouts(a):
    """The same values as: C order, Fortran order, a strided view, a list."""
    yield np.ascontiguousarray(a)
    yield np.asfortranarray(a)
    wide = np.zeros((a.shape[0], a.shape[1] * 2), a.dtype)
    wide[:, ::2] = a
    yield wide[:, ::2]
    yield a.tolist()


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_layouts_and_dtypes_agree(mesh, dtype):
    v, f = mesh
    rng = np.random.default_rng(1)
    p = rng.uniform(-2, 2, (300, 3))
    d = rng.uniform(-1, 1, (300, 3))
    base = bvhkit.TriangleMesh(v.astype(dtype), f.astype(np.int64), dtype=dtype)
    want_hit = base.intersect(p, d)
    want_cp = base.closest_point(p)
    for vv in layouts(v.astype(dtype)):
        for ff in [f.astype(np.int32), f.astype(np.int64), np.asfortranarray(f), f.astype(np.uint16)]:
            scene = bvhkit.TriangleMesh(vv, ff, dtype=dtype)
            for pp in layouts(p):
                got = scene.closest_point(pp)
                np.testing.assert_array_equal(got.distance, want_cp.distance)
                np.testing.assert_array_equal(got.face, want_cp.face)
            for pp, dd in zip(layouts(p), layouts(d)):
                got = scene.intersect(pp, dd)
                np.testing.assert_array_equal(got.t, want_hit.t)
                np.testing.assert_array_equal(got.face, want_hit.face)
    assert want_cp.distance.dtype == dtype and want_hit.t.dtype == dtype
    # float64 vertices in a float32 scene are rounded once, as float32 vertices would be.
    if dtype == np.float32:
        s64 = bvhkit.TriangleMesh(v.astype(np.float64), f, dtype=np.float32)
        np.testing.assert_array_equal(s64.closest_point(p).distance, want_cp.distance)


def test_single_rows_are_accepted(mesh):
    v, f = mesh
    scene = bvhkit.TriangleMesh(v, f)
    assert scene.closest_point([0.1, 0.2, 0.3]).distance.shape == (1,)
    assert scene.intersect([0, 0, -5], [0, 0, 1]).t.shape == (1,)


BAD_SCENES = [
    (lambda v, f: bvhkit.TriangleMesh(v[:, :2], f), ValueError, "vertices"),
    (lambda v, f: bvhkit.TriangleMesh(v, f[:, :2]), ValueError, "faces"),
    (lambda v, f: bvhkit.TriangleMesh(v, f.astype(np.float64)), TypeError, "faces"),
    (lambda v, f: bvhkit.TriangleMesh(v.astype(str), f), TypeError, "vertices"),
    (lambda v, f: bvhkit.TriangleMesh(v, f + len(v)), ValueError, "faces"),
    (lambda v, f: bvhkit.TriangleMesh(v, f - f.max() - 1), ValueError, "faces"),
    (lambda v, f: bvhkit.TriangleMesh(v, f, dtype=np.int32), TypeError, "dtype"),
    (lambda v, f: bvhkit.TriangleMesh(v, f, dtype=np.float16), TypeError, "dtype"),
    (lambda v, f: bvhkit.TriangleMesh(v, f, builder="nope"), ValueError, "builder"),
    (lambda v, f: bvhkit.TriangleMesh(v, f, ray_test="nope"), ValueError, "ray_test"),
    (lambda v, f: bvhkit.TriangleMesh(v, f, threads=-1), ValueError, "threads"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).closest_point(v[:, :2]), ValueError, "points"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).closest_point(v, max_distance=-1), ValueError,
     "max_distance"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).closest_point(v, max_distance=np.nan), ValueError,
     "max_distance"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).intersect(v, v[:-1]), ValueError, "directions"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).intersect(v, v, tmax=np.ones(2)), ValueError, "tmax"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).signed_distance(v, sign="x"), ValueError, "sign"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).winding_number(v, beta=0), ValueError, "beta"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).refit(v[:-1]), ValueError, "vertices"),
    (lambda v, f: bvhkit.TriangleMesh(v, f).closest_point(v, threads=1.5), TypeError, "threads"),
    (lambda v, f: bvhkit.CollisionModel(v, f, volume="box"), ValueError, "volume"),
    (lambda v, f: bvhkit.CollisionModel(v, f + 1000), ValueError, "faces"),
    (lambda v, f: bvhkit.load_mesh("/no/such/file.obj"), ValueError, "file.obj"),
    (lambda v, f: bvhkit.load_mesh(3), TypeError, "path_or_spec"),
]


@pytest.mark.parametrize("call,error,name", BAD_SCENES)
def test_bad_input_names_the_argument(mesh, call, error, name):
    v, f = mesh
    with pytest.raises(error, match=name):
        call(v, f)


def test_bad_poses(mesh):
    v, f = mesh
    a = bvhkit.CollisionModel(v, f)
    b = bvhkit.CollisionModel(v, f, volume="rss")
    c = bvhkit.CollisionModel(v, f, dtype=np.float64)
    eye = np.eye(3)[None]
    with pytest.raises(TypeError, match="b"):
        bvhkit.collide(a, b, eye, [[0, 0, 0]])
    with pytest.raises(TypeError, match="b"):
        bvhkit.distance(a, c, eye, [[0, 0, 0]])
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.collide(a, a, eye * 2, [[0, 0, 0]])  # not a rotation
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.collide(a, a, -eye, [[0, 0, 0]])  # a reflection
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.collide(a, a, np.full((1, 3, 3), np.nan), [[0, 0, 0]])
    with pytest.raises(ValueError, match="translations"):
        bvhkit.collide(a, a, eye, [[np.inf, 0, 0]])
    with pytest.raises(ValueError, match="translations"):
        bvhkit.collide(a, a, np.stack([np.eye(3)] * 2), [[0, 0, 0]])
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.collide(a, a, np.eye(4)[None], [[0, 0, 0]])
    with pytest.raises(TypeError, match="a"):
        bvhkit.collide("a", a, eye, [[0, 0, 0]])
    with pytest.raises(ValueError, match="relative_tolerance"):
        bvhkit.distance(a, a, eye, [[0, 0, 0]], relative_tolerance=-1)


def test_bad_dynamic_tree_input():
    t = bvhkit.DynamicTree2D()
    with pytest.raises(ValueError, match="lo"):
        t.create([[0, 0, 0]], [[1, 1, 1]])  # 3D boxes in a 2D tree
    with pytest.raises(TypeError, match="ids"):
        t.destroy([0.5])
    with pytest.raises(ValueError, match="ids"):
        t.destroy([-1])
    with pytest.raises(ValueError, match="margin"):
        bvhkit.DynamicTree3D(margin=-1)
    with pytest.raises(ValueError, match="max_fraction"):
        t.ray_cast([[0, 0]], [[1, 0]], max_fraction=np.nan)
    assert len(t) == 0


def test_cpp_errors_become_value_errors(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(ValueError, match="bad.obj"):
        bvhkit.load_mesh(str(bad))
    with pytest.raises(ValueError, match="sphere"):
        bvhkit.load_mesh("sphere:subdiv=99")


def test_empty_batches_and_read_only_arrays(mesh):
    v, f = mesh
    v = v.copy()
    v.setflags(write=False)
    f32 = f.astype(np.int32)
    f32.setflags(write=False)
    scene = bvhkit.TriangleMesh(v, f32)
    none = np.zeros((0, 3))
    assert scene.closest_point(none).distance.shape == (0,)
    assert scene.intersect(none, none).t.shape == (0,)
    assert scene.winding_number(none).shape == (0,)
    m = bvhkit.CollisionModel(v, f32)
    assert bvhkit.collide(m, m, np.zeros((0, 3, 3)), none).shape == (0,)
    assert bvhkit.collide(m, m, None, none, contacts=True) == []
    assert bvhkit.distance(m, m, None, none).distance.shape == (0,)
    t = bvhkit.DynamicTree2D()
    assert t.create(np.zeros((0, 2)), np.zeros((0, 2))).shape == (0,)
    assert t.find_pairs().shape == (0, 2)
    assert t.query(np.zeros((0, 2)), np.zeros((0, 2))).shape == (0, 2)
    # An absurd thread count is capped, not an error.
    assert scene.closest_point(v[:5], threads=100000).face.shape == (5,)
