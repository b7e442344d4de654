"""Argument checks shared by the bvhkit package: every argument goes through here once.

An array that already has the wanted dtype and is C-contiguous is passed on as it is (no copy);
anything else is converted once. Scalars (numbers, flags, option names, thread counts) are checked
with isinstance alone, so a call pays no numpy work for them. Errors name the argument: TypeError
for the wrong kind of value (a str where a number belongs, 1 where a bool belongs), ValueError for
a value out of range. The option names' Literal types live here too, and the run-time checks read
their choices from them, so the two cannot drift apart.
"""

from __future__ import annotations

import functools
import math
import numbers
from typing import Any, Literal, Optional, get_args

import numpy as np

# The names a builder= may take: every configuration the C++ library parses
# (bvhkit::parse_builder), spelt with underscores as the Python docs do (hyphens work too).
Builder = Literal[
    "binned_sah", "sweep_sah", "top_down", "bottom_up", "insertion", "lbvh",
    "median_longest", "mean_longest", "spatial_longest",
    "median_variance", "mean_variance", "spatial_variance",
    "binned_sah+opt", "sweep_sah+opt", "top_down+opt", "bottom_up+opt", "insertion+opt",
    "lbvh+opt", "median_longest+opt", "mean_longest+opt", "spatial_longest+opt",
    "median_variance+opt", "mean_variance+opt", "spatial_variance+opt",
]  # fmt: skip
RayTest = Literal["watertight", "fast"]
Sign = Literal["pseudonormal", "winding_number"]
Volume = Literal["obb", "rss", "obbrss", "aabb", "sphere", "kdop18", "hull"]

INF = math.inf
RAY_TESTS: tuple = get_args(RayTest)
SIGNS: tuple = get_args(Sign)
VOLUMES: tuple = get_args(Volume)

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
    if (type(value) is np.ndarray and value.dtype is dtype and value.ndim == 2
            and value.shape[1] == width and value.flags.c_contiguous and not finite):
        return value  # already what the C++ calls take: no numpy work
    a = _as_array(name, value)
    if a.dtype.kind not in "fiu":  # bool's kind is "b"
        raise TypeError(f"{name}: dtype must be a real number type, not {a.dtype}")
    if a.ndim == 1 and a.shape[0] == width:
        a = a.reshape(1, width)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name}: shape must be (k, {width}), not {a.shape}")
    if a.dtype is not dtype or not a.flags.c_contiguous:
        a = a.astype(dtype, order="C")
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


def column(
    name: str, value: Any, count: int, dtype: np.dtype, none: Optional[float] = None
) -> np.ndarray:
    """A number or (count,) array of numbers as a C-contiguous (count,) array of `dtype`. None
    stands for `none` where the argument has a meaning for it (tmax: no limit), else TypeError."""
    if value is None:
        if none is None:
            raise TypeError(f"{name}: must be a number or an array of numbers, not None")
        return np.full(count, none, dtype=dtype)
    if type(value) is float or type(value) is int:
        if count == 1:
            return _one(number(name, value), dtype)
        return np.full(count, number(name, value), dtype=dtype)
    a = _as_array(name, value)
    if a.dtype.kind not in "fiu" or a.dtype == np.bool_:
        raise TypeError(f"{name}: must be a number or an array of numbers, not {_kind(value, a)}")
    if a.ndim == 0:
        return np.full(count, a, dtype=dtype)
    if a.shape != (count,):
        raise ValueError(f"{name}: shape must be () or ({count},), not {a.shape}")
    return np.ascontiguousarray(a, dtype=dtype)


@functools.lru_cache(maxsize=64)
def _one(value: float, dtype: np.dtype) -> np.ndarray:
    """A read-only (1,) array holding `value`: the array a one-ray call's scalar tmin or tmax
    would otherwise allocate anew each call."""
    a = np.full(1, value, dtype=dtype)
    a.flags.writeable = False
    return a


def _kind(value: Any, a: np.ndarray) -> str:
    """How an error names what was given: the type, and the dtype of an array."""
    t = type(value).__name__
    return f"a {t} of {a.dtype}" if isinstance(value, (np.ndarray, list, tuple)) else t


# A thread count travels to C++ as an unsigned 32-bit int; a batch starts at most 1024 threads
# (common.hpp, batch_threads), so the bound only keeps the conversion from failing.
THREADS_MAX = 2**32 - 1


def threads(value: Any) -> int:
    """``threads=``: 0 for every core, else a positive count (at most THREADS_MAX)."""
    if type(value) is not int:
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise TypeError(f"threads: must be an int, not {type(value).__name__}")
        value = int(value)
    if value < 0 or value > THREADS_MAX:
        raise ValueError(
            f"threads: must be in 0..{THREADS_MAX} (0 = every core), not {value}"
        )
    return value


def number(name: str, value: Any) -> float:
    """A real number argument as a Python float: int, float, numpy integers and floats, and 0-d
    real arrays; TypeError naming it for anything else (a str, a bool, None, a list)."""
    t = type(value)
    if t is float:
        return value
    if (
        t is int
        or (isinstance(value, numbers.Real) and not isinstance(value, bool))
        or (isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "fiu")
    ):
        try:
            return float(value)
        except OverflowError:  # an int beyond any float
            raise ValueError(f"{name}: {value} is beyond the range of a float") from None
    raise TypeError(f"{name}: must be a real number, not {type(value).__name__}")


def limit(name: str, value: Any) -> float:
    """A distance limit: a number >= 0 (not NaN), inf or None for no limit."""
    x = math.inf if value is None else number(name, value)
    if not x >= 0:
        raise ValueError(f"{name}: must be >= 0 (inf or None for no limit), not {value}")
    return x


def flag(name: str, value: Any) -> bool:
    """A bool argument: True or False (numpy's bool too), never a truthy stand-in such as "no"."""
    if value is True or value is False:
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    raise TypeError(f"{name}: must be a bool (True or False), not {type(value).__name__}")


def option(name: str, value: Any, choices: tuple) -> str:
    """An option name: a str, one of `choices`."""
    if not isinstance(value, str):
        raise TypeError(
            f"{name}: must be a str, one of {', '.join(map(repr, choices))}; "
            f"not {type(value).__name__}"
        )
    if value not in choices:
        raise ValueError(f"{name}: {value!r} is not one of {', '.join(map(repr, choices))}")
    return value


def text(name: str, value: Any) -> str:
    """A str argument (a builder's name: the C++ parser checks the value)."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: must be a str, not {type(value).__name__}")
    return value


def path(name: str, value: Any) -> Any:
    """A file path: a str, bytes or an os.PathLike giving one."""
    import os

    try:
        return os.fspath(value)
    except TypeError:
        raise TypeError(f"{name}: must be a str or path, not {type(value).__name__}") from None


def rotations(value: Any, dtype: np.dtype, values: bool = True) -> np.ndarray:
    """Rotations: (k, 3, 3) (a single (3, 3) becomes (1, 3, 3)), finite, with max |R^T R - I| and
    |det R - 1| at most 1e-4 for float32 and float64 alike (the C++ check_rigid_pose's rule: a
    rotation read from float32 data serves a float64 model; the pose is used as given).
    ``values=False`` checks the type and shape alone, for a caller whose C++ call checks the
    values as it reads them (collide and distance: python/src/collision.hpp)."""
    a = _as_array("rotations", value)
    if a.dtype.kind not in "fiu" or a.dtype == np.bool_:
        raise TypeError(f"rotations: dtype must be a real number type, not {a.dtype}")
    if a.ndim == 2:
        a = a.reshape((1,) + a.shape)
    if a.ndim != 3 or a.shape[1:] != (3, 3):
        raise ValueError(f"rotations: shape must be (k, 3, 3), not {a.shape}")
    a = np.ascontiguousarray(a, dtype=dtype)
    if not values:
        return a
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
