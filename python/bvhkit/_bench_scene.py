"""Workload P6 of ``python -m bvhkit.bench``: a collision manager called once per robot
configuration, as a motion planner calls it. A six-link arm of capsule meshes (about 1,000
triangles each) among an environment of three scanned meshes, each configuration a new set of
link poses from forward kinematics, then "does the arm touch the environment?". bvhkit: one
``Scene`` (float64), the environment and the arm told apart by group and mask; per configuration
``set_poses`` and ``any_collision``, or ``any_collision_at`` (the scene unchanged), and all the
configurations in one ``any_collision_at`` call. python-fcl: the same meshes as ``BVHModel`` objects in two
``DynamicAABBTreeCollisionManager``s (arm, environment); per configuration the links'
``setTransform``, the arm manager's ``update`` and a manager-against-manager ``collide`` that stops
at the first contact. Both answer the same yes/no; the rows say on how many configurations they
agree.
"""

from __future__ import annotations

import time
from typing import Callable, List

import numpy as np

import bvhkit

ARM, WORLD = 1, 2
LINKS = 6


def capsule(radius: float, half_length: float, around: int = 32, rings: int = 16):
    """A closed capsule along z: two hemispheres of `rings` rings joined by the cylinder between
    them, `around` segments round (2 * around * (2 * rings) triangles or so)."""
    theta = np.linspace(0, np.pi / 2, rings + 1)
    phi = np.linspace(0, 2 * np.pi, around, endpoint=False)
    rows = []
    for sign in (1, -1):  # top hemisphere from the pole down, then bottom from its equator
        ts = theta if sign > 0 else theta[::-1]
        for t in ts:
            z = sign * (half_length + radius * np.cos(t))
            r = radius * np.sin(t)
            rows.append(np.stack([r * np.cos(phi), r * np.sin(phi), np.full(around, z)], 1))
    ring_count = len(rows)
    v = np.concatenate(rows)
    faces = []
    for i in range(ring_count - 1):
        for j in range(around):
            a, b = i * around + j, i * around + (j + 1) % around
            c, d = a + around, b + around
            faces += [(a, c, d), (a, d, b)]
    return v, np.array(faces)  # the poles' rings are points: degenerate faces there, harmless


def _rotation(axis: int, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    r = np.zeros(angle.shape + (3, 3))
    i, j = [k for k in range(3) if k != axis]
    r[..., axis, axis] = 1
    r[..., i, i], r[..., i, j], r[..., j, i], r[..., j, j] = c, -s, s, c
    return r


def arm_poses(q: np.ndarray, length: float):
    """Forward kinematics of a chain of LINKS links of `length`, alternating joints about z and
    y: (k, LINKS, 3, 3) rotations and (k, LINKS, 3) translations of each link's centre."""
    k = len(q)
    rot = np.broadcast_to(np.eye(3), (k, 3, 3)).copy()
    joint = np.zeros((k, 3))
    rotations, translations = [], []
    for link in range(LINKS):
        rot = rot @ _rotation(2 if link % 2 == 0 else 1, q[:, link])
        along = rot[:, :, 2]  # the capsule's axis
        rotations.append(rot.copy())
        translations.append(joint + along * length / 2)
        joint = joint + along * length
    return np.stack(rotations, 1), np.stack(translations, 1)


def p6(meshes, configurations: int, reps: int, fcl) -> List[str]:
    rng = np.random.default_rng(6)
    cv, cf = capsule(0.04, 0.11)
    length = 0.3
    # The environment: each mesh scaled to 0.4 across, around the arm's reach.
    places = [np.array([0.45, 0.0, 0.2]), np.array([-0.3, 0.4, 0.1]), np.array([0.0, -0.5, 0.6])]
    world = []
    for (v, f), at in zip(meshes, places):
        v = v.astype(np.float64)
        lo, hi = v.min(0), v.max(0)
        world.append(((v - (lo + hi) / 2) * (0.4 / np.max(hi - lo)), f, at))
    q = rng.uniform(-np.pi, np.pi, (configurations, LINKS))
    rotations, translations = arm_poses(q, length)
    translations[:, :, 2] += 0.05  # the base above the origin

    scene = bvhkit.Scene(dtype=np.float64)
    link_mesh = scene.add_mesh(cv, cf)
    for v, f, at in world:
        scene.add_instance(scene.add_mesh(v, f), translation=at, group=WORLD, mask=ARM)
    links = scene.add_instances(link_mesh, rotations[0], translations[0], group=ARM, mask=WORLD)
    scene.prepare()

    def run_bvhkit() -> np.ndarray:
        out = np.empty(configurations, bool)
        for i in range(configurations):
            scene.set_poses(links, rotations[i], translations[i])
            out[i] = scene.any_collision()
        return out

    def run_at() -> np.ndarray:
        # One configuration per call, the scene unchanged (any_collision_at): no set_poses.
        out = np.empty(configurations, bool)
        for i in range(configurations):
            out[i] = scene.any_collision_at(links, rotations[i], translations[i])
        return out

    def run_batched(threads: int) -> Callable[[], np.ndarray]:
        # Every configuration in one call, spread over the threads.
        return lambda: scene.any_collision_at(links, rotations, translations, threads=threads)

    runs = {"bvhkit Scene": run_bvhkit, "bvhkit any_collision_at, one a call": run_at,
            "bvhkit any_collision_at, all in one call (1)": run_batched(1),
            "bvhkit any_collision_at, all in one call (all)": run_batched(0)}
    rows: List[str] = []
    if fcl is not None:
        def model(v, f):
            m = fcl.BVHModel()
            m.beginModel(len(v), len(f))
            m.addSubModel(np.asarray(v, np.float64), np.asarray(f, np.int32))
            m.endModel()
            return m

        link_model = model(cv, cf)
        arm = [fcl.CollisionObject(link_model, fcl.Transform()) for _ in range(LINKS)]
        env = [fcl.CollisionObject(model(v, f), fcl.Transform(np.eye(3), at)) for v, f, at in world]
        arm_manager, env_manager = fcl.DynamicAABBTreeCollisionManager(), \
            fcl.DynamicAABBTreeCollisionManager()
        arm_manager.registerObjects(arm)
        arm_manager.setup()
        env_manager.registerObjects(env)
        env_manager.setup()

        def run_fcl() -> np.ndarray:
            out = np.empty(configurations, bool)
            for i in range(configurations):
                for obj, r, t in zip(arm, rotations[i], translations[i]):
                    obj.setTransform(fcl.Transform(r, t))
                arm_manager.update()
                data = fcl.CollisionData(request=fcl.CollisionRequest())
                arm_manager.collide(env_manager, data, fcl.defaultCollisionCallback)
                out[i] = data.result.is_collision
            return out

        runs["python-fcl DynamicAABBTreeCollisionManager"] = run_fcl
    else:
        rows.append("P6        python-fcl                              skipped: not installed")
    times = {k: [] for k in runs}
    answers = {}
    for _ in range(reps):
        for k, run in runs.items():
            t = time.perf_counter()
            answers[k] = run()
            times[k].append(time.perf_counter() - t)
    # The ratio: the peer's time over each bvhkit row's (above 1: bvhkit is faster), or for a
    # bvhkit row, python-fcl's time over it.
    peer = "python-fcl DynamicAABBTreeCollisionManager"
    base = float(np.median(times[peer])) if peer in times else None
    ref = answers["bvhkit Scene"]
    for k in runs:
        t = float(np.median(times[k]))
        ratio = "" if base is None or k == peer else f"{base / t:8.2f}x"
        agree = "" if k == "bvhkit Scene" else \
            f"agree on {np.mean(answers[k] == ref) * 100:.2f}% of {configurations}"
        rows.append(f"P6        {k:44} {t / configurations * 1e6:8.1f} us per configuration "
                    f"{ratio:>9}  {agree}")
    rows.append(f"P6        colliding configurations: {int(ref.sum())} of {configurations}")
    return rows
