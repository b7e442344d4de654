"""Argument checks shared by the bvhkit package: every array goes through here once.

An array that already has the wanted dtype and is C-contiguous is passed on as it is (no copy);
anything else is converted once. Errors name the argument.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

FLOAT_TYPES = (np.dtype(np.float32), np.dtype(np.float64))


def scalar_type(dtype: Any) -> np.dtype:
    """The scene scalar type for a ``dtype=`` argument: float32 or float64."""
    try:
        dt = np.dtype(dtype)
    except TypeError as e:
        raise TypeError(f"dtype: {dtype!r} is not a numpy dtype") from e
    if dt not in FLOAT_TYPES:
        raise TypeError(f"dtype: must be float32 or float64, not {dt}")
    return dt


def _as_array(name: str, value: Any) -> np.ndarray:
    if isinstance(value, np.ndarray):
        return value
    try:
        return np.asarray(value)
    except Exception as e:  # ragged lists and the like
        raise TypeError(f"{name}: cannot be read as an array ({e})") from e


def rows(name: str, value: Any, width: int, dtype: np.dtype, finite: bool = False) -> np.ndarray:
    """A C-contiguous (k, width) array of `dtype`; a single row of `width` becomes (1, width)."""
    a = _as_array(name, value)
    if a.dtype.kind not in "fiu" or a.dtype == np.bool_:
        raise TypeError(f"{name}: dtype must be a real number type, not {a.dtype}")
    if a.ndim == 1 and a.shape[0] == width:
        a = a.reshape(1, width)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name}: shape must be (k, {width}), not {a.shape}")
    a = np.ascontiguousarray(a, dtype=dtype)
    if finite and not np.isfinite(a).all():
        bad = int(np.argwhere(~np.isfinite(a))[0][0])
        raise ValueError(f"{name}: row {bad} has a NaN or infinite coordinate")
    return a


def vertices(name: str, value: Any, dtype: np.dtype) -> np.ndarray:
    """Vertices: float32 or float64 (n, 3). Integer input is accepted and converted."""
    return rows(name, value, 3, dtype)


def faces(value: Any, vertex_count: int, name: str = "faces") -> np.ndarray:
    """Faces: int32 or int64 (m, 3), every index in [0, vertex_count)."""
    a = _as_array(name, value)
    if a.dtype.kind not in "iu" or a.dtype == np.bool_:
        raise TypeError(f"{name}: dtype must be an integer type (int32 or int64), not {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: shape must be (m, 3), not {a.shape}")
    if a.dtype not in (np.dtype(np.int32), np.dtype(np.int64)):
        a = a.astype(np.int64)  # uint64 beyond int64's range fails the range check below
    a = np.ascontiguousarray(a)
    if a.size:
        lo, hi = int(a.min()), int(a.max())
        if lo < 0 or hi >= vertex_count:
            bad = lo if lo < 0 else hi
            row = int(np.argwhere(a == bad)[0][0])
            raise ValueError(
                f"{name}: face {row} names vertex {bad}; valid indices are 0..{vertex_count - 1}"
            )
    return a


def column(name: str, value: Any, count: int, dtype: np.dtype) -> np.ndarray:
    """A scalar or (count,) array as a C-contiguous (count,) array of `dtype`."""
    a = _as_array(name, value)
    if a.ndim == 0:
        return np.full(count, a, dtype=dtype)
    if a.shape != (count,):
        raise ValueError(f"{name}: shape must be () or ({count},), not {a.shape}")
    return np.ascontiguousarray(a, dtype=dtype)


def threads(value: Any) -> int:
    """``threads=``: 0 for every core, else a positive count."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"threads: must be an int, not {type(value).__name__}")
    if value < 0:
        raise ValueError(f"threads: must be >= 0 (0 = every core), not {value}")
    return int(value)


def rotations(value: Any, dtype: np.dtype) -> np.ndarray:
    """Rotations: (k, 3, 3) (a single (3, 3) becomes (1, 3, 3)), finite, with max |R^T R - I| and
    |det R - 1| at most 1e-4 for float32 and float64 alike (the C++ check_rigid_pose's rule: a
    rotation read from float32 data serves a float64 model; the pose is used as given)."""
    a = _as_array("rotations", value)
    if a.dtype.kind not in "fiu" or a.dtype == np.bool_:
        raise TypeError(f"rotations: dtype must be a real number type, not {a.dtype}")
    if a.ndim == 2:
        a = a.reshape((1,) + a.shape)
    if a.ndim != 3 or a.shape[1:] != (3, 3):
        raise ValueError(f"rotations: shape must be (k, 3, 3), not {a.shape}")
    a = np.ascontiguousarray(a, dtype=dtype)
    if not np.isfinite(a).all():
        bad = int(np.argwhere(~np.isfinite(a))[0][0])
        raise ValueError(f"rotations: rotation {bad} has a NaN or infinite entry")
    if len(a):
        r = a.astype(np.float64)
        err = np.abs(np.einsum("kji,kjl->kil", r, r) - np.eye(3)).max(axis=(1, 2))
        det = np.linalg.det(r)
        bad = np.flatnonzero(~((err <= 1e-4) & (np.abs(det - 1) <= 1e-4)))
        if len(bad):
            raise ValueError(
                f"rotations: rotation {int(bad[0])} is not a rotation matrix "
                "(R^T R must be the identity and det R = +1, to 1e-4)"
            )
    return a
