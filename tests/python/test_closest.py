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
