"""The argument checks and the result tuples of bvhkit.Scene (_instances.py): each check names
the argument at fault, as the rest of the package does."""

from __future__ import annotations

from typing import Any, NamedTuple, Optional

import numpy as np

from . import _arrays as _a

_U32 = 2**32 - 1
_U64 = 2**64 - 1
_I64 = 2**63 - 1


class SceneHits(NamedTuple):
    """What :meth:`Scene.intersect` returns, one entry per ray."""

    t: np.ndarray
    """(k,) ray parameter of the closest hit (units of the direction's length); inf on a miss."""
    instance: np.ndarray
    """(k,) int64 id of the instance hit; -1 on a miss."""
    geometry: np.ndarray
    """(k,) int64 id of its mesh (what :meth:`Scene.add_mesh` returned); -1 on a miss."""
    face: np.ndarray
    """(k,) int64 index of the face hit in that mesh; -1 on a miss."""
    barycentric: np.ndarray
    """(k, 3) weights of the face's three vertices at the hit; zeros on a miss."""
    normal: np.ndarray
    """(k, 3) unit world-space geometric normal of the face hit ((p1 - p0) x (p2 - p0) under the
    instance's rotation); zeros on a miss."""


class SceneIntersections(NamedTuple):
    """What :meth:`Scene.list_intersections` returns: every hit of every ray, one entry per hit,
    sorted by ray, then t (then instance slot, then face)."""

    ray_index: np.ndarray
    """(n,) int64 index of the ray."""
    t: np.ndarray
    """(n,) ray parameter of the hit."""
    instance: np.ndarray
    """(n,) int64 id of the instance hit."""
    geometry: np.ndarray
    """(n,) int64 id of its mesh."""
    face: np.ndarray
    """(n,) int64 index of the face in that mesh."""
    barycentric: np.ndarray
    """(n, 3) weights of the face's vertices at the hit."""
    ray_splits: np.ndarray
    """(k + 1,) int64: ray i's hits are entries ray_splits[i]:ray_splits[i + 1]."""


class SceneClosest(NamedTuple):
    """What :meth:`Scene.closest_point` and :meth:`Scene.signed_distance` return, one entry
    per point."""

    distance: np.ndarray
    """(k,) distance to the nearest instance (signed by :meth:`Scene.signed_distance`: negative
    inside); inf for an empty scene or a non-finite point."""
    point: np.ndarray
    """(k, 3) the nearest point, world space; NaN where there is none."""
    instance: np.ndarray
    """(k,) int64 id of the instance it lies on; -1 where there is none."""
    geometry: np.ndarray
    """(k,) int64 id of that instance's mesh; -1 where there is none."""
    face: np.ndarray
    """(k,) int64 index of the face in that mesh; -1 where there is none."""
    barycentric: np.ndarray
    """(k, 3) weights of the face's vertices at the point."""


class SceneDistances(NamedTuple):
    """What :meth:`Scene.pairs_within` returns (and :meth:`Scene.closest_pair` and
    :meth:`Scene.closest_instance`, with at most one entry), one entry per pair."""

    distance: np.ndarray
    """(p,) the meshes' distance less both margins (<= 0: the pair collides, with a margin)."""
    pairs: np.ndarray
    """(p, 2) int64 ids, the first the lower slot; -1 first for :meth:`Scene.closest_instance`
    (the posed mesh)."""
    point_a: np.ndarray
    """(p, 3) the closest point on the first's mesh, world space."""
    point_b: np.ndarray
    """(p, 3) the closest point on the second's mesh, world space."""
    faces: np.ndarray
    """(p, 2) int64 the faces the two points lie on."""


class SceneFaceContacts(NamedTuple):
    """What :meth:`Scene.colliding_faces` returns: one entry per crossing triangle pair of each
    colliding pair of instances (or, for a pair that collides only through its margins, one
    entry with its closest triangles, ``separated``)."""

    pairs: np.ndarray
    """(c, 2) int64 instance ids, as :meth:`Scene.colliding_pairs` gives them."""
    faces: np.ndarray
    """(c, 2) int64 the triangles of the first's and of the second's mesh."""
    p: np.ndarray
    """(c, 3) world space: one end of the segment where the triangles cross (``separated``: the
    closest point on the first's mesh)."""
    q: np.ndarray
    """(c, 3) the segment's other end (``separated``: the closest point on the second's mesh)."""
    coplanar: np.ndarray
    """(c,) bool: the triangles are coplanar and overlap."""
    separated: np.ndarray
    """(c,) bool: the pair is within its margins, its triangles apart."""


def _index(name: str, value: Any, top: int) -> int:
    """An id or index argument: an int (numpy integers too, not bool) in [0, top]."""
    if type(value) is not int:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"{name}: must be an int, not {type(value).__name__}")
        value = int(value)
    if not 0 <= value <= top:
        raise ValueError(f"{name}: must be in 0..{top}, not {value}")
    return value


def _ids(name: str, value: Any, live_checked: bool = False) -> np.ndarray:
    """Instance ids: an int or an integer array, as a C-contiguous (k,) int64 array.
    ``live_checked``: the C++ call names every id that is not a live instance (a negative one
    included), so an int64 array skips the range pass (a planner's set_poses pays it per call)."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: must be an int or an array of ints, not bool")
    a = value if isinstance(value, np.ndarray) else np.asarray(value)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.shape == (0,) and not isinstance(value, np.ndarray):
        return np.empty(0, np.int64)  # [] reads as float64: no id, of any type
    if a.dtype.kind not in "iu":
        raise TypeError(f"{name}: dtype must be an integer type, not {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"{name}: shape must be (k,), not {a.shape}")
    if live_checked and a.dtype == np.int64 and a.flags.c_contiguous:
        return a
    if a.size and (int(a.min()) < 0 or int(a.max()) > _I64):
        raise ValueError(f"{name}: every id must be one add_instance returned (0 <= id < 2^63)")
    return np.ascontiguousarray(a, dtype=np.int64)


def _integers(name: str, value: Any, k: int, top: int, dtype: Any) -> np.ndarray:
    """An int or a (k,) integer array of values in [0, top], as (k,) `dtype`."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: must be an int or an array of ints, not bool")
    a = value if isinstance(value, np.ndarray) else np.asarray(value)
    if a.dtype.kind not in "iu":
        raise TypeError(f"{name}: must be an int or an array of ints, not {a.dtype}")
    if a.ndim != 0 and a.shape != (k,):
        raise ValueError(f"{name}: shape must be () or ({k},), not {a.shape}")
    if a.size and (int(a.min()) < 0 or int(a.max()) > top):
        raise ValueError(f"{name}: every value must be in 0..{top}")
    return np.ascontiguousarray(np.broadcast_to(a.astype(dtype), (k,)))


def _rotations(name: str, value: Any, k: Optional[int], dtype: np.dtype, values: bool = True
               ) -> np.ndarray:
    """(k, 3, 3) rigid rotations (None: identities), checked as _arrays.rotations checks them
    (``values=False``: type and shape only), the error naming `name`."""
    if value is None:
        return np.ascontiguousarray(np.broadcast_to(np.eye(3, dtype=dtype), (k or 1, 3, 3)))
    try:
        r = _a.rotations(value, dtype, values=values)
    except (TypeError, ValueError) as e:
        raise type(e)(str(e).replace("rotations:", f"{name}:", 1)) from None
    if k is not None and len(r) != k:
        raise ValueError(f"{name}: {len(r)} rotations, expected {k}")
    return r


def _translations(name: str, value: Any, k: Optional[int], dtype: np.dtype, finite: bool = True
                  ) -> np.ndarray:
    if value is None:
        return np.zeros((k or 1, 3), dtype)
    t = _a.rows(name, value, 3, dtype, finite=finite)
    if k is not None and len(t) != k:
        raise ValueError(f"{name}: {len(t)} rows, expected {k}")
    return t


def _margins(value: Any, k: int, dtype: np.dtype) -> np.ndarray:
    m = _a.column("margin", value, k, dtype)
    if not (np.isfinite(m) & (m >= 0)).all():
        raise ValueError(f"margin: must be finite and >= 0, not {value}")
    return m


def _one_rotation(value: Any) -> Any:
    """A single rotation argument must be (3, 3) (or None)."""
    if value is None:
        return None
    a = value if isinstance(value, np.ndarray) else np.asarray(value)
    if a.shape != (3, 3):
        raise ValueError(f"rotation: shape must be (3, 3), not {a.shape}")
    return a


def _one_translation(value: Any) -> Any:
    if value is None:
        return None
    a = value if isinstance(value, np.ndarray) else np.asarray(value)
    if a.shape != (3,):
        raise ValueError(f"translation: shape must be (3,), not {a.shape}")
    return a
