"""bvhkit: bounding volume hierarchies on numpy arrays.

- :func:`load_mesh` reads OBJ, PLY and STL files, or generates a mesh from a spec.
- :class:`TriangleMesh`: rays (closest hit, occlusion, hit counts), closest points, signed distance,
  winding numbers and inside/outside on one triangle mesh.
- :class:`CollisionModel` with :func:`collide`, :func:`contacts`, :func:`distance` and
  :func:`self_intersections`:
  mesh against mesh over batches of rigid poses.
- :class:`Solid` with :func:`signed_distance_between`: the distance, or the penetration depth,
  between two closed meshes over batches of rigid poses.
- :class:`Sphere`, :class:`Box`, :class:`Capsule`, :class:`Cylinder`, :class:`Cone` and
  :class:`ConvexHull` with :func:`convex_distance` (GJK) and :func:`convex_signed_distance` (EPA),
  and against a mesh with :func:`convex_mesh_distance` and :func:`convex_mesh_collides`.
- :class:`DynamicTree2D` and :class:`DynamicTree3D`: a dynamic AABB tree for moving boxes.
- :class:`Scene`: many posed instances of shared meshes, for rays, closest points and collision
  (with :func:`pinhole_rays` for a camera's rays).

Arrays go in and come out as numpy arrays. Inputs that are C-contiguous and of the object's scalar
type are used in place; anything else is converted once. Every batch query releases the GIL and
runs on ``threads`` threads (0 = every core), with the same answers for every thread count.
Objects may be queried from several Python threads at once.
"""

# Everything but the API is imported under a private name (and without `from __future__ import
# annotations`, which would bind `annotations`), so that dir(bvhkit) shows the API alone.
import os as _os
import typing as _typing

import numpy as _np
import numpy.typing as _npt

from . import _arrays as _a
from . import _bvhkit
from . import _scene_file

__version__: str = _bvhkit.version

__all__ = [
    "load_mesh",
    "TriangleMesh",
    "RayHits",
    "ClosestPoints",
    "CollisionModel",
    "collide",
    "contacts",
    "Contacts",
    "distance",
    "Distances",
    "self_intersections",
    "Solid",
    "signed_distance_between",
    "MeshSignedDistances",
    "ConvexShape",
    "Sphere",
    "Box",
    "Capsule",
    "Cylinder",
    "Cone",
    "ConvexHull",
    "convex_distance",
    "ConvexDistances",
    "convex_signed_distance",
    "ConvexSignedDistances",
    "convex_mesh_distance",
    "convex_mesh_collides",
    "ConvexMeshDistances",
    "DynamicTree2D",
    "DynamicTree3D",
    "Scene",
    "SceneHits",
    "SceneIntersections",
    "SceneClosest",
    "SceneDistances",
    "SceneFaceContacts",
    "pinhole_rays",
    "MissingFileError",
]

#: Raised for a file named as input that does not exist: a FileNotFoundError and a ValueError.
MissingFileError = _bvhkit.MissingFileError


def load_mesh(
    path_or_spec: _typing.Union[str, "_os.PathLike[str]"],
) -> tuple[_np.ndarray, _np.ndarray]:
    """Reads a mesh file (.obj, .ply including triangle strips, .stl ascii or binary) or generates
    one from a spec such as ``"sphere:subdiv=4"``, ``"torus"`` or ``"terrain:n=64"``.

    Returns ``(vertices, faces)``: float32 (n, 3) and int64 (m, 3); polygons are split into fans.
    Raises ValueError naming the file and line for a malformed file, or when the argument is
    neither an existing file nor a valid spec.
    """
    p = _a.path("path_or_spec", path_or_spec)
    if not isinstance(p, str):
        raise TypeError(f"path_or_spec: must be a str or path, not {type(path_or_spec).__name__}")
    return _bvhkit.load_mesh(p)


class RayHits(_typing.NamedTuple):
    """What :meth:`TriangleMesh.intersect` returns, one entry per ray."""

    t: _np.ndarray
    """(k,) distance along the ray in units of its direction's length; inf on a miss."""
    face: _np.ndarray
    """(k,) int64 index of the face hit; -1 on a miss."""
    barycentric: _np.ndarray
    """(k, 3) weights of the face's three vertices at the hit point; zeros on a miss."""


class ClosestPoints(_typing.NamedTuple):
    """What :meth:`TriangleMesh.closest_point` returns, one entry per point."""

    distance: _np.ndarray
    """(k,) distance to the mesh; inf where nothing is within max_distance (or the point is not
    finite, or the mesh is empty)."""
    closest: _np.ndarray
    """(k, 3) closest point on the mesh; NaN where there is none."""
    face: _np.ndarray
    """(k,) int64 index of the face the closest point lies on; -1 where there is none."""
    barycentric: _np.ndarray
    """(k, 3) weights of that face's three vertices at the closest point."""


class TriangleMesh:
    """A triangle mesh ready for rays and proximity queries.

    ``vertices``: (n, 3) float32 or float64; ``faces``: (m, 3) int32 or int64 indices into
    ``vertices``. ``dtype`` is the scalar type the scene computes in (float32 by default);
    query arrays are converted to it. ``builder`` picks the tree builder (``"binned_sah"``,
    ``"sweep_sah"``, ``"bottom_up"``, ``"lbvh"``, ``"insertion"``, ...; ``+opt`` adds the
    reinsertion optimizer). ``ray_test`` is ``"watertight"`` (the default; Woop et al. 2013: a ray through a shared edge
    never slips between the two faces) or ``"fast"`` (Moller-Trumbore, which can).
    ``spatial_splits=True`` builds the ray tree with spatial splits (Stich, Friedrich and
    Dietrich 2009; ``builder="binned_sah"`` only): 6-21x the build time (serial), for faster rays
    on meshes of long, thin or very unequal triangles (CAD tessellations, architecture, soups;
    on even scans it buys nothing). The same hits, but that among faces hit at the same t up to
    rounding another may be named; docs/python.md has the figures. ``spatial_splits="auto"``
    builds the default tree and, where its sibling boxes overlap enough for splits to pay
    (rooms, soups; not scans), the split tree instead (``stats()["spatial_splits"]`` says
    which); with another builder than ``"binned_sah"`` it is the default build.

    Faces with a NaN or infinite coordinate at the build are left out of every query (see
    :meth:`skipped`), and stay out after a :meth:`refit`; zero-area faces are never hit by rays.
    The ray tree is built at once; the closest point and winding number structures on first use.
    """

    def __init__(
        self,
        vertices: _npt.ArrayLike,
        faces: _npt.ArrayLike,
        builder: _a.Builder = "binned_sah",
        dtype: _npt.DTypeLike = _np.float32,
        ray_test: _a.RayTest = "watertight",
        threads: int = 0,
        spatial_splits: _typing.Union[bool, _typing.Literal["auto"]] = False,
    ) -> None:
        self.dtype: _np.dtype = _a.scalar_type(dtype)
        _a.text("builder", builder)
        _a.option("ray_test", ray_test, _a.RAY_TESTS)
        if isinstance(spatial_splits, str) and spatial_splits == "auto":
            splits = "auto"
        elif spatial_splits is True or spatial_splits is False or isinstance(spatial_splits,
                                                                             _np.bool_):
            splits = "on" if spatial_splits else "off"
        else:
            raise TypeError("spatial_splits: must be True, False or 'auto', not "
                            f"{spatial_splits!r}")
        n = _a.threads(threads)
        if splits == "on" and builder.replace("-", "_") != "binned_sah":
            raise ValueError(f"spatial_splits: needs builder='binned_sah', not {builder!r}")
        v = _a.vertices("vertices", vertices, self.dtype)
        f = _a.faces(faces, len(v))
        impl = _bvhkit.Scene32 if self.dtype == _np.float32 else _bvhkit.Scene64
        try:
            self._impl = impl(v, f, builder.replace("_", "-"), ray_test, n, splits)
        except ValueError as e:
            if "builder" not in str(e):
                raise
            raise ValueError(f"builder: {e}") from None
        self._vertex_count = len(v)
        self._builder = builder.replace("_", "-")

    # ------------------------------------------------------------------ rays

    def _rays(self, origins: object, directions: object, tmin: object, tmax: object,
              threads: object) -> tuple:
        o = _a.rows("origins", origins, 3, self.dtype)
        d = _a.rows("directions", directions, 3, self.dtype)
        if d.shape[0] != o.shape[0]:
            raise ValueError(f"directions: {d.shape[0]} rows, origins has {o.shape[0]}")
        t0 = _a.column("tmin", tmin, len(o), self.dtype)
        t1 = _a.column("tmax", tmax, len(o), self.dtype, none=_np.inf)
        return o, d, t0, t1, _a.threads(threads)

    def intersect(
        self,
        origins: _npt.ArrayLike,
        directions: _npt.ArrayLike,
        tmin: _npt.ArrayLike = 0.0,
        tmax: _typing.Optional[_npt.ArrayLike] = _np.inf,
        threads: int = 0,
    ) -> RayHits:
        """The closest hit of each ray ``origin + t * direction``, t in [tmin, tmax].

        ``origins`` and ``directions``: (k, 3); ``tmin``/``tmax``: numbers or (k,) arrays
        (``tmax=None``: no limit, as inf).
        Returns :class:`RayHits` ``(t, face, barycentric)``: t = inf and face = -1 on a miss.
        Directions need not be unit length (t is in units of the direction given).
        """
        dtype = self.dtype
        if (
            type(origins) is _np.ndarray and type(directions) is _np.ndarray
            and origins.dtype is dtype and directions.dtype is dtype and origins.ndim == 2
            and origins.shape[1] == 3 and directions.shape == origins.shape
            and type(tmin) is float and type(tmax) is float
            and type(threads) is int and 0 <= threads <= _a.THREADS_MAX
        ):
            # The one-ray call's usual arguments: one [tmin, tmax] for all, no array made for it
            # (the C++ call converts a non-contiguous array as the general path would).
            k = len(origins)
            t = _np.empty(k, dtype)
            face = _np.empty(k, _np.int64)
            bary = _np.empty((k, 3), dtype)
            self._impl.intersect_shared(origins, directions, tmin, tmax, t, face, bary, threads)
            return RayHits(t, face, bary)
        return self._hits(self._impl.intersect, origins, directions, tmin, tmax, threads)

    def intersect_packets(
        self,
        origins: _npt.ArrayLike,
        directions: _npt.ArrayLike,
        tmin: _npt.ArrayLike = 0.0,
        tmax: _typing.Optional[_npt.ArrayLike] = _np.inf,
        threads: int = 0,
    ) -> RayHits:
        """:meth:`intersect` for rays the caller knows to be coherent (camera rays, shadow rays
        towards one light): every 32 consecutive rays walk the tree together as one packet
        (float32 meshes with the watertight test on a CPU with AVX2; elsewhere the rays walk one
        by one, with the same answers).

        The answers are :meth:`intersect`'s, bit for bit; only the speed depends on the order.
        Give camera rays in tiles: 32 consecutive rays an 8x4 block of pixels (or two rows of a
        16x16 tile, or 32 pixels of one row). :meth:`intersect` already walks the runs of 32 rays
        it finds coherent as packets; this call skips that test and walks every run so.
        """
        return self._hits(self._impl.intersect_packets, origins, directions, tmin, tmax, threads)

    def _hits(self, call: object, origins: object, directions: object, tmin: object,
              tmax: object, threads: object) -> RayHits:
        """call(...) of the binding (intersect or intersect_packets) on checked arguments."""
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        k = len(o)
        t = _np.empty(k, self.dtype)
        face = _np.empty(k, _np.int64)
        bary = _np.empty((k, 3), self.dtype)
        call(o, d, t0, t1, t, face, bary, n)
        return RayHits(t, face, bary)

    def occluded(
        self,
        origins: _npt.ArrayLike,
        directions: _npt.ArrayLike,
        tmin: _npt.ArrayLike = 0.0,
        tmax: _typing.Optional[_npt.ArrayLike] = _np.inf,
        threads: int = 0,
    ) -> _np.ndarray:
        """Whether each ray hits any face within [tmin, tmax]: (k,) bool (any-hit, shadow rays)."""
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        out = _np.empty(len(o), _np.bool_)
        self._impl.occluded(o, d, t0, t1, out, n)
        return out

    def count_intersections(
        self,
        origins: _npt.ArrayLike,
        directions: _npt.ArrayLike,
        tmin: _npt.ArrayLike = 0.0,
        tmax: _typing.Optional[_npt.ArrayLike] = _np.inf,
        threads: int = 0,
    ) -> _np.ndarray:
        """How many faces each ray hits within [tmin, tmax]: (k,) int64.

        With the default watertight test a ray through an edge or vertex shared by several faces
        counts each face whose closed triangle it meets; ``ray_test="fast"`` may miss or double
        count there.
        """
        o, d, t0, t1, n = self._rays(origins, directions, tmin, tmax, threads)
        out = _np.empty(len(o), _np.int64)
        self._impl.count_intersections(o, d, t0, t1, out, n)
        return out

    # ------------------------------------------------------------------ proximity

    def _points(self, points: _typing.Any) -> _np.ndarray:
        return _a.rows("points", points, 3, self.dtype)

    def closest_point(
        self,
        points: _npt.ArrayLike,
        max_distance: _typing.Optional[float] = _np.inf,
        threads: int = 0,
    ) -> ClosestPoints:
        """The closest point of the mesh to each point, within ``max_distance``.

        ``points``: (k, 3); ``max_distance``: a number >= 0, inf or None for no limit. Returns
        :class:`ClosestPoints` ``(distance, closest, face, barycentric)``; where no face is within
        max_distance (or the point has a NaN or infinite coordinate): distance = inf, closest =
        NaN, face = -1.
        """
        p = self._points(points)
        md = _a.limit("max_distance", max_distance)
        n = _a.threads(threads)
        k = len(p)
        dist = _np.empty(k, self.dtype)
        closest = _np.empty((k, 3), self.dtype)
        face = _np.empty(k, _np.int64)
        bary = _np.empty((k, 3), self.dtype)
        self._impl.closest_point(p, md, dist, closest, face, bary, n)
        return ClosestPoints(dist, closest, face, bary)

    def signed_distance(
        self, points: _npt.ArrayLike, sign: _a.Sign = "pseudonormal", threads: int = 0
    ) -> _np.ndarray:
        """Distance to the mesh, negative inside: (k,).

        ``sign="pseudonormal"`` takes the sign from the angle-weighted pseudonormal at the
        closest point (Baerentzen and Aanaes 2005): exact for closed, consistently oriented
        meshes. ``sign="winding_number"`` takes it from the generalized winding number
        (inside where it exceeds 1/2; Jacobson et al. 2013): robust for meshes with holes or
        self-intersections. Points with a non-finite coordinate, or an empty mesh, give inf.
        """
        _a.option("sign", sign, _a.SIGNS)
        p = self._points(points)
        n = _a.threads(threads)
        out = _np.empty(len(p), self.dtype)
        self._impl.signed_distance(p, sign, out, n)
        return out

    def winding_number(
        self, points: _npt.ArrayLike, exact: bool = False, beta: float = 2.0, threads: int = 0
    ) -> _np.ndarray:
        """The generalized winding number of the mesh at each point: (k,).

        About 1 inside a closed outward-oriented mesh, 0 outside. ``exact=True`` sums every
        face's solid angle (cost: faces x points); otherwise the tree's dipole approximation
        (Barill et al. 2018) is used, accurate where nodes are more than ``beta`` times their
        radius away.
        """
        p = self._points(points)
        e = _a.flag("exact", exact)
        b = _a.number("beta", beta)
        if not 0 < b < _a.INF:
            raise ValueError(f"beta: must be a positive finite number, not {beta}")
        n = _a.threads(threads)
        out = _np.empty(len(p), self.dtype)
        self._impl.winding_number(p, e, b, out, n)
        return out

    def contains(self, points: _npt.ArrayLike, threads: int = 0) -> _np.ndarray:
        """Whether each point is inside the mesh (winding number above 1/2): (k,) bool.

        Where the mesh is a closed oriented surface (:attr:`is_closed`), the winding number is an
        integer that one ray's signed crossings give exactly (one ray a point); where that ray
        meets an edge or a vertex exactly, grazes a face or starts on the surface, and on other
        meshes (holes, flipped or non-manifold pieces), the fast winding number decides, as
        :meth:`winding_number` with its default ``beta``. Points with a NaN or infinite
        coordinate are outside.
        """
        p = self._points(points)
        n = _a.threads(threads)
        out = _np.empty(len(p), _np.bool_)
        self._impl.contains(p, out, n)
        return out

    @property
    def is_closed(self) -> bool:
        """Whether :meth:`contains` decides by ray crossings: after welding corners at equal
        positions, every edge of the faces in the tree is used as often in one direction as in
        the other (a closed oriented surface: no holes, nothing open), and the ray test is the
        watertight one. Found on first use (one sort of the edges) and after a refit."""
        return bool(self._impl.is_closed())

    # ------------------------------------------------------------------ changes and measures

    def refit(self, vertices: _npt.ArrayLike) -> None:
        """New positions for the same vertices (same faces): the trees are refitted, not rebuilt
        (fast, for deforming meshes; their quality degrades if the motion is large).

        The faces left out at the build (:meth:`skipped`) stay out of every query even where the
        new vertices make them finite; a NaN or infinite coordinate in any other face is a
        ValueError naming ``vertices``, and the scene is left as it was."""
        v = _a.vertices("vertices", vertices, self.dtype)
        if len(v) != self._vertex_count:
            raise ValueError(f"vertices: {len(v)} rows, the mesh has {self._vertex_count}")
        self._impl.refit(v)

    def stats(self) -> dict:
        """Measures of the ray tree: triangles, skipped, nodes, leaves, depth, average leaf size,
        SAH cost, builder, whether it has spatial splits, and its triangle references (the faces
        in the tree, or more where spatial splits cut some)."""
        return dict(self._impl.stats())

    def skipped(self) -> _np.ndarray:
        """Indices (int64) of faces left out for a NaN or infinite coordinate."""
        return self._impl.skipped()

    @property
    def face_count(self) -> int:
        """Number of faces."""
        return int(self._impl.triangle_count)

    def __repr__(self) -> str:
        """Face count and dtype."""
        return f"TriangleMesh(faces={self.face_count}, dtype={self.dtype})"

    # ------------------------------------------------------------------ saving and loading

    def to_bytes(self) -> bytes:
        """The scene as bytes (format: docs/scale-out.md): the mesh (as refitted, if it was) and
        the trees built so far, the proximity ones only if a query has built them. Reading it back
        with :meth:`from_bytes` rebuilds nothing and answers bit for bit as this scene does; a ray
        tree with spatial splits alone has no file format and is built again on reading (the same
        tree on the same kind of machine, unless the scene was refitted: then a new one over the
        refitted mesh)."""
        return _scene_file.encode(self.dtype, self._builder, self._impl.state())

    @classmethod
    def from_bytes(cls, data: _typing.Union[bytes, bytearray, memoryview], threads: int = 0
                   ) -> "TriangleMesh":
        """A scene from :meth:`to_bytes`'s bytes. Everything is checked (a checksum over the whole,
        the sizes, and each tree as the library's loaders check it); damaged or foreign data
        raises ValueError. ``threads`` is for the trees built later, if any."""
        return cls._from_bytes(data, "data", _a.threads(threads))

    def save(self, path: _typing.Union[str, "_os.PathLike[str]"]) -> None:
        """Writes :meth:`to_bytes` to the file ``path``."""
        # Written beside and renamed: a failed write (a full disk) leaves no partial file.
        _bvhkit.write_file(_a.path("path", path), self.to_bytes())

    @classmethod
    def load(cls, path: _typing.Union[str, "_os.PathLike[str]"], threads: int = 0
             ) -> "TriangleMesh":
        """A scene from a file written by :meth:`save` (ValueError naming the file if damaged)."""
        p = _a.path("path", path)
        n = _a.threads(threads)
        data = _bvhkit.read_file(p)  # refuses devices and FIFOs, which may never end
        return cls._from_bytes(data, p, n)

    @classmethod
    def _from_bytes(cls, data: _typing.Any, what: str, threads: int) -> "TriangleMesh":
        self = cls.__new__(cls)
        self._load(data, what, threads)
        return self

    def _load(self, data: _typing.Any, what: str, threads: int) -> None:
        d = _scene_file.decode(data, what)
        impl = _bvhkit.Scene32 if d.dtype == _np.float32 else _bvhkit.Scene64
        try:
            self._impl = impl(
                d.vertices,
                d.faces,
                d.builder,
                threads,
                d.tree,
                d.sdf,
                d.winding,
                d.spatial_splits,
                d.fast,
            )
        except ValueError as e:
            raise ValueError(f"{what}: {e}") from None
        self.dtype = d.dtype
        self._vertex_count = len(d.vertices)
        self._builder = d.builder
        _scene_file.load_count += 1

    def __getstate__(self) -> dict:
        """Pickles through :meth:`to_bytes`: the trees travel built."""
        return {"bvhkit.TriangleMesh": self.to_bytes()}

    def __setstate__(self, state: dict) -> None:
        """Unpickles through :meth:`from_bytes`."""
        if not isinstance(state, dict) or "bvhkit.TriangleMesh" not in state:
            raise ValueError("state: not a pickled bvhkit.TriangleMesh")
        self._load(state["bvhkit.TriangleMesh"], "pickled TriangleMesh", 0)


from ._collision import (  # noqa: E402
    CollisionModel,
    Contacts,
    Distances,
    collide,
    contacts,
    distance,
    self_intersections,
)
from ._convex import (  # noqa: E402
    Box,
    Capsule,
    Cone,
    ConvexDistances,
    ConvexHull,
    ConvexMeshDistances,
    ConvexShape,
    ConvexSignedDistances,
    Cylinder,
    Sphere,
    convex_distance,
    convex_mesh_collides,
    convex_mesh_distance,
    convex_signed_distance,
)
from ._dynamic import DynamicTree2D, DynamicTree3D  # noqa: E402
from ._solid import MeshSignedDistances, Solid, signed_distance_between  # noqa: E402
from ._instances import Scene  # noqa: E402
from ._scene_args import (  # noqa: E402
    SceneClosest,
    SceneDistances,
    SceneFaceContacts,
    SceneHits,
    SceneIntersections,
)
from ._camera import pinhole_rays  # noqa: E402
