"""Mesh against mesh: CollisionModel, collide, distance, self_intersections."""

from __future__ import annotations

from typing import Any, List, NamedTuple, Union

import numpy as np

from . import _arrays as _a
from . import _bvhkit

VOLUMES = ("obb", "rss", "obbrss", "aabb", "sphere", "kdop18")


class CollisionModel:
    """A triangle mesh ready for collision and distance queries against another one.

    ``vertices``: (n, 3) float32 or float64; ``faces``: (m, 3) int32 or int64. ``volume`` is the
    bounding volume of the tree: ``"obb"`` (oriented boxes, Gottschalk et al. 1996: the fastest
    for collision), ``"rss"`` (rectangle swept spheres, Larsen et al. 1999: the fastest for
    distance), ``"obbrss"`` (both in one model: boxes for collision, swept spheres for distance),
    ``"aabb"``, ``"sphere"`` or ``"kdop18"``. ``dtype``: float32 (default) or float64.
    Both models of a query must have the same volume and dtype.

    Faces with a NaN or infinite coordinate are left out; zero-area faces never collide.
    """

    def __init__(
        self,
        vertices: Any,
        faces: Any,
        volume: str = "obb",
        dtype: Any = np.float32,
        threads: int = 0,
    ) -> None:
        if volume not in VOLUMES:
            raise ValueError(f"volume: {volume!r} is not one of {', '.join(map(repr, VOLUMES))}")
        self.volume: str = volume
        self.dtype: np.dtype = _a.scalar_type(dtype)
        v = _a.vertices("vertices", vertices, self.dtype)
        f = _a.faces(faces, len(v))
        suffix = "f32" if self.dtype == np.float32 else "f64"
        self._impl = getattr(_bvhkit, f"Model_{volume}_{suffix}")(v, f, _a.threads(threads))
        self._vertex_count = len(v)

    def refit(self, vertices: Any) -> None:
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


def _poses(a: CollisionModel, b: CollisionModel, rotations: Any, translations: Any):
    for name, m in (("a", a), ("b", b)):
        if not isinstance(m, CollisionModel):
            raise TypeError(f"{name}: must be a CollisionModel, not {type(m).__name__}")
    if a.volume != b.volume or a.dtype != b.dtype:
        raise TypeError(
            f"b: a has volume {a.volume!r} and dtype {a.dtype}, b has {b.volume!r} and {b.dtype}; "
            "both models must have the same volume and dtype"
        )
    t = _a.rows("translations", translations, 3, a.dtype, finite=True)
    if rotations is None:
        r = np.ascontiguousarray(np.broadcast_to(np.eye(3, dtype=a.dtype), (len(t), 3, 3)))
    else:
        r = _a.rotations(rotations, a.dtype)
    if len(r) != len(t):
        raise ValueError(f"translations: {len(t)} rows, rotations has {len(r)}")
    return r, t


def collide(
    a: CollisionModel,
    b: CollisionModel,
    rotations: Any,
    translations: Any,
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
    r, t = _poses(a, b, rotations, translations)
    n = _a.threads(threads)
    if not contacts:
        out = np.empty(len(r), np.bool_)
        a._impl.collides(b._impl, r, t, out, n)
        return out
    pairs, offsets = a._impl.contacts(b._impl, r, t, n)
    return [pairs[offsets[i] : offsets[i + 1]] for i in range(len(r))]


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
    rotations: Any,
    translations: Any,
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
    r, t = _poses(a, b, rotations, translations)
    tol = []
    for name, value in (("absolute_tolerance", absolute_tolerance),
                        ("relative_tolerance", relative_tolerance)):
        x = float(value)
        if not (x >= 0 and np.isfinite(x)):
            raise ValueError(f"{name}: must be a finite number >= 0, not {value}")
        tol.append(x)
    k = len(r)
    d = np.empty(k, a.dtype)
    pa = np.empty((k, 3), a.dtype)
    pb = np.empty((k, 3), a.dtype)
    fa = np.empty(k, np.int64)
    fb = np.empty(k, np.int64)
    a._impl.distance(b._impl, r, t, tol[0], tol[1], d, pa, pb, fa, fb, _a.threads(threads))
    return Distances(d, pa, pb, fa, fb)


def self_intersections(model: CollisionModel) -> np.ndarray:
    """Pairs of faces of ``model`` that intersect and share no vertex index: (p, 2) int64, each
    row (i, j) with i < j, sorted. Faces that share a vertex index touch by construction and are
    left out (weld duplicated vertices first)."""
    if not isinstance(model, CollisionModel):
        raise TypeError(f"model: must be a CollisionModel, not {type(model).__name__}")
    return model._impl.self_intersections()
