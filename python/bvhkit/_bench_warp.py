"""P10 of python -m bvhkit.bench: warp-lang's mesh queries on the CPU (its BVH over a wp.Mesh)
beside bvhkit's: closest-hit rays, closest points and the winding-number sign. Warp compiles its
kernels on first use: that compile is timed and reported apart, outside the medians."""

from __future__ import annotations

import time
from typing import List

import numpy as np

import bvhkit

from .bench import Workload, _check_distances, _check_hits, _rays


def _warp_kernels(wp):
    @wp.kernel
    def closest_hits(mesh: wp.uint64, origins: wp.array(dtype=wp.vec3),
                     directions: wp.array(dtype=wp.vec3), t: wp.array(dtype=float),
                     face: wp.array(dtype=int)):
        i = wp.tid()
        q = wp.mesh_query_ray(mesh, origins[i], directions[i], 1.0e30)
        if q.result:
            t[i] = q.t
            face[i] = q.face
        else:
            t[i] = wp.inf
            face[i] = -1

    @wp.kernel
    def closest_points(mesh: wp.uint64, points: wp.array(dtype=wp.vec3),
                       distance: wp.array(dtype=float)):
        i = wp.tid()
        q = wp.mesh_query_point_no_sign(mesh, points[i], 1.0e30)
        if q.result:
            distance[i] = wp.length(points[i] - wp.mesh_eval_position(mesh, q.face, q.u, q.v))
        else:
            distance[i] = wp.inf

    @wp.kernel
    def winding_signs(mesh: wp.uint64, points: wp.array(dtype=wp.vec3),
                      distance: wp.array(dtype=float)):
        i = wp.tid()
        # accuracy 2 and threshold 0.5: Warp's defaults (Barill et al. 2018's fast winding number)
        q = wp.mesh_query_point_sign_winding_number(mesh, points[i], 1.0e30, 2.0, 0.5)
        if q.result:
            d = wp.length(points[i] - wp.mesh_eval_position(mesh, q.face, q.u, q.v))
            distance[i] = d * q.sign
        else:
            distance[i] = wp.inf

    return closest_hits, closest_points, winding_signs


def p10(v, f, n, reps, wp) -> List[str]:
    v = np.ascontiguousarray(v, dtype=np.float32)
    o, d = _rays(v, n, 10)
    rng = np.random.default_rng(10)
    lo, hi = v.min(0), v.max(0)
    p = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), (n, 3)).astype(np.float32)
    scene = bvhkit.TriangleMesh(v, f)
    scene.closest_point(p[:10])  # build outside the timing, as the peer's mesh is
    rays = Workload("P10 rays", n)
    points = Workload("P10 point", n)
    signs = Workload("P10 sign", n)
    rays.add("bvhkit (1 thread)", "1", lambda: scene.intersect(o, d, threads=1))
    rays.add("bvhkit (all threads)", "all", lambda: scene.intersect(o, d))
    points.add("bvhkit (1 thread)", "1", lambda: scene.closest_point(p, threads=1))
    points.add("bvhkit (all threads)", "all", lambda: scene.closest_point(p))
    signs.add("bvhkit (1 thread)", "1",
              lambda: scene.signed_distance(p, sign="winding_number", threads=1))
    signs.add("bvhkit (all threads)", "all",
              lambda: scene.signed_distance(p, sign="winding_number"))
    compile_note = []
    if wp is not None:
        def setup():
            wp.init()
            device = "cpu"
            mesh = wp.Mesh(points=wp.array(v, dtype=wp.vec3, device=device),
                           indices=wp.array(f.astype(np.int32).ravel(), dtype=int, device=device))
            hits_k, points_k, signs_k = _warp_kernels(wp)
            wo, wd = wp.array(o, dtype=wp.vec3), wp.array(d, dtype=wp.vec3)
            wpnt = wp.array(p, dtype=wp.vec3)
            t_out, face_out = wp.empty(n, dtype=float), wp.empty(n, dtype=int)
            dist_out = wp.empty(n, dtype=float)

            def launch(kernel, inputs):
                wp.launch(kernel, dim=n, inputs=inputs, device=device)
                wp.synchronize()
            run_hits = lambda: launch(hits_k, [mesh.id, wo, wd, t_out, face_out])  # noqa: E731
            run_points = lambda: launch(points_k, [mesh.id, wpnt, dist_out])  # noqa: E731
            run_signs = lambda: launch(signs_k, [mesh.id, wpnt, dist_out])  # noqa: E731
            start = time.perf_counter()
            # The first launch of each kernel compiles it (or loads it from Warp's cache).
            for kernel, inputs in ((hits_k, [mesh.id, wo, wd, t_out, face_out]),
                                   (points_k, [mesh.id, wpnt, dist_out]),
                                   (signs_k, [mesh.id, wpnt, dist_out])):
                wp.launch(kernel, dim=1, inputs=inputs, device=device)
            wp.synchronize()
            compile_note.append(f"P10       warp-lang {wp.__version__}: first launches (compile or "
                                f"cache load) {time.perf_counter() - start:.2f} s, not in the medians")
            rays.add("warp mesh_query_ray (cpu)", "1", lambda: (run_hits(), t_out.numpy())[1],
                     lambda r: r)
            points.add("warp mesh_query_point_no_sign (cpu)", "1",
                       lambda: (run_points(), dist_out.numpy().copy())[1], lambda r: r)
            signs.add("warp ..._sign_winding_number (cpu)", "1",
                      lambda: (run_signs(), dist_out.numpy().copy())[1], lambda r: r)
        rays.peer("warp-lang", setup)

    def check_signs(answer, reference):
        same = np.sign(np.asarray(answer)) == np.sign(np.asarray(reference)[: len(answer)])
        return f"same sign at {same.mean() * 100:.3f}% of {len(answer)} points"
    return (compile_note + rays.measure(reps, _check_hits) + points.measure(reps, _check_distances)
            + signs.measure(reps, check_signs))
