"""P4 and P5 of python -m bvhkit.bench: collision and distance between two copies of a mesh at
random poses, and the cost of one call, beside python-fcl and Coal."""

from __future__ import annotations

import statistics
import time
from typing import Callable, List

import numpy as np

import bvhkit

from .bench import Workload, _rotations


def p4(v, f, k, reps, mods):
    rng = np.random.default_rng(4)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    rot = _rotations(rng, k)
    trans = rng.uniform(-0.5, 0.5, (k, 3)) * diag
    obb = bvhkit.CollisionModel(v, f, volume="obb")
    rss = bvhkit.CollisionModel(v, f, volume="rss")
    hull = bvhkit.CollisionModel(v, f, volume="hull")  # the fastest volume for distance
    c = Workload("P4 collide", k)
    d = Workload("P4 dist", k)
    c.add("bvhkit (1 thread)", "1", lambda: bvhkit.collide(obb, obb, rot, trans, threads=1))
    c.add("bvhkit (all threads)", "all", lambda: bvhkit.collide(obb, obb, rot, trans))
    d.add("bvhkit (1 thread)", "1", lambda: bvhkit.distance(hull, hull, rot, trans * 2, threads=1))
    d.add("bvhkit (all threads)", "all", lambda: bvhkit.distance(hull, hull, rot, trans * 2))
    d.add("bvhkit rss volume (1 thread)", "1",
          lambda: bvhkit.distance(rss, rss, rot, trans * 2, threads=1), lambda r: r.distance)
    v64 = v.astype(np.float64)

    fcl = mods.get("fcl")
    if fcl:
        def setup_fcl():
            model = fcl.BVHModel()
            model.beginModel(len(v), len(f))
            model.addSubModel(v64, f.astype(np.int32))
            model.endModel()
            a = fcl.CollisionObject(model, fcl.Transform())

            def one(r, t, distance):
                b = fcl.CollisionObject(model, fcl.Transform(r, t))
                if distance:
                    res = fcl.DistanceResult()
                    return fcl.distance(a, b, fcl.DistanceRequest(), res)
                return fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()) > 0
            c.add("python-fcl collide (loop)", "1",
                  lambda: np.array([one(rot[i], trans[i], False) for i in range(k)]), bool_)
            d.add("python-fcl distance (loop)", "1",
                  lambda: np.array([one(rot[i], 2 * trans[i], True) for i in range(k)]), float_)
        c.peer("python-fcl", setup_fcl)
    coal = mods.get("coal")
    if coal:
        def setup_coal():
            model = coal.BVHModelOBBRSS()
            model.beginModel(len(f), len(v))
            model.addVertices(v64)
            model.addTriangles(f.astype(np.int64))
            model.endModel()
            identity = coal.Transform3s()

            def one(r, t, distance):
                pose = coal.Transform3s(np.ascontiguousarray(r), np.ascontiguousarray(t))
                if distance:
                    res = coal.DistanceResult()
                    coal.distance(model, identity, model, pose, coal.DistanceRequest(), res)
                    return max(res.min_distance, 0.0)
                res = coal.CollisionResult()
                coal.collide(model, identity, model, pose, coal.CollisionRequest(), res)
                return res.isCollision()
            c.add("coal collide (loop)", "1",
                  lambda: np.array([one(rot[i], trans[i], False) for i in range(k)]), bool_)
            d.add("coal distance (loop)", "1",
                  lambda: np.array([one(rot[i], 2 * trans[i], True) for i in range(k)]), float_)
        c.peer("coal", setup_coal)

    def check_collide(answer, reference):
        return f"same yes/no on {int((answer == reference).sum())}/{len(reference)} poses"

    def check_distance(answer, reference):
        ref = reference.distance
        err = np.abs(np.maximum(answer, 0) - ref).max() / diag
        return f"max |diff| {err:.1e} of the diagonal"
    return c.measure(reps, check_collide) + d.measure(reps, check_distance)


def bool_(r):
    return np.asarray(r, dtype=bool)


def _per_call(call: Callable[[], object], reps: int) -> float:
    """Median over `reps` rounds of the mean time of one call (us), rounds of about 20 ms."""
    call()
    n = max(1, int(0.02 / max(1e-7, _timed(call))))
    rounds = [_timed(lambda: [call() for _ in range(n)]) / n for _ in range(reps)]
    return statistics.median(rounds) * 1e6


def _timed(call: Callable[[], object]) -> float:
    t = time.perf_counter()
    call()
    return time.perf_counter() - t


def p5(v, f, reps, mods) -> List[str]:
    model, scene = bvhkit.CollisionModel(v, f), bvhkit.TriangleMesh(v, f)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    eye, far = np.eye(3), np.array([2.0 * diag, 0, 0])
    center = v.mean(0)
    point = (center + (v[0] - center) * 1.05)[None]  # just outside the mesh, near a vertex
    origin, up = (center - [0, 0, diag])[None], np.array([[0, 0, 1.0]])
    calls = {
        "bvhkit collide, 1 pose, apart": lambda: bvhkit.collide(model, model, eye, far),
        "bvhkit signed_distance, 1 point": lambda: scene.signed_distance(point),
        "bvhkit intersect, 1 ray": lambda: scene.intersect(origin, up),
    }
    if "fcl" in mods:
        fcl = mods["fcl"]
        m = fcl.BVHModel()
        m.beginModel(len(v), len(f))
        m.addSubModel(v.astype(np.float64), f.astype(np.int32))
        m.endModel()
        a = fcl.CollisionObject(m, fcl.Transform())
        b = fcl.CollisionObject(m, fcl.Transform(eye, far))
        request = fcl.CollisionRequest()
        calls["python-fcl collide, 1 pose, apart"] = \
            lambda: fcl.collide(a, b, request, fcl.CollisionResult())
    rows = [f"P5        {k:38} {_per_call(c, reps):8.2f} us per call" for k, c in calls.items()]
    rng = np.random.default_rng(6)
    for k in (1, 10, 100, 1000):
        rot, trans = _rotations(rng, k), rng.uniform(-0.5, 0.5, (k, 3)) * diag
        t0, t1 = (_per_call(lambda n=n: bvhkit.collide(model, model, rot, trans, threads=n), reps)
                  for n in (0, 1))
        rows.append(f"P5        collide {k:>5} poses threads=0 {t0:10.1f} us, threads=1 "
                    f"{t1:10.1f} us: {t0 / t1:.2f}x")
    return rows


def float_(r):
    return np.asarray(r, dtype=np.float64)
