"""The shared real meshes (BVHKIT_DATA_DIR, else ../shared/data beside the checkout) against numpy
brute force; skipped when they are absent."""

import os
import pathlib

import numpy as np
import pytest

import bvhkit
from reference import point_triangle_pairs, ray_hits, triangles

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = pathlib.Path(os.environ.get("BVHKIT_DATA_DIR", ROOT.parent / "shared" / "data"))


def mesh_or_skip(name):
    path = DATA / name
    if not path.exists():
        pytest.skip(f"{path} not found (set BVHKIT_DATA_DIR)")
    return bvhkit.load_mesh(str(path))


def sample_points(rng, v, k):
    lo, hi = v.min(axis=0), v.max(axis=0)
    c, r = (lo + hi) / 2, (hi - lo) / 2
    return rng.uniform(c - 1.3 * r, c + 1.3 * r, (k, 3))


@pytest.mark.parametrize("name", ["stanford-bunny.obj", "spot.obj", "fandisk.obj"])
def test_closest_points_and_rays_on_shared_mesh(name):
    v, f = mesh_or_skip(name)
    v64 = v.astype(np.float64)
    rng = np.random.default_rng(31)
    scene = bvhkit.TriangleMesh(v, f, dtype=np.float64)
    p = sample_points(rng, v64, 24)
    r = scene.closest_point(p)
    a, b, c = triangles(v64, f)
    for i in range(len(p)):
        d, _ = point_triangle_pairs(p[i][None], a, b, c)
        assert r.distance[i] == pytest.approx(d.min(), rel=1e-9, abs=1e-12)
    target = sample_points(rng, v64, 24) * 0.3 + v64.mean(axis=0) * 0.7
    o = sample_points(rng, v64, 24) * 3
    hits = scene.intersect(o, target - o)
    for i in range(len(o)):
        t, margin = ray_hits(v64, f, o[i][None], (target - o)[i][None])
        if np.all((margin >= 1e-9) | ~np.isfinite(margin)):
            best = t.min()
            assert np.isfinite(best) == (hits.face[i] >= 0)
            if np.isfinite(best):
                assert hits.t[i] == pytest.approx(best, rel=1e-9)


def test_closed_shared_mesh_signs_agree_with_exact_winding_number():
    v, f = mesh_or_skip("spot.obj")
    rng = np.random.default_rng(5)
    scene = bvhkit.TriangleMesh(v, f, dtype=np.float64)
    p = sample_points(rng, v.astype(np.float64), 400)
    exact = scene.winding_number(p, exact=True)
    clear = np.abs(exact - 0.5) > 0.1
    inside = exact > 0.5
    for sign in ("pseudonormal", "winding_number"):
        sd = scene.signed_distance(p, sign=sign)
        np.testing.assert_array_equal((sd < 0)[clear], inside[clear])
