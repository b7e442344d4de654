"""CollisionModel.save / load, to_bytes / from_bytes and pickling: the same collide and distance
answers bit for bit, and damaged or forged data refused with ValueError."""

import pickle

import numpy as np
import pytest

import bvhkit
from bvhkit import _collision
from test_collision import random_rotations

VOLUMES = ["obb", "rss", "obbrss", "aabb", "sphere", "kdop18", "hull"]


def meshes(dtype):
    va, fa = bvhkit.load_mesh("sphere:subdiv=3")
    vb, fb = bvhkit.load_mesh("torus:u=24,v=12")
    rng = np.random.default_rng(3)
    va = va + rng.normal(scale=0.01, size=va.shape).astype(va.dtype)
    return va.astype(dtype), fa, (vb * 0.5).astype(dtype), fb


def answers(a, b, rot, trans):
    """Every query's arrays, for an exact comparison."""
    contacts = bvhkit.collide(a, b, rot, trans, contacts=True)
    return [
        bvhkit.collide(a, b, rot, trans),
        np.concatenate(contacts),
        np.array([len(c) for c in contacts]),
        *bvhkit.distance(a, b, rot, trans),
        bvhkit.self_intersections(a),
    ]


def assert_same(x, y):
    assert len(x) == len(y)
    for p, q in zip(x, y):
        assert p.dtype == q.dtype and p.shape == q.shape
        np.testing.assert_array_equal(p.view(np.uint8), q.view(np.uint8))  # NaN included


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("volume", VOLUMES)
def test_round_trips_answer_bit_for_bit(tmp_path, volume, dtype):
    va, fa, vb, fb = meshes(dtype)
    a = bvhkit.CollisionModel(va, fa, volume=volume, dtype=dtype)
    b = bvhkit.CollisionModel(vb, fb, volume=volume, dtype=dtype)
    rng = np.random.default_rng(5)
    k = 300
    rot = random_rotations(rng, k)
    trans = rng.uniform(-1.5, 1.5, (k, 3))
    expected = answers(a, b, rot, trans)
    assert 0 < expected[0].sum() < k  # some poses collide, some do not
    path = tmp_path / "a.bvhcm"
    a.save(path)
    assert path.read_bytes() == a.to_bytes()
    loads = _collision.load_count
    copies = [
        (bvhkit.CollisionModel.from_bytes(a.to_bytes()), b),
        (bvhkit.CollisionModel.load(path), b),
        (pickle.loads(pickle.dumps(a)), pickle.loads(pickle.dumps(b))),
        pickle.loads(pickle.dumps((pickle.loads(pickle.dumps(a)), b))),
    ]
    assert _collision.load_count == loads + 7  # every copy came through the format
    for ca, cb in copies:
        assert (ca.volume, ca.dtype, ca.face_count) == (a.volume, a.dtype, a.face_count)
        assert_same(answers(ca, cb, rot, trans), expected)
        assert ca.to_bytes() == a.to_bytes()


def test_refitted_model_travels_and_refits_again():
    va, fa, vb, fb = meshes(np.float32)
    a = bvhkit.CollisionModel(va, fa, volume="rss")
    b = bvhkit.CollisionModel(vb, fb, volume="rss")
    a.refit(va * 1.3)
    copy = pickle.loads(pickle.dumps(a))
    rot = np.eye(3, dtype=np.float32)[None].repeat(20, 0)
    trans = np.linspace(-2, 2, 60, dtype=np.float32).reshape(20, 3)
    assert_same(answers(copy, b, rot, trans), answers(a, b, rot, trans))
    copy.refit(va)
    a.refit(va)
    assert copy.to_bytes() == a.to_bytes()
    with pytest.raises(ValueError, match="vertices: "):
        copy.refit(va[:-1])


def test_faces_left_out_and_empty_models_round_trip():
    va, fa, _, _ = meshes(np.float64)
    va = va.copy()
    va[fa[3, 0]] = np.nan
    a = bvhkit.CollisionModel(va, fa, volume="obb", dtype=np.float64)
    assert pickle.loads(pickle.dumps(a)).to_bytes() == a.to_bytes()
    empty = bvhkit.CollisionModel(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    assert pickle.loads(pickle.dumps(empty)).to_bytes() == empty.to_bytes()


def small_bytes(volume="obb"):
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    return bvhkit.CollisionModel(v, f, volume=volume).to_bytes()


def test_every_truncation_is_a_value_error():
    data = small_bytes()
    for n in range(0, len(data), 7):
        with pytest.raises(ValueError, match="^data: "):
            bvhkit.CollisionModel.from_bytes(data[:n])
    with pytest.raises(ValueError, match="^data: "):
        bvhkit.CollisionModel.from_bytes(data + b"\0")


def test_random_byte_flips_are_value_errors():
    data = small_bytes()
    rng = np.random.default_rng(1)
    for _ in range(300):
        bad = bytearray(data)
        for at in rng.integers(0, len(bad), rng.integers(1, 4)):
            bad[at] ^= int(rng.integers(1, 256))
        if bytes(bad) == data:
            continue
        with pytest.raises(ValueError):
            bvhkit.CollisionModel.from_bytes(bytes(bad))


def reseal(dtype, volume, state):
    return _collision._encode(np.dtype(dtype), volume, state)


def test_forged_containers_are_value_errors():
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    a = bvhkit.CollisionModel(v, f, volume="obb")
    vertices, faces, model = a._impl.state()
    # A damaged model file inside a container with a valid checksum: the C++ loader's checksum.
    bad = bytearray(model)
    bad[100] ^= 1
    with pytest.raises(ValueError, match="checksum"):
        bvhkit.CollisionModel.from_bytes(reseal(np.float32, "obb", (vertices, faces, bytes(bad))))
    # The container says rss, the model file holds boxes.
    with pytest.raises(ValueError, match="bounding volume"):
        bvhkit.CollisionModel.from_bytes(reseal(np.float32, "rss", (vertices, faces, model)))
    # The container says float64.
    with pytest.raises(ValueError, match="float"):
        bvhkit.CollisionModel.from_bytes(reseal(np.float64, "obb", (vertices, faces, model)))
    # Another mesh beside the model: moved vertices, other faces, fewer faces.
    with pytest.raises(ValueError, match="does not hold face"):
        bvhkit.CollisionModel.from_bytes(reseal(np.float32, "obb", (vertices * 2, faces, model)))
    with pytest.raises(ValueError, match="does not hold face"):
        bvhkit.CollisionModel.from_bytes(
            reseal(np.float32, "obb", (vertices, faces[:, [1, 2, 0]], model)))
    with pytest.raises(ValueError, match="covers"):
        bvhkit.CollisionModel.from_bytes(reseal(np.float32, "obb", (vertices, faces[1:], model)))
    with pytest.raises(ValueError, match="faces: face 0 names vertex"):
        bvhkit.CollisionModel.from_bytes(
            reseal(np.float32, "obb", (vertices, faces + len(vertices), model)))
    # A finite face the model lists as left out.
    vn = v.copy()
    vn[f[0, 0]] = np.nan
    holed = bvhkit.CollisionModel(vn, f, volume="obb")
    with pytest.raises(ValueError, match="finite but left out"):
        bvhkit.CollisionModel.from_bytes(
            reseal(np.float32, "obb", (v, f, holed._impl.state()[2])))
    with pytest.raises(ValueError, match="not a bvhkit CollisionModel"):
        bvhkit.CollisionModel.from_bytes(bvhkit.TriangleMesh(v, f).to_bytes())


def test_bad_arguments(tmp_path):
    with pytest.raises(TypeError, match="data: must be bytes-like"):
        bvhkit.CollisionModel.from_bytes(12)
    a = bvhkit.CollisionModel.__new__(bvhkit.CollisionModel)
    with pytest.raises(ValueError, match="state"):
        a.__setstate__({"something": b""})
    path = tmp_path / "bad.bvhcm"
    path.write_bytes(small_bytes()[:-1])
    with pytest.raises(ValueError, match="bad.bvhcm"):
        bvhkit.CollisionModel.load(path)
