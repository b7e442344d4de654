"""bvhkit.dask: the same answers as the single-process calls, the scene shipped once per worker,
and a clear ImportError without dask."""

import subprocess
import sys

import numpy as np
import pytest

import bvhkit

# The last test needs no dask; the others skip without it (scripts/test-python.sh installs it).
try:
    import dask.array as da

    import bvhkit.dask as bd
except ImportError:
    da = bd = None
needs_dask = pytest.mark.skipif(da is None, reason="dask is not installed")


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(11)
    v, f = bvhkit.load_mesh("sphere:subdiv=3")
    scene = bvhkit.TriangleMesh(v, f)
    points = rng.uniform(-1.5, 1.5, (4000, 3)).astype(np.float32)
    origins = rng.uniform(-2, 2, (4000, 3))
    directions = rng.normal(size=(4000, 3))
    return scene, points, origins, directions


def same(a, b):
    return np.array_equal(a, b, equal_nan=True) and a.dtype == b.dtype


def check_all(scene_or_shared, scene, points, origins, directions):
    p = da.from_array(points, chunks=(700, 3))
    o = da.from_array(origins, chunks=(900, 3))
    d = da.from_array(directions, chunks=(500, 3))  # rechunked to the origins' rows
    got = [
        bd.signed_distance(scene_or_shared, p),
        bd.signed_distance(scene_or_shared, p, sign="winding_number"),
        bd.winding_number(scene_or_shared, p),
        bd.contains(scene_or_shared, p),
        *bd.closest_point(scene_or_shared, p),
        *bd.intersect(scene_or_shared, o, d),
        bd.occluded(scene_or_shared, o, d, tmax=1.0),
        bd.count_intersections(scene_or_shared, o, d),
    ]
    assert got[0].numblocks == (6,)
    want = [
        scene.signed_distance(points),
        scene.signed_distance(points, sign="winding_number"),
        scene.winding_number(points),
        scene.contains(points),
        *scene.closest_point(points),
        *scene.intersect(origins, directions),
        scene.occluded(origins, directions, tmax=1.0),
        scene.count_intersections(origins, directions),
    ]
    computed = da.compute(*got)
    for i, (g, w) in enumerate(zip(computed, want)):
        assert same(g, w), i


@needs_dask
def test_threaded_scheduler_matches(data):
    scene = data[0]
    check_all(scene, *data)
    check_all(bd.share(scene), *data)


def loads_per_worker(client):
    return client.run(lambda: __import__("bvhkit")._scene_file.load_count)


@needs_dask
def test_cluster_matches_and_ships_the_scene_once_per_worker(data):
    distributed = pytest.importorskip("distributed")
    scene, points = data[0], data[1]
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        assert set(loads_per_worker(client).values()) == {0}
        p = da.from_array(points, chunks=(250, 3))  # 16 partitions over 2 workers
        got = bd.signed_distance(scene, p).compute()
        assert same(got, scene.signed_distance(points))
        assert set(loads_per_worker(client).values()) == {1}  # once per worker, not per partition
        shared = bd.share(scene)
        assert set(loads_per_worker(client).values()) == {2}
        check_all(shared, *data)  # nine calls, no further shipment
        assert set(loads_per_worker(client).values()) == {2}


@needs_dask
def test_bad_arguments(data):
    scene, points = data[0], data[1]
    with pytest.raises(TypeError, match="scene"):
        bd.signed_distance("scene", points)
    with pytest.raises(ValueError, match="points: must have shape"):
        bd.signed_distance(scene, points[:, :2])
    with pytest.raises(ValueError, match="sign"):
        bd.signed_distance(scene, points, sign="nope")
    with pytest.raises(ValueError, match="directions: 3 rows"):
        bd.intersect(scene, points, points[:3])
    with pytest.raises(TypeError, match="tmax: must be a real number"):
        bd.occluded(scene, points, points, tmax=np.ones(len(points)))
    with pytest.raises(TypeError, match="threads"):
        bd.winding_number(scene, points, threads=1.5)


def test_without_dask_import_bvhkit_works_and_bvhkit_dask_names_the_package():
    code = (
        "import sys; sys.modules['dask'] = None; sys.modules['dask.array'] = None\n"
        "import bvhkit\n"
        "try:\n"
        "    import bvhkit.dask\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert 'pip install "dask' in out.stdout
