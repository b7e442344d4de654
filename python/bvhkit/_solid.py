"""Closed meshes as solids: Solid, signed_distance_between (penetration depth)."""

from __future__ import annotations

from typing import Literal, NamedTuple, Optional

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from . import _bvhkit
from ._collision import _pose_arrays

SOLID_VOLUMES = ("obb", "rss")


class Solid:
    """A closed, outward-oriented triangle mesh as a solid, for :func:`signed_distance_between`.

    ``vertices``: (n, 3) float32 or float64; ``faces``: (m, 3) int32 or int64. The mesh must be
    closed (every edge, after welding equal corners, used as often in each direction) and finite:
    otherwise ValueError. ``volume``: ``"obb"`` (default) or ``"rss"``, the tree used for the exact
    overlap test and the distance. ``dtype``: float32 (default) or float64. Building checks
    closedness and convexity and builds a collision tree, a winding-number tree and the convex
    hull, so build once and query many poses.
    """

    def __init__(
        self,
        vertices: npt.ArrayLike,
        faces: npt.ArrayLike,
        volume: Literal["obb", "rss"] = "obb",
        dtype: npt.DTypeLike = np.float32,
        threads: int = 0,
    ) -> None:
        self.volume: str = _a.option("volume", volume, SOLID_VOLUMES)
        self.dtype: np.dtype = _a.scalar_type(dtype)
        n = _a.threads(threads)
        v = _a.vertices("vertices", vertices, self.dtype)
        f = _a.faces(faces, len(v))
        suffix = "f32" if self.dtype == np.float32 else "f64"
        self._impl_type = getattr(_bvhkit, f"Solid_{self.volume}_{suffix}")
        self._impl = self._impl_type(v, f, n)

    @property
    def convex(self) -> bool:
        """Whether the mesh is convex (then depths against another convex solid are exact)."""
        return bool(self._impl.convex)

    @property
    def face_count(self) -> int:
        """Number of faces."""
        return int(self._impl.triangle_count)

    def __repr__(self) -> str:
        return (f"Solid({self.face_count} faces, volume={self.volume!r}, dtype={self.dtype}, "
                f"convex={self.convex})")


class MeshSignedDistances(NamedTuple):
    """What :func:`signed_distance_between` returns, one entry per pose (all in a's frame)."""

    signed_distance: np.ndarray
    """(k,) the distance when the interiors are disjoint, minus the penetration depth when they
    overlap (faces that only touch count as overlapping, depth about 0)."""
    point_a: np.ndarray
    """(k, 3) apart: the closest point of a; overlapping: where b touches a once moved by
    depth * normal."""
    point_b: np.ndarray
    """(k, 3) apart: the closest point of b; overlapping: the point of b (at the pose) that comes
    to point_a. point_b - point_a = signed_distance * normal."""
    normal: np.ndarray
    """(k, 3) unit: apart, from point_a to point_b; overlapping, the direction b moves by the
    depth to separate."""
    exact: np.ndarray
    """(k,) bool: the distance when apart, or the depth of two convex solids (EPA's tolerance);
    False: a separating translation that is a local optimum over directions (an upper bound)."""
    contained: np.ndarray
    """(k,) bool: overlapping with no faces meeting (one solid inside the other)."""


def signed_distance_between(
    a: Solid,
    b: Solid,
    rotations: Optional[npt.ArrayLike],
    translations: npt.ArrayLike,
    threads: int = 0,
) -> MeshSignedDistances:
    """The signed distance between solids ``a`` and ``b``, b placed at each pose (``rotations``
    (k, 3, 3) or None for the identity, ``translations`` (k, 3), as in :func:`collide`): the
    distance when apart, minus the translational penetration depth (the length of the shortest
    translation of b that leaves the interiors disjoint) when they overlap. Moving b by
    ``-signed_distance * normal`` (times 1 + 1e-6) separates the solids by the exact test; by
    (1 - 1e-3) of it they still overlap. Poses are spread over ``threads`` threads (0 = every
    core), without the GIL.
    """
    if not isinstance(a, Solid):
        raise TypeError(f"a: must be a Solid, not {type(a).__name__}")
    if not isinstance(b, Solid):
        raise TypeError(f"b: must be a Solid, not {type(b).__name__}")
    if a._impl_type is not b._impl_type:
        raise TypeError(
            f"b: a has volume {a.volume!r} and dtype {a.dtype}, b has {b.volume!r} and {b.dtype}; "
            "both solids must have the same volume and dtype"
        )
    n = _a.threads(threads)
    r, t, k = _pose_arrays(rotations, translations, a.dtype)
    d = np.empty(k, a.dtype)
    pa = np.empty((k, 3), a.dtype)
    pb = np.empty((k, 3), a.dtype)
    nn = np.empty((k, 3), a.dtype)
    ex = np.empty(k, np.bool_)
    inside = np.empty(k, np.bool_)
    a._impl.signed_distance(b._impl, r, t, d, pa, pb, nn, ex, inside, n)
    return MeshSignedDistances(d, pa, pb, nn, ex, inside)



