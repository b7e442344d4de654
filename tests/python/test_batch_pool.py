"""The batch thread pool (python/src/batch.cpp): small batches with the default threads=0 cost what
threads=1 costs, several Python threads may run threads=0 batches at once, a forked child gets a
pool of its own, and one-pose calls check their poses in C++ with the messages of the Python
checks they replace."""

import os
import signal
import statistics
import sys
import threading
import time

import numpy as np
import pytest

import bvhkit
from test_collision import random_rotations


@pytest.fixture(scope="module")
def sphere():
    v, f = bvhkit.load_mesh("sphere:subdiv=3")
    return bvhkit.CollisionModel(v, f), bvhkit.TriangleMesh(v, f)


def poses(k, seed=1):
    rng = np.random.default_rng(seed)
    return random_rotations(rng, k), rng.uniform(-3, 3, (k, 3))


def median_time(call, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


@pytest.mark.parametrize("k", [1, 10])
def test_small_batches_with_threads_0_cost_what_threads_1_costs(sphere, k):
    # Medians of interleaved rounds, and a margin of 2x: a loaded machine slows both alike, while
    # starting threads per call (what the pool replaced) cost several times a 10-pose batch.
    model, _ = sphere
    r, t = poses(k)
    ratios = []
    for _ in range(5):
        t0 = median_time(lambda: bvhkit.collide(model, model, r, t, threads=0), 101)
        t1 = median_time(lambda: bvhkit.collide(model, model, r, t, threads=1), 101)
        ratios.append(t0 / t1)
    print(f"{k} poses: threads=0 / threads=1 = {sorted(ratios)}")
    assert statistics.median(ratios) < 2.0


def test_python_threads_run_threads_0_batches_at_once(sphere):
    # Batches long enough to call in the pool, from four Python threads: one holds the pool, the
    # others run alone; none waits for another, and every answer is the threads=1 answer.
    model, scene = sphere
    r, t = poses(3000, seed=2)
    points = np.random.default_rng(3).uniform(-1.5, 1.5, (20000, 3))
    want_hits = bvhkit.collide(model, model, r, t, threads=1)
    want_sd = scene.signed_distance(points, threads=1)
    errors = []

    def work():
        try:
            for _ in range(5):
                np.testing.assert_array_equal(bvhkit.collide(model, model, r, t), want_hits)
                np.testing.assert_array_equal(scene.signed_distance(points), want_sd)
        except Exception as e:  # reported below
            errors.append(e)

    workers = [threading.Thread(target=work) for _ in range(4)]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout=300)
    assert not any(w.is_alive() for w in workers), "a batch never finished"
    assert not errors, errors


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_forked_child_gets_its_own_pool(sphere):
    model, _ = sphere
    r, t = poses(3000, seed=4)
    want = bvhkit.collide(model, model, r, t, threads=0)  # the parent's pool exists now
    pid = os.fork()
    if pid == 0:  # the child: its first parallel batch starts a new pool
        ok = False
        try:
            ok = bool(np.array_equal(bvhkit.collide(model, model, r, t, threads=0), want))
        finally:
            os._exit(0 if ok else 1)
    deadline = time.monotonic() + 120
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            pytest.fail("the forked child's batch never finished")
        time.sleep(0.01)
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0


def test_pose_errors_name_the_first_bad_pose_in_the_python_layers_order(sphere):
    # The C++ pass checks each pose as it reads it, on every thread; the message is the one the
    # Python checks gave: a bad translation before a bad rotation entry before a rotation that is
    # not rigid, each the first of its kind.
    model, _ = sphere
    r, t = poses(4000, seed=5)
    r[100] *= 2  # not rigid
    r[2000, 0, 0] = np.nan
    t[3000, 1] = np.inf
    t[3500, 1] = np.nan
    for threads in (0, 1, 3):
        with pytest.raises(ValueError, match=r"^translations: row 3000 has a NaN or infinite"):
            bvhkit.collide(model, model, r, t, threads=threads)
        t_ok = np.nan_to_num(t, posinf=0.0)
        with pytest.raises(ValueError, match=r"^rotations: rotation 2000 has a NaN or infinite"):
            bvhkit.distance(model, model, r, t_ok, threads=threads)
        r_ok = np.nan_to_num(r)
        with pytest.raises(ValueError, match=r"^rotations: rotation 100 is not a rotation matrix"):
            bvhkit.collide(model, model, r_ok, t_ok, contacts=True, threads=threads)
    with pytest.raises(ValueError, match=r"^translations: row 3000 has a NaN"):
        bvhkit.collide(model, model, r[:5], t)  # before the count mismatch
    with pytest.raises(ValueError, match=r"^translations: 4000 rows, rotations has 5"):
        bvhkit.collide(model, model, r_ok[:5], t_ok)


def test_one_pose_shapes_and_dtypes(sphere):
    # A pose as a planner holds it, (3, 3) and (3,) float64 with a float32 model, answers as the
    # batch form converted by numpy does; so do float32, a non-contiguous view, lists and None.
    model, _ = sphere
    r, t = poses(20, seed=6)
    want = bvhkit.collide(model, model, r.astype(np.float32), t.astype(np.float32))
    got = [bool(bvhkit.collide(model, model, r[i], t[i])[0]) for i in range(20)]
    assert got == list(want)
    got = [bool(bvhkit.collide(model, model, r[i].tolist(), t[i].tolist())[0]) for i in range(20)]
    assert got == list(want)
    r_view = r.transpose(0, 2, 1).copy().transpose(0, 2, 1)  # not C-contiguous
    np.testing.assert_array_equal(bvhkit.collide(model, model, r_view, np.asfortranarray(t)), want)
    eye = bvhkit.collide(model, model, np.broadcast_to(np.eye(3), (20, 3, 3)), t)
    np.testing.assert_array_equal(bvhkit.collide(model, model, None, t), eye)
    d = bvhkit.distance(model, model, r[3], t[3])
    want_d = bvhkit.distance(model, model, r[3:4], t[3:4]).distance
    np.testing.assert_array_equal(d.distance, want_d)
    assert d.point_a.shape == (1, 3)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q", "-s"]))
