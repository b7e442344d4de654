"""pinhole_rays: a pinhole camera's rays, for Scene.intersect and TriangleMesh.intersect."""

from __future__ import annotations

import math
from typing import Tuple

import numpy as np
import numpy.typing as npt

from . import _arrays as _a
from ._instances import _index


def pinhole_rays(
    width: int,
    height: int,
    fov_deg: float,
    eye: npt.ArrayLike,
    center: npt.ArrayLike,
    up: npt.ArrayLike,
    dtype: npt.DTypeLike = np.float32,
) -> Tuple[np.ndarray, np.ndarray]:
    """The rays of a pinhole camera at ``eye`` looking at ``center``, ``up`` giving the image's
    up direction, ``fov_deg`` the horizontal field of view (0 < fov_deg < 180) and square pixels:
    (origins, directions), each (height * width, 3) of ``dtype``, one ray through each pixel's
    centre, row by row from the top left (``t.reshape(height, width)`` is the depth image). The
    directions are unit length, so t is the distance from the eye."""
    dt = _a.scalar_type(dtype)
    w = _index("width", width, 1 << 16)
    h = _index("height", height, 1 << 16)
    if w == 0 or h == 0:
        raise ValueError(f"{'width' if w == 0 else 'height'}: must be at least 1")
    fov = _a.number("fov_deg", fov_deg)
    if not 0 < fov < 180:
        raise ValueError(f"fov_deg: must be in (0, 180), not {fov_deg}")
    e, c, u = (_a.rows(name, v, 3, np.dtype(np.float64), finite=True)
               for name, v in (("eye", eye), ("center", center), ("up", up)))
    for name, v in (("eye", e), ("center", c), ("up", u)):
        if len(v) != 1:
            raise ValueError(f"{name}: shape must be (3,), not {v.shape}")
    forward = (c - e)[0]
    if not np.linalg.norm(forward) > 0:
        raise ValueError("center: must differ from eye")
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, u[0])
    if not np.linalg.norm(right) > 1e-12 * np.linalg.norm(u[0]):
        raise ValueError("up: must not be parallel to center - eye")
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    focal = 0.5 * w / math.tan(math.radians(fov) / 2)
    x = np.arange(w) + 0.5 - 0.5 * w
    y = 0.5 * h - (np.arange(h) + 0.5)
    d = (focal * forward + x[None, :, None] * right + y[:, None, None] * true_up).reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = np.ascontiguousarray(np.broadcast_to(e[0].astype(dt), d.shape))
    return origins, np.ascontiguousarray(d, dtype=dt)
