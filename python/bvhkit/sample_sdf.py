"""python -m bvhkit sample-sdf MESH_DIR --out DIR --points N [options]

Signed-distance samples for every mesh file (.obj, .ply, .stl) of MESH_DIR, written as
DIR/NAME.npz (NAME: the file's name without its extension) with ``points`` float32 (N, 3) and
``sdf`` float32 (N,), negative inside. The first N // 2 points are uniform in the mesh's bounding
box grown by 5% of its size on every side (5% of the diagonal along an axis of zero extent); the
rest lie near the surface: a point of the surface drawn by area, plus gaussian noise of
SIGMA times the box's diagonal. The sign comes from the generalized winding number
(``sign="winding_number"``), so meshes with holes get sensible signs.

The samples depend only on the seed, the mesh file's name and its contents: any scheduler and any
number of workers write the same bytes. With ``--scheduler`` the meshes are spread over Dask
workers, one task per mesh (``local:K``: a local cluster of K single-threaded worker processes;
anything else is a scheduler's address; the workers must see MESH_DIR at the same path). Without
it they are done one by one in this process. A mesh that fails is reported and skipped, the others
go on, and the exit status is 1 at the end. Meshes whose .npz exists are skipped, so a rerun
finishes what an interrupted one left.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
import zipfile
import zlib
from typing import Any, Optional, Sequence

import numpy as np

MESH_SUFFIXES = (".obj", ".ply", ".stl")


def sample(
    path: str, name: str, points: int, sigma: float, seed: int, threads: int = 1
) -> tuple[np.ndarray, np.ndarray]:
    """The samples of one mesh file: ``(points float32 (N, 3), sdf float32 (N,))``; ``name``
    (with ``seed``) seeds the random numbers. ValueError if the mesh cannot be read or has no
    face of positive area."""
    import bvhkit

    v, f = bvhkit.load_mesh(path)
    tri = v.astype(np.float64)[f]  # (m, 3, 3)
    tri = tri[np.isfinite(tri).all(axis=(1, 2))]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    total = area.sum()
    if not total > 0 or not np.isfinite(total):
        raise ValueError(f"{path}: no face of positive finite area")
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    diagonal = float(np.linalg.norm(hi - lo))
    extent = hi - lo
    margin = 0.05 * np.where(extent > 0, extent, diagonal)
    # zlib.crc32, not hash(): the same number in every process.
    rng = np.random.default_rng([seed, zlib.crc32(name.encode("utf-8"))])
    n_uniform = points // 2
    n_near = points - n_uniform
    uniform = rng.uniform(lo - margin, hi + margin, (n_uniform, 3))
    which = rng.choice(len(tri), n_near, p=area / total)
    r1, r2 = rng.random(n_near), rng.random(n_near)
    s = np.sqrt(r1)  # uniform over each triangle
    bary = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
    surface = np.einsum("ij,ijk->ik", bary, tri[which])
    near = surface + rng.normal(scale=sigma * diagonal, size=(n_near, 3))
    p = np.concatenate([uniform, near]).astype(np.float32)
    scene = bvhkit.TriangleMesh(v, f)
    sdf = scene.signed_distance(p, sign="winding_number", threads=threads).astype(np.float32)
    return p, sdf


def _task(path: str, name: str, points: int, sigma: float, seed: int) -> tuple:
    """One mesh on a worker: the arrays and the seconds taken (the client writes the file)."""
    t = time.perf_counter()
    p, sdf = sample(path, name, points, sigma, seed)
    return p, sdf, time.perf_counter() - t


def write_npz(path: str, arrays: dict[str, np.ndarray]) -> None:
    """An .npz (np.load reads it) with fixed timestamps, so equal arrays give equal bytes
    (np.savez stamps the time of writing); written beside and renamed, so a file that exists is
    complete."""
    tmp = f"{path}.tmp{os.getpid()}"
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_STORED) as z:
        for key, a in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            with z.open(info, "w") as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(a), allow_pickle=False)
    os.replace(tmp, path)


def _client(scheduler: str, stack: contextlib.ExitStack) -> Any:
    """A distributed Client for ``--scheduler``, closed (with its local cluster) by ``stack``."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise SystemExit(
            'sample-sdf: --scheduler needs dask\'s distributed: pip install "dask[distributed]"'
        ) from None
    if scheduler.startswith("local:"):
        k = int(scheduler[len("local:") :])
        cluster = stack.enter_context(
            LocalCluster(n_workers=k, threads_per_worker=1, processes=True, dashboard_address=None)
        )
        return stack.enter_context(Client(cluster))
    return stack.enter_context(Client(scheduler))


def _scheduler(value: str) -> str:
    if value.startswith("local:"):
        k = value[len("local:") :]
        if not k.isdigit() or int(k) < 1:
            raise argparse.ArgumentTypeError(f"local:K needs a worker count K >= 1, not {k!r}")
    return value


def _positive_int(value: str) -> int:
    n = int(value)
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, not {n}")
    return n


def _sigma(value: str) -> float:
    x = float(value)
    if not x >= 0 or not np.isfinite(x):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, not {value}")
    return x


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs the command; returns the exit status (1 if any mesh failed)."""
    ap = argparse.ArgumentParser(
        prog="python -m bvhkit sample-sdf",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("mesh_dir", metavar="MESH_DIR", help="folder of .obj, .ply, .stl files")
    ap.add_argument("--out", required=True, metavar="DIR", help="folder for the .npz files")
    ap.add_argument("--points", required=True, type=_positive_int, metavar="N",
                    help="samples per mesh")
    ap.add_argument("--near-surface", type=_sigma, default=0.01, metavar="SIGMA",
                    help="noise of the near-surface half, times the box diagonal (0.01)")
    ap.add_argument("--scheduler", type=_scheduler, default=None,
                    help="local:K (K worker processes) or a Dask scheduler's address")
    ap.add_argument("--seed", type=int, default=0, help="random seed (0)")
    args = ap.parse_args(argv)
    if not os.path.isdir(args.mesh_dir):
        ap.error(f"MESH_DIR: {args.mesh_dir!r} is not a folder")
    os.makedirs(args.out, exist_ok=True)

    failed = 0
    todo: list[tuple[str, str]] = []
    seen: dict[str, str] = {}
    for file in sorted(os.listdir(args.mesh_dir)):
        name, ext = os.path.splitext(file)
        if ext.lower() not in MESH_SUFFIXES:
            continue
        if name in seen:
            print(f"FAILED {file}: writes {name}.npz as {seen[name]} does; skipped",
                  file=sys.stderr)
            failed += 1
            continue
        seen[name] = file
        if os.path.exists(os.path.join(args.out, name + ".npz")):
            print(f"skip {file}: {name}.npz exists")
            continue
        todo.append((file, name))
    total = len(todo)
    done = written = 0

    def finish(file: str, name: str, result: Any, error: Optional[BaseException]) -> None:
        nonlocal done, written, failed
        done += 1
        if error is not None:
            failed += 1
            print(f"[{done}/{total}] FAILED {file}: {type(error).__name__}: {error}",
                  file=sys.stderr, flush=True)
            return
        p, sdf, seconds = result
        write_npz(os.path.join(args.out, name + ".npz"), {"points": p, "sdf": sdf})
        written += 1
        inside = float(np.mean(np.signbit(sdf)))
        print(f"[{done}/{total}] {file}: {len(p)} samples in {seconds:.2f} s, "
              f"{100 * inside:.1f}% inside", flush=True)

    def job(file: str, name: str) -> tuple:
        path = os.path.abspath(os.path.join(args.mesh_dir, file))
        return (path, name, args.points, args.near_surface, args.seed)

    start = time.perf_counter()
    if args.scheduler is None:
        for file, name in todo:
            try:
                result, error = _task(*job(file, name)), None
            except Exception as e:  # noqa: BLE001 - reported, and the others go on
                result, error = None, e
            finish(file, name, result, error)
    elif todo:
        from distributed import as_completed

        with contextlib.ExitStack() as stack:
            client = _client(args.scheduler, stack)
            futures = {
                client.submit(_task, *job(file, name), pure=False): (file, name)
                for file, name in todo
            }
            for future in as_completed(futures):
                file, name = futures[future]
                try:
                    result, error = future.result(), None
                except Exception as e:  # noqa: BLE001
                    result, error = None, e
                finish(file, name, result, error)
                future.release()
    elapsed = time.perf_counter() - start
    print(f"sample-sdf: {written} of {total} meshes written in "
          f"{elapsed:.2f} s" + (f"; {failed} failed" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
