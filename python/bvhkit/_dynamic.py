"""The dynamic AABB tree in 2D and 3D, changed and asked in batches."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from . import _bvhkit


def _ids(value: Any) -> np.ndarray:
    a = np.asarray(value)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.dtype.kind not in "iu" or a.dtype == np.bool_:
        raise TypeError(f"ids: dtype must be an integer type, not {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"ids: shape must be (k,), not {a.shape}")
    if a.size and (a.min() < 0 or a.max() > np.iinfo(np.int64).max):
        raise ValueError("ids: every id must be one create() returned (0 <= id < 2^63)")
    return np.ascontiguousarray(a, dtype=np.int64)


class _DynamicTree:
    _dim = 3

    def __init__(
        self,
        margin: float = 0.1,
        margin_relative: float = 0.0,
        displacement_multiplier: float = 4.0,
        dtype: npt.DTypeLike = np.float32,
    ) -> None:
        self.dtype: np.dtype = _a.scalar_type(dtype)
        for name, value in (("margin", margin), ("margin_relative", margin_relative),
                            ("displacement_multiplier", displacement_multiplier)):
            x = _a.number(name, value)
            if not 0 <= x < _a.INF:
                raise ValueError(f"{name}: must be a finite number >= 0, not {value}")
        suffix = "f32" if self.dtype == np.float32 else "f64"
        cls = getattr(_bvhkit, f"Tree{self._dim}_{suffix}")
        self._impl = cls(float(margin), float(margin_relative), float(displacement_multiplier))

    def _boxes(self, lo: Any, hi: Any, lo_name: str = "lo", hi_name: str = "hi"):
        lo_ = _a.rows(lo_name, lo, self._dim, self.dtype, finite=True)
        hi_ = _a.rows(hi_name, hi, self._dim, self.dtype, finite=True)
        if len(lo_) != len(hi_):
            raise ValueError(f"{hi_name}: {len(hi_)} rows, {lo_name} has {len(lo_)}")
        bad = np.flatnonzero((lo_ > hi_).any(axis=1))
        if len(bad):
            raise ValueError(f"{lo_name}: row {int(bad[0])} has min > max on some axis")
        return lo_, hi_

    def create(self, lo: npt.ArrayLike, hi: npt.ArrayLike) -> np.ndarray:
        """Adds one proxy per box (``lo``, ``hi``: (k, D) corners) and returns their ids, (k,)
        int64. An id is the proxy's slot plus 2^32 times the slot's generation: a slot freed by
        destroy() is reused with a new generation, so an id kept past its proxy's destroy() is
        never the id of another proxy (passing it is a ValueError)."""
        lo_, hi_ = self._boxes(lo, hi)
        ids = np.empty(len(lo_), np.int64)
        self._impl.create(lo_, hi_, ids)
        return ids

    def move(
        self,
        ids: npt.ArrayLike,
        lo: npt.ArrayLike,
        hi: npt.ArrayLike,
        displacement: Optional[npt.ArrayLike] = None,
    ) -> np.ndarray:
        """Gives the proxies ``ids`` new boxes. ``displacement`` (k, D), optional, is each box's
        predicted motion until its next move (its fat box is stretched along it). Returns (k,)
        bool: whether the tree was restructured for that proxy (its box left its fat box).
        Nothing changes if any id or box is bad."""
        i = _ids(ids)
        lo_, hi_ = self._boxes(lo, hi)
        if len(i) != len(lo_):
            raise ValueError(f"ids: {len(i)} ids for {len(lo_)} boxes")
        if displacement is None:
            disp = np.zeros_like(lo_)
        else:
            disp = _a.rows("displacement", displacement, self._dim, self.dtype, finite=True)
        out = np.empty(len(i), np.bool_)
        self._impl.move(i, lo_, hi_, disp, out)
        return out

    def destroy(self, ids: npt.ArrayLike) -> None:
        """Removes the proxies ``ids`` (each live, none twice; else nothing changes)."""
        self._impl.destroy(_ids(ids))

    def find_pairs(self) -> np.ndarray:
        """The pairs of overlapping boxes that involve a proxy created or moved since the last
        call, each once: (p, 2) int64, rows (a, b) with a < b, sorted."""
        return self._impl.find_pairs()

    def query(self, lo: npt.ArrayLike, hi: npt.ArrayLike, threads: int = 0) -> np.ndarray:
        """Every proxy whose box overlaps each query box (touching counts): (p, 2) int64 rows
        (query index, proxy id), grouped by query in order."""
        lo_, hi_ = self._boxes(lo, hi)
        return self._impl.query(lo_, hi_, _a.threads(threads))

    def ray_cast(
        self,
        origins: npt.ArrayLike,
        directions: npt.ArrayLike,
        max_fraction: npt.ArrayLike = 1.0,
        threads: int = 0,
    ) -> np.ndarray:
        """Every proxy whose box the segment ``origin + s * direction``, s in [0, max_fraction],
        crosses: (p, 2) int64 rows (ray index, proxy id), grouped by ray in order."""
        o = _a.rows("origins", origins, self._dim, self.dtype, finite=True)
        d = _a.rows("directions", directions, self._dim, self.dtype, finite=True)
        if len(d) != len(o):
            raise ValueError(f"directions: {len(d)} rows, origins has {len(o)}")
        f = _a.column("max_fraction", max_fraction, len(o), self.dtype)
        if not (np.isfinite(f).all() and (f >= 0).all()):
            raise ValueError("max_fraction: must be finite and >= 0")
        return self._impl.ray_cast(o, d, f, _a.threads(threads))

    def boxes(self, ids: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The tight boxes of the proxies ``ids``: (lo, hi), each (k, D)."""
        return self._impl.boxes(_ids(ids))

    def stats(self) -> dict:
        """proxies, height, sah_cost, area_ratio and memory_bytes."""
        return dict(self._impl.stats())

    def validate(self) -> None:
        """Checks every invariant of the tree; raises ValueError naming the first one broken."""
        self._impl.validate()

    def rebuild(self) -> None:
        """Rebuilds the tree top-down with binned SAH (after many moves, for query speed)."""
        self._impl.rebuild()

    def __len__(self) -> int:
        """Number of live proxies."""
        return len(self._impl)

    def __repr__(self) -> str:
        """Class, proxy count and dtype."""
        return f"{type(self).__name__}(proxies={len(self)}, dtype={self.dtype})"


class DynamicTree2D(_DynamicTree):
    """A dynamic AABB tree of 2D boxes (fat boxes with ``margin``, SAH insertion with rotations):
    create, move and destroy proxies in batches, then find overlapping pairs, query boxes and
    cast rays. ``dtype``: float32 (default) or float64."""

    _dim = 2


class DynamicTree3D(_DynamicTree):
    """A dynamic AABB tree of 3D boxes (fat boxes with ``margin``, SAH insertion with rotations):
    create, move and destroy proxies in batches, then find overlapping pairs, query boxes and
    cast rays. ``dtype``: float32 (default) or float64."""

    _dim = 3
