"""Batches give the same answers for every thread count, Python threads may call at once, and the
GIL is released while a batch runs."""

import threading
import time

import numpy as np

import bvhkit


def big_scene():
    v, f = bvhkit.load_mesh("sphere:subdiv=4")
    return v, f, bvhkit.TriangleMesh(v, f)


def test_thread_counts_agree():
    v, f, scene = big_scene()
    rng = np.random.default_rng(8)
    p = rng.uniform(-1.5, 1.5, (5000, 3))
    d = rng.normal(size=(5000, 3))
    for call in (lambda n: scene.intersect(p, d, threads=n),
                 lambda n: (scene.occluded(p, d, threads=n),),
                 lambda n: (scene.count_intersections(p, d, threads=n),),
                 lambda n: scene.closest_point(p, threads=n),
                 lambda n: (scene.signed_distance(p, threads=n),),
                 lambda n: (scene.signed_distance(p, sign="winding_number", threads=n),),
                 lambda n: (scene.winding_number(p[:1000], threads=n),)):
        one, four = call(1), call(4)
        for x, y in zip(one, four):
            np.testing.assert_array_equal(x, y)
    m = bvhkit.CollisionModel(v, f)
    rot = np.stack([np.eye(3)] * 32)
    trans = rng.uniform(-2, 2, (32, 3))
    np.testing.assert_array_equal(bvhkit.collide(m, m, rot, trans, threads=1),
                                  bvhkit.collide(m, m, rot, trans, threads=4))
    c1 = bvhkit.collide(m, m, rot, trans, contacts=True, threads=1)
    c4 = bvhkit.collide(m, m, rot, trans, contacts=True, threads=4)
    for x, y in zip(c1, c4):
        np.testing.assert_array_equal(x, y)
    for x, y in zip(bvhkit.distance(m, m, rot, trans * 3, threads=1),
                    bvhkit.distance(m, m, rot, trans * 3, threads=4)):
        np.testing.assert_array_equal(x, y)
    tree = bvhkit.DynamicTree3D()
    lo = rng.uniform(0, 50, (1000, 3))
    tree.create(lo, lo + 1)
    q = rng.uniform(0, 50, (1000, 3))
    np.testing.assert_array_equal(tree.query(q, q + 2, threads=1), tree.query(q, q + 2, threads=4))
    np.testing.assert_array_equal(tree.ray_cast(q, q * 0 + 3, threads=1),
                                  tree.ray_cast(q, q * 0 + 3, threads=4))


def test_four_python_threads_at_once():
    _, _, scene = big_scene()
    rng = np.random.default_rng(12)
    p = rng.uniform(-1.5, 1.5, (5000, 3))
    want = scene.closest_point(p, threads=1)
    want_sd = scene.signed_distance(p, threads=1)
    results = [None] * 4
    errors = []

    def work(i):
        try:
            results[i] = (scene.closest_point(p, threads=1), scene.signed_distance(p, threads=1))
        except Exception as e:  # reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    elapsed = time.perf_counter() - start
    assert not errors
    for cp, sd in results:
        np.testing.assert_array_equal(cp.distance, want.distance)
        np.testing.assert_array_equal(cp.face, want.face)
        np.testing.assert_array_equal(sd, want_sd)
    print(f"4 Python threads: {elapsed:.3f} s")


def test_gil_is_released_during_a_batch():
    # While one thread runs a long batch, this thread keeps running Python code: the longest
    # pause it sees is far shorter than the batch (with the GIL held it would span all of it).
    _, _, scene = big_scene()
    p = np.random.default_rng(3).uniform(-1.5, 1.5, (100000, 3))
    scene.closest_point(p[:10])  # build the structures outside the timed part
    done = threading.Event()

    def work():
        scene.closest_point(p, threads=1)
        done.set()

    t = threading.Thread(target=work)
    start = time.perf_counter()
    t.start()
    last, gap = time.perf_counter(), 0.0
    while not done.is_set():
        now = time.perf_counter()
        gap = max(gap, now - last)
        last = now
    t.join()
    total = time.perf_counter() - start
    print(f"batch {total:.3f} s, longest pause of the main thread {gap:.3f} s")
    assert total > 0.05
    assert gap < 0.5 * total
