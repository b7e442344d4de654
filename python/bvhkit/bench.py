"""Side-by-side timings of bvhkit and the Python libraries a user would otherwise pick, in one
process: ``python -m bvhkit.bench [--scale S] [--reps R] [--only P1,P2,...]``.

Workloads (sizes times --scale):
  P1  rays: 1M random rays (closest hit) through a scanned mesh and a 1.3M-triangle sphere, and
      the camera rays of a 1024x1024 pinhole image of the scanned mesh, pixel by pixel
  P2  closest point for 1M points
  P3  signed distance on a 128^3 grid, for a closed mesh and for one with holes; sign errors are
      counted against the exact winding number on a sample of the grid
  P4  1,000 random poses of collision (yes/no) and of distance between two copies of a mesh
  P5  per-call cost: one-pose collide (and python-fcl's), one-point signed distance and one-ray
      intersect, in microseconds per Python call; and collide on batches of 1, 10, 100 and 1,000
      poses with threads=0 against threads=1 (the ratio: at most about 1 for small batches)
  P6  a collision manager per robot configuration: a six-link arm among three scanned meshes,
      1,000 configurations one call each (set_poses then any_collision, or any_collision_at),
      and all in one any_collision_at call (1 thread, all threads), against python-fcl's
      DynamicAABBTreeCollisionManager; the ratio is python-fcl's time over the row's
      (bvhkit/_bench_scene.py)
  P7  scene proximity: closest point and signed distance for 200,000 points over 100 posed
      closed objects, against Open3D's RaycastingScene holding one geometry per object
      (bvhkit/_bench_proximity.py)
  P8  instanced rays: 100 copies of the bunny at random rigid poses (a crowd whose neighbours
      overlap now and then), camera rays framing the crowd and random rays from inside its box;
      bvhkit.Scene.intersect against Open3D's RaycastingScene holding one posed copy per
      instance (it has no instancing); agreement: the same hit or miss, the same instance, t
      within 1e-4 relative
  P9  contacts between a mesh and itself at 200 random poses (issue 41's K2; the teapot, the
      bunny and igea), per colliding pose: the pairs, the manifold three ways, and python-fcl's
      collide with contacts; where FCL's triangle-pair contacts lie against bvhkit's intersection
      segments (bvhkit/_bench_contacts.py)
  P10 warp-lang's mesh queries on the CPU (wp.Mesh: mesh_query_ray, mesh_query_point_no_sign,
      the winding-number sign) beside bvhkit's intersect, closest_point and signed_distance, 1M
      rays or points on the P1 mesh; Warp's first-launch compile reported apart (bvhkit/_bench_warp.py)

A peer runs when it imports and sets up; a peer that fails is listed with the reason and the rest
go on. Peers: Open3D (RaycastingScene), Embree 4 through embreex (its scene's `run`, one
`rtcIntersect1` a ray on one thread), trimesh (with embreex for rays when present), libigl (igl),
fcpw, python-fcl (fcl) and coal. Each row says its threads: "1", "all" (every core) or "own" (the
peer's default, which may use several). The ratio compares a row with bvhkit on as many threads
(bvhkit's "1" for a "1" row, "all" otherwise): above 1 means bvhkit is faster. Times are medians of
interleaved repetitions (each library in turn), after one untimed round in which the peers
that build lazily build their trees. Every peer's answers are checked against bvhkit's
on the same input and the agreement is printed beside its time.
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
    except Exception as e:  # a peer missing or broken is reported, never fatal
        return e


def _mesh(spec: str) -> Tuple[np.ndarray, np.ndarray, str]:
    """The mesh named by spec, looked up in $BVHKIT_DATA_DIR and ../shared/data; a file that is
    not found is replaced by a procedural sphere, and the name printed says which was used."""
    if ":" in spec or os.path.exists(spec):
        return (*bvhkit.load_mesh(spec), spec)
    for folder in (os.environ.get("BVHKIT_DATA_DIR"), os.path.join("..", "shared", "data")):
        if folder and os.path.exists(os.path.join(folder, spec)):
            path = os.path.join(folder, spec)
            return (*bvhkit.load_mesh(path), path)
    fallback = "sphere:subdiv=7"
    return (*bvhkit.load_mesh(fallback), f"{fallback} ({spec} not found)")


class Workload:
    """The runs of one workload: each a timed call, its thread mode, and how to read its answer."""

    def __init__(self, name: str, items: int):
        self.name, self.items = name, items
        self.runs: Dict[str, Tuple[str, Callable[[], object], Optional[Callable]]] = {}
        self.skipped: Dict[str, str] = {}
        self.rate_items: Dict[str, int] = {}  # a run over fewer items than the workload

    def add(self, label: str, threads: str, run: Callable[[], object],
            answer: Optional[Callable[[object], object]] = None) -> None:
        self.runs[label] = (threads, run, answer)

    def peer(self, label: str, setup: Callable[[], None]) -> None:
        """Runs setup (which calls add); a failure is recorded instead of raised."""
        try:
            setup()
        except Exception as e:
            self.skipped[label] = f"{type(e).__name__}: {str(e).splitlines()[0][:90]}"

    def measure(self, reps: int, check: Callable[[object, object], str]) -> List[str]:
        times: Dict[str, List[float]] = {k: [] for k in self.runs}
        last: Dict[str, object] = {}
        # One untimed round first: some peers build their tree lazily, on the first query.
        for rep in range(reps + 1):
            for k, (_, run, _) in list(self.runs.items()):
                if k in self.skipped:
                    continue
                try:
                    t = time.perf_counter()
                    last[k] = run()
                    if rep > 0:
                        times[k].append(time.perf_counter() - t)
                except Exception as e:
                    self.skipped[k] = f"{type(e).__name__}: {str(e).splitlines()[0][:90]}"
        med = {k: statistics.median(v) for k, v in times.items() if v and k not in self.skipped}
        reference = last.get("bvhkit (all threads)")
        base = {"1": med.get("bvhkit (1 thread)"), "all": med.get("bvhkit (all threads)")}
        rows = []
        for k, t in med.items():
            threads, _, answer = self.runs[k]
            b = base["1" if threads == "1" else "all"]
            items = self.rate_items.get(k, self.items)
            if b and items != self.items:
                b *= items / self.items  # bvhkit's time for as many items
            ratio = "" if k.startswith("bvhkit") or not b else f"{t / b:8.2f}x"
            note = ""
            if answer is not None and reference is not None:
                try:
                    note = check(answer(last[k]), reference)
                except Exception as e:
                    note = f"answer not read: {type(e).__name__}"
            rows.append(f"{self.name:9} {k:38} {threads:>4} {t * 1e3:10.1f} ms "
                        f"{items / t / 1e6:8.2f} M/s {ratio:>9}  {note}")
        rows += [f"{self.name:9} {k:38}  skipped: {why}" for k, why in self.skipped.items()]
        return rows


def _rays(v, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = v.min(0), v.max(0)
    o = rng.uniform(lo - (hi - lo), hi + (hi - lo), (n, 3)).astype(np.float32)
    d = (rng.uniform(lo, hi, (n, 3)) - o).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)  # unit: every library's t is then a distance
    return o, d


def _check_hits(t, reference) -> str:
    """Share of rays with the same hit or miss and, on a hit, t within 1e-4 relative."""
    t = np.asarray(t, dtype=np.float64)
    t_ref = reference[0][: len(t)].astype(np.float64)
    hit, hit_ref = np.isfinite(t), np.isfinite(t_ref)
    with np.errstate(invalid="ignore"):  # inf - inf where both miss
        close = np.abs(t - t_ref) <= 1e-4 * np.maximum(1.0, np.abs(t_ref))
    same = (hit == hit_ref) & (~hit | close)
    return f"agree {same.mean() * 100:.3f}% of {len(t)} rays"


def _camera_rays(v, side):
    """A side x side pinhole camera looking at the mesh's centre from 1.5 box diagonals away, 60
    degrees across, rays in pixel order (row by row): the coherent rays of a rendered image."""
    lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
    centre, diag = (lo + hi) / 2, np.linalg.norm(hi - lo)
    eye = centre + diag * np.array([0.9, 0.6, 1.0]) / np.linalg.norm([0.9, 0.6, 1.0]) * 1.5
    forward = (centre - eye) / np.linalg.norm(centre - eye)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    s = np.tan(np.radians(30.0)) * (2 * (np.arange(side) + 0.5) / side - 1)
    yy, xx = np.meshgrid(-s, s, indexing="ij")
    d = forward + xx.reshape(-1, 1) * right + yy.reshape(-1, 1) * up
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.broadcast_to(eye, d.shape)
    return np.ascontiguousarray(o, dtype=np.float32), d.astype(np.float32)


def p1(v, f, n, reps, mods, label):
    if label == "camera":
        side = max(16, int(round(np.sqrt(n))))
        o, d = _camera_rays(v, side)
        n = side * side
    else:
        o, d = _rays(v, n, 1)
    w = Workload(f"P1 {label}", n)
    scene = bvhkit.TriangleMesh(v, f)
    fast = bvhkit.TriangleMesh(v, f, ray_test="fast")
    w.add("bvhkit (1 thread)", "1", lambda: scene.intersect(o, d, threads=1))
    w.add("bvhkit (all threads)", "all", lambda: scene.intersect(o, d))
    w.add("bvhkit fast test", "all", lambda: fast.intersect(o, d), lambda r: r[0])
    o3d = mods.get("open3d")
    if o3d:
        def setup_o3d():
            rs = o3d.t.geometry.RaycastingScene()
            rs.add_triangles(o3d.core.Tensor(v.astype(np.float32)),
                             o3d.core.Tensor(f.astype(np.uint32)))
            rays = o3d.core.Tensor(np.hstack([o, d]))
            read = lambda r: r["t_hit"].numpy()
            w.add("open3d cast_rays (1 thread)", "1", lambda: rs.cast_rays(rays, nthreads=1),
                  read)
            w.add("open3d cast_rays (all threads)", "all", lambda: rs.cast_rays(rays), read)
        w.peer("open3d cast_rays", setup_o3d)
    embreex = mods.get("embreex")
    if embreex:
        def setup_embree():
            from embreex.mesh_construction import TriangleMesh as EmbreeMesh
            from embreex.rtcore_scene import EmbreeScene
            es = EmbreeScene()
            EmbreeMesh(es, v.astype(np.float32), f.astype(np.int32))
            es.run(o[:1], d[:1], output=1)  # commits the scene (builds its tree) outside the timing
            read = lambda r: np.where(r["geomID"] >= 0, r["tfar"], np.inf)
            version = getattr(embreex, "__version__", "")
            w.add(f"embree4 embreex {version} run".strip(), "1",
                  lambda: es.run(o, d, output=1), read)
        w.peer("embree4 embreex run", setup_embree)
    tm = mods.get("trimesh")
    if tm:
        def setup_trimesh():
            mesh = tm.Trimesh(v, f, process=False)
            engine = type(mesh.ray).__module__.split(".")[-1]
            w.add(f"trimesh intersects_first ({engine})", "own",
                  lambda: mesh.ray.intersects_first(o, d),
                  lambda faces: np.where(np.asarray(faces) >= 0, 0.0, np.inf))
        w.peer("trimesh intersects_first", setup_trimesh)
    fcpw = mods.get("fcpw")
    if fcpw:
        def setup_fcpw():
            s = _fcpw_scene(fcpw, v, f)
            of, df = np.asfortranarray(o), np.asfortranarray(d)
            bound = np.full(n, np.inf, np.float32)

            def run():
                hits = fcpw.interaction_3D_list()
                s.intersect(of, df, bound, hits, False)
                return hits
            w.add("fcpw intersect", "own", run, _fcpw_distances)
        w.peer("fcpw intersect", setup_fcpw)
    return w.measure(reps, _check_hits_any)


def _check_hits_any(answer, reference) -> str:
    """Rays: t from peers that give it; trimesh gives 0 for a hit (hit/miss only)."""
    t = np.asarray(answer, dtype=np.float64)
    if np.all((t == 0) | np.isinf(t)):  # hit/miss only
        same = np.isfinite(t) == np.isfinite(reference[0][: len(t)])
        return f"hit/miss agree {same.mean() * 100:.3f}% of {len(t)} rays"
    return _check_hits(t, reference)


def _fcpw_scene(fcpw, v, f):
    s = fcpw.scene_3D()
    s.set_object_count(1)
    s.set_object_vertices(np.asfortranarray(v, dtype=np.float32), 0)
    s.set_object_triangles(np.asfortranarray(f, dtype=np.int32), 0)
    s.build(fcpw.aggregate_type.bvh_surface_area, True)
    return s


def _fcpw_distances(interactions, limit=20000):
    """fcpw's distances (inf on a miss), read for the first `limit` queries only: reading its
    result objects one by one in Python is slow and is not part of the timing."""
    k = min(len(interactions), limit)
    d = np.array([interactions[i].d for i in range(k)], dtype=np.float64)
    d[d >= np.finfo(np.float32).max] = np.inf
    return d


def _check_distances(d, reference) -> str:
    """The largest difference to bvhkit's distances as a share of the largest distance, and the
    largest relative difference among points farther than 1e-4 of it: the relative difference of
    a point within float32 rounding of the surface says nothing (a peer that returns float32
    closest points differs there by 8% at 1e-7 of the mesh's size from the surface)."""
    d_ref = reference[0][: len(d)].astype(np.float64)
    d = np.asarray(d, dtype=np.float64)
    scale = np.abs(d_ref).max()
    diff = np.abs(d - d_ref)
    far = d_ref > 1e-4 * scale
    rel = diff[far] / d_ref[far]
    return (f"max diff {diff.max() / scale:.1e} of the largest, "
            f"{rel.max() if rel.size else 0.0:.1e} relative, {len(d)} points")


def p2(v, f, n, reps, mods):
    rng = np.random.default_rng(2)
    lo, hi = v.min(0), v.max(0)
    p = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), (n, 3)).astype(np.float32)
    w = Workload("P2", n)
    scene = bvhkit.TriangleMesh(v, f)
    scene.closest_point(p[:10])  # build outside the timing, as the peers' scenes are
    w.add("bvhkit (1 thread)", "1", lambda: scene.closest_point(p, threads=1))
    w.add("bvhkit (all threads)", "all", lambda: scene.closest_point(p))
    o3d = mods.get("open3d")
    if o3d:
        def setup_o3d():
            rs = o3d.t.geometry.RaycastingScene()
            rs.add_triangles(o3d.core.Tensor(v.astype(np.float32)),
                             o3d.core.Tensor(f.astype(np.uint32)))
            q = o3d.core.Tensor(p)
            read = lambda r: np.linalg.norm(r["points"].numpy().astype(np.float64) - p, axis=1)
            w.add("open3d compute_closest_points (1)", "1",
                  lambda: rs.compute_closest_points(q, nthreads=1), read)
            w.add("open3d compute_closest_points (all)", "all",
                  lambda: rs.compute_closest_points(q), read)
        w.peer("open3d compute_closest_points", setup_o3d)
    igl = mods.get("igl")
    if igl:
        def setup_igl():
            v64, f64, p64 = v.astype(np.float64), f.astype(np.int64), p.astype(np.float64)
            w.add("igl point_mesh_squared_distance", "own",
                  lambda: igl.point_mesh_squared_distance(p64, v64, f64),
                  lambda r: np.sqrt(r[0]))
        w.peer("igl point_mesh_squared_distance", setup_igl)
    fcpw = mods.get("fcpw")
    if fcpw:
        def setup_fcpw():
            s = _fcpw_scene(fcpw, v, f)
            pf, r2 = np.asfortranarray(p), np.full(n, np.inf, np.float32)

            def run():
                out = fcpw.interaction_3D_list()
                s.find_closest_points(pf, r2, out)
                return out
            w.add("fcpw find_closest_points", "own", run, _fcpw_distances)
        w.peer("fcpw find_closest_points", setup_fcpw)
    tm = mods.get("trimesh")
    if tm:
        # trimesh's closest_point gathers candidate triangles per point in one array (24 GiB for
        # 50,000 points on igea): it runs on the first 2,000 points, and its rate is of those.
        def setup_trimesh():
            mesh = tm.Trimesh(v, f, process=False)
            few = p[:2000]
            w.add("trimesh closest_point (2,000 points)", "own",
                  lambda: tm.proximity.closest_point(mesh, few), lambda r: r[1])
            w.rate_items["trimesh closest_point (2,000 points)"] = len(few)
        w.peer("trimesh closest_point", setup_trimesh)
    return w.measure(reps, _check_distances)


def p3(v, f, grid, reps, mods, label):
    lo, hi = v.min(0), v.max(0)
    axes = [np.linspace(lo[i] - 0.1 * (hi - lo)[i], hi[i] + 0.1 * (hi - lo)[i], grid)
            for i in range(3)]
    p = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3).astype(np.float32)
    w = Workload(f"P3 {label}", len(p))
    scene = bvhkit.TriangleMesh(v, f)
    scene.signed_distance(p[:10], sign="winding_number")
    # Signs are judged on a sample of the grid against the exact winding number in float64.
    rng = np.random.default_rng(3)
    pick = rng.choice(len(p), min(len(p), 2000), replace=False)
    exact = bvhkit.TriangleMesh(v, f, dtype=np.float64).winding_number(p[pick], exact=True)
    inside = exact > 0.5
    signs = lambda r: np.asarray(r)[pick] < 0
    w.add("bvhkit (1 thread)", "1", lambda: scene.signed_distance(p, threads=1), signs)
    w.add("bvhkit (all threads)", "all", lambda: scene.signed_distance(p), signs)
    w.add("bvhkit winding_number sign", "all",
          lambda: scene.signed_distance(p, sign="winding_number"), signs)
    o3d = mods.get("open3d")
    if o3d:
        def setup_o3d():
            rs = o3d.t.geometry.RaycastingScene()
            rs.add_triangles(o3d.core.Tensor(v.astype(np.float32)),
                             o3d.core.Tensor(f.astype(np.uint32)))
            q = o3d.core.Tensor(p)
            read = lambda r: r.numpy()[pick] < 0
            w.add("open3d compute_signed_distance (1)", "1",
                  lambda: rs.compute_signed_distance(q, nthreads=1), read)
            w.add("open3d compute_signed_distance (all)", "all",
                  lambda: rs.compute_signed_distance(q), read)
        w.peer("open3d compute_signed_distance", setup_o3d)
    igl = mods.get("igl")
    if igl:
        def setup_igl():
            v64, f64, p64 = v.astype(np.float64), f.astype(np.int64), p.astype(np.float64)
            w.add("igl signed_distance", "own", lambda: igl.signed_distance(p64, v64, f64),
                  lambda r: r[0][pick] < 0)
        w.peer("igl signed_distance", setup_igl)
    # Every row, bvhkit's own included, is judged against the exact winding number.
    return w.measure(reps, lambda negative, _: (
        f"sign errors {int((negative != inside).sum())}/{len(pick)}"))


def _rotations(rng, k):
    q = rng.normal(size=(k, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


def _crowd(v, k, rng, density=0.3):
    """k rigid poses of the mesh: rotations uniform over SO(3) about the box's centre, the
    centres uniform in a cube sized so that the bounding spheres fill `density` of it."""
    lo, hi = v.min(0).astype(np.float64), v.max(0).astype(np.float64)
    c, radius = (lo + hi) / 2, np.linalg.norm(hi - lo) / 2
    side = (k * 4 / 3 * np.pi * radius ** 3 / density) ** (1 / 3)
    r = _rotations(rng, k)
    p = rng.uniform(-side / 2, side / 2, (k, 3))
    t = p - np.einsum("kij,j->ki", r, c)
    return r.astype(np.float32), t.astype(np.float32)


def _check_instances(answer, reference) -> str:
    """Share of rays with the same hit or miss, the same instance (by its index) and t within
    1e-4 relative (or 1e-6 of the crowd's size, for rays starting next to a surface)."""
    t, idx = (np.asarray(a) for a in answer)
    t_ref, idx_ref, slack = reference.t.astype(np.float64), reference.index, reference.slack
    t = t.astype(np.float64)
    hit, hit_ref = np.isfinite(t), np.isfinite(t_ref)
    with np.errstate(invalid="ignore"):
        close = np.abs(t - t_ref) <= 1e-4 * np.abs(t_ref) + slack
    same = (hit == hit_ref) & (~hit | (close & (idx == idx_ref)))
    return (f"agree {same.mean() * 100:.4f}% of {len(t)} rays "
            f"({len(t) - same.sum()} differ; {hit_ref.sum()} hits)")


class _SceneAnswer:
    """bvhkit's answer in the form the checks read: t, the instance's index, and the slack."""

    def __init__(self, hits, index_of, slack):
        self.t, self.slack = hits.t, slack
        self.index = np.where(hits.instance >= 0, index_of(hits.instance), -1)


def p8(v, f, k, n, reps, mods) -> List[str]:
    rng = np.random.default_rng(8)
    rot, trans = _crowd(v, k, rng)
    scene = bvhkit.Scene()
    g = scene.add_mesh(v, f)
    ids = scene.add_instances(g, rot, trans)
    order = np.argsort(ids)
    index_of = lambda inst: order[np.searchsorted(ids[order], inst)]
    world = [(v.astype(np.float64) @ r.T.astype(np.float64) + t).astype(np.float32)
             for r, t in zip(rot, trans)]
    lo = np.min([w.min(0) for w in world], 0)
    hi = np.max([w.max(0) for w in world], 0)
    slack = 1e-6 * float(np.linalg.norm(hi - lo))
    box = np.vstack([lo, hi])
    side = max(16, int(round(np.sqrt(n))))
    sets = {"camera": _camera_rays(box, side)}
    r2 = np.random.default_rng(9)
    o = r2.uniform(lo, hi, (n, 3)).astype(np.float32)
    d = r2.normal(size=(n, 3))
    sets["random"] = (o, (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32))
    rows = []
    for label, (o, d) in sets.items():
        w = Workload(f"P8 {label}", len(o))
        read = lambda h: (h.t, np.where(h.instance >= 0, index_of(h.instance), -1))
        w.add("bvhkit (1 thread)", "1",
              lambda o=o, d=d: scene.intersect(o, d, threads=1), read)
        w.add("bvhkit (all threads)", "all", lambda o=o, d=d: scene.intersect(o, d))
        o3d = mods.get("open3d")
        if o3d:
            def setup_o3d(o=o, d=d):
                rs = o3d.t.geometry.RaycastingScene()
                faces = o3d.core.Tensor(f.astype(np.uint32))
                for wv in world:  # ids 0, 1, 2, ...: the instance's index
                    rs.add_triangles(o3d.core.Tensor(wv), faces)
                rays = o3d.core.Tensor(np.hstack([o, d]))
                miss = o3d.t.geometry.RaycastingScene.INVALID_ID

                def read_o3d(r):
                    gid = r["geometry_ids"].numpy().astype(np.int64)
                    return r["t_hit"].numpy(), np.where(gid == miss, -1, gid)
                w.add(f"open3d {o3d.__version__} cast_rays (1 thread)", "1",
                      lambda: rs.cast_rays(rays, nthreads=1), read_o3d)
                w.add(f"open3d {o3d.__version__} cast_rays (all)", "all",
                      lambda: rs.cast_rays(rays), read_o3d)
            w.peer("open3d cast_rays", setup_o3d)
        rows += w.measure(reps, lambda answer, ref: _check_instances(
            answer, _SceneAnswer(ref, index_of, slack)))
    return rows


def main(argv=None) -> None:
    """Runs the workloads and prints one table."""
    ap = argparse.ArgumentParser(prog="python -m bvhkit.bench", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scale", type=float, default=1.0, help="workload size factor (1 = full)")
    ap.add_argument("--reps", type=int, default=3, help="repetitions (median reported)")
    ap.add_argument("--only", default="P1,P2,P3,P4,P5,P6,P7,P8,P9,P10",
                    help="comma-separated workloads")
    ap.add_argument("--mesh", default="igea.ply", help="mesh file or spec for P1 and P2")
    ap.add_argument("--big-mesh", default="sphere:subdiv=8,displacement=0.2",
                    help="the large mesh of P1 (1.3M triangles by default); 'none' skips it")
    ap.add_argument("--sdf-mesh", default="spot.obj", help="closed mesh for P3 (holes are cut)")
    ap.add_argument("--collision-mesh", default="stanford-bunny.obj", help="mesh for P4")
    args = ap.parse_args(argv)
    mods = {m: _optional(m) for m in ("open3d", "embreex", "trimesh", "igl", "fcpw", "fcl",
                                         "coal")}
    absent = {m: x for m, x in mods.items() if isinstance(x, Exception)}
    mods = {m: x for m, x in mods.items() if m not in absent}
    print(f"bvhkit {bvhkit.__version__}; cores {os.cpu_count()}; peers present: "
          f"{', '.join(mods) or 'none'}")
    for m, e in absent.items():
        print(f"  {m} not used: {type(e).__name__}: {str(e).splitlines()[0][:100]}")
    s = args.scale
    only = set(args.only.split(","))
    print("work      library                                thr     median        rate"
          "  vs bvhkit  answers")

    def show(rows):
        print("\n".join(rows), flush=True)

    if "P1" in only:
        v, f, name = _mesh(args.mesh)
        print(f"P1: {name}, {len(f)} triangles")
        show(p1(v, f, int(1_000_000 * s), args.reps, mods, "scan"))
        if args.big_mesh != "none":
            bv, bf, bname = _mesh(args.big_mesh)
            print(f"P1: {bname}, {len(bf)} triangles")
            show(p1(bv, bf, int(1_000_000 * s), args.reps, mods, "big"))
        print(f"P1: {name}, camera rays")
        show(p1(v, f, int(1024 * 1024 * s), args.reps, mods, "camera"))
    if "P2" in only:
        v, f, name = _mesh(args.mesh)
        print(f"P2: {name}, {len(f)} triangles")
        show(p2(v, f, int(1_000_000 * s), args.reps, mods))
    if "P3" in only:
        grid = max(8, int(round(128 * s ** (1 / 3))))
        sv, sf, name = _mesh(args.sdf_mesh)
        print(f"P3: {name}, {len(sf)} triangles, {grid}^3 grid")
        show(p3(sv, sf, grid, args.reps, mods, "closed"))
        holes = np.random.default_rng(5).random(len(sf)) > 0.01  # drop 1% of the faces
        show(p3(sv, sf[holes], grid, args.reps, mods, "holes"))
    if "P4" in only:
        cv, cf, name = _mesh(args.collision_mesh)
        print(f"P4: {name}, {len(cf)} triangles")
        from ._bench_collision import p4

        show(p4(cv, cf, max(10, int(1000 * s)), args.reps, mods))
    if "P5" in only:
        cv, cf, name = _mesh(args.collision_mesh)
        print(f"P5: {name}, {len(cf)} triangles")
        from ._bench_collision import p5

        show(p5(cv, cf, max(args.reps, 5), mods))
    if "P6" in only:
        from ._bench_scene import p6

        meshes = [_mesh(m)[:2] for m in ("stanford-bunny.obj", "igea.ply", "spot.obj")]
        print(f"P6: arm of 6 capsules among {', '.join(str(len(f)) for _, f in meshes)} "
              "triangles")
        show(p6(meshes, max(10, int(1000 * s)), args.reps, mods.get("fcl")))
    if "P7" in only:
        from ._bench_proximity import p7

        meshes = [_mesh(m)[:2] for m in ("spot.obj", "fandisk.obj", "dragon-lowres.ply",
                                         "torus:u=96,v=48")]
        print(f"P7: 100 objects of {', '.join(str(len(f)) for _, f in meshes)} triangles")
        show(p7(meshes, max(1000, int(200_000 * s)), args.reps, mods, Workload))
    if "P8" in only:
        bv, bf, name = _mesh("stanford-bunny.obj")
        print(f"P8: 100 instances of {name}, {len(bf)} triangles each")
        show(p8(bv, bf, 100, int(1_000_000 * s), args.reps, mods))
    if "P9" in only:
        from ._bench_contacts import p9

        for m in ("teapot.obj", "stanford-bunny.obj", "igea.ply"):
            cv, cf, name = _mesh(m)
            show(p9(cv, cf, name, max(10, int(200 * s)), args.reps, mods.get("fcl")))
    if "P10" in only:
        from ._bench_warp import p10

        v, f, name = _mesh(args.mesh)
        print(f"P10: {name}, {len(f)} triangles, warp-lang on the CPU")
        warp = _optional("warp")
        if isinstance(warp, Exception):
            print(f"  warp-lang not used: {type(warp).__name__}: {str(warp).splitlines()[0][:100]}")
            warp = None
        else:
            warp.config.quiet = True  # no banner in the table
        show(p10(v, f, int(1_000_000 * s), args.reps, warp))


if __name__ == "__main__":
    main()
