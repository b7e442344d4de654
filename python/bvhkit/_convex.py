"""Convex shapes (Sphere, Box, Capsule, Cylinder, Cone, ConvexHull) and the distance (GJK) and
signed distance (GJK, then EPA) between two of them over a batch of poses: the C++ library's
convex/ headers (docs/api/convex.md), in float64."""

from __future__ import annotations

import math
from typing import Any, NamedTuple, Optional, Tuple

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from . import _bvhkit
from ._collision import _pose_arrays

_F64 = np.dtype(np.float64)


def _size(name: str, value: Any) -> float:
    """A shape parameter: a finite number >= 0 (zero is allowed: a sphere of radius 0 is a
    point)."""
    x = _a.number(name, value)
    if not 0 <= x < math.inf:
        raise ValueError(f"{name}: must be a finite number >= 0, not {value!r}")
    return x


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


class ConvexShape:
    """A convex shape in its own local frame (float64), for :func:`convex_distance` and
    :func:`convex_signed_distance`. Made as one of :class:`Sphere`, :class:`Box`,
    :class:`Capsule`, :class:`Cylinder`, :class:`Cone` or :class:`ConvexHull`; immutable, so one
    shape may serve any number of queries and threads at once. Each pickles as its constructor's
    arguments."""

    # The parameters live in _args (what pickling passes to the constructor) and are read through
    # properties: a shape that could be changed would no longer match its C++ object.
    __slots__ = ("_impl", "_args")
    _impl: Any
    _args: tuple

    def __init__(self) -> None:
        raise TypeError("ConvexShape: make a Sphere, Box, Capsule, Cylinder, Cone or ConvexHull")

    @property
    def bounding_radius(self) -> float:
        """The largest distance of a point of the shape from its local origin."""
        return float(self._impl.bounding_radius)

    def __reduce__(self) -> tuple:
        return (type(self), self._args)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(map(repr, self._args))})"


class Sphere(ConvexShape):
    """The ball of ``radius`` about the local origin."""

    __slots__ = ()

    def __init__(self, radius: float) -> None:
        self._args = (_size("radius", radius),)
        self._impl = _bvhkit.Convex.sphere(*self._args)

    @property
    def radius(self) -> float:
        return self._args[0]


class Box(ConvexShape):
    """The box ``[-h, h]`` on each local axis, ``h = half_extents`` (3 numbers)."""

    __slots__ = ()

    def __init__(self, half_extents: npt.ArrayLike) -> None:
        h = _a._as_array("half_extents", half_extents)
        if h.dtype.kind not in "fiu":
            kind = _a._kind(half_extents, h)
            raise TypeError(f"half_extents: must be 3 real numbers, not {kind}")
        if h.shape != (3,):
            raise ValueError(f"half_extents: shape must be (3,), not {h.shape}")
        h = h.astype(_F64)
        if not ((h >= 0) & (h < math.inf)).all():
            raise ValueError(f"half_extents: must be finite and >= 0, not {h.tolist()}")
        self._args = ((float(h[0]), float(h[1]), float(h[2])),)
        self._impl = _bvhkit.Convex.box(*self._args[0])

    @property
    def half_extents(self) -> Tuple[float, float, float]:
        return self._args[0]


class Capsule(ConvexShape):
    """The points within ``radius`` of the segment from ``(0, 0, -half_length)`` to
    ``(0, 0, half_length)``."""

    __slots__ = ()

    def __init__(self, radius: float, half_length: float) -> None:
        self._args = (_size("radius", radius), _size("half_length", half_length))
        self._impl = _bvhkit.Convex.capsule(*self._args)

    @property
    def radius(self) -> float:
        return self._args[0]

    @property
    def half_length(self) -> float:
        return self._args[1]


class Cylinder(ConvexShape):
    """The solid cylinder of ``radius`` about local z, ``z`` in ``[-half_height, half_height]``."""

    __slots__ = ()

    def __init__(self, radius: float, half_height: float) -> None:
        self._args = (_size("radius", radius), _size("half_height", half_height))
        self._impl = _bvhkit.Convex.cylinder(*self._args)

    @property
    def radius(self) -> float:
        return self._args[0]

    @property
    def half_height(self) -> float:
        return self._args[1]


class Cone(ConvexShape):
    """The solid cone about local z: base disc of ``radius`` at ``z = -height / 2``, apex at
    ``(0, 0, height / 2)`` (the origin is the middle of its axis)."""

    __slots__ = ()

    def __init__(self, radius: float, height: float) -> None:
        self._args = (_size("radius", radius), _size("height", height))
        self._impl = _bvhkit.Convex.cone(*self._args)

    @property
    def radius(self) -> float:
        return self._args[0]

    @property
    def height(self) -> float:
        return self._args[1]


class ConvexHull(ConvexShape):
    """The convex hull of ``points``: (n, 3), n >= 1, all finite (converted to float64). Interior
    and repeated points are dropped; fewer than 4 non-coplanar points give a flat polygon, a
    segment or a point, each a valid convex shape. It keeps the hull's vertices alone
    (:attr:`vertices`) and pickles as them."""

    __slots__ = ()

    def __init__(self, points: npt.ArrayLike) -> None:
        p = _a.rows("points", points, 3, _F64, finite=True)
        if len(p) == 0:
            raise ValueError("points: a hull needs at least one point, not (0, 3)")
        self._impl = _bvhkit.Convex.hull(p)
        self._args = (_read_only(self._impl.vertices()),)

    @property
    def vertices(self) -> np.ndarray:
        """(m, 3) float64: the hull's vertices, read only."""
        return self._args[0]

    def __repr__(self) -> str:
        return f"ConvexHull(<{len(self.vertices)} vertices>)"


class ConvexDistances(NamedTuple):
    """What :func:`convex_distance` returns, one entry per pose, all in a's frame (float64)."""

    distance: np.ndarray
    """(k,) the distance; 0 where the shapes meet (touching counts)."""
    point_a: np.ndarray
    """(k, 3) the closest point on a; where they meet, a point common to both."""
    point_b: np.ndarray
    """(k, 3) the closest point on b (``point_b - point_a = distance * normal``)."""
    normal: np.ndarray
    """(k, 3) unit, from a towards b; zero where the shapes meet."""


class ConvexSignedDistances(NamedTuple):
    """What :func:`convex_signed_distance` returns, one entry per pose, all in a's frame."""

    signed_distance: np.ndarray
    """(k,) the distance when apart, minus the penetration depth when overlapping."""
    point_a: np.ndarray
    """(k, 3) the closest point on a; overlapping, the deepest point of a (on its boundary)."""
    point_b: np.ndarray
    """(k, 3) the same on b: ``point_b - point_a = signed_distance * normal`` (to rounding)."""
    normal: np.ndarray
    """(k, 3) unit, from a towards b: b moved by ``-signed_distance`` along it separates."""
    converged: np.ndarray
    """(k,) bool: False where EPA stopped at its capacity before its bounds met (the depth is then
    the least upper bound found, still a separating move)."""


def _shapes(a: Any, b: Any) -> None:
    if not isinstance(a, ConvexShape):
        raise TypeError(f"a: must be a ConvexShape (Sphere, Box, ...), not {type(a).__name__}")
    if not isinstance(b, ConvexShape):
        raise TypeError(f"b: must be a ConvexShape (Sphere, Box, ...), not {type(b).__name__}")


def _threads(threads: Any) -> int:
    if type(threads) is int and 0 <= threads <= _a.THREADS_MAX:
        return threads
    return _a.threads(threads)


def convex_distance(
    a: ConvexShape,
    b: ConvexShape,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    threads: int = 0,
) -> ConvexDistances:
    """The distance between ``a`` and ``b`` placed at each pose, with the closest points and the
    direction from a to b (GJK).

    A pose maps a point x of b to ``rotations[i] @ x + translations[i]`` in a's frame, as in
    :func:`collide`: ``rotations`` (k, 3, 3) (or None for the identity), ``translations`` (k, 3);
    one pose may be (3, 3) and (3,) (the answers are then (1,) and (1, 3) arrays). Each pose is
    checked: finite, rotations rigid to 1e-4. Poses are spread over ``threads`` threads (0 = every
    core); the answers are the same for every thread count.
    """
    _shapes(a, b)
    r, t, k = _pose_arrays(rotations, translations, _F64)
    n = _threads(threads)
    d = np.empty(k, _F64)
    pa = np.empty((k, 3), _F64)
    pb = np.empty((k, 3), _F64)
    normal = np.empty((k, 3), _F64)
    _bvhkit.convex_distance(a._impl, b._impl, r, t, d, pa, pb, normal, n)
    return ConvexDistances(d, pa, pb, normal)


def convex_signed_distance(
    a: ConvexShape,
    b: ConvexShape,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    threads: int = 0,
) -> ConvexSignedDistances:
    """The signed distance between ``a`` and ``b`` placed at each pose (poses as in
    :func:`convex_distance`): the distance when apart, minus the penetration depth (the length of
    the shortest translation of b that separates them) when they overlap, with the closest or
    deepest points and the normal (GJK, then EPA).

    Moving b by ``-signed_distance`` (slightly more) along ``normal`` separates the shapes.
    """
    _shapes(a, b)
    r, t, k = _pose_arrays(rotations, translations, _F64)
    n = _threads(threads)
    d = np.empty(k, _F64)
    pa = np.empty((k, 3), _F64)
    pb = np.empty((k, 3), _F64)
    normal = np.empty((k, 3), _F64)
    converged = np.empty(k, np.bool_)
    _bvhkit.convex_signed_distance(a._impl, b._impl, r, t, d, pa, pb, normal, converged, n)
    return ConvexSignedDistances(d, pa, pb, normal, converged)


class ConvexMeshDistances(NamedTuple):
    """What :func:`convex_mesh_distance` returns, one entry per pose, in the mesh's frame."""

    distance: np.ndarray
    """(k,) the distance between the shape and the mesh's triangles; 0 where they meet; inf for
    a mesh without triangles."""
    overlap: np.ndarray
    """(k,) bool: the shape meets the mesh (touching counts)."""
    point_shape: np.ndarray
    """(k, 3) the closest point on the shape; where they meet, a point of the contact (NaN for a
    mesh without triangles)."""
    point_mesh: np.ndarray
    """(k, 3) the closest point on the mesh (``point_mesh - point_shape`` has length
    ``distance``)."""
    face: np.ndarray
    """(k,) int64 the mesh's face that point_mesh lies on (-1 for a mesh without triangles)."""


def _shape_and_mesh(shape: Any, mesh: Any) -> None:
    from ._collision import CollisionModel

    if not isinstance(shape, ConvexShape):
        raise TypeError(
            f"shape: must be a ConvexShape (Sphere, Box, ...), not {type(shape).__name__}")
    if not isinstance(mesh, CollisionModel):
        raise TypeError(f"mesh: must be a CollisionModel, not {type(mesh).__name__}")
    if mesh.dtype != _F64:
        raise TypeError(f"mesh: must be a float64 CollisionModel (the shapes are float64), not "
                        f"{mesh.dtype}")


def convex_mesh_distance(
    shape: ConvexShape,
    mesh: Any,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    threads: int = 0,
) -> ConvexMeshDistances:
    """The distance between ``shape`` placed at each pose and the triangles of ``mesh`` (a float64
    :class:`CollisionModel` of any volume), with the closest points and the mesh's face: the
    mesh's tree walked best first, GJK between the shape and each triangle reached (spheres and
    capsules exact to rounding). A pose maps a point x of the shape to ``rotations[i] @ x +
    translations[i]`` in the mesh's frame (as in :func:`collide`; one pose may be (3, 3) and
    (3,)); poses are spread over ``threads`` threads (0 = every core)."""
    _shape_and_mesh(shape, mesh)
    r, t, k = _pose_arrays(rotations, translations, _F64)
    n = _threads(threads)
    d = np.empty(k, _F64)
    overlap = np.empty(k, np.bool_)
    ps = np.empty((k, 3), _F64)
    pm = np.empty((k, 3), _F64)
    face = np.empty(k, np.int64)
    _bvhkit.convex_mesh(mesh._impl, shape._impl, r, t, d, overlap, ps, pm, face, False, n)
    return ConvexMeshDistances(d, overlap, ps, pm, face)


def convex_mesh_collides(
    shape: ConvexShape,
    mesh: Any,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    threads: int = 0,
) -> np.ndarray:
    """Whether ``shape`` placed at each pose meets the triangles of ``mesh`` (poses as in
    :func:`convex_mesh_distance`): (k,) bool, each pose stopping at the first triangle met."""
    _shape_and_mesh(shape, mesh)
    r, t, k = _pose_arrays(rotations, translations, _F64)
    n = _threads(threads)
    overlap = np.empty(k, np.bool_)
    empty = np.empty((0,), _F64)
    _bvhkit.convex_mesh(mesh._impl, shape._impl, r, t, empty, overlap, empty.reshape(0, 3),
                        empty.reshape(0, 3), np.empty(0, np.int64), True, n)
    return overlap
