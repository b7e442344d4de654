"""Rays against a numpy Moller-Trumbore brute force in float64."""

import pickle

import numpy as np
import pytest

import bvhkit
from reference import random_soup, ray_hits

DTYPES = [np.float32, np.float64]
# Rays closer than this (relative barycentric / t margin) to an edge or an interval end may go
# either way in float32 and are left out of the comparison.
MARGIN = {np.float32: 1e-3, np.float64: 1e-9}
RTOL = {np.float32: 1e-4, np.float64: 1e-10}


def random_rays(rng, k, spread=2.0):
    o = rng.uniform(-spread, spread, (k, 3))
    target = rng.uniform(-1, 1, (k, 3))
    return o, target - o


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("case", ["unit", "far", "tiny", "huge"])
def test_intersect_matches_brute_force(dtype, case):
    rng = np.random.default_rng(11)
    offset, scale = {"unit": (0, 1), "far": (1e4, 1), "tiny": (0, 1e-6), "huge": (0, 1e6)}[case]
    if case == "far" and dtype == np.float32:
        scale = 100.0  # keep float32 relative precision sensible at 1e4
    v, f = random_soup(rng, 60, scale=scale, offset=offset)
    v = v.astype(dtype).astype(np.float64)  # the scene's own vertices, exactly
    o, d = random_rays(rng, 800)
    o, d = (o * scale + offset).astype(dtype), (d * scale).astype(dtype)
    tmax = np.where(rng.uniform(size=len(o)) < 0.3, 1.0, np.inf)
    scene = bvhkit.TriangleMesh(v, f, dtype=dtype)
    hits = scene.intersect(o, d, tmax=tmax)
    t_ref, margin = ray_hits(v, f, o, d, tmax=tmax)
    robust = (margin >= MARGIN[dtype]) | ~np.isfinite(margin)
    clean = robust.all(axis=1)  # no triangle is near-grazed by this ray
    assert clean.sum() > 400
    best = t_ref.min(axis=1)
    hit = np.isfinite(best)
    np.testing.assert_array_equal(np.isfinite(hits.t[clean]), hit[clean])
    np.testing.assert_array_equal(hits.face[clean] >= 0, hit[clean])
    both = clean & hit
    np.testing.assert_allclose(hits.t[both], best[both], rtol=RTOL[dtype] * 100)
    # The face found is one at the least t (ties only between coplanar duplicates).
    t_of_face = t_ref[np.flatnonzero(both), hits.face[both]]
    np.testing.assert_allclose(t_of_face, best[both], rtol=RTOL[dtype] * 100)
    # Misses report inf and -1.
    assert np.all(hits.t[~np.isfinite(hits.t)] == np.inf)
    assert np.all(hits.face[np.isinf(hits.t)] == -1)
    # The barycentrics rebuild the hit point.
    idx = np.flatnonzero(both)
    tri = v[f[hits.face[idx]]]
    p = np.einsum("ki,kij->kj", hits.barycentric[idx].astype(np.float64), tri)
    q = o[idx].astype(np.float64) + hits.t[idx, None] * d[idx].astype(np.float64)
    extent = np.abs(v).max() + scale
    np.testing.assert_allclose(p, q, atol=extent * RTOL[dtype] * 100)
    # occluded and count_intersections agree with the same reference.
    occ = scene.occluded(o, d, tmax=tmax)
    np.testing.assert_array_equal(occ[clean], hit[clean])
    counts = scene.count_intersections(o, d, tmax=tmax)
    np.testing.assert_array_equal(counts[clean], np.isfinite(t_ref).sum(axis=1)[clean])


def test_tmin_per_ray_and_duplicates_and_degenerates():
    rng = np.random.default_rng(5)
    v, f = random_soup(rng, 30)
    # A duplicate of face 0, a zero-area face (three equal vertices), a needle.
    v = np.vstack([v, v[f[0]], [[0.1, 0.1, 0.1]] * 3, [[0, 0, 0], [1, 0, 0], [2, 1e-9, 0]]])
    n = len(f)
    f = np.vstack([f, [[3 * n, 3 * n + 1, 3 * n + 2]], [[3 * n + 3] * 3],
                   [[3 * n + 6, 3 * n + 7, 3 * n + 8]]])
    o, d = random_rays(rng, 500)
    tmin = rng.uniform(0, 0.5, len(o))
    scene = bvhkit.TriangleMesh(v, f, dtype=np.float64)
    hits = scene.intersect(o, d, tmin=tmin)
    t_ref, margin = ray_hits(v, f, o, d, tmin=tmin)
    clean = ((margin >= 1e-9) | ~np.isfinite(margin)).all(axis=1)
    best = t_ref.min(axis=1)
    np.testing.assert_array_equal(np.isfinite(hits.t[clean]), np.isfinite(best[clean]))
    ok = clean & np.isfinite(best)
    np.testing.assert_allclose(hits.t[ok], best[ok], rtol=1e-9)
    assert not np.any(hits.face == len(f) - 2)  # the zero-area face is never hit


def test_nan_vertices_are_skipped_and_nan_rays_miss():
    rng = np.random.default_rng(3)
    v, f = random_soup(rng, 20)
    v[1, 2] = np.nan  # face 0 has a NaN corner
    scene = bvhkit.TriangleMesh(v, f)
    assert list(scene.skipped()) == [0]
    assert scene.stats()["skipped"] == 1
    o, d = random_rays(rng, 200)
    hits = scene.intersect(o, d)
    assert not np.any(hits.face == 0)
    nan_rays = scene.intersect([[np.nan, 0, 0]], [[1, 0, 0]])
    assert nan_rays.face[0] == -1 and nan_rays.t[0] == np.inf


def test_watertight_ray_through_shared_edge():
    # Two triangles sharing the edge x = 0.5 of a unit square; rays straight down through it.
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0, 0], [0.5, 1, 0]], float)
    f = np.array([[0, 4, 5], [0, 5, 3], [4, 1, 2], [4, 2, 5]])
    y = np.linspace(0.01, 0.99, 97)
    o = np.stack([np.full_like(y, 0.5), y, np.ones_like(y)], axis=1)
    d = np.tile([0.0, 0.0, -1.0], (len(y), 1))
    for dtype in DTYPES:
        scene = bvhkit.TriangleMesh(v, f, dtype=dtype, ray_test="watertight")
        assert np.all(scene.intersect(o, d).face >= 0)
        assert np.all(scene.occluded(o, d))


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_refit_with_a_non_finite_vertex_is_an_error_and_changes_nothing(bad):
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    o = np.array([[0, 0, -5.0], [0.1, 0.2, -5.0]])
    d = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    scene = bvhkit.TriangleMesh(v, f)
    model = bvhkit.CollisionModel(v, f)
    before = scene.intersect(o, d).t
    moved = v * 2
    moved[f[5, 1], 0] = bad
    with pytest.raises(ValueError, match="vertices"):
        scene.refit(moved)
    with pytest.raises(ValueError, match="vertices"):
        model.refit(moved)
    assert np.array_equal(scene.intersect(o, d).t, before)
    # The vertices kept are the old ones: a pickled copy and a second refit see no NaN.
    assert np.array_equal(pickle.loads(pickle.dumps(scene)).intersect(o, d).t, before)
    scene.refit(v * 2)
    model.refit(v * 2)
    assert abs(scene.intersect(o, d).t[0] - 3) < 1e-5
    assert bvhkit.collide(model, model, np.eye(3)[None], np.zeros((1, 3)))[0]


def test_refit_moves_the_hits():
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    scene = bvhkit.TriangleMesh(v, f)
    o = np.array([[0, 0, -5.0]])
    d = np.array([[0, 0, 1.0]])
    t0 = scene.intersect(o, d).t[0]
    scene.refit(v * 2)
    t1 = scene.intersect(o, d).t[0]
    assert abs(t0 - 4) < 1e-5 and abs(t1 - 3) < 1e-5
    # The proximity structures follow the refit too.
    assert abs(scene.closest_point([[0, 0, 0]]).distance[0] - 2) < 0.05


def test_large_mesh_batches_match_per_ray_answers():
    # 82k triangles: the batch calls walk eight rays at once (docs/rays.md, "Streams"). Each ray's
    # answer must be its own whatever its place in a chunk: a permuted batch gives the permuted
    # answers, hit/miss equals count_intersections > 0 (all hits, walked one ray at a time), and a
    # sample equals the float64 brute force.
    v, f = bvhkit.load_mesh("sphere:subdiv=6")
    scene = bvhkit.TriangleMesh(v, f)
    rng = np.random.default_rng(3)
    k = 3000  # two batches of 1024 and a part one, chunks of 256 and a part one
    o, d = random_rays(rng, k)
    d[::7, 1] = 0.0  # zero direction components
    d[::11, 2] = 1e-40  # a subnormal component: the one-ray walk
    o[5::97, 0] = np.nan  # NaN rays miss
    hits = scene.intersect(o, d)
    counts = scene.count_intersections(o, d)
    assert 0.3 * k < (counts > 0).sum() < k
    np.testing.assert_array_equal(hits.face >= 0, counts > 0)
    np.testing.assert_array_equal(scene.occluded(o, d), counts > 0)
    perm = rng.permutation(k)
    for threads in (1, 2):
        again = scene.intersect(o[perm], d[perm], threads=threads)
        np.testing.assert_array_equal(again.t, hits.t[perm])
        np.testing.assert_array_equal(again.face, hits.face[perm])
        np.testing.assert_array_equal(again.barycentric, hits.barycentric[perm])
        np.testing.assert_array_equal(scene.occluded(o[perm], d[perm], threads=threads),
                                      counts[perm] > 0)
    vs = v.astype(np.float32).astype(np.float64)
    sample = np.flatnonzero(np.isfinite(o).all(axis=1))[:64]
    for part in np.array_split(sample, 8):
        with np.errstate(invalid="ignore"):  # inf - inf in the reference's margin: no margin
            t_ref, margin = ray_hits(vs, f, o[part].astype(np.float32),
                                     d[part].astype(np.float32))
        best = t_ref.min(axis=1)
        clean = ((margin >= 1e-3) | ~np.isfinite(margin)).all(axis=1)
        np.testing.assert_array_equal(np.isfinite(hits.t[part])[clean], np.isfinite(best)[clean])
        both = clean & np.isfinite(best)
        np.testing.assert_allclose(hits.t[part][both], best[both], rtol=1e-2)
        np.testing.assert_allclose(t_ref[np.flatnonzero(both), hits.face[part][both]], best[both],
                                   rtol=1e-2)


def needle_scene(rng, offset, scale):
    """Long needles across the cube, a floor of two large triangles, small triangles among them:
    the unequal, overlapping triangles where spatial splits cut references."""
    k = 40
    a = rng.uniform(-1, 1, (k, 3))
    b = -a + rng.uniform(-0.2, 0.2, (k, 3))
    c = a + rng.uniform(-1e-3, 1e-3, (k, 3))  # width about 1e-3 against a length about 3
    needles = np.stack([a, b, c], axis=1)
    floor = np.array([[[-1, -1, -0.9], [1, -1, -0.9], [1, 1, -0.9]],
                      [[-1, -1, -0.9], [1, 1, -0.9], [-1, 1, -0.9]]], float)
    sv, _ = random_soup(rng, 200, size=0.05)
    tris = np.concatenate([needles, floor, sv.reshape(-1, 3, 3)])
    return tris.reshape(-1, 3) * scale + offset, np.arange(3 * len(tris)).reshape(-1, 3)


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("case", ["unit", "far", "tiny"])
def test_spatial_splits_answer_as_the_default_tree(dtype, case):
    # The same triangle test on a different tree: t and barycentrics bit for bit, each triangle
    # counted once although the split tree holds parts of it in several leaves, and the float64
    # brute force agrees.
    rng = np.random.default_rng(23)
    offset, scale = {"unit": (0.0, 1.0), "far": (1e4, 100.0), "tiny": (0.0, 1e-6)}[case]
    v, f = needle_scene(rng, offset, scale)
    v = v.astype(dtype).astype(np.float64)
    plain = bvhkit.TriangleMesh(v, f, dtype=dtype)
    split = bvhkit.TriangleMesh(v, f, dtype=dtype, spatial_splits=True)
    stats = split.stats()
    assert stats["spatial_splits"] and not plain.stats()["spatial_splits"]
    assert stats["references"] > len(f) == plain.stats()["references"]
    o, d = random_rays(rng, 3000, spread=1.5)
    o, d = (o * scale + offset).astype(dtype), (d * scale).astype(dtype)
    d[::13, 0] = 0.0
    for _ in range(2):  # as built, then both refitted the same way
        a, b = plain.intersect(o, d), split.intersect(o, d)
        np.testing.assert_array_equal(a.t, b.t)
        same = a.face == b.face  # a different face only at an equal t (a tie)
        assert same.mean() > 0.999
        np.testing.assert_array_equal(a.barycentric[same], b.barycentric[same])
        np.testing.assert_array_equal(plain.occluded(o, d), split.occluded(o, d))
        np.testing.assert_array_equal(plain.count_intersections(o, d),
                                      split.count_intersections(o, d))
        t_ref, margin = ray_hits(v, f, o[:600], d[:600])
        clean = ((margin >= MARGIN[dtype]) | ~np.isfinite(margin)).all(axis=1)
        best = t_ref.min(axis=1)
        assert clean.sum() > 300 and np.isfinite(best[clean]).sum() > 100
        np.testing.assert_array_equal(np.isfinite(b.t[:600][clean]), np.isfinite(best[clean]))
        hit = clean & np.isfinite(best)
        np.testing.assert_allclose(b.t[:600][hit], best[hit], rtol=RTOL[dtype] * 100)
        np.testing.assert_array_equal(split.count_intersections(o[:600], d[:600])[clean],
                                      np.isfinite(t_ref).sum(axis=1)[clean])
        moved = (v - offset) * 1.25 + offset
        plain.refit(moved)
        split.refit(moved)
        v = moved.astype(dtype).astype(np.float64)


def test_spatial_splits_bad_arguments():
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    with pytest.raises(TypeError, match="spatial_splits"):
        bvhkit.TriangleMesh(v, f, spatial_splits="yes")
    for builder in ["lbvh", "binned_sah+opt", "sweep_sah"]:
        with pytest.raises(ValueError, match="spatial_splits"):
            bvhkit.TriangleMesh(v, f, builder=builder, spatial_splits=True)
    assert bvhkit.TriangleMesh(v, f, spatial_splits=np.bool_(True)).stats()["spatial_splits"]


def test_spatial_splits_auto_decides_per_mesh():
    # A soup's boxes overlap enough for the split tree, a sphere's do not; where the split tree
    # is kept its answers are the forced one's (the same options, a deterministic build), and a
    # pickled scene keeps the choice. With another builder "auto" is the default build.
    rng = np.random.default_rng(31)
    soup_v, soup_f = bvhkit.load_mesh("soup:n=3000")
    sphere_v, sphere_f = bvhkit.load_mesh("sphere:subdiv=4")
    auto_soup = bvhkit.TriangleMesh(soup_v, soup_f, spatial_splits="auto")
    forced = bvhkit.TriangleMesh(soup_v, soup_f, spatial_splits=True)
    assert auto_soup.stats()["spatial_splits"]
    assert auto_soup.stats()["references"] == forced.stats()["references"] > len(soup_f)
    sphere = bvhkit.TriangleMesh(sphere_v, sphere_f, spatial_splits="auto")
    assert not sphere.stats()["spatial_splits"]
    assert not bvhkit.TriangleMesh(soup_v, soup_f, builder="lbvh",
                                   spatial_splits="auto").stats()["spatial_splits"]
    o, d = random_rays(rng, 2000, spread=1.0)
    o = (o * 0.5 + 0.5).astype(np.float32)
    d = d.astype(np.float32)
    a, b = auto_soup.intersect(o, d), forced.intersect(o, d)
    assert np.isfinite(a.t).sum() > 200
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.face, b.face)
    loaded = pickle.loads(pickle.dumps(auto_soup))
    assert loaded.stats()["spatial_splits"]
    np.testing.assert_array_equal(loaded.intersect(o, d).face, a.face)
    with pytest.raises(TypeError, match="spatial_splits"):
        bvhkit.TriangleMesh(soup_v, soup_f, spatial_splits="always")


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e-120, 1e120, 1e200, 1e300])
def test_float64_rays_at_extreme_scales(scale):
    # t does not change when the mesh, the origins and the directions are scaled together, so the
    # numpy reference at unit scale (whose own products would leave float64's range out there)
    # judges the scaled scene. Rays grazing an edge at unit scale are left out.
    rng = np.random.default_rng(5)
    v, f = random_soup(rng, 60, scale=1.0, offset=0)
    o, d = random_rays(rng, 600)
    t_ref, margin = ray_hits(v, f, o, d, tmax=np.full(len(o), np.inf))
    clean = ((margin >= 1e-6) | ~np.isfinite(margin)).all(axis=1)
    assert clean.sum() > 300
    best = t_ref.min(axis=1)
    hit = np.isfinite(best)
    assert hit[clean].sum() > 100
    scene = bvhkit.TriangleMesh(v * scale, f, dtype=np.float64)
    hits = scene.intersect(o * scale, d * scale)
    np.testing.assert_array_equal(np.isfinite(hits.t[clean]), hit[clean])
    both = clean & hit
    np.testing.assert_allclose(hits.t[both], best[both], rtol=1e-9)
    np.testing.assert_array_equal(scene.occluded(o * scale, d * scale)[clean], hit[clean])


@pytest.mark.parametrize("dtype", DTYPES)
def test_shared_limits_answer_as_per_ray_limits(dtype):
    """The one-[tmin, tmax]-for-all path (float limits, arrays of the mesh's dtype) gives the
    bits of the per-ray path (array limits), and either spelling of the arguments reaches one."""
    rng = np.random.default_rng(8)
    v, f = random_soup(rng, 200)
    scene = bvhkit.TriangleMesh(v, f, dtype=dtype)
    o, d = (a.astype(dtype) for a in random_rays(rng, 3000))
    for tmin, tmax in ((0.0, np.inf), (0.5, 2.0), (np.nan, 3.0), (1.0, 0.5)):
        shared = scene.intersect(o, d, tmin=tmin, tmax=tmax)
        k = len(o)
        per_ray = scene.intersect(o, d, tmin=np.full(k, tmin), tmax=np.full(k, tmax))
        for a, b in zip(shared, per_ray):
            np.testing.assert_array_equal(a, b)
        # One ray at a time, non-contiguous rows, and float64 rays for a float32 mesh alike.
        for i in range(0, k, 500):
            one = scene.intersect(o[i : i + 1], d[i : i + 1], tmin=tmin, tmax=tmax)
            assert one.face[0] == shared.face[i] and np.array_equal(one.t[:1], shared.t[i : i + 1])
        strided = scene.intersect(np.asfortranarray(o), d[:, :], tmin=tmin, tmax=tmax)
        np.testing.assert_array_equal(strided.t, shared.t)
