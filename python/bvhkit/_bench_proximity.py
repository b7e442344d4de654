"""Workload P7 of ``python -m bvhkit.bench``: proximity over a scene of 100 posed objects. Four
closed meshes (each scaled to 1 across) placed 25 times each at random rotations on a jittered
5 x 5 x 4 grid (2 apart: no two objects overlap, so "inside" means the same to every library), and
random points over the scene's box. bvhkit: one ``Scene`` (float32; each mesh once, 100
instances), ``closest_point`` and ``signed_distance``. Open3D: a ``RaycastingScene`` holding one
geometry per object (``add_triangles`` of each posed copy: it has no instancing),
``compute_closest_points`` and ``compute_signed_distance`` (its sign from ray crossings). The
rows print how far the distances are apart and on how many points the signs agree.
"""

from __future__ import annotations

from typing import List

import numpy as np

import bvhkit


def _place(meshes, rng):
    """Each mesh centred and scaled to 1 across; 100 (mesh, rotation, translation), 25 a mesh."""
    unit = []
    for v, f in meshes:
        v = v.astype(np.float64)
        lo, hi = v.min(0), v.max(0)
        unit.append(((v - (lo + hi) / 2) / np.max(hi - lo), np.asarray(f)))
    grid = np.stack(np.meshgrid(np.arange(5), np.arange(5), np.arange(4), indexing="ij"),
                    -1).reshape(-1, 3) * 2.0
    q = rng.normal(size=(len(grid), 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    rotations = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)
    # A unit object reaches at most sqrt(3) / 2 from its centre: 0.13 of jitter keeps 2 apart
    # clear of overlaps.
    translations = grid + rng.uniform(-0.13, 0.13, grid.shape)
    which = np.arange(len(grid)) % len(unit)
    return unit, which, rotations, translations


def p7(meshes, n: int, reps: int, mods, workload) -> List[str]:
    rng = np.random.default_rng(7)
    unit, which, rotations, translations = _place(meshes, rng)
    scene = bvhkit.Scene(dtype=np.float32)
    geometry = [scene.add_mesh(v, f) for v, f in unit]
    scene.add_instances(np.asarray(geometry)[which], rotations, translations)
    lo, hi = scene.bounds()
    p = rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), (n, 3)).astype(np.float32)
    scene.signed_distance(p[:10])  # builds every mesh's tree outside the timing
    scene.closest_point(p[:10])
    o3d = mods.get("open3d")
    version = getattr(o3d, "__version__", "")

    rows: List[str] = []
    for kind in ("closest", "signed"):
        w = workload(f"P7 {kind}", n)
        if kind == "closest":
            w.add("bvhkit (1 thread)", "1", lambda: scene.closest_point(p, threads=1))
            w.add("bvhkit (all threads)", "all", lambda: scene.closest_point(p))
        else:
            w.add("bvhkit (1 thread)", "1", lambda: scene.signed_distance(p, threads=1))
            w.add("bvhkit (all threads)", "all", lambda: scene.signed_distance(p))
        if o3d:
            def setup_o3d(kind=kind, w=w):
                rs = o3d.t.geometry.RaycastingScene()
                for g, r, t in zip(which, rotations, translations):
                    v, f = unit[g]
                    rs.add_triangles(o3d.core.Tensor((v @ r.T + t).astype(np.float32)),
                                     o3d.core.Tensor(f.astype(np.uint32)))
                q = o3d.core.Tensor(p)
                if kind == "closest":
                    read = lambda r: np.linalg.norm(
                        r["points"].numpy().astype(np.float64) - p, axis=1)
                    run = rs.compute_closest_points
                else:
                    read = lambda r: r.numpy().astype(np.float64)
                    run = rs.compute_signed_distance
                w.add(f"open3d {version} (1 thread)", "1", lambda: run(q, nthreads=1), read)
                w.add(f"open3d {version} (all threads)", "all", lambda: run(q), read)
            w.peer("open3d RaycastingScene", setup_o3d)
        rows += w.measure(reps, _agreement)
    rows.append(f"P7        {len(which)} objects, {sum(len(unit[g][1]) for g in which)} "
                f"triangles posed ({len(unit)} meshes held once by bvhkit), {n} points, "
                f"{int(scene.contains(p).sum())} inside")
    return rows


def _agreement(d, reference) -> str:
    """How far a peer's distances are from bvhkit's, and on how many points the signs agree."""
    ref = reference.distance.astype(np.float64)
    d = np.asarray(d, dtype=np.float64)
    apart = np.abs(np.abs(d) - np.abs(ref)).max() if len(d) else 0.0
    signs = np.mean(np.signbit(d) == np.signbit(ref)) * 100
    return f"max |d| diff {apart:.1e}, signs agree {signs:.3f}% of {len(d)}"
