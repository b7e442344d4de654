"""Side-by-side timings of bvhkit and the Python libraries a user would otherwise pick, in one
process: ``python -m bvhkit.bench [--scale S] [--reps R] [--only P1,P2,...]``.

Workloads (sizes times --scale):
  P1  rays: 1M random rays through a mesh (closest hit), and occlusion
  P2  closest point for 1M points
  P3  signed distance on a 128^3 grid, for a closed mesh and for one with holes; sign errors are
      counted against the exact winding number on a sample of the grid
  P4  1,000 random poses of collision (yes/no) and of distance between two copies of a mesh

A peer runs when it can be imported: Open3D (RaycastingScene), trimesh (with embreex for rays when
present), libigl (igl), python-fcl (fcl). bvhkit runs with threads=1 and with every core; peers
as they run by default. Times are medians of interleaved repetitions (each library in turn).
"""

from __future__ import annotations

import argparse
import importlib
import os
import statistics
import time
from typing import Callable, Dict, List, Optional, Tuple

import numpy as np

import bvhkit


def _optional(name: str):
    try:
        return importlib.import_module(name)
    except Exception:
        return None


def _mesh(spec: str) -> Tuple[np.ndarray, np.ndarray]:
    data = os.environ.get("BVHKIT_DATA_DIR")
    if data and os.path.exists(os.path.join(data, spec)):
        spec = os.path.join(data, spec)
    if not os.path.exists(spec) and ":" not in spec:
        spec = "sphere:subdiv=7"
    return bvhkit.load_mesh(spec)


def _time(runs: Dict[str, Callable[[], object]], reps: int) -> Dict[str, float]:
    """Medians over `reps` rounds; each round calls every entry once, in turn."""
    times: Dict[str, List[float]] = {k: [] for k in runs}
    for _ in range(reps):
        for k, f in runs.items():
            t = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t)
    return {k: statistics.median(v) for k, v in times.items()}


def _rows(workload: str, result: Dict[str, float], items: int, notes: Optional[Dict] = None):
    base = result.get("bvhkit (1 thread)")
    out = []
    for k, t in result.items():
        speed = "" if base is None or k.startswith("bvhkit") else f"{t / base:8.2f}x"
        note = (notes or {}).get(k, "")
        out.append(f"{workload:4}  {k:34} {t * 1e3:10.1f} ms  {items / t / 1e6:8.2f} M/s  "
                   f"{speed:>9}  {note}")
    return out


def p1(v, f, n, reps, mods):
    rng = np.random.default_rng(1)
    lo, hi = v.min(0), v.max(0)
    o = rng.uniform(lo - (hi - lo), hi + (hi - lo), (n, 3)).astype(np.float32)
    d = (rng.uniform(lo, hi, (n, 3)) - o).astype(np.float32)
    scene = bvhkit.TriangleMesh(v, f)
    runs = {"bvhkit (1 thread)": lambda: scene.intersect(o, d, threads=1),
            "bvhkit (all threads)": lambda: scene.intersect(o, d)}
    o3d = mods.get("open3d")
    if o3d:
        rs = o3d.t.geometry.RaycastingScene()
        rs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
        rays = o3d.core.Tensor(np.hstack([o, d]))
        runs["open3d cast_rays"] = lambda: rs.cast_rays(rays)
    tm = mods.get("trimesh")
    if tm:
        mesh = tm.Trimesh(v, f, process=False)
        runs["trimesh intersects_first"] = lambda: mesh.ray.intersects_first(o, d)
    return _rows("P1", _time(runs, reps), n)


def p2(v, f, n, reps, mods):
    rng = np.random.default_rng(2)
    lo, hi = v.min(0), v.max(0)
    p = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), (n, 3)).astype(np.float32)
    scene = bvhkit.TriangleMesh(v, f)
    scene.closest_point(p[:10])  # build outside the timing, as the peers' scenes are
    runs = {"bvhkit (1 thread)": lambda: scene.closest_point(p, threads=1),
            "bvhkit (all threads)": lambda: scene.closest_point(p)}
    o3d = mods.get("open3d")
    if o3d:
        rs = o3d.t.geometry.RaycastingScene()
        rs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
        q = o3d.core.Tensor(p)
        runs["open3d compute_closest_points"] = lambda: rs.compute_closest_points(q)
    igl = mods.get("igl")
    if igl:
        v64, f64 = v.astype(np.float64), f.astype(np.int64)
        p64 = p.astype(np.float64)
        runs["igl point_mesh_squared_distance"] = lambda: igl.point_mesh_squared_distance(
            p64, v64, f64)
    tm = mods.get("trimesh")
    if tm and n <= 100_000:  # trimesh's closest point is far slower: only small batches
        mesh = tm.Trimesh(v, f, process=False)
        runs["trimesh closest_point"] = lambda: tm.proximity.closest_point(mesh, p)
    return _rows("P2", _time(runs, reps), n)


def p3(v, f, grid, reps, mods, label):
    lo, hi = v.min(0), v.max(0)
    axes = [np.linspace(lo[i] - 0.1 * (hi - lo)[i], hi[i] + 0.1 * (hi - lo)[i], grid)
            for i in range(3)]
    p = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3).astype(np.float32)
    scene = bvhkit.TriangleMesh(v, f)
    scene.signed_distance(p[:10], sign="winding_number")
    runs = {"bvhkit (1 thread)": lambda: scene.signed_distance(p, threads=1),
            "bvhkit (all threads)": lambda: scene.signed_distance(p),
            "bvhkit winding_number sign": lambda: scene.signed_distance(p, sign="winding_number")}
    # Sign errors on a sample, against the exact winding number in float64.
    rng = np.random.default_rng(3)
    sample = p[rng.choice(len(p), min(len(p), 2000), replace=False)]
    exact = bvhkit.TriangleMesh(v, f, dtype=np.float64).winding_number(sample, exact=True)
    inside = exact > 0.5
    results = {"bvhkit (1 thread)": scene.signed_distance(sample) < 0,
               "bvhkit winding_number sign":
                   scene.signed_distance(sample, sign="winding_number") < 0}
    o3d = mods.get("open3d")
    if o3d:
        rs = o3d.t.geometry.RaycastingScene()
        rs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
        q = o3d.core.Tensor(p)
        runs["open3d compute_signed_distance"] = lambda: rs.compute_signed_distance(q)
        results["open3d compute_signed_distance"] = (
            rs.compute_signed_distance(o3d.core.Tensor(sample)).numpy() < 0)
    igl = mods.get("igl")
    if igl:
        v64, f64, p64 = v.astype(np.float64), f.astype(np.int64), p.astype(np.float64)
        runs["igl signed_distance"] = lambda: igl.signed_distance(p64, v64, f64)
        results["igl signed_distance"] = igl.signed_distance(sample.astype(np.float64), v64,
                                                             f64)[0] < 0
    notes = {k: f"sign errors {int((r != inside).sum())}/{len(sample)}"
             for k, r in results.items()}
    return _rows(f"P3{label}", _time(runs, reps), len(p), notes)


def _rotations(rng, k):
    q = rng.normal(size=(k, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def p4(v, f, k, reps, mods):
    rng = np.random.default_rng(4)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    rot = _rotations(rng, k)
    trans = rng.uniform(-0.5, 0.5, (k, 3)) * diag
    obb = bvhkit.CollisionModel(v, f, volume="obb")
    rss = bvhkit.CollisionModel(v, f, volume="rss")
    runs = {"bvhkit (1 thread)": lambda: bvhkit.collide(obb, obb, rot, trans, threads=1),
            "bvhkit (all threads)": lambda: bvhkit.collide(obb, obb, rot, trans)}
    dist_runs = {"bvhkit (1 thread)": lambda: bvhkit.distance(rss, rss, rot, trans * 2,
                                                               threads=1),
                 "bvhkit (all threads)": lambda: bvhkit.distance(rss, rss, rot, trans * 2)}
    fcl = mods.get("fcl")
    if fcl:
        model = fcl.BVHModel()
        model.beginModel(len(v), len(f))
        model.addSubModel(v.astype(np.float64), f.astype(np.int32))
        model.endModel()
        a = fcl.CollisionObject(model, fcl.Transform())

        def fcl_collide(scale=1.0, distance=False):
            for i in range(k):
                b = fcl.CollisionObject(model, fcl.Transform(rot[i], trans[i] * scale))
                if distance:
                    fcl.distance(a, b, fcl.DistanceRequest(), fcl.DistanceResult())
                else:
                    fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult())

        runs["python-fcl collide (loop)"] = fcl_collide
        dist_runs["python-fcl distance (loop)"] = lambda: fcl_collide(2.0, True)
    return _rows("P4c", _time(runs, reps), k) + _rows("P4d", _time(dist_runs, reps), k)


def _show(rows: List[str]) -> None:
    print("\n".join(rows), flush=True)


def main(argv=None) -> None:
    """Runs the workloads and prints one table."""
    ap = argparse.ArgumentParser(prog="python -m bvhkit.bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", type=float, default=1.0, help="workload size factor (1 = full)")
    ap.add_argument("--reps", type=int, default=3, help="repetitions (median reported)")
    ap.add_argument("--only", default="P1,P2,P3,P4", help="comma-separated workloads")
    ap.add_argument("--mesh", default="igea.ply", help="mesh file or spec for P1 and P2")
    ap.add_argument("--sdf-mesh", default="spot.obj", help="closed mesh for P3 (holes are cut)")
    ap.add_argument("--collision-mesh", default="stanford-bunny.obj", help="mesh for P4")
    args = ap.parse_args(argv)
    mods = {m: _optional(m) for m in ("open3d", "trimesh", "igl", "fcl")}
    present = [m for m, x in mods.items() if x is not None]
    print(f"bvhkit {bvhkit.__version__}; cores {os.cpu_count()}; peers present: "
          f"{', '.join(present) or 'none'}")
    v, f = _mesh(args.mesh)
    s = args.scale
    only = set(args.only.split(","))
    print("work  library                                 median        rate    peer/bvhkit(1)")

    if "P1" in only:
        _show(p1(v, f, int(1_000_000 * s), args.reps, mods))
    if "P2" in only:
        _show(p2(v, f, int(1_000_000 * s), args.reps, mods))
    if "P3" in only:
        grid = max(8, int(round(128 * s ** (1 / 3))))
        sv, sf = _mesh(args.sdf_mesh)
        _show(p3(sv, sf, grid, args.reps, mods, " closed"))
        holes = np.random.default_rng(5).random(len(sf)) > 0.01  # drop 1% of the faces
        _show(p3(sv, sf[holes], grid, args.reps, mods, " holes"))
    if "P4" in only:
        cv, cf = _mesh(args.collision_mesh)
        _show(p4(cv, cf, max(10, int(1000 * s)), args.reps, mods))


if __name__ == "__main__":
    main()
