"""TriangleMesh.save / load, to_bytes / from_bytes and pickling: the same answers bit for bit, and
damaged data refused with ValueError."""

import pickle

import numpy as np
import pytest

import bvhkit
from bvhkit import _scene_file


def answers(scene, points, origins, directions):
    """Every query's arrays, for an exact comparison."""
    hits = scene.intersect(origins, directions)
    cp = scene.closest_point(points)
    return [
        *hits,
        scene.occluded(origins, directions),
        scene.count_intersections(origins, directions),
        *cp,
        scene.signed_distance(points),
        scene.signed_distance(points, sign="winding_number"),
        scene.winding_number(points),
    ]


def assert_same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype
        # Bit for bit, NaN included.
        np.testing.assert_array_equal(x.view(np.uint8), y.view(np.uint8))


def queries(rng, k):
    points = rng.uniform(-1.5, 1.5, (k, 3))
    origins = rng.uniform(-2, 2, (k, 3))
    directions = rng.normal(size=(k, 3))
    return points, origins, directions


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("ray_test", ["watertight", "fast"])
@pytest.mark.parametrize("built", [False, True])
def test_round_trips_answer_bit_for_bit(tmp_path, dtype, ray_test, built):
    rng = np.random.default_rng(7)
    v, f = bvhkit.load_mesh("sphere:subdiv=4")
    v = v + rng.normal(scale=0.01, size=v.shape).astype(v.dtype)  # not a perfect sphere
    scene = bvhkit.TriangleMesh(v, f, dtype=dtype, ray_test=ray_test, builder="sweep_sah")
    pts, o, d = queries(rng, 10_000)
    if built:  # the proximity trees travel only once built
        scene.signed_distance(pts[:10], sign="winding_number")
    data = scene.to_bytes()
    path = tmp_path / "scene.bvhscene"
    scene.save(path)
    assert path.read_bytes() == data
    copies = [
        bvhkit.TriangleMesh.from_bytes(data),
        bvhkit.TriangleMesh.load(path),
        pickle.loads(pickle.dumps(scene)),
        pickle.loads(pickle.dumps(pickle.loads(pickle.dumps(scene)))),
    ]
    expected = answers(scene, pts, o, d)  # builds the proximity trees where they were not
    for copy in copies:
        assert copy.dtype == scene.dtype
        assert copy.stats() == scene.stats()
        assert_same(answers(copy, pts, o, d), expected)
    # Saving the answered scene again gives the same bytes as saving the loaded one.
    assert bvhkit.TriangleMesh.from_bytes(scene.to_bytes()).to_bytes() == scene.to_bytes()


def test_built_trees_travel_and_refit_is_kept():
    v, f = bvhkit.load_mesh("sphere:subdiv=3")
    scene = bvhkit.TriangleMesh(v, f)
    bare = len(scene.to_bytes())
    scene.winding_number(np.zeros((1, 3)))
    with_winding = len(scene.to_bytes())
    scene.closest_point(np.zeros((1, 3)))
    with_both = len(scene.to_bytes())
    assert bare < with_winding < with_both
    scene.refit(v * 2)
    copy = bvhkit.TriangleMesh.from_bytes(scene.to_bytes())
    p = np.array([[1.5, 0, 0], [2.5, 0, 0]])
    np.testing.assert_array_equal(copy.contains(p), [True, False])
    copy.refit(v)  # the loaded scene keeps the mesh, so it can refit
    np.testing.assert_array_equal(copy.contains(p), [False, False])


def test_empty_mesh_round_trips():
    scene = bvhkit.TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    copy = bvhkit.TriangleMesh.from_bytes(scene.to_bytes())
    assert copy.face_count == 0
    assert np.isinf(copy.signed_distance(np.zeros((2, 3)))).all()


def small_scene_bytes():
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    scene = bvhkit.TriangleMesh(v, f)
    scene.signed_distance(np.zeros((1, 3)), sign="winding_number")
    return scene.to_bytes()


def test_every_truncation_is_a_value_error():
    data = small_scene_bytes()
    for n in range(len(data)):
        with pytest.raises(ValueError, match="^data: "):
            bvhkit.TriangleMesh.from_bytes(data[:n])
    with pytest.raises(ValueError, match="^data: "):
        bvhkit.TriangleMesh.from_bytes(data + b"\0")


def test_random_byte_flips_are_value_errors():
    data = small_scene_bytes()
    rng = np.random.default_rng(3)
    for _ in range(300):
        b = bytearray(data)
        for i in rng.integers(0, len(b), rng.integers(1, 4)):
            b[i] ^= int(rng.integers(1, 256))
        with pytest.raises(ValueError):
            bvhkit.TriangleMesh.from_bytes(bytes(b))


def reseal(b: bytearray) -> bytes:
    """The container with its checksum recomputed, so that the checks behind it are reached."""
    h = _scene_file._HEADER.size
    b[h : h + 8] = _scene_file._checksum(bytes(b[:h]), bytes(b[h + 8 :]))
    return bytes(b)


def test_forged_containers_are_value_errors():
    data = bytearray(small_scene_bytes())
    h = _scene_file.HEADER_SIZE
    # A face index past the vertices, with the checksum made to match.
    (nv,) = np.frombuffer(bytes(data[16:24]), "<u8")
    name_len = int(np.frombuffer(bytes(data[32:40]), "<u8")[0])
    faces_at = h + name_len + (-name_len % 8) + 12 * int(nv) + (-12 * int(nv) % 8)
    b = bytearray(data)
    b[faces_at : faces_at + 4] = np.uint32(nv).tobytes()
    with pytest.raises(ValueError, match="faces: face 0 names vertex"):
        bvhkit.TriangleMesh.from_bytes(reseal(b))
    # Random changes behind a valid checksum reach the tree loaders: ValueError or a scene.
    rng = np.random.default_rng(5)
    loaded = 0
    for _ in range(300):
        b = bytearray(data)
        for i in rng.integers(h, len(b), rng.integers(1, 3)):
            b[i] ^= int(rng.integers(1, 256))
        try:
            s = bvhkit.TriangleMesh.from_bytes(reseal(b))
        except ValueError:
            continue
        loaded += 1
        s.signed_distance(np.zeros((4, 3)))  # answers without crashing
    assert loaded < 300
    with pytest.raises(ValueError, match="not a bvhkit TriangleMesh"):
        bvhkit.TriangleMesh.from_bytes(b"x" * 200)


def test_bad_arguments():
    with pytest.raises(TypeError, match="data: must be bytes-like"):
        bvhkit.TriangleMesh.from_bytes("not bytes")
    with pytest.raises(TypeError, match="threads"):
        bvhkit.TriangleMesh.from_bytes(small_scene_bytes(), threads=1.5)
    s = object.__new__(bvhkit.TriangleMesh)
    with pytest.raises(ValueError, match="state"):
        s.__setstate__({"other": 1})


def test_load_names_the_file(tmp_path):
    path = tmp_path / "bad.bvhscene"
    path.write_bytes(small_scene_bytes()[:-3])
    with pytest.raises(ValueError, match="bad.bvhscene"):
        bvhkit.TriangleMesh.load(path)


def test_to_bytes_while_other_threads_query_and_build():
    from concurrent.futures import ThreadPoolExecutor

    v, f = bvhkit.load_mesh("sphere:subdiv=4")
    scene = bvhkit.TriangleMesh(v, f)
    p = np.random.default_rng(1).uniform(-1.5, 1.5, (20_000, 3))
    want = bvhkit.TriangleMesh(v, f).signed_distance(p, sign="winding_number")
    with ThreadPoolExecutor(4) as pool:
        # The first queries build the proximity trees while to_bytes snapshots the scene.
        queries = [pool.submit(scene.signed_distance, p, "winding_number", 1) for _ in range(4)]
        saved = [pool.submit(scene.to_bytes) for _ in range(4)]
        for q in queries:
            np.testing.assert_array_equal(q.result(), want)
    for s in saved:
        copy = bvhkit.TriangleMesh.from_bytes(s.result())
        np.testing.assert_array_equal(copy.signed_distance(p, sign="winding_number"), want)


@pytest.mark.parametrize("ray_test", ["watertight", "fast"])
def test_spatial_split_scenes_rebuild_their_ray_tree(ray_test):
    # A ray tree with spatial splits has no file: the container holds no tree and flags the
    # rebuild (with the fast test when it was used), and the copy answers bit for bit.
    rng = np.random.default_rng(9)
    v = rng.uniform(-1, 1, (300, 3))
    v[::3] *= 0.02  # long triangles among small ones
    f = rng.integers(0, len(v), (400, 3))
    scene = bvhkit.TriangleMesh(v, f, ray_test=ray_test, spatial_splits=True)
    assert scene.stats()["spatial_splits"]
    # (With the fast test the tree is binary and priced per triangle: here it splits none.)
    assert scene.stats()["references"] > 400 or ray_test == "fast"
    scene.closest_point(np.zeros((1, 3)))
    data = scene.to_bytes()
    d = _scene_file.decode(data, "data")
    assert d.tree == b"" and d.spatial_splits and d.fast == (ray_test == "fast")  # none left out
    pts, o, dirs = queries(rng, 5000)
    expected = answers(scene, pts, o, dirs)
    for copy in [bvhkit.TriangleMesh.from_bytes(data), pickle.loads(pickle.dumps(scene))]:
        assert copy.stats() == scene.stats()
        assert_same(answers(copy, pts, o, dirs), expected)
    assert bvhkit.TriangleMesh.from_bytes(data).to_bytes() == data
    # The two flags and the tree section must agree.
    flags_at = 13
    for flags, tree_kept in [(8, True), (4 | 8, True), (0, False)]:
        b = bytearray(data if not tree_kept else small_scene_bytes())
        b[flags_at] = (b[flags_at] & 3) | flags
        with pytest.raises(ValueError, match="flag|left out|TriangleBvh file"):
            bvhkit.TriangleMesh.from_bytes(reseal(b))


def with_tree_section(data: bytes, section: bytes) -> bytes:
    """A spatial-split container whose ray tree section is replaced by `section`."""
    d = _scene_file.decode(data, "data")
    assert d.spatial_splits
    state = (d.vertices, d.faces, "fast" if d.fast else "watertight", section, d.sdf, d.winding,
             True)
    return _scene_file.encode(d.dtype, d.builder, state)


def test_spatial_split_scenes_keep_the_faces_left_out():
    # A face with a NaN corner is left out of the tree; a refit that makes it finite keeps it out.
    # The rebuilt tree of a loaded copy must leave out the same faces.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1]], float)
    f = np.array([[0, 1, 2], [3, 4, 5]])
    bad = v.copy()
    bad[3, 0] = np.nan
    scene = bvhkit.TriangleMesh(bad, f, spatial_splits=True)
    scene.refit(v)
    o, d = [[0.2, 0.2, 2.0]], [[0.0, 0.0, -1.0]]
    data = scene.to_bytes()
    for copy in [bvhkit.TriangleMesh.from_bytes(data), pickle.loads(pickle.dumps(scene))]:
        np.testing.assert_array_equal(copy.skipped(), [1])
        np.testing.assert_array_equal(copy.intersect(o, d).face, [0])
        np.testing.assert_array_equal(copy.count_intersections(o, d), [1])
    # A list of faces left out that is not one: each a ValueError.
    clean = bvhkit.TriangleMesh(v, f, spatial_splits=True).to_bytes()
    for section, message in [
        (b"\1\0\0", "multiple of 4"),
        (np.array([2], "<u4").tobytes(), "ascending face indices"),
        (np.array([1, 0], "<u4").tobytes(), "ascending face indices"),
        (np.array([1, 1], "<u4").tobytes(), "ascending face indices"),
    ]:
        with pytest.raises(ValueError, match=message):
            bvhkit.TriangleMesh.from_bytes(with_tree_section(clean, section))
    # The list must name every face with a non-finite corner, and only those it may leave out.
    nan_mesh = bvhkit.TriangleMesh(bad, f, spatial_splits=True).to_bytes()
    with pytest.raises(ValueError, match="faces left out are not the ones"):
        bvhkit.TriangleMesh.from_bytes(with_tree_section(nan_mesh, b""))
    kept_out = bvhkit.TriangleMesh.from_bytes(
        with_tree_section(clean, np.array([0], "<u4").tobytes()))
    np.testing.assert_array_equal(kept_out.skipped(), [0])
