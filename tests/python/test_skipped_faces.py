"""One set of faces for every structure of a scene (docs/python.md, "Bad input"): the faces left out
at the build for a NaN or infinite coordinate stay out of every query after a refit that makes them
finite, whether the proximity structures were built before the refit, after it, or in a loaded copy.
The references are float64 brute force over the faces kept (tests/python/reference.py) and an
analytic solid-angle sum."""

import pickle

import numpy as np
import pytest

import bvhkit
from reference import point_triangle, ray_hits


def solid_angle_winding(points, vertices, faces):
    """The generalized winding number by the formula of Van Oosterom and Strackee, in float64 with
    numpy (per face, summed over faces; the library sums in its own order and type)."""
    tri = vertices[faces]  # (m, 3, 3)
    out = np.empty(len(points))
    for i, q in enumerate(points):
        a, b, c = (tri[:, k] - q for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        num = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc
               + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb)
        out[i] = np.sum(2 * np.arctan2(num, den)) / (4 * np.pi)
    return out


def sphere_with_a_nan_vertex():
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    v = v.astype(np.float64)
    k = 7
    bad = v.copy()
    bad[k, 1] = np.nan
    left_out = np.flatnonzero((f == k).any(axis=1))
    return v, bad, f, k, left_out


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("when", ["before_refit", "after_refit", "loaded", "spatial_splits"])
def test_refit_keeps_the_faces_left_out_at_the_build_out_of_every_query(dtype, when):
    v, bad, f, k, left_out = sphere_with_a_nan_vertex()
    kept = np.setdiff1d(np.arange(len(f)), left_out)
    scene = bvhkit.TriangleMesh(bad, f, dtype=dtype, spatial_splits=when == "spatial_splits")
    assert np.array_equal(scene.skipped(), left_out) and len(left_out) >= 5
    # Points round the hole, just outside and inside the sphere, and the centre.
    rng = np.random.default_rng(5)
    near = v[k] * rng.uniform(0.9, 1.1, (40, 1)) + rng.normal(0, 0.05, (40, 3))
    points = np.vstack([near, [[0, 0, 0]], v[k] * 1.02, v[k] * 0.98])
    if when == "before_refit":
        scene.closest_point(points)  # the proximity structures built over the NaN mesh
        scene.winding_number(points)
    scene.refit(v)
    if when == "loaded":
        scene = pickle.loads(pickle.dumps(scene))  # no proximity structure built yet
    assert np.array_equal(scene.skipped(), left_out)
    vd = v.astype(dtype).astype(np.float64)  # the vertices as the scene holds them

    # Closest points: the face found is a kept one, at the brute-force distance over kept faces.
    got = scene.closest_point(points)
    want_d = point_triangle(points, vd, f[kept])[0].min(axis=1)
    assert np.isin(got.face, kept).all(), np.setdiff1d(got.face, kept)
    tol = 1e-5 if dtype == np.float32 else 1e-12
    np.testing.assert_allclose(got.distance, want_d, rtol=0, atol=tol)
    sd = scene.signed_distance(points)
    np.testing.assert_allclose(np.abs(sd), want_d, rtol=0, atol=tol)
    sdw = scene.signed_distance(points, sign="winding_number")
    np.testing.assert_allclose(np.abs(sdw), want_d, rtol=0, atol=tol)

    # Winding numbers: the sum over the kept faces (the hole lowers it inside from 1).
    want_w = solid_angle_winding(points, vd, f[kept])
    np.testing.assert_allclose(scene.winding_number(points, exact=True), want_w, atol=1e-5)
    np.testing.assert_allclose(scene.winding_number(points, beta=8.0), want_w, atol=2e-3)
    assert want_w[len(near)] < 0.99  # the centre: 1 with the hole closed
    np.testing.assert_array_equal(scene.contains(points), scene.winding_number(points) > 0.5)

    # Rays from outside through the hole: the far side, as the brute force over kept faces says.
    o = np.tile(v[k] * 3, (6, 1))
    d = -v[k] + rng.normal(0, 0.03, (6, 3))
    t_all, margin = ray_hits(vd, f[kept], o, d)
    assert (margin[np.isfinite(t_all)] > 1e-4).all()  # no ray grazes an edge
    hits = scene.intersect(o, d)
    np.testing.assert_array_equal(hits.face, kept[t_all.argmin(axis=1)])
    np.testing.assert_allclose(hits.t, t_all.min(axis=1), rtol=1e-5)
    np.testing.assert_array_equal(scene.count_intersections(o, d), np.isfinite(t_all).sum(1))
    assert (np.isfinite(t_all).sum(1) == 1).all()


def test_a_refit_cannot_give_a_kept_face_a_nan():
    v, bad, f, k, left_out = sphere_with_a_nan_vertex()
    scene = bvhkit.TriangleMesh(v, f)
    with pytest.raises(ValueError, match="vertices"):
        scene.refit(bad)
    assert scene.skipped().size == 0


def test_collision_models_keep_the_same_rule():
    # A small triangle where the hole is: a model built with the NaN vertex and refitted finite
    # still has no faces there, as a TriangleMesh has none.
    v, bad, f, k, left_out = sphere_with_a_nan_vertex()
    probe_v = v[k] + np.array([[0.02, 0, 0], [0, 0.02, 0], [0, 0, 0.02]]) - 0.01
    probe = bvhkit.CollisionModel(probe_v, [[0, 1, 2]])
    model = bvhkit.CollisionModel(bad, f)
    model.refit(v)
    pose = (np.eye(3)[None], np.zeros((1, 3)))
    assert not bvhkit.collide(model, probe, *pose)[0]
    assert bvhkit.collide(bvhkit.CollisionModel(v, f), probe, *pose)[0]
