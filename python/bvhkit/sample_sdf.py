"""python -m bvhkit sample-sdf MESH_DIR --out DIR --points N [options]

Signed-distance samples for every mesh file (.obj, .ply, .stl) of MESH_DIR, written as
DIR/NAME.npz (NAME: the file's name without its extension) with ``points`` float32 (N, 3),
``sdf`` float32 (N,), negative inside, and ``meta``, a JSON string recording what made them: the
mesh file's name and SHA-256, N, the near-surface noise, the seed and every option below that is
not at its default. The first N // 2 points (a share U of them with ``--uniform U``) are uniform
in the mesh's bounding box grown by 5% of its size on every side (5% of the diagonal along an axis
of zero extent); the rest lie near the surface: a point of the surface drawn by area, plus gaussian
noise of SIGMA (0 to 1) times the box's diagonal. ``--near-surface 0.005:0.4,0.05:0.1`` asks for
several noise levels, each SIGMA:SHARE with SHARE the part of all N points (the shares and U sum to
1; without shares the near part is split evenly), in that order after the uniform points. The sign
comes from the generalized winding number (``sign="winding_number"``), so meshes with holes get
sensible signs.

Optional outputs (``--outputs occupancy,normals,closest``): ``occupancy`` uint8 (N,), 1 where the
sdf's sign bit is set (inside: winding number above 1/2), as occupancy networks train on;
``closest`` float32 (N, 3), each sample's closest point of the surface; ``normals`` float32 (N, 3),
the unit normal of the triangle holding that closest point, from the triangle's winding (zero for a
triangle of no area). ``--normalize sphere`` first maps the mesh into the unit sphere (its box's
centre to the origin, its farthest vertex to distance 1), ``--normalize cube`` into the cube
[-1/2, 1/2]^3 (the box's longest side to length 1, centred); every output is then in those
coordinates, and ``offset`` float64 (3,) and ``scale`` float64 () record the map, normalized = (mesh
- offset) * scale, in the file and in ``meta``.

The samples depend only on the seed, the mesh file's name and its contents: any scheduler and any
number of workers write the same bytes. With ``--scheduler`` the meshes are spread over Dask
workers, one task per mesh (``local:K``: a local cluster of K single-threaded worker processes;
anything else is a scheduler's address; the workers must see MESH_DIR at the same path). Without
it they are done one by one in this process. A mesh that fails (unreadable, no face of positive
area, samples or distances beyond float32's range, its file cannot be written) is reported and
skipped, the others go on, and the exit status is 1 at the end; a write that the output folder
refuses as a whole (full, read-only, over quota) stops the run at once. No partial file is left:
each is written beside, checked, synced and renamed.

A mesh whose .npz exists with the same record is skipped, so a rerun finishes what an
interrupted one left, with the same bytes. If an existing .npz was made with other parameters or
from other mesh contents (or records nothing), the run refuses before sampling anything and names
those files; --overwrite redoes them.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import errno
import hashlib
import json
import os
import re
import sys
import time
import zipfile
import zlib
from typing import Any, Optional, Sequence

import numpy as np

MESH_SUFFIXES = (".obj", ".ply", ".stl")
# Names the sampler itself (margins, the uniform/near split, the record's keys): outputs of
# another version are refused like outputs of other parameters.
FORMAT = "bvhkit sample-sdf 1"
# Write errors that every later file would meet too: the run stops instead of failing each mesh.
_FOLDER_ERRORS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.EFBIG}
_F32_MAX = float(np.finfo(np.float32).max)


def file_digest(path: str) -> str:
    """SHA-256 of the file's bytes, as hex."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


_OUTPUTS = ("occupancy", "normals", "closest")
_NORMALIZE = ("none", "sphere", "cube")


class Recipe:
    """What to sample and write besides the points and the sdf. The defaults are the original
    recipe, whose record has no key for them: outputs made before these options stay valid."""

    def __init__(self, near=((0.01, 0.5),), uniform=0.5, outputs=(), normalize="none"):
        self.near = tuple((float(s), float(w)) for s, w in near)  # (sigma, share of all N)
        self.uniform = float(uniform)
        self.outputs = tuple(o for o in _OUTPUTS if o in outputs)  # a fixed order
        self.normalize = normalize

    def counts(self, points: int) -> tuple[int, list[int]]:
        """The uniform count, then one count per near-surface level; they sum to ``points``."""
        n_uniform = points // 2 if self.uniform == 0.5 else int(np.floor(points * self.uniform))
        rest = points - n_uniform
        total = sum(w for _, w in self.near)
        counts = [int(np.floor(rest * w / total)) if total > 0 else 0 for _, w in self.near[:-1]]
        return n_uniform, counts + [rest - sum(counts)]

    def fields(self) -> dict[str, Any]:
        """The record's keys for this recipe (none for the default one)."""
        out: dict[str, Any] = {}
        if self.uniform != 0.5 or len(self.near) != 1:
            out["near_surface"] = [list(level) for level in self.near]
            out["uniform"] = self.uniform
        else:
            out["near_surface"] = self.near[0][0]
        if self.outputs:
            out["outputs"] = list(self.outputs)
        if self.normalize != "none":
            out["normalize"] = self.normalize
        return out


def record(file: str, digest: str, points: int, sigma: Any, seed: int,
           recipe: Optional[Recipe] = None, transform: Optional[tuple] = None) -> str:
    """The ``meta`` of an output: what made it, and no time, so a rerun writes the same bytes.
    ``sigma`` is used when no recipe is given; ``transform`` is (offset, scale) of --normalize."""
    fields = recipe.fields() if recipe is not None else {"near_surface": sigma}
    if transform is not None:
        fields["offset"], fields["scale"] = [float(x) for x in transform[0]], float(transform[1])
    return json.dumps(
        {"format": FORMAT, "mesh": file, "mesh_sha256": digest, "points": points,
         "seed": seed, **fields},
        sort_keys=True,
    )


def _normalization(v: np.ndarray, how: str) -> tuple[np.ndarray, float]:
    """(offset, scale) mapping the vertices into the unit sphere or the cube [-1/2, 1/2]^3."""
    v = v.astype(np.float64)
    v = v[np.isfinite(v).all(axis=1)]
    lo, hi = v.min(axis=0), v.max(axis=0)
    offset = (lo + hi) / 2
    size = np.linalg.norm(v - offset, axis=1).max() if how == "sphere" else (hi - lo).max()
    if not (size > 0 and np.isfinite(size) and np.isfinite(1.0 / size)):
        raise ValueError(f"--normalize {how}: the mesh has no extent to scale")
    return offset, 1.0 / size


def sample(
    path: str, name: str, points: int, sigma: float, seed: int, threads: int = 1,
    recipe: Optional[Recipe] = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The samples of one mesh file: ``(points float32 (N, 3), sdf float32 (N,))``; ``name``
    (with ``seed``) seeds the random numbers. ValueError if the mesh cannot be read, has no face
    of positive area, or its samples or distances do not fit float32. With a ``recipe``, sigma is
    ignored and the answer is a dict of every array to write."""
    import bvhkit

    v, f = bvhkit.load_mesh(path)
    plain = recipe is None
    if plain:
        recipe = Recipe(near=((sigma, 0.5),))
    transform = None
    if recipe.normalize != "none":
        transform = _normalization(v, recipe.normalize)
        v = ((v.astype(np.float64) - transform[0]) * transform[1]).astype(v.dtype)
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
    if not np.all(np.abs(np.concatenate([lo - margin, hi + margin])) <= _F32_MAX):
        raise ValueError(f"{path}: the box grown by 5% does not fit float32 (samples are float32)")
    sigmas = np.array([level[0] for level in recipe.near])
    scales = sigmas * diagonal
    if not np.isfinite(scales).all():
        raise ValueError(f"{path}: --near-surface {sigmas.max()} times the diagonal is not finite")
    # zlib.crc32, not hash(): the same number in every process.
    rng = np.random.default_rng([seed, zlib.crc32(name.encode("utf-8"))])
    n_uniform, n_levels = recipe.counts(points)
    n_near = points - n_uniform
    uniform = rng.uniform(lo - margin, hi + margin, (n_uniform, 3))
    which = rng.choice(len(tri), n_near, p=area / total)
    r1, r2 = rng.random(n_near), rng.random(n_near)
    s = np.sqrt(r1)  # uniform over each triangle
    bary = np.stack([1 - s, s * (1 - r2), s * r2], axis=1)
    surface = np.einsum("ij,ijk->ik", bary, tri[which])
    # One draw with a scale per sample: with one level this is the draw the recipe always made.
    per_sample = np.repeat(scales, n_levels)[:, None]
    near = surface + rng.normal(scale=per_sample, size=(n_near, 3))
    with np.errstate(over="ignore"):
        p = np.concatenate([uniform, near]).astype(np.float32)
    if not np.isfinite(p).all():
        raise ValueError(
            f"{path}: --near-surface {sigmas.max()} times the diagonal ({scales.max():.3g}) puts "
            "samples beyond float32's range"
        )
    scene = bvhkit.TriangleMesh(v, f)
    sdf = scene.signed_distance(p, sign="winding_number", threads=threads).astype(np.float32)
    if not np.isfinite(sdf).all():
        raise ValueError(f"{path}: signed distances beyond float32's range (the mesh is too large)")
    if plain:
        return p, sdf
    arrays: dict[str, np.ndarray] = {"points": p, "sdf": sdf}
    if "occupancy" in recipe.outputs:
        arrays["occupancy"] = np.signbit(sdf).astype(np.uint8)
    if "normals" in recipe.outputs or "closest" in recipe.outputs:
        _, closest, face, _ = scene.closest_point(p, threads=threads)
        if "normals" in recipe.outputs:
            t = v.astype(np.float64)[f[face]]
            n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
            length = np.linalg.norm(n, axis=1, keepdims=True)
            with np.errstate(invalid="ignore", divide="ignore"):
                n = np.where(length > 0, n / length, 0.0)
            arrays["normals"] = n.astype(np.float32)
        if "closest" in recipe.outputs:
            arrays["closest"] = np.asarray(closest, dtype=np.float32)
    if transform is not None:
        arrays["offset"] = np.asarray(transform[0], dtype=np.float64)
        arrays["scale"] = np.float64(transform[1])
    return arrays


def _task(path: str, name: str, points: int, recipe: Recipe, seed: int) -> tuple:
    """One mesh on a worker: the arrays, the digest of the file they came from, and the seconds
    taken (the client writes the file)."""
    t = time.perf_counter()
    before = os.stat(path)
    digest = file_digest(path)
    arrays = sample(path, name, points, 0.0, seed, recipe=recipe)
    after = os.stat(path)
    if (before.st_size, before.st_mtime_ns, before.st_ino) != (
        after.st_size, after.st_mtime_ns, after.st_ino
    ):
        raise ValueError(f"{path}: the file changed while it was read")
    return arrays, digest, time.perf_counter() - t


def write_npz(path: str, arrays: dict[str, np.ndarray]) -> None:
    """An .npz (np.load reads it) with fixed timestamps, so equal arrays give equal bytes
    (np.savez stamps the time of writing). Written beside, synced and renamed, every step checked:
    a file that exists is complete, and on an error (OSError) the temporary is removed."""
    tmp = f"{path}.tmp{os.getpid()}"
    try:
        with open(tmp, "wb") as fh:
            with zipfile.ZipFile(fh, "w", compression=zipfile.ZIP_STORED) as z:
                for key, a in arrays.items():
                    info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
                    with z.open(info, "w") as out:
                        np.lib.format.write_array(out, np.asarray(a, order="C"),
                                                  allow_pickle=False)
            fh.flush()
            os.fsync(fh.fileno())  # a rename that outlives a crash names complete contents
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


def _mismatch(path: str, expected: dict[str, Any]) -> Optional[str]:
    """How the output at ``path`` differs from what this run would write; None if it does not."""
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = str(z["meta"]) if "meta" in z.files else None
    except Exception as e:  # noqa: BLE001 - any unreadable file is reported, not used
        return f"unreadable ({type(e).__name__}: {e})"
    if meta is None:
        return "records no parameters (made by an older bvhkit)"
    try:
        got = json.loads(meta)
    except ValueError:
        return "its record is not JSON"
    if not isinstance(got, dict):
        return "its record is not a JSON object"
    options = {"points": "--points", "near_surface": "--near-surface", "seed": "--seed",
               "uniform": "--uniform", "outputs": "--outputs", "normalize": "--normalize"}
    diffs, had, has = [], [], []
    # A key the record has and this run would not write is an option this run leaves at its
    # default; offset and scale are results of --normalize, not options.
    keys = list(expected) + [k for k in got if k not in expected and k not in ("offset", "scale")]
    for key in keys:
        want = expected.get(key)
        have = got.get(key)
        if have == want:
            continue
        if key in options:
            had.append(f"{options[key]} {have}")
            has.append(f"{options[key]} {want}")
        elif key == "mesh_sha256":
            diffs.append("made from other contents of the mesh file")
        else:
            diffs.append(f"{key} {have!r}, this run's is {want!r}")
    if had:
        diffs.insert(0, f"made with {' '.join(had)}, this run has {' '.join(has)}")
    return "; ".join(diffs) or None


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
        return stack.enter_context(Client(cluster, set_as_default=False))
    import dask

    # The Client is used through its own submit only, so it is never made the default one: a
    # Client that cannot connect would otherwise stay the process's default client, "connecting"
    # for good, and every later dask compute in the process would wait on it. A failed one may
    # still have changed dask's config: that is put back too.
    saved = copy.deepcopy(dask.config.config)
    try:
        return stack.enter_context(Client(scheduler, set_as_default=False))
    except BaseException:
        dask.config.config.clear()
        dask.config.config.update(saved)
        raise


def _scheduler(value: str) -> str:
    if value.startswith("local:"):
        k = value[len("local:") :]
        if not re.fullmatch(r"[0-9]+", k) or int(k) < 1:
            raise argparse.ArgumentTypeError(f"local:K needs a worker count K >= 1, not {k!r}")
    return value


def _int(value: str, low: int) -> int:
    try:
        n = int(value)
    except ValueError:
        msg = f"must be a whole number >= {low}, not {value!r}"
        raise argparse.ArgumentTypeError(msg) from None
    if n < low:
        raise argparse.ArgumentTypeError(f"must be >= {low}, not {n}")
    return n


def _positive_int(value: str) -> int:
    return _int(value, 1)


def _seed(value: str) -> int:
    return _int(value, 0)  # numpy's seed sequences take no negative numbers


def _share(value: str) -> float:
    """A number from 0 to 1: a share of N, or a noise level (noise beyond the box's diagonal is
    no longer near the surface)."""
    try:
        x = float(value)
    except ValueError:
        x = float("nan")
    if not 0 <= x <= 1:
        raise argparse.ArgumentTypeError(f"must be a number from 0 to 1, not {value!r}")
    return x


_sigma = _share


def _levels(value: str) -> list[tuple[float, Optional[float]]]:
    """SIGMA or SIGMA:SHARE, comma-separated; every level gives a share or none does."""
    levels: list[tuple[float, Optional[float]]] = []
    for part in value.split(","):
        sigma, _, share = part.strip().partition(":")
        w = None
        if share:
            try:
                w = float(share)
            except ValueError:
                w = float("nan")
            if not 0 <= w <= 1:
                raise argparse.ArgumentTypeError(
                    f"a share must be a number from 0 to 1, not {share!r} in {value!r}")
        levels.append((_sigma(sigma), w))
    if len({w is None for _, w in levels}) > 1:
        raise argparse.ArgumentTypeError(
            f"give a share to every level or to none, not to some: {value!r}")
    return levels


def _outputs(value: str) -> tuple[str, ...]:
    names = tuple(o.strip() for o in value.split(",") if o.strip())
    wrong = [o for o in names if o not in _OUTPUTS]
    if wrong:
        raise argparse.ArgumentTypeError(
            f"unknown output {wrong[0]!r}; choose from {', '.join(_OUTPUTS)}")
    return names


def _recipe(ap: argparse.ArgumentParser, args: argparse.Namespace) -> Recipe:
    """The recipe of the options, with the shares checked to sum to 1."""
    levels = args.near_surface
    if levels[0][1] is None:  # no shares: the near part split evenly
        uniform = 0.5 if args.uniform is None else args.uniform
        near = [(sig, (1 - uniform) / len(levels)) for sig, _ in levels]
    else:
        near = [(sig, float(w)) for sig, w in levels]
        named = sum(w for _, w in near)
        uniform = 1 - named if args.uniform is None else args.uniform
        if uniform < -1e-9 or abs(uniform + named - 1) > 1e-9:
            ap.error(f"--near-surface shares ({named:g}) and --uniform ({uniform:g}) must sum "
                     "to 1")
        uniform = max(0.0, uniform)
    if uniform < 1 and sum(w for _, w in near) <= 0:
        ap.error("--near-surface: the shares are all 0 but --uniform leaves points to place")
    return Recipe(near=near, uniform=uniform, outputs=args.outputs, normalize=args.normalize)


class _Stop(Exception):
    """A write that the output folder refuses as a whole."""


def _prepare_out(ap: argparse.ArgumentParser, out: str) -> None:
    """Creates ``out`` and checks that a file can be written there before any mesh is sampled."""
    try:
        os.makedirs(out, exist_ok=True)
        probe = os.path.join(out, f".sample-sdf-probe{os.getpid()}")
        try:
            with open(probe, "wb") as fh:
                fh.write(b"probe")
                fh.flush()
                os.fsync(fh.fileno())
        finally:
            with contextlib.suppress(OSError):
                os.remove(probe)
    except OSError as e:
        ap.error(f"--out: cannot write to {out!r}: {e.strerror or e}")


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs the command; returns the exit status (1 if any mesh failed or outputs were refused)."""
    ap = argparse.ArgumentParser(
        prog="python -m bvhkit sample-sdf",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("mesh_dir", metavar="MESH_DIR", help="folder of .obj, .ply, .stl files")
    ap.add_argument("--out", required=True, metavar="DIR", help="folder for the .npz files")
    ap.add_argument("--points", required=True, type=_positive_int, metavar="N",
                    help="samples per mesh")
    ap.add_argument("--near-surface", type=_levels, default=[(0.01, None)],
                    metavar="SIGMA[:SHARE],...",
                    help="noise of the near-surface points, times the box diagonal, 0 to 1; "
                    "several levels with their shares of N, e.g. 0.005:0.4,0.05:0.1 (0.01)")
    ap.add_argument("--uniform", type=_share, default=None, metavar="U",
                    help="share of N uniform in the box (0.5, or what the shares leave)")
    ap.add_argument("--outputs", type=_outputs, default=(), metavar="NAME,...",
                    help="also write occupancy, normals and/or closest (none)")
    ap.add_argument("--normalize", choices=_NORMALIZE, default="none",
                    help="map the mesh into the unit sphere or the cube [-1/2, 1/2]^3 first "
                    "(none)")
    ap.add_argument("--scheduler", type=_scheduler, default=None,
                    help="local:K (K worker processes) or a Dask scheduler's address")
    ap.add_argument("--seed", type=_seed, default=0, help="random seed, >= 0 (0)")
    ap.add_argument("--overwrite", action="store_true",
                    help="redo outputs made with other parameters or mesh contents")
    args = ap.parse_args(argv)
    if not os.path.isdir(args.mesh_dir):
        ap.error(f"MESH_DIR: {args.mesh_dir!r} is not a folder")
    recipe = _recipe(ap, args)
    _prepare_out(ap, args.out)

    def expected(file: str, digest: str) -> dict[str, Any]:
        return json.loads(record(file, digest, args.points, None, args.seed, recipe))

    failed = 0
    todo: list[tuple[str, str]] = []
    refused: list[tuple[str, str]] = []
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
        out = os.path.join(args.out, name + ".npz")
        if os.path.lexists(out):
            try:
                digest = file_digest(os.path.join(args.mesh_dir, file))
            except OSError as e:
                print(f"FAILED {file}: {e}", file=sys.stderr)
                failed += 1
                continue
            why = _mismatch(out, expected(file, digest))
            if why is None:
                print(f"skip {file}: {name}.npz exists")
                continue
            if not args.overwrite:
                refused.append((name, why))
                continue
            print(f"redo {file}: {name}.npz {why}")
        todo.append((file, name))
    if refused:
        for name, why in refused:
            print(f"REFUSED {name}.npz: {why}", file=sys.stderr)
        print(f"sample-sdf: {len(refused)} existing output(s) in {args.out} do not match this "
              "run; nothing written. Rerun with --overwrite to redo them, or use another --out.",
              file=sys.stderr)
        return 1
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
        arrays, digest, seconds = result
        transform = (arrays["offset"], arrays["scale"]) if "offset" in arrays else None
        meta = record(file, digest, args.points, None, args.seed, recipe, transform)
        p, sdf = arrays["points"], arrays["sdf"]
        try:
            write_npz(os.path.join(args.out, name + ".npz"), {**arrays, "meta": np.array(meta)})
        except OSError as e:
            failed += 1
            print(f"[{done}/{total}] FAILED {file}: cannot write {name}.npz: "
                  f"{e.strerror or e}", file=sys.stderr, flush=True)
            if e.errno in _FOLDER_ERRORS:
                raise _Stop(e) from None
            return
        written += 1
        inside = float(np.mean(np.signbit(sdf)))
        print(f"[{done}/{total}] {file}: {len(p)} samples in {seconds:.2f} s, "
              f"{100 * inside:.1f}% inside", flush=True)

    def job(file: str, name: str) -> tuple:
        path = os.path.abspath(os.path.join(args.mesh_dir, file))
        return (path, name, args.points, recipe, args.seed)

    start = time.perf_counter()
    try:
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
                try:
                    client = _client(args.scheduler, stack)
                except (OSError, ValueError) as e:  # unreachable or malformed; TimeoutError too
                    ap.error(f"argument --scheduler: cannot connect to {args.scheduler!r}: {e}")
                futures = {
                    client.submit(_task, *job(file, name), pure=False): (file, name)
                    for file, name in todo
                }
                for future in as_completed(futures, loop=client.loop):  # not the default client
                    file, name = futures[future]
                    try:
                        result, error = future.result(), None
                    except Exception as e:  # noqa: BLE001
                        result, error = None, e
                    future.release()
                    finish(file, name, result, error)
    except _Stop as e:
        print(f"sample-sdf: stopped: {args.out} takes no more files ({e}); {total - done} "
              "mesh(es) not done. Free space (or fix the folder) and rerun to finish.",
              file=sys.stderr)
    elapsed = time.perf_counter() - start
    print(f"sample-sdf: {written} of {total} meshes written in "
          f"{elapsed:.2f} s" + (f"; {failed} failed" if failed else ""))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
