"""bvhkit's point and ray queries over dask arrays, partition by partition.

Each function takes a :class:`bvhkit.TriangleMesh` or a :class:`bvhkit.Scene` (or the
:class:`SharedScene` that :func:`share` returns) and a dask array of points (n, 3), or of ray
origins and directions (n, 3) each, and returns dask arrays chunked as the input's rows;
``.compute()`` gives exactly the arrays the single-process call gives (every point and ray is
answered on its own).

The scene reaches each worker once, not once per partition: with a distributed Client active it
is scattered to every worker (``client.scatter(scene, broadcast=True)``); without one it is a
single key of the graph, which the local threaded scheduler uses in place. A TriangleMesh travels
in its file format, trees included, so no worker rebuilds them (docs/scale-out.md; a ray tree
with spatial splits alone is rebuilt by each worker that loads the scene); a Scene in the scene
file format, its top-level tree included, its per-mesh trees built by each worker at its first
query. A Scene answers closest_point and signed_distance (SceneClosest), contains, intersect
(SceneHits) and occluded; the other functions are TriangleMesh's alone.
To reuse one shipment for several calls, pass ``share(scene)`` instead of the scene.

``threads`` is per partition and defaults to 1: dask already runs partitions in parallel.

dask is optional for bvhkit; this module needs it (``pip install "dask[distributed]"``).
"""

from __future__ import annotations

import uuid
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

try:
    import dask
    import dask.array as da
except ImportError as e:  # pragma: no cover - exercised where dask is absent
    raise ImportError(
        'bvhkit.dask needs dask: pip install "dask[array]" (or "dask[distributed]" for a cluster)'
    ) from e

from . import ClosestPoints, RayHits, Scene, SceneClosest, SceneHits, TriangleMesh
from . import _arrays as _a

__all__ = [
    "SharedScene",
    "share",
    "closest_point",
    "signed_distance",
    "winding_number",
    "contains",
    "intersect",
    "occluded",
    "count_intersections",
]


class SharedScene:
    """A scene shipped to the workers once (see :func:`share`); pass it to the functions of this
    module in place of the scene. ``ref`` is a distributed Future or a dask Delayed."""

    def __init__(self, ref: Any, dtype: np.dtype, of_scene: bool = False) -> None:
        self.ref = ref
        self.dtype = dtype
        self.of_scene = of_scene  # a bvhkit.Scene (else a TriangleMesh)

    def __repr__(self) -> str:
        """The reference."""
        return f"SharedScene({self.ref!r})"


_Scene = Union[TriangleMesh, Scene, SharedScene]


def _active_client() -> Any:
    try:
        from distributed import default_client
    except ImportError:
        return None
    try:
        client = default_client()
    except ValueError:  # no client in this process
        return None
    # A Client that failed to connect, or was closed, can still be the default one: not active.
    return client if getattr(client, "status", None) == "running" else None


def share(scene: _Scene, client: Any = None) -> SharedScene:
    """Ships ``scene`` once for any number of later calls: scattered to every worker of
    ``client`` (default: the active distributed Client), or, with none, wrapped as one graph key.
    The scene is copied as it is now; a later ``refit`` of it is not seen by the shared copy."""
    if isinstance(scene, SharedScene):
        return scene
    if not isinstance(scene, (TriangleMesh, Scene)):
        raise TypeError(
            f"scene: must be a bvhkit.TriangleMesh or Scene, not {type(scene).__name__}"
        )
    client = client if client is not None else _active_client()
    if client is not None:
        ref = client.scatter(scene, broadcast=True, hash=False)
    else:
        # An explicit name: dask would otherwise tokenize the scene by pickling it.
        ref = dask.delayed(scene, name=f"bvhkit-scene-{uuid.uuid4().hex}", traverse=False)
    return SharedScene(ref, scene.dtype, isinstance(scene, Scene))


def _rows(name: str, value: Any, like: Optional[da.Array] = None) -> da.Array:
    """(n, 3) as a dask array with whole rows in each chunk (and ``like``'s row chunks)."""
    a = value if isinstance(value, da.Array) else da.asarray(value)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: must have shape (n, 3), not {a.shape}")
    if like is not None:
        if a.shape[0] != like.shape[0]:
            raise ValueError(f"{name}: {a.shape[0]} rows, origins has {like.shape[0]}")
        return a.rechunk((like.chunks[0], 3))
    return a.rechunk({1: 3})


def _map(
    scene: Any,
    arrays: Sequence[da.Array],
    fn: Callable[..., Any],
    outputs: Sequence[tuple[tuple[int, ...], Any]],
) -> list[da.Array]:
    """fn(scene, *blocks) on each row partition; ``outputs``: per result, the shape after the row
    axis and the dtype. Returns one dask array per result."""
    shared = share(scene)
    blocks = [a.to_delayed().ravel() for a in arrays]
    call = dask.delayed(fn, pure=True, nout=len(outputs))
    columns: list[list[da.Array]] = [[] for _ in outputs]
    for i, rows in enumerate(arrays[0].chunks[0]):
        results = call(shared.ref, *(b[i] for b in blocks))
        for out, (tail, dtype), result in zip(columns, outputs, results):
            out.append(da.from_delayed(result, (rows, *tail), dtype=dtype))
    if not arrays[0].chunks[0]:
        return [da.empty((0, *tail), dtype=dtype) for tail, dtype in outputs]
    return [da.concatenate(c) for c in columns]


def _dtype(scene: Any) -> np.dtype:
    if isinstance(scene, (TriangleMesh, Scene, SharedScene)):
        return scene.dtype
    raise TypeError(
        f"scene: must be a bvhkit.TriangleMesh, Scene or SharedScene, not {type(scene).__name__}"
    )


def _is_scene(scene: Any) -> bool:
    """Whether ``scene`` is (or shares) a bvhkit.Scene."""
    return isinstance(scene, Scene) or (isinstance(scene, SharedScene) and scene.of_scene)


def _mesh_only(scene: Any, name: str) -> None:
    if _is_scene(scene):
        raise TypeError(f"scene: {name} is a TriangleMesh query; a bvhkit.Scene has none")


def closest_point(
    scene: _Scene, points: npt.ArrayLike, max_distance: Optional[float] = np.inf, threads: int = 1
) -> ClosestPoints:
    """:meth:`TriangleMesh.closest_point` on each partition: ClosestPoints of dask arrays; for a
    :class:`bvhkit.Scene`, :meth:`Scene.closest_point`'s SceneClosest (``max_distance`` must
    then be inf)."""
    t, md = _a.threads(threads), _a.limit("max_distance", max_distance)
    dt = _dtype(scene)
    p = _rows("points", points)
    if _is_scene(scene):
        if md != _a.INF:
            raise ValueError("max_distance: a bvhkit.Scene's closest_point has no limit: give inf")

        def scene_block(s: Scene, b: np.ndarray) -> tuple:
            return tuple(s.closest_point(b, threads=t))

        i64 = np.int64
        souts = [((), dt), ((3,), dt), ((), i64), ((), i64), ((), i64), ((3,), dt)]
        return SceneClosest(*_map(scene, [p], scene_block, souts))  # type: ignore[return-value]

    def block(s: TriangleMesh, b: np.ndarray) -> tuple:
        return tuple(s.closest_point(b, md, threads=t))

    outs = [((), dt), ((3,), dt), ((), np.int64), ((3,), dt)]
    return ClosestPoints(*_map(scene, [p], block, outs))


def signed_distance(
    scene: _Scene, points: npt.ArrayLike, sign: _a.Sign = "pseudonormal", threads: int = 1
) -> da.Array:
    """:meth:`TriangleMesh.signed_distance` on each partition; for a :class:`bvhkit.Scene`,
    :meth:`Scene.signed_distance`'s SceneClosest of dask arrays."""
    t = _a.threads(threads)
    _a.option("sign", sign, _a.SIGNS)
    p = _rows("points", points)
    if _is_scene(scene):
        dt = _dtype(scene)

        def scene_block(s: Scene, b: np.ndarray) -> tuple:
            return tuple(s.signed_distance(b, sign=sign, threads=t))

        i64 = np.int64
        souts = [((), dt), ((3,), dt), ((), i64), ((), i64), ((), i64), ((3,), dt)]
        return SceneClosest(*_map(scene, [p], scene_block, souts))  # type: ignore[return-value]

    def block(s: TriangleMesh, b: np.ndarray) -> tuple:
        return (s.signed_distance(b, sign=sign, threads=t),)

    return _map(scene, [p], block, [((), _dtype(scene))])[0]


def winding_number(
    scene: _Scene, points: npt.ArrayLike, exact: bool = False, beta: float = 2.0, threads: int = 1
) -> da.Array:
    """:meth:`TriangleMesh.winding_number` on each partition."""
    _mesh_only(scene, "winding_number")
    t, e, b_ = _a.threads(threads), _a.flag("exact", exact), _a.number("beta", beta)
    if not 0 < b_ < _a.INF:
        raise ValueError(f"beta: must be a positive finite number, not {beta}")
    p = _rows("points", points)

    def block(s: TriangleMesh, b: np.ndarray) -> tuple:
        return (s.winding_number(b, exact=e, beta=b_, threads=t),)

    return _map(scene, [p], block, [((), _dtype(scene))])[0]


def contains(scene: _Scene, points: npt.ArrayLike, threads: int = 1) -> da.Array:
    """:meth:`TriangleMesh.contains` on each partition: (n,) bool; for a :class:`bvhkit.Scene`,
    :meth:`Scene.contains`."""
    if _is_scene(scene):
        t = _a.threads(threads)
        p = _rows("points", points)
        _dtype(scene)

        def scene_block(s: Scene, b: np.ndarray) -> tuple:
            return (s.contains(b, threads=t),)

        return _map(scene, [p], scene_block, [((), np.bool_)])[0]
    return winding_number(scene, points, threads=threads) > 0.5


def _ray_args(scene: Any, origins: Any, directions: Any, tmin: Any, tmax: Any):
    _dtype(scene)
    o = _rows("origins", origins)
    d = _rows("directions", directions, like=o)
    t1 = _a.INF if tmax is None else _a.number("tmax", tmax)  # None: no limit
    return o, d, _a.number("tmin", tmin), t1


def intersect(
    scene: _Scene,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    tmin: float = 0.0,
    tmax: Optional[float] = np.inf,
    threads: int = 1,
) -> RayHits:
    """:meth:`TriangleMesh.intersect` on each partition (``tmin``, ``tmax``: scalars): RayHits of
    dask arrays; for a :class:`bvhkit.Scene`, :meth:`Scene.intersect`'s SceneHits."""
    t = _a.threads(threads)
    o, d, t0, t1 = _ray_args(scene, origins, directions, tmin, tmax)
    dt = _dtype(scene)
    if _is_scene(scene):

        def scene_block(s: Scene, bo: np.ndarray, bd: np.ndarray) -> tuple:
            return tuple(s.intersect(bo, bd, t0, t1, threads=t))

        i64 = np.int64
        souts = [((), dt), ((), i64), ((), i64), ((), i64), ((3,), dt), ((3,), dt)]
        return SceneHits(*_map(scene, [o, d], scene_block, souts))  # type: ignore[return-value]

    def block(s: TriangleMesh, bo: np.ndarray, bd: np.ndarray) -> tuple:
        return tuple(s.intersect(bo, bd, t0, t1, threads=t))

    return RayHits(*_map(scene, [o, d], block, [((), dt), ((), np.int64), ((3,), dt)]))


def occluded(
    scene: _Scene,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    tmin: float = 0.0,
    tmax: Optional[float] = np.inf,
    threads: int = 1,
) -> da.Array:
    """:meth:`TriangleMesh.occluded` on each partition: (n,) bool."""
    return _per_ray(scene, origins, directions, tmin, tmax, threads, "occluded", np.bool_)


def count_intersections(
    scene: _Scene,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    tmin: float = 0.0,
    tmax: Optional[float] = np.inf,
    threads: int = 1,
) -> da.Array:
    """:meth:`TriangleMesh.count_intersections` on each partition: (n,) int64."""
    _mesh_only(scene, "count_intersections")
    return _per_ray(
        scene, origins, directions, tmin, tmax, threads, "count_intersections", np.int64
    )


def _per_ray(
    scene: Any,
    origins: Any,
    directions: Any,
    tmin: float,
    tmax: float,
    threads: int,
    method: str,
    dtype: Any,
) -> da.Array:
    """One value per ray from the scene's `method`, partition by partition."""
    t = _a.threads(threads)
    o, d, t0, t1 = _ray_args(scene, origins, directions, tmin, tmax)

    def block(s: TriangleMesh, bo: np.ndarray, bd: np.ndarray) -> tuple:
        return (getattr(s, method)(bo, bd, t0, t1, threads=t),)

    return _map(scene, [o, d], block, [((), dtype)])[0]
