"""TriangleMesh.intersect_packets: coherent rays (camera rays in tiles and rows, shadow rays towards
one light) give intersect's answers bit for bit, and the one-ray calls' too; bad arguments are a
ValueError naming the argument."""

import numpy as np
import pytest

import bvhkit
from reference import ray_hits, random_soup

DTYPES = [np.float32, np.float64]


def camera_rays(eye, target, w, h, tiles):
    """Pinhole rays from eye towards target, w x h pixels, in rows or in 8x4 tiles."""
    forward = target - eye
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, [0.1, 1.0, 0.2])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    x, y = np.meshgrid(np.arange(w), np.arange(h))
    if tiles:  # 32 consecutive rays one 8x4 tile
        order = np.lexsort((x.ravel() % 8, y.ravel() % 4, x.ravel() // 8, y.ravel() // 4))
        x, y = x.ravel()[order], y.ravel()[order]
    sx = (2 * (x.ravel() + 0.5) / w - 1) * 0.6
    sy = (1 - 2 * (y.ravel() + 0.5) / h) * 0.45
    d = forward + sx[:, None] * right + sy[:, None] * up
    return np.broadcast_to(eye, d.shape).copy(), d


def scene_and_rays(dtype, offset, scale):
    rng = np.random.default_rng(3)
    v, f = random_soup(rng, 400, scale=scale, offset=offset)
    # Coplanar duplicates: the first 50 faces again (ties at one t, the lower index wins).
    f = np.concatenate([f, f[:50]])
    scene = bvhkit.TriangleMesh(v, f, dtype=dtype)
    eye = np.array([2.5, 1.5, 3.0]) * scale + offset
    target = np.zeros(3) + offset
    rays = [camera_rays(eye, target, 64, 48, tiles) for tiles in (False, True)]
    o = np.concatenate([r[0] for r in rays]).astype(dtype)
    d = np.concatenate([r[1] for r in rays]).astype(dtype)
    return scene, v, f, o, d


def one_ray_walks(scene, o, d, tmin=0.0, tmax=np.inf):
    """intersect() in batches of 5 rays, which never walk as packets (a run needs 8): the one-ray
    walk's answers, the reference the packets must equal."""
    tmin = np.broadcast_to(np.asarray(tmin, o.dtype), len(o))
    parts = [
        scene.intersect(o[i : i + 5], d[i : i + 5], tmin=tmin[i : i + 5], tmax=tmax, threads=1)
        for i in range(0, len(o), 5)
    ]
    return type(parts[0])(*(np.concatenate(column) for column in zip(*parts)))


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("case", [(0.0, 1.0), (1e4, 100.0), (0.0, 1e-6), (0.0, 1e6)])
def test_packets_equal_intersect_and_one_ray_calls(dtype, case):
    offset, scale = case
    scene, v, f, o, d = scene_and_rays(dtype, offset, scale)
    plain = one_ray_walks(scene, o, d)
    assert (plain.face >= 0).sum() > len(o) // 20  # the rays do reach the soup
    for threads in (1, 2):
        for packed in (
            scene.intersect_packets(o, d, threads=threads),
            scene.intersect(o, d, threads=threads),  # Auto: the coherent runs as packets
        ):
            for a, b in zip(packed, plain):
                np.testing.assert_array_equal(a, b)
    # Shadow rays from the hits towards one light, with per-ray limits.
    hit = plain.face >= 0
    p = o[hit] + plain.t[hit, None] * d[hit]
    light = np.array([0.5, 4.0, -1.0]) * scale + offset
    so, sd = p.astype(dtype), (light - p).astype(dtype)
    tmin = np.full(len(so), 1e-4, dtype)
    shadow = scene.intersect_packets(so, sd, tmin=tmin, tmax=1.0)
    for a, b in zip(shadow, one_ray_walks(scene, so, sd, tmin=tmin, tmax=1.0)):
        np.testing.assert_array_equal(a, b)


def test_packets_against_brute_force():
    """The faces intersect_packets reports are the closest by a float64 brute force, away from
    edges, with the lower index among the duplicated faces (the tie rule of every walk)."""
    scene, v, f, o, d = scene_and_rays(np.float32, 0.0, 1.0)
    packed = scene.intersect_packets(o, d)
    v = v.astype(np.float32).astype(np.float64)  # the scene's own vertices, exactly
    t_ref, margin = ray_hits(v, f, o, d)
    clean = ((margin >= 1e-3) | ~np.isfinite(margin)).all(axis=1)
    best = t_ref.min(axis=1)
    assert clean.sum() > len(o) // 2
    np.testing.assert_allclose(packed.t[clean], best[clean], rtol=1e-4)
    hit = clean & np.isfinite(best)
    assert hit.sum() > 100
    # Faces n0 .. n0 + 49 copy faces 0 .. 49: met at the same t, the original (lower) index wins.
    n0 = len(f) - 50
    duplicated = hit & (np.isin(np.argmin(t_ref, axis=1), np.arange(50)) | (packed.face >= n0))
    assert duplicated.sum() > 10
    assert (packed.face[hit] < n0).all()


def test_packets_bad_arguments():
    scene, v, f, o, d = scene_and_rays(np.float32, 0.0, 1.0)
    with pytest.raises(ValueError, match="directions"):
        scene.intersect_packets(o, d[:-1])
    with pytest.raises(ValueError, match="origins"):
        scene.intersect_packets(o[:, :2], d)
    with pytest.raises(ValueError, match="tmax"):
        scene.intersect_packets(o, d, tmax=np.ones(3))
    with pytest.raises((ValueError, TypeError), match="threads"):
        scene.intersect_packets(o, d, threads=-1)
    empty = scene.intersect_packets(np.zeros((0, 3)), np.zeros((0, 3)))
    assert len(empty.t) == 0
