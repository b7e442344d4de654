"""Throughput of bvhkit.dask.signed_distance over 1 and 2 local Dask workers (docs/scale-out.md).

    python bench/scale_out.py [MESH] [--points N] [--reps R]

Times, for 10^6 random points in MESH's bounding box (partitions of 10^5): the single-process
call on 1 and 2 threads; then for a LocalCluster of K single-threaded worker processes (K = 1, 2)
the shipment of the scene (bvhkit.dask.share) and the computation with it, each answer checked
equal to the single-process one. Medians of R runs.
"""

import argparse
import statistics
import time

import numpy as np


def median_time(fn, reps):
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    import dask.array as da
    from distributed import Client, LocalCluster

    import bvhkit
    import bvhkit.dask as bd

    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh", nargs="?", default="igea.ply")
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args()
    import os

    path = args.mesh
    if not os.path.exists(path) and os.environ.get("BVHKIT_DATA_DIR"):
        path = os.path.join(os.environ["BVHKIT_DATA_DIR"], path)
    v, f = bvhkit.load_mesh(path)
    scene = bvhkit.TriangleMesh(v, f)
    scene.signed_distance(np.zeros((1, 3)))  # build the proximity trees here, once
    p = np.random.default_rng(0).uniform(v.min(0), v.max(0), (args.points, 3)).astype(np.float32)
    n = len(p)
    print(f"{path}: {len(f)} faces; {len(scene.to_bytes()) / 1e6:.1f} MB pickled; {n} points")
    want = scene.signed_distance(p)
    for t in (1, 2):
        s = median_time(lambda: scene.signed_distance(p, threads=t), args.reps)
        print(f"  one process, threads={t}: {s:.2f} s, {n / s / 1e3:.0f} k points/s")
    x = da.from_array(p, chunks=(100_000, 3))
    for k in (1, 2):
        with LocalCluster(n_workers=k, threads_per_worker=1, dashboard_address=None) as c, \
                Client(c):
            t = time.perf_counter()
            shared = bd.share(scene)
            ship = time.perf_counter() - t
            assert np.array_equal(bd.signed_distance(shared, x).compute(), want)
            s = median_time(lambda: bd.signed_distance(shared, x).compute(), args.reps)
            print(f"  dask, {k} worker(s) x 1 thread: shipping the scene {ship:.2f} s; "
                  f"{s:.2f} s, {n / s / 1e3:.0f} k points/s")


if __name__ == "__main__":
    main()
