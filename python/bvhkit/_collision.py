"""Mesh against mesh: CollisionModel, collide, distance, self_intersections."""

from __future__ import annotations

import os
import struct
from typing import Any, List, Literal, NamedTuple, Optional, Union, overload

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from . import _bvhkit
from ._scene_file import _checksum, _join_sections, _split_sections  # the scenes' framing

VOLUMES = _a.VOLUMES

# ---------------------------------------------------------------- the container (docs/python.md)
# Header: magic, version, scalar (1 float32, 2 float64), volume (the C++ file's volume code),
# reserved, then vertex count, face count, model file size, payload size; an 8-byte BLAKE2b
# checksum of header and payload; the payload: vertices (little-endian scalars), faces (u32), the
# model's own file (docs/serialization.md, kind 6), each padded to 8 bytes.
_MAGIC = b"BVHKCM\x1a\n"
_VERSION = 1
_HEADER = struct.Struct("<8sIBBH4Q")
_HEADER_SIZE = _HEADER.size + 8
_SCALARS = {1: np.dtype("<f4"), 2: np.dtype("<f8")}
_VOLUME_CODES = {"aabb": 1, "sphere": 3, "obb": 4, "rss": 5, "obbrss": 6, "kdop18": 8, "hull": 10}

load_count: int = 0
"""How many models this process has loaded (from_bytes, load, unpickling); a diagnostic."""


def _encode(dtype: np.dtype, volume: str, state: tuple) -> bytes:
    vertices, faces, model = state
    scalar = 1 if dtype == np.float32 else 2
    sections = [
        np.ascontiguousarray(vertices, _SCALARS[scalar]).tobytes(),
        np.ascontiguousarray(faces, "<u4").tobytes(),
        model,
    ]
    payload = _join_sections(sections)
    header = _HEADER.pack(
        _MAGIC, _VERSION, scalar, _VOLUME_CODES[volume], 0, len(vertices), len(faces),
        len(model), len(payload)
    )
    return header + _checksum(header, payload) + payload


def _decode(data: Any, what: str):
    """(dtype, volume, vertices, faces, model file bytes), checked against the size and the
    checksum (the model is checked by the C++ loader); ValueError starting with ``what``."""

    def fail(msg: str) -> ValueError:
        return ValueError(f"{what}: {msg}")

    try:
        view = memoryview(data).cast("B")
    except TypeError:
        raise TypeError(f"{what}: must be bytes-like, not {type(data).__name__}") from None
    if len(view) < _HEADER_SIZE:
        raise fail(f"{len(view)} bytes, shorter than the {_HEADER_SIZE}-byte header")
    magic, version, scalar, volume, reserved, nv, nf, nmodel, npayload = _HEADER.unpack_from(view)
    if magic != _MAGIC:
        raise fail("not a bvhkit CollisionModel file (wrong magic)")
    if version != _VERSION:
        raise fail(f"format version {version}, this bvhkit reads {_VERSION}")
    if scalar not in _SCALARS:
        raise fail(f"unknown scalar code {scalar}")
    names = {code: name for name, code in _VOLUME_CODES.items()}
    if volume not in names:
        raise fail(f"unknown volume code {volume}")
    if reserved:
        raise fail("reserved bits set")
    if npayload != len(view) - _HEADER_SIZE:
        raise fail(f"the header says {npayload} payload bytes, there are {len(view) - _HEADER_SIZE}")
    payload = view[_HEADER_SIZE:]
    if _checksum(bytes(view[: _HEADER.size]), payload) != bytes(view[_HEADER.size : _HEADER_SIZE]):
        raise fail("checksum mismatch (the data is damaged)")
    dtype = _SCALARS[scalar]
    sizes = [3 * nv * dtype.itemsize, 3 * nf * 4, nmodel]
    parts = _split_sections(payload, sizes, fail)
    native = np.dtype(np.float32 if scalar == 1 else np.float64)
    vertices = np.frombuffer(parts[0], dtype).astype(native).reshape(nv, 3)
    faces = np.frombuffer(parts[1], "<u4").astype(np.int64).reshape(nf, 3)
    return native, names[volume], vertices, faces, bytes(parts[2])


class CollisionModel:
    """A triangle mesh ready for collision and distance queries against another one.

    ``vertices``: (n, 3) float32 or float64; ``faces``: (m, 3) int32 or int64. ``volume`` is the
    bounding volume of the tree: ``"obb"`` (oriented boxes, Gottschalk et al. 1996: the fastest
    for collision), ``"rss"`` (rectangle swept spheres, Larsen et al. 1999), ``"obbrss"`` (both in
    one model: boxes for collision, swept spheres for distance), ``"hull"`` (convex hulls of at most
    16 vertices: the slowest to build, the fastest for distance), ``"aabb"``, ``"sphere"`` or
    ``"kdop18"``. ``dtype``: float32 (default) or float64.
    Both models of a query must have the same volume and dtype.

    Faces with a NaN or infinite coordinate are left out; zero-area faces never collide.
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        volume: _a.Volume = "obb",
        dtype: npt.DTypeLike = np.float32,
        threads: int = 0,
    ) -> None:
        self.volume: str = _a.option("volume", volume, VOLUMES)
        self.dtype: np.dtype = _a.scalar_type(dtype)
        n = _a.threads(threads)
        v = _a.vertices("vertices", vertices, self.dtype)
        f = _a.faces(faces, len(v))
        suffix = "f32" if self.dtype == np.float32 else "f64"
        self._impl_type = getattr(_bvhkit, f"Model_{volume}_{suffix}")
        self._impl = self._impl_type(v, f, n)
        self._vertex_count = len(v)

    # ------------------------------------------------------------------ saving and loading

    def to_bytes(self) -> bytes:
        """The model as bytes (format: docs/python.md): the mesh (as refitted, if it was), the
        volume type and the model's tree in the library's file format. Reading it back with
        :meth:`from_bytes` rebuilds nothing and answers bit for bit as this model does."""
        return _encode(self.dtype, self.volume, self._impl.state())

    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview]) -> "CollisionModel":
        """A model from :meth:`to_bytes`'s bytes. Everything is checked (a checksum over the
        whole, the sizes, the tree as the library's loader checks it, and that it is the model of
        the mesh stored beside it); damaged or foreign data raises ValueError."""
        return cls._from_bytes(data, "data")

    def save(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes :meth:`to_bytes` to the file ``path``."""
        # Written beside and renamed: a failed write (a full disk) leaves no partial file.
        _bvhkit.write_file(_a.path("path", path), self.to_bytes())

    @classmethod
    def load(cls, path: Union[str, "os.PathLike[str]"]) -> "CollisionModel":
        """A model from a file written by :meth:`save` (ValueError naming the file if damaged)."""
        p = _a.path("path", path)
        data = _bvhkit.read_file(p)  # refuses devices and FIFOs, which may never end
        return cls._from_bytes(data, p)

    @classmethod
    def _from_bytes(cls, data: Any, what: str) -> "CollisionModel":
        self = cls.__new__(cls)
        self._load(data, what)
        return self

    def _load(self, data: Any, what: str) -> None:
        global load_count
        dtype, volume, vertices, faces, model = _decode(data, what)
        suffix = "f32" if dtype == np.float32 else "f64"
        impl_type = getattr(_bvhkit, f"Model_{volume}_{suffix}")
        try:
            self._impl = impl_type(vertices, faces, model)
        except ValueError as e:
            raise ValueError(f"{what}: {e}") from None
        self._impl_type = impl_type
        self.volume = volume
        self.dtype = dtype
        self._vertex_count = len(vertices)
        load_count += 1

    def __getstate__(self) -> dict:
        """Pickles through :meth:`to_bytes`: the tree travels built."""
        return {"bvhkit.CollisionModel": self.to_bytes()}

    def __setstate__(self, state: dict) -> None:
        """Unpickles through :meth:`from_bytes`."""
        if not isinstance(state, dict) or "bvhkit.CollisionModel" not in state:
            raise ValueError("state: not a pickled bvhkit.CollisionModel")
        self._load(state["bvhkit.CollisionModel"], "pickled CollisionModel")

    def refit(self, vertices: npt.ArrayLike) -> None:
        """New positions for the same vertices (same faces): every volume is refitted, the tree's
        shape kept."""
        v = _a.vertices("vertices", vertices, self.dtype)
        if len(v) != self._vertex_count:
            raise ValueError(f"vertices: {len(v)} rows, the model has {self._vertex_count}")
        self._impl.refit(v)

    @property
    def face_count(self) -> int:
        """Number of faces."""
        return int(self._impl.triangle_count)

    def __repr__(self) -> str:
        """Face count and dtype."""
        return f"CollisionModel(faces={self.face_count}, volume={self.volume!r}, dtype={self.dtype})"


# The dtypes the C++ calls read poses in, whatever the model's (each value rounded to the model's
# type as numpy's astype rounds it).
_POSE_TYPES = (np.dtype(np.float32), np.dtype(np.float64))


def _poses(a: Any, b: Any, rotations: Any, translations: Any):
    """(rotations or None, translations, pose count) as the C++ call takes them: shapes and types
    checked here, values (finite, rigid) by the C++ call as it reads each pose, with the same
    messages as _arrays.rotations and _arrays.rows(finite=True) give. A C-contiguous float32 or
    float64 array in a right shape, or None, is passed on as it is, whatever the model's dtype: a
    one-pose call pays no numpy work here."""
    if type(a) is not CollisionModel and not isinstance(a, CollisionModel):
        raise TypeError(f"a: must be a CollisionModel, not {type(a).__name__}")
    if type(b) is not CollisionModel and not isinstance(b, CollisionModel):
        raise TypeError(f"b: must be a CollisionModel, not {type(b).__name__}")
    if a._impl_type is not b._impl_type:
        raise TypeError(
            f"b: a has volume {a.volume!r} and dtype {a.dtype}, b has {b.volume!r} and {b.dtype}; "
            "both models must have the same volume and dtype"
        )
    return _pose_arrays(rotations, translations, a.dtype)


def _pose_arrays(rotations: Any, translations: Any, dt: np.dtype):
    """_poses' pose part, for any caller whose C++ call reads poses as collision.hpp's
    PoseValues does (convex_distance too); `dt` is the type other input is converted to."""
    t = translations
    if (type(t) is np.ndarray and t.dtype in _POSE_TYPES and t.flags.c_contiguous
            and (t.shape == (3,) or t.ndim == 2 and t.shape[1] == 3)):
        k = 1 if t.ndim == 1 else t.shape[0]
    else:
        t = _a.rows("translations", t, 3, dt)
        k = t.shape[0]
    r = rotations
    if r is None or (type(r) is np.ndarray and r.dtype in _POSE_TYPES and r.flags.c_contiguous
                     and (r.shape == (3, 3) or r.ndim == 3 and r.shape[1:] == (3, 3))):
        return r, t, k
    try:
        r = _a.rotations(r, dt, values=False)
    except (TypeError, ValueError):
        _a.rows("translations", t, 3, dt, finite=True)  # a bad translation is reported first
        raise
    return r, t, k


@overload
def collide(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    contacts: Literal[False] = ...,
    threads: int = ...,
) -> np.ndarray: ...
@overload
def collide(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    contacts: Literal[True],
    threads: int = ...,
) -> List[np.ndarray]: ...
@overload
def collide(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    contacts: bool = ...,
    threads: int = ...,
) -> Union[np.ndarray, List[np.ndarray]]: ...
def collide(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    contacts: bool = False,
    threads: int = 0,
) -> Union[np.ndarray, List[np.ndarray]]:
    """Whether ``b``, placed at each pose, intersects ``a``.

    A pose maps a point x of b to ``rotations[i] @ x + translations[i]`` in a's frame:
    ``rotations`` (k, 3, 3) proper rotation matrices (or None for the identity),
    ``translations`` (k, 3). Poses are spread over ``threads`` threads (0 = every core).

    Returns a (k,) bool array, or with ``contacts=True`` a list of k int64 arrays (p_i, 2) of
    the intersecting (face of a, face of b) pairs at each pose, sorted. Faces that only touch
    count as intersecting.
    """
    want_contacts = contacts if contacts is False else _a.flag("contacts", contacts)
    n = threads if type(threads) is int and 0 <= threads <= _a.THREADS_MAX else _a.threads(threads)
    r, t, k = _poses(a, b, rotations, translations)
    if not want_contacts:
        out = np.empty(k, np.bool_)
        a._impl.collides(b._impl, r, t, out, n)
        return out
    pairs, offsets = a._impl.contacts(b._impl, r, t, n)
    return [pairs[offsets[i] : offsets[i + 1]] for i in range(k)]


class Contacts(NamedTuple):
    """What :func:`contacts` returns for one pose: p contacts, region by region (each region's
    deepest first), all in a's frame. docs/collision.md defines each quantity."""

    faces: np.ndarray
    """(p, 2) int64 (face of a, face of b) of each contact."""
    points: np.ndarray
    """(p, 3) the contact points."""
    normals: np.ndarray
    """(p, 3) unit normals from b into a: moving a along one by its depth separates that contact."""
    depths: np.ndarray
    """(p,) depths >= 0: a vertex's (or edge point's) distance to the other surface, 0 on the
    intersection curve."""
    regions: np.ndarray
    """(p,) int64 index of the connected overlap region each contact belongs to."""
    kinds: np.ndarray
    """(p,) int8: 0 on the intersection curve, 1 a vertex of a inside b, 2 a vertex of b inside a,
    3 a point of an edge of a inside b, 4 of an edge of b inside a."""


def contacts(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    max_points: int = 4,
    inside_vertices: bool = True,
    walk_inside: bool = True,
    threads: int = 0,
) -> List[Contacts]:
    """The contact manifold of ``a`` and ``b`` placed at each pose (poses as in :func:`collide`):
    a list of k :class:`Contacts`, empty arrays where they do not meet.

    The contacts are the ends of the intersection segments of the intersecting face pairs, the
    vertices of each mesh inside the other and the middles of edge pieces inside the other (for
    closed, outward-oriented meshes; with
    ``inside_vertices=False`` only the curve points, for open meshes). They are grouped into
    connected overlap regions and reduced to at most ``max_points`` well-spread points per region,
    the deepest first (0: keep every contact). ``walk_inside=False`` tests only the corners of the
    intersecting faces (work in proportion to the intersecting pairs; a deep overlap's inner
    vertices are then not seen). The first call on a model builds what the inside
    test needs (a signed-distance tree, kept until :meth:`CollisionModel.refit`).
    """
    r, t, k = _poses(a, b, rotations, translations)
    if type(max_points) is not int or isinstance(max_points, bool):
        raise TypeError(f"max_points: must be an int, not {type(max_points).__name__}")
    if not 0 <= max_points < 2**32:
        raise ValueError(f"max_points: must be >= 0 (0 keeps every contact), not {max_points}")
    inside = _a.flag("inside_vertices", inside_vertices)
    walk = _a.flag("walk_inside", walk_inside)
    n = threads if type(threads) is int and 0 <= threads <= _a.THREADS_MAX else _a.threads(threads)
    faces, points, normals, depths, regions, kinds, offsets = a._impl.manifold(
        b._impl, r, t, max_points, inside, walk, n)
    out = []
    for i in range(k):
        s = slice(offsets[i], offsets[i + 1])
        out.append(Contacts(faces[s], points[s], normals[s], depths[s], regions[s], kinds[s]))
    return out


class Distances(NamedTuple):
    """What :func:`distance` returns, one entry per pose."""

    distance: np.ndarray
    """(k,) minimum distance between the meshes (0 where they intersect; inf if one is empty)."""
    point_a: np.ndarray
    """(k, 3) the closest point on a, in a's frame."""
    point_b: np.ndarray
    """(k, 3) the closest point on b, in a's frame (apply the inverse pose for b's own frame)."""
    face_a: np.ndarray
    """(k,) int64 face of a holding point_a (-1 if a model is empty)."""
    face_b: np.ndarray
    """(k,) int64 face of b holding point_b."""


def distance(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    absolute_tolerance: float = 0.0,
    relative_tolerance: float = 0.0,
    threads: int = 0,
) -> Distances:
    """The minimum distance between ``a`` and ``b`` placed at each pose, with a closest pair of
    points and faces (poses as in :func:`collide`).

    With tolerances the answer may exceed the true distance by at most
    max(absolute_tolerance, relative_tolerance * distance), and is found faster; both 0 (the
    default) give the exact minimum up to rounding.
    """
    r, t, k = _poses(a, b, rotations, translations)
    tol = (absolute_tolerance, relative_tolerance)
    if not (type(tol[0]) is float and type(tol[1]) is float and 0 <= tol[0] < _a.INF
            and 0 <= tol[1] < _a.INF):
        tol = []
        for name, value in (("absolute_tolerance", absolute_tolerance),
                            ("relative_tolerance", relative_tolerance)):
            x = _a.number(name, value)
            if not 0 <= x < _a.INF:
                raise ValueError(f"{name}: must be a finite number >= 0, not {value}")
            tol.append(x)
    n = threads if type(threads) is int and 0 <= threads <= _a.THREADS_MAX else _a.threads(threads)
    d = np.empty(k, a.dtype)
    pa = np.empty((k, 3), a.dtype)
    pb = np.empty((k, 3), a.dtype)
    fa = np.empty(k, np.int64)
    fb = np.empty(k, np.int64)
    a._impl.distance(b._impl, r, t, tol[0], tol[1], d, pa, pb, fa, fb, n)
    return Distances(d, pa, pb, fa, fb)


def self_intersections(model: CollisionModel) -> np.ndarray:
    """Pairs of faces of ``model`` that intersect and share no vertex index: (p, 2) int64, each
    row (i, j) with i < j, sorted. Faces that share a vertex index touch by construction and are
    left out (weld duplicated vertices first)."""
    if not isinstance(model, CollisionModel):
        raise TypeError(f"model: must be a CollisionModel, not {type(model).__name__}")
    return model._impl.self_intersections()
