"""Scene: many posed instances of shared meshes, for rays, closest points and collision.

A thin layer over the C++ ``bvhkit::Scene<T>`` (docs/scenes.md): this module checks and converts
the arguments, naming the one at fault; the extension (python/src/instanced_scene.cpp) does the
work without the GIL.
"""

from __future__ import annotations

import os
from typing import Any, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from . import _bvhkit
from ._scene_pairs import ScenePairs
from ._scene_args import (
    _I64,
    _U32,
    _U64,
    SceneClosest,
    SceneHits,
    SceneIntersections,
    _ids,
    _index,
    _integers,
    _margins,
    _one_rotation,
    _one_translation,
    _rotations,
    _translations,
)

class Scene(ScenePairs):
    """Many posed instances of shared triangle meshes: rays, closest points and collision over
    all of them, without moving a vertex (docs/scenes.md).

    Meshes are added once (:meth:`add_mesh`, which returns a geometry id) and placed any number
    of times by instances (:meth:`add_instance`, which returns an instance id): each has a rigid
    pose ``x -> rotation @ x + translation``, user data (an int), a collision group and mask and
    a margin. ``dtype`` (float32, the default, or float64) is the scalar type of the meshes, the
    poses and the queries; instances far from the origin are queried in their own frames, so a
    float mesh keeps its detail at 1e5.

    Instance ids are Python ints (int64 in arrays): the instance's slot and the slot's generation.
    A removed instance's id stays stale for good (the slot's next instance gets another id):
    every call given it raises ValueError, as do bad geometry ids, non-finite or non-rigid poses
    and negative margins.

    Threads: queries may run from many Python threads at once, and batch queries spread over
    ``threads`` threads (0 = every core) without the GIL; changes (add, set_poses, remove) hold
    an exclusive lock, so they wait for running queries and queries wait for them: no thread can
    see a half-made change.
    """

    def __init__(self, dtype: npt.DTypeLike = np.float32) -> None:
        self.dtype: np.dtype = _a.scalar_type(dtype)
        impl = _bvhkit.InstancedScene32 if self.dtype == np.float32 else _bvhkit.InstancedScene64
        self._impl = impl()

    # ------------------------------------------------------------------ contents

    def add_mesh(self, vertices: npt.ArrayLike, faces: npt.ArrayLike) -> int:
        """Adds a triangle mesh (copied; its convex hull is computed once) and returns its
        geometry id: 0, 1, 2, ... Faces with a NaN or infinite corner are never hit, found or
        collided with."""
        v = _a.vertices("vertices", vertices, self.dtype)
        f = _a.faces(faces, len(v))
        return int(self._impl.add_mesh(v, f))

    @property
    def geometry_count(self) -> int:
        """Number of meshes added."""
        return int(self._impl.geometry_count())

    def add_instance(
        self,
        geometry: int,
        rotation: Optional[npt.ArrayLike] = None,
        translation: Optional[npt.ArrayLike] = None,
        *,
        user_data: int = 0,
        group: int = 1,
        mask: int = 0xFFFFFFFF,
        margin: float = 0.0,
    ) -> int:
        """Places mesh ``geometry`` at ``x -> rotation @ x + translation`` (rotation (3, 3), a
        rotation matrix to 1e-4, None for the identity; translation (3,), None for zero) and
        returns the instance's id.

        ``user_data``: an int in 0..2^64-1, yours. ``group``, ``mask``: 32-bit collision filter;
        two instances may collide iff ``group_a & mask_b`` and ``group_b & mask_a``.
        ``margin`` >= 0: they collide when their meshes come within ``margin_a + margin_b``."""
        r, t = _one_rotation(rotation), _one_translation(translation)
        if r is None and t is None:
            t = np.zeros(3)
        return int(self._add(geometry, r, t, user_data, group, mask, margin, "rotation",
                             "translation")[0])

    def add_instances(
        self,
        geometry: Any,
        rotations: Optional[npt.ArrayLike] = None,
        translations: Optional[npt.ArrayLike] = None,
        *,
        user_data: Any = 0,
        group: Any = 1,
        mask: Any = 0xFFFFFFFF,
        margin: Any = 0.0,
    ) -> np.ndarray:
        """:meth:`add_instance` for k instances at once: ``rotations`` (k, 3, 3) or None,
        ``translations`` (k, 3) or None (one of them gives k), ``geometry`` and the options an
        int (a number) or a (k,) array. Returns the (k,) int64 ids. Everything is checked before
        the first is added: an error adds none."""
        return self._add(geometry, rotations, translations, user_data, group, mask, margin,
                         "rotations", "translations")

    def _add(self, geometry: Any, rotations: Any, translations: Any, user_data: Any, group: Any,
             mask: Any, margin: Any, rn: str, tn: str) -> np.ndarray:
        if rotations is None and translations is None:
            raise ValueError(f"{tn}: give translations or rotations (or both)")
        r = None if rotations is None else _rotations(rn, rotations, None, self.dtype)
        k = len(r) if r is not None else None
        t = _translations(tn, translations, k, self.dtype)
        k = len(t)
        if r is None:
            r = _rotations(rn, None, k, self.dtype)
        g = _integers("geometry", geometry, k, _I64, np.int64)
        ud = _integers("user_data", user_data, k, _U64, np.uint64)
        gr = _integers("group", group, k, _U32, np.uint32)
        ma = _integers("mask", mask, k, _U32, np.uint32)
        mg = _margins(margin, k, self.dtype)
        ids = np.empty(k, np.int64)
        self._impl.add_instances(g, r, t, ud, gr, ma, mg, ids)
        return ids

    def set_pose(self, id: int, rotation: Optional[npt.ArrayLike] = None,
                 translation: Optional[npt.ArrayLike] = None) -> None:
        """Moves one instance (rotation None: the identity; translation None: zero)."""
        self._set_poses(_ids("id", _index("id", id, _I64)), _one_rotation(rotation),
                        _one_translation(translation), "rotation", "translation")

    def set_poses(self, ids: npt.ArrayLike, rotations: Optional[npt.ArrayLike],
                  translations: Optional[npt.ArrayLike]) -> None:
        """Moves instances ``ids`` (k,) to poses ``rotations`` (k, 3, 3) (None: identities) and
        ``translations`` (k, 3) (None: zeros), in one call. Every id and pose is checked before
        any instance moves: an error (a stale id, a non-rigid rotation, a NaN) leaves the scene
        as it was. An id given twice ends at its last pose."""
        self._set_poses(_ids("ids", ids, live_checked=True), rotations, translations, "rotations",
                        "translations")

    def _set_poses(self, i: np.ndarray, rotations: Any, translations: Any, rn: str, tn: str
                   ) -> None:
        # Types and shapes here; values (finite, rigid) in the C++ call's one pass, which names
        # the argument and row as _rotations would (a planner calls this once a configuration).
        r = _rotations(rn, rotations, len(i), self.dtype, values=False)
        t = _translations(tn, translations, len(i), self.dtype, finite=False)
        try:
            self._impl.set_poses(i, r, t)
        except ValueError as e:
            message = str(e)
            if message.startswith("ids") and rn == "rotation":
                raise ValueError("id" + message[len("ids[0]"):]) from None
            for plural, name in (("rotations", rn), ("translations", tn)):
                if message.startswith(plural + ":") and name != plural:
                    raise ValueError(name + message[len(plural):]) from None
            raise

    def set_options(
        self,
        ids: npt.ArrayLike,
        *,
        user_data: Any = None,
        group: Any = None,
        mask: Any = None,
        margin: Any = None,
    ) -> None:
        """New options for instances ``ids`` (an id or (k,) ids): each given option an int (a
        number) or a (k,) array; those not given (None) stay as they are. Everything is checked
        before anything changes (a gripper that takes hold of a part: the part's mask, so that
        the pair no longer counts)."""
        i = _ids("ids", ids)
        k = len(i)
        ud = _integers("user_data", 0 if user_data is None else user_data, k, _U64, np.uint64)
        gr = _integers("group", 0 if group is None else group, k, _U32, np.uint32)
        ma = _integers("mask", 0 if mask is None else mask, k, _U32, np.uint32)
        mg = _margins(0.0 if margin is None else margin, k, self.dtype)
        given = sum(bit for bit, x in ((1, user_data), (2, group), (4, mask), (8, margin))
                    if x is not None)
        self._impl.set_options(i, ud, gr, ma, mg, given)

    def remove(self, ids: npt.ArrayLike) -> None:
        """Removes instances (an id or an array of ids; all checked first). Their ids are stale
        from now on."""
        self._impl.remove(_ids("ids", ids))

    def __len__(self) -> int:
        """Number of live instances."""
        return int(len(self._impl))

    def __contains__(self, id: object) -> bool:
        """Whether ``id`` names a live instance of this scene."""
        if isinstance(id, (bool, np.bool_)) or not isinstance(id, (int, np.integer)):
            return False
        return 0 <= int(id) <= _I64 and bool(self._impl.contains(int(id)))

    def ids(self) -> np.ndarray:
        """The live instances' ids, (n,) int64, by slot."""
        return self._impl.ids()

    def _describe(self, id: Any) -> tuple:
        i = _ids("id", _index("id", id, _I64))
        dt = self.dtype
        out = (np.empty(1, np.int64), np.empty(1, np.uint64), np.empty(1, np.uint32),
               np.empty(1, np.uint32), np.empty(1, dt), np.empty((1, 3, 3), dt),
               np.empty((1, 3), dt))
        try:
            self._impl.describe(i, *out)
        except ValueError as e:
            raise ValueError("id" + str(e)[len("ids[0]"):]) from None
        return out

    def user_data(self, id: int) -> int:
        """The instance's user data."""
        return int(self._describe(id)[1][0])

    def geometry_of(self, id: int) -> int:
        """The instance's geometry id."""
        return int(self._describe(id)[0][0])

    def pose(self, id: int) -> Tuple[np.ndarray, np.ndarray]:
        """The instance's pose: (rotation (3, 3), translation (3,))."""
        d = self._describe(id)
        return d[5][0], d[6][0]

    def options(self, id: int) -> dict:
        """The instance's ``user_data``, ``group``, ``mask`` and ``margin``."""
        d = self._describe(id)
        return {"user_data": int(d[1][0]), "group": int(d[2][0]), "mask": int(d[3][0]),
                "margin": float(d[4][0])}

    def bounds(self) -> Tuple[np.ndarray, np.ndarray]:
        """(lo, hi): the box around every instance (each instance's tight world box, padded by a
        few rounding units); lo = inf and hi = -inf for an empty scene."""
        lo, hi = self._impl.bounds()
        return lo, hi

    def validate(self) -> None:
        """Checks every invariant of the scene; ValueError naming the first broken."""
        self._impl.validate()

    def prepare(self) -> None:
        """Builds every mesh's ray, closest point and collision trees now (each is otherwise
        built by the first query that needs it)."""
        self._impl.prepare()

    def __repr__(self) -> str:
        return f"Scene(instances={len(self)}, meshes={self.geometry_count}, dtype={self.dtype})"

    # ------------------------------------------------------------------ rays

    def _rays(self, origins: Any, directions: Any, tmin: Any, tmax: Any, threads: Any) -> tuple:
        o = _a.rows("origins", origins, 3, self.dtype)
        d = _a.rows("directions", directions, 3, self.dtype)
        if d.shape[0] != o.shape[0]:
            raise ValueError(f"directions: {d.shape[0]} rows, origins has {o.shape[0]}")
        t0 = _a.column("tmin", tmin, len(o), self.dtype)
        t1 = _a.column("tmax", tmax, len(o), self.dtype, none=np.inf)
        return o, d, t0, t1, _a.threads(threads)

    def intersect(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: npt.ArrayLike = 0.0,
        tmax: Optional[npt.ArrayLike] = np.inf,
        threads: int = 0,
    ) -> SceneHits:
        """The closest hit over all instances of each ray ``origin + t * direction``, t in
        [tmin, tmax] (``tmin`` >= 0; numbers or (k,) arrays; ``tmax=None``: no limit).

        Returns :class:`SceneHits` ``(t, instance, geometry, face, barycentric, normal)``;
        instance = -1 on a miss. Rays with a NaN or infinite component or a zero direction miss.
        """
        dt = self.dtype
        if (
            type(origins) is np.ndarray and type(directions) is np.ndarray
            and origins.dtype is dt and directions.dtype is dt and origins.ndim == 2
            and origins.shape[1] == 3 and directions.shape == origins.shape
            and type(tmin) is float and type(tmax) is float
            and type(threads) is int and 0 <= threads <= _a.THREADS_MAX
        ):
            # The one-ray call's usual arguments: one [tmin, tmax] for all, no array made for it
            # (the C++ call converts a non-contiguous array as the general path would).
            k = len(origins)
            t = np.empty(k, dt)
            inst, geom, face = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.int64)
            bary, normal = np.empty((k, 3), dt), np.empty((k, 3), dt)
            self._impl.intersect_shared(origins, directions, tmin, tmax, t, inst, geom, face,
                                        bary, normal, threads)
            return SceneHits(t, inst, geom, face, bary, normal)
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        k = len(o)
        t = np.empty(k, dt)
        inst, geom, face = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.int64)
        bary, normal = np.empty((k, 3), dt), np.empty((k, 3), dt)
        self._impl.intersect(o, d, t0, t1, t, inst, geom, face, bary, normal, n)
        return SceneHits(t, inst, geom, face, bary, normal)

    def occluded(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: npt.ArrayLike = 0.0,
        tmax: Optional[npt.ArrayLike] = np.inf,
        threads: int = 0,
    ) -> np.ndarray:
        """Whether each ray hits any instance within [tmin, tmax]: (k,) bool (shadow rays)."""
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        out = np.empty(len(o), np.bool_)
        self._impl.occluded(o, d, t0, t1, out, n)
        return out

    def list_intersections(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        tmin: npt.ArrayLike = 0.0,
        tmax: Optional[npt.ArrayLike] = np.inf,
        threads: int = 0,
    ) -> SceneIntersections:
        """Every hit of each ray within [tmin, tmax], as flat arrays sorted by ray, then t:
        :class:`SceneIntersections` ``(ray_index, t, instance, geometry, face, barycentric,
        ray_splits)``; ray i's hits are ``ray_splits[i]:ray_splits[i + 1]``. A ray through an
        edge shared by two faces lists both."""
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        return SceneIntersections(*self._impl.list_intersections(o, d, t0, t1, n))

    # ------------------------------------------------------------------ proximity

    def closest_point(self, points: npt.ArrayLike, threads: int = 0) -> SceneClosest:
        """The nearest point over all instances to each point: :class:`SceneClosest`
        ``(distance, point, instance, geometry, face, barycentric)``. Points with a NaN or
        infinite coordinate, and every point of an empty scene, find nothing: distance = inf,
        point = NaN, instance = face = -1."""
        p = _a.rows("points", points, 3, self.dtype)
        n = _a.threads(threads)
        k, dt = len(p), self.dtype
        dist, point, bary = np.empty(k, dt), np.empty((k, 3), dt), np.empty((k, 3), dt)
        inst, geom, face = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.int64)
        self._impl.closest_point(p, dist, point, inst, geom, face, bary, n)
        return SceneClosest(dist, point, inst, geom, face, bary)

    def signed_distance(
        self, points: npt.ArrayLike, sign: _a.Sign = "pseudonormal", threads: int = 0
    ) -> SceneClosest:
        """The distance from each point to the nearest surface of any instance, negative where
        the point is inside any instance (overlapping instances: inside their union), as on the
        scene made one world-space mesh: :class:`SceneClosest` ``(distance, point, instance,
        geometry, face, barycentric)``, as :meth:`closest_point` gives, the distance signed.

        Inside an instance, as :meth:`TriangleMesh.signed_distance` decides it on that one
        mesh: ``sign="pseudonormal"`` by the angle-weighted pseudonormal at the instance's
        closest point (exact for closed, consistently oriented meshes);
        ``sign="winding_number"`` by :meth:`contains`'s rule (meshes with holes). Only the
        instances whose world box holds the point are asked. A point on one instance's surface
        and inside another gets -0.0 (``np.signbit``). Points with a NaN or infinite
        coordinate, and every point of a scene without faces: distance = inf, instance = -1.
        """
        _a.option("sign", sign, _a.SIGNS)
        p = _a.rows("points", points, 3, self.dtype)
        n = _a.threads(threads)
        k, dt = len(p), self.dtype
        dist, point, bary = np.empty(k, dt), np.empty((k, 3), dt), np.empty((k, 3), dt)
        inst, geom, face = np.empty(k, np.int64), np.empty(k, np.int64), np.empty(k, np.int64)
        self._impl.signed_distance(p, sign, dist, point, inst, geom, face, bary, n)
        return SceneClosest(dist, point, inst, geom, face, bary)

    def contains(self, points: npt.ArrayLike, threads: int = 0) -> np.ndarray:
        """Whether each point is inside any instance: (k,) bool. Inside one instance as
        :meth:`TriangleMesh.contains` decides it (winding number above 1/2: exactly by one
        ray's crossings on a closed mesh, by the fast winding number otherwise). Points with a
        NaN or infinite coordinate are outside. (``id in scene`` asks whether an instance id is
        live.)"""
        p = _a.rows("points", points, 3, self.dtype)
        n = _a.threads(threads)
        out = np.empty(len(p), np.bool_)
        self._impl.contains_points(p, out, n)
        return out

    # ------------------------------------------------------------------ saving and loading

    def to_bytes(self) -> bytes:
        """The scene as bytes (the library's scene file, docs/serialization.md kind 7): each
        mesh once, every instance with its id, pose and options, and the top-level tree as
        built. :meth:`from_bytes` gives a scene with the same ids that answers every query bit
        for bit as this one; its per-mesh trees are built again at the first query that needs
        them (or by :meth:`prepare`)."""
        return self._impl.to_bytes()

    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview]) -> "Scene":
        """A scene from :meth:`to_bytes`'s bytes (its dtype is the saved one). Everything is
        checked (a checksum over the whole, every count, id, pose and box); damaged or foreign
        data raises ValueError."""
        return cls._from_bytes(data, "data")

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes :meth:`to_bytes` to the file ``path`` (beside and renamed: a failed write
        leaves no partial file)."""
        _bvhkit.write_file(_a.path("path", path), self.to_bytes())

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "Scene":
        """A scene from a file written by :meth:`save` (ValueError naming the file if damaged)."""
        p = _a.path("path", path)
        return cls._from_bytes(_bvhkit.read_file(p), p)

    @classmethod
    def _from_bytes(cls, data: Any, what: str) -> "Scene":
        self = cls.__new__(cls)
        self._load(data, what)
        return self

    def _load(self, data: Any, what: str) -> None:
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"{what}: must be bytes, not {type(data).__name__}")
        b = bytes(data)
        # The envelope's scalar byte (docs/serialization.md) picks the type; the loader checks
        # everything else, this byte included.
        dtype = np.dtype(np.float64) if len(b) > 16 and b[16] == 2 else np.dtype(np.float32)
        impl = (_bvhkit.InstancedScene32 if dtype == np.float32 else _bvhkit.InstancedScene64)()
        try:
            impl.load_bytes(b)
        except ValueError as e:
            raise ValueError(f"{what}: {e}") from None
        self.dtype = dtype
        self._impl = impl

    def __getstate__(self) -> dict:
        """Pickles through :meth:`to_bytes`."""
        return {"bvhkit.Scene": self.to_bytes()}

    def __setstate__(self, state: dict) -> None:
        """Unpickles through :meth:`from_bytes`."""
        if not isinstance(state, dict) or "bvhkit.Scene" not in state:
            raise ValueError("state: not a pickled bvhkit.Scene")
        self._load(state["bvhkit.Scene"], "pickled Scene")
