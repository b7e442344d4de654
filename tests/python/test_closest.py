"""Closest points against a numpy brute force in float64 (plane projection or best edge)."""

import numpy as np
import pytest

import bvhkit
from reference import point_triangle, random_soup

DTYPES = [np.float32, np.float64]
RTOL = {np.float32: 2e-5, np.float64: 1e-12}


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("case", ["unit", "far", "tiny", "huge"])
def test_closest_point_matches_brute_force(dtype, case):
    rng = np.random.default_rng(7)
    offset, scale = {"unit": (0, 1), "far": (1e5, 1), "tiny": (0, 1e-6), "huge": (0, 1e6)}[case]
    if case == "far" and dtype == np.float32:
        offset = 1e3
    v, f = random_soup(rng, 50, scale=scale, offset=offset)
    # Slivers and a needle, a duplicate and a zero-area face.
    extra = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1e-7, 0], [0, 0, 0], [1e-7, 0, 0], [0, 0, 1],
                      [0.3, 0.3, 0.3], [0.3, 0.3, 0.3], [0.3, 0.3, 0.3]]) * scale + offset
    n = len(v)
    v = np.vstack([v, extra, v[f[0]]])
    f = np.vstack([f, [[n, n + 1, n + 2], [n + 3, n + 4, n + 5], [n + 6, n + 7, n + 8],
                       [n + 9, n + 10, n + 11]]])
    v = v.astype(dtype).astype(np.float64)
    p = (rng.uniform(-2.5, 2.5, (600, 3)) * scale + offset).astype(dtype).astype(np.float64)
    scene = bvhkit.TriangleMesh(v, f, dtype=dtype)
    r = scene.closest_point(p)
    d_ref, _ = point_triangle(p, v, f)
    best = d_ref.min(axis=1)
    # Rounding of the inputs' magnitude bounds the error, not only the distance's.
    atol = (np.abs(v).max()) * RTOL[dtype] * 4
    np.testing.assert_allclose(r.distance, best, rtol=RTOL[dtype] * 4, atol=atol)
    # The face reported is at that distance, the point is on it, the distance is |p - point|.
    np.testing.assert_allclose(d_ref[np.arange(len(p)), r.face], best, rtol=RTOL[dtype] * 4,
                               atol=atol)
    np.testing.assert_allclose(np.linalg.norm(r.closest - p, axis=1), r.distance,
                               rtol=RTOL[dtype] * 4, atol=atol)
    tri = v[f[r.face]]
    rebuilt = np.einsum("ki,kij->kj", r.barycentric.astype(np.float64), tri)
    np.testing.assert_allclose(rebuilt, r.closest, rtol=0, atol=atol * 10)
    assert np.all(r.barycentric >= -1e-6) and np.allclose(r.barycentric.sum(axis=1), 1, atol=1e-5)


def test_max_distance_and_nan_points():
    rng = np.random.default_rng(9)
    v, f = random_soup(rng, 30)
    p = rng.uniform(-3, 3, (300, 3))
    scene = bvhkit.TriangleMesh(v, f, dtype=np.float64)
    full = scene.closest_point(p)
    near = scene.closest_point(p, max_distance=0.5)
    inside = full.distance <= 0.5
    np.testing.assert_array_equal(near.distance[inside], full.distance[inside])
    assert np.all(near.distance[~inside] == np.inf) and np.all(near.face[~inside] == -1)
    assert np.all(np.isnan(near.closest[~inside]))
    r = scene.closest_point([[np.nan, 0, 0], [np.inf, 0, 0]])
    assert list(r.face) == [-1, -1] and np.all(r.distance == np.inf)


def test_empty_mesh():
    scene = bvhkit.TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int32))
    assert scene.closest_point([[0, 0, 0]]).face[0] == -1
    assert scene.intersect([[0, 0, 0]], [[1, 0, 0]]).face[0] == -1
    assert scene.signed_distance([[0, 0, 0]])[0] == np.inf
    assert scene.winding_number([[0, 0, 0]])[0] == 0


@pytest.mark.parametrize(
    "dtype,scales",
    [
        (np.float32, [1e-38, 1e-30, 1e-25, 1e-20, 1.0, 1e20, 1e25, 1e30, 1e35]),
        (np.float64, [1e-300, 1e-200, 1e-160, 1.0, 1e160, 1e200, 1e300]),
    ],
)
def test_max_distance_at_extreme_scales(dtype, scales):
    # A right triangle in the plane z = 0 and points above its inside at heights of 1e-3 to 1e3
    # sizes: the distance is the height, exactly (analytic, whatever the arithmetic). A limit
    # 0.1% above it finds the triangle, one 0.1% below finds nothing, at every scale: the limit's
    # square (once taken in the mesh's dtype) would be inf or 0 at most of these.
    for s in scales:
        v = np.array([[0, 0, 0], [s, 0, 0], [0, s, 0]], dtype=dtype)
        scene = bvhkit.TriangleMesh(v, [[0, 1, 2]], dtype=dtype)
        for h in [1e-3, 1.0, 1e3]:
            p = np.array([[0.25 * s, 0.25 * s, h * s]], dtype=dtype)
            z = float(p[0, 2])
            if z == 0 or not np.isfinite(z):
                continue
            found = scene.closest_point(p, max_distance=z * 1.001)
            assert found.face[0] == 0, (s, h)
            np.testing.assert_allclose(found.distance[0], z, rtol=4 * np.finfo(dtype).eps)
            none = scene.closest_point(p, max_distance=z * 0.999)
            assert none.face[0] == -1 and none.distance[0] == np.inf, (s, h)


@pytest.mark.parametrize(
    "dtype,distances",
    [(np.float32, [1e10, 1e20, 1e30, 3e38]), (np.float64, [1e100, 1e160, 1e200, 1e300])],
)
def test_max_distance_from_far_points(dtype, distances):
    # A unit triangle and points far above it: distance d (d - 0 rounds to d), found within 2 d
    # and not within d / 2 (the squares of both limits are past float32's range from 1.8e19).
    scene = bvhkit.TriangleMesh(
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=dtype), [[0, 1, 2]], dtype=dtype
    )
    for d in distances:
        p = np.array([[0.25, 0.25, d]], dtype=dtype)
        z = float(p[0, 2])
        assert scene.closest_point(p, max_distance=2 * z).face[0] == 0, d
        assert scene.closest_point(p, max_distance=z / 2).face[0] == -1, d
