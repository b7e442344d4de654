"""The collision, face contact, configuration and distance calls of bvhkit.Scene (a base class of
it, kept apart so that each file holds one concern): thin layers over scene/collision.hpp,
scene/face_contacts.hpp, scene/configurations.hpp and scene/distance.hpp, with the arguments
checked and named here and the work done without the GIL in python/src/instanced_scene_pairs.hpp.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from ._scene_args import (
    _I64,
    _U32,
    SceneDistances,
    SceneFaceContacts,
    _ids,
    _index,
    _one_rotation,
    _one_translation,
    _rotations,
    _translations,
)

if TYPE_CHECKING:
    from ._instances import Scene


class ScenePairs:
    """Collision and distance over pairs of instances (see :class:`bvhkit.Scene`)."""

    _impl: Any
    dtype: np.dtype

    # ------------------------------------------------------------------ collision

    @staticmethod
    def _ignore(ignore: Any) -> np.ndarray:
        if ignore is None:
            return np.empty((0, 2), np.int64)
        a = ignore if isinstance(ignore, np.ndarray) else np.asarray(ignore)
        if a.dtype.kind not in "iu" or a.dtype == np.bool_:
            raise TypeError(f"ignore: dtype must be an integer type, not {a.dtype}")
        if a.size == 0:
            return np.empty((0, 2), np.int64)
        if a.ndim == 1 and a.shape[0] == 2:
            a = a.reshape(1, 2)
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(f"ignore: shape must be (p, 2), not {a.shape}")
        if int(a.min()) < 0 or int(a.max()) > _I64:
            raise ValueError("ignore: every id must be one add_instance returned")
        return np.ascontiguousarray(a, dtype=np.int64)

    def colliding_pairs(self, ignore: Optional[npt.ArrayLike] = None) -> np.ndarray:
        """Every pair of instances that collide (the group/mask filter lets them, and their
        meshes touch or come within the sum of their margins): (p, 2) int64 ids, each row's
        first the lower slot, sorted. ``ignore``: (q, 2) pairs of ids to leave out (either
        order; every id live, else ValueError)."""
        return self._impl.colliding_pairs(self._ignore(ignore))

    def any_collision(self, ignore: Optional[npt.ArrayLike] = None) -> bool:
        """Whether any pair collides (stops at the first)."""
        return bool(self._impl.any_collision(self._ignore(ignore)))

    def colliding_instances(
        self,
        geometry: int,
        rotation: Optional[npt.ArrayLike] = None,
        translation: Optional[npt.ArrayLike] = None,
        *,
        group: int = 1,
        mask: int = 0xFFFFFFFF,
        margin: float = 0.0,
    ) -> np.ndarray:
        """The instances that mesh ``geometry`` placed at (rotation, translation) would collide
        with, as an instance with that group, mask and margin would: (n,) int64 ids by slot.
        The scene is not changed (a gripper's candidate pose against the cell)."""
        return self._one_against(geometry, rotation, translation, group, mask, margin, False)

    def collides_with(
        self,
        geometry: int,
        rotation: Optional[npt.ArrayLike] = None,
        translation: Optional[npt.ArrayLike] = None,
        *,
        group: int = 1,
        mask: int = 0xFFFFFFFF,
        margin: float = 0.0,
    ) -> bool:
        """Whether :meth:`colliding_instances` would find any (stops at the first)."""
        found = self._one_against(geometry, rotation, translation, group, mask, margin, True)
        return len(found) > 0

    def _one_against(self, geometry: Any, rotation: Any, translation: Any, group: Any,
                     mask: Any, margin: Any, first: bool) -> np.ndarray:
        posed = self._posed(geometry, rotation, translation, group, mask, margin)
        return self._impl.colliding_instances(*posed, first)

    def _posed(self, geometry: Any, rotation: Any, translation: Any, group: Any, mask: Any,
               margin: Any) -> tuple:
        """One more posed mesh of the scene's, its arguments checked and named: (geometry,
        rotation (1, 3, 3), translation (1, 3), group, mask, margin)."""
        g = _index("geometry", geometry, _I64)
        r = _rotations("rotation", _one_rotation(rotation), 1, self.dtype)
        t = _translations("translation", _one_translation(translation), 1, self.dtype)
        gr = _index("group", group, _U32)
        ma = _index("mask", mask, _U32)
        m = _a.number("margin", margin)
        if not 0 <= m < math.inf:
            raise ValueError(f"margin: must be finite and >= 0, not {margin}")
        return g, r, t, gr, ma, m

    def _other(self, other: Any) -> Any:
        if not isinstance(other, ScenePairs):  # bvhkit.Scene is the one class built on this
            raise TypeError(f"other: must be a bvhkit.Scene, not {type(other).__name__}")
        if other.dtype != self.dtype:
            raise TypeError(f"other: dtype {other.dtype} is not this scene's {self.dtype}")
        return other._impl

    def colliding_pairs_with(self, other: "Scene", ignore: Optional[npt.ArrayLike] = None
                             ) -> np.ndarray:
        """Every pair (a of this scene, b of ``other``) that collides, by the rule of
        :meth:`colliding_pairs`: (p, 2) int64 ids, sorted by a's slot then b's. ``other``: a
        Scene of the same dtype (this scene itself compares every instance with every one,
        itself included). ``ignore``: (q, 2) rows (id of this scene, id of other)."""
        o = self._other(other)
        return self._impl.colliding_pairs_with(o, self._ignore(ignore))

    def any_collision_with(self, other: "Scene", ignore: Optional[npt.ArrayLike] = None) -> bool:
        """Whether any pair (a of this scene, b of ``other``) collides (stops at the first)."""
        o = self._other(other)
        return bool(self._impl.any_collision_with(o, self._ignore(ignore)))

    def colliding_faces(self, ignore: Optional[npt.ArrayLike] = None) -> SceneFaceContacts:
        """Where the colliding pairs of :meth:`colliding_pairs` touch: for each pair, every
        pair of its triangles that cross, with the world-space segment where they do
        (:class:`SceneFaceContacts`); a pair that collides only through its margins gives one
        entry, its closest triangles and points, marked ``separated``."""
        return self._faces(self._impl.colliding_faces(self._ignore(ignore)))

    def colliding_faces_with(self, other: "Scene", ignore: Optional[npt.ArrayLike] = None
                             ) -> SceneFaceContacts:
        """:meth:`colliding_faces` for the pairs of :meth:`colliding_pairs_with`."""
        o = self._other(other)
        return self._faces(self._impl.colliding_faces_with(o, self._ignore(ignore)))

    @staticmethod
    def _faces(raw: tuple) -> SceneFaceContacts:
        pairs, faces, p, q, coplanar, separated = raw
        return SceneFaceContacts(pairs, faces, p, q, coplanar.view(np.bool_),
                                 separated.view(np.bool_))

    # ------------------------------------------------------------------ configurations

    def _configurations(self, ids: Any, rotations: Any, translations: Any
                        ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, Optional[int]]:
        """ids (n,), and the poses as (K * n, 3, 3) and (K * n, 3) rows with K (None for one
        configuration given as (n, 3, 3) and (n, 3))."""
        i = _ids("ids", ids, live_checked=True)
        n = len(i)
        r = None if rotations is None else np.asarray(rotations)
        t = None if translations is None else np.asarray(translations)
        k: Optional[int] = None
        if r is not None and r.ndim == 4:
            k = r.shape[0]
        elif t is not None and t.ndim == 3:
            k = t.shape[0]
        if k is not None:
            for name, a, tail in (("rotations", r, (3, 3)), ("translations", t, (3,))):
                if a is not None and a.shape[:2] != (k, n):
                    raise ValueError(f"{name}: shape must be ({k}, {n}) + {tail} for {k} "
                                     f"configurations of {n} instances, not {a.shape}")
            r = None if r is None else r.reshape((k * n, 3, 3))
            t = None if t is None else t.reshape((k * n, 3))
        rows = n * (1 if k is None else k)
        return (i, _rotations("rotations", r, rows, self.dtype, values=False),
                _translations("translations", t, rows, self.dtype, finite=False), k)

    def colliding_pairs_at(self, ids: npt.ArrayLike, rotations: Optional[npt.ArrayLike],
                           translations: Optional[npt.ArrayLike],
                           ignore: Optional[npt.ArrayLike] = None) -> np.ndarray:
        """The colliding pairs with one of instances ``ids`` (n,) placed at ``rotations``
        (n, 3, 3) and ``translations`` (n, 3) (None: identities, zeros), every other instance
        where it is, without changing the scene: the pairs :meth:`colliding_pairs` would give
        among those with a moved instance after ``set_poses(ids, rotations, translations)``.
        (p, 2) int64 ids, sorted. Pairs of two unmoved instances are not looked at."""
        i, r, t, k = self._configurations(ids, rotations, translations)
        if k is not None:
            raise ValueError("rotations: one configuration, (n, 3, 3), for colliding_pairs_at")
        return self._impl.colliding_pairs_at(i, r, t, self._ignore(ignore))

    def any_collision_at(self, ids: npt.ArrayLike, rotations: Optional[npt.ArrayLike],
                         translations: Optional[npt.ArrayLike],
                         ignore: Optional[npt.ArrayLike] = None, threads: int = 0
                         ) -> Union[bool, np.ndarray]:
        """Whether any pair with a moved instance collides, as :meth:`colliding_pairs_at`, the
        scene unchanged. One configuration (``rotations`` (n, 3, 3), ``translations`` (n, 3)):
        a bool. Many (``rotations`` (K, n, 3, 3), ``translations`` (K, n, 3)): (K,) bool, the
        configurations spread over ``threads`` threads (0 = every core) without the GIL, each
        answer the same for any count. A stale or repeated id, or a bad pose, raises ValueError
        naming the lowest bad configuration, and no answer is returned."""
        i, r, t, k = self._configurations(ids, rotations, translations)
        n = _a.threads(threads)
        if len(i) == 0:  # nothing moved: no pair to test
            return np.zeros(k, np.bool_) if k is not None else False
        out = self._impl.any_collisions_at(i, r, t, self._ignore(ignore), n if k else 1)
        return out.view(np.bool_) if k is not None else bool(out[0]) if len(out) else False

    # ------------------------------------------------------------------ distance

    def closest_pair(self, ignore: Optional[npt.ArrayLike] = None) -> SceneDistances:
        """The closest pair of instances that may collide (the group/mask filter, not in
        ``ignore``): :class:`SceneDistances` with one entry, or none when no pair has triangles.
        The distance is the meshes' less both margins; the points lie on the meshes. Of pairs at
        the same distance, the lowest slots win."""
        return SceneDistances(*self._impl.closest_pair(self._ignore(ignore)))

    def closest_pair_with(self, other: "Scene", ignore: Optional[npt.ArrayLike] = None
                          ) -> SceneDistances:
        """The closest pair (a of this scene, b of ``other``) that may collide, as
        :meth:`closest_pair` gives within one scene: one entry or none. ``ignore``: (q, 2) rows
        (id of this scene, id of other)."""
        o = self._other(other)
        return SceneDistances(*self._impl.closest_pair_with(o, self._ignore(ignore)))

    def pairs_within(self, threshold: float, ignore: Optional[npt.ArrayLike] = None
                     ) -> SceneDistances:
        """Every pair that may collide whose distance (less both margins) is at most
        ``threshold``, sorted by slots: :class:`SceneDistances`."""
        t = _a.number("threshold", threshold)
        if math.isnan(t):
            raise ValueError("threshold: must not be NaN")
        return SceneDistances(*self._impl.pairs_within(t, self._ignore(ignore)))

    def pairs_within_with(self, other: "Scene", threshold: float,
                          ignore: Optional[npt.ArrayLike] = None) -> SceneDistances:
        """Every pair (a of this scene, b of ``other``) that may collide whose distance (less
        both margins) is at most ``threshold``, sorted by a's slot then b's. ``ignore``: (q, 2)
        rows (id of this scene, id of other)."""
        o = self._other(other)
        t = _a.number("threshold", threshold)
        if math.isnan(t):
            raise ValueError("threshold: must not be NaN")
        return SceneDistances(*self._impl.pairs_within_with(o, t, self._ignore(ignore)))

    def closest_instance(
        self,
        geometry: int,
        rotation: Optional[npt.ArrayLike] = None,
        translation: Optional[npt.ArrayLike] = None,
        *,
        group: int = 1,
        mask: int = 0xFFFFFFFF,
        margin: float = 0.0,
    ) -> SceneDistances:
        """The instance nearest to mesh ``geometry`` placed at (rotation, translation), with
        the filter and margin an instance with that group, mask and margin would have:
        :class:`SceneDistances` with one entry (pairs[0] = (-1, id); point_a on the posed mesh)
        or none."""
        posed = self._posed(geometry, rotation, translation, group, mask, margin)
        return SceneDistances(*self._impl.closest_instance(*posed))
