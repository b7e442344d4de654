"""TriangleMesh.contains on closed surfaces (one ray's signed crossings) and on the rest (the fast
winding number), judged by the exact winding number (a sum of solid angles, arithmetic the
crossings do not share) and by analytic insides: spheres and boxes, overlapping and nested
shells, inward-facing surfaces, split seams, points on grids that run along a box's edges, far
from the origin, tiny and huge scales."""

import pathlib

import numpy as np
import pytest

import bvhkit


def box(centre=(0.0, 0.0, 0.0), half=(1.0, 1.0, 1.0)):
    """An axis-aligned box as 12 outward triangles."""
    c, h = np.asarray(centre, float), np.asarray(half, float)
    s = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    v = c + s * h
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = np.array([t for a, b, cc, d in quads for t in ((a, b, cc), (a, cc, d))])
    normal = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    out = np.einsum("ij,ij->i", normal, v[f].mean(axis=1) - c) > 0
    f[~out] = f[~out][:, [0, 2, 1]]
    return v, f


def sphere(centre=(0.0, 0.0, 0.0), radius=1.0):
    v, f = bvhkit.load_mesh("sphere:subdiv=3")
    return np.asarray(centre) + radius * v.astype(np.float64), f


def union(*meshes):
    vs, fs, base = [], [], 0
    for v, f in meshes:
        vs.append(v)
        fs.append(f + base)
        base += len(v)
    return np.concatenate(vs), np.concatenate(fs)


def judge(v, f, p, dtype=np.float64, margin=1e-6):
    """contains against the exact winding number, away from the surface (within `margin` of
    the mesh's size a point may round to either side)."""
    mesh = bvhkit.TriangleMesh(v.astype(dtype), f, dtype=dtype)
    got = mesh.contains(p.astype(dtype))
    exact = mesh.winding_number(p.astype(dtype), exact=True)
    size = np.linalg.norm(v.max(0) - v.min(0))
    clear = np.abs(mesh.signed_distance(p.astype(dtype))) > margin * size
    np.testing.assert_array_equal(got[clear], exact[clear] > 0.5)
    return mesh, got


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_closed_meshes_by_crossings_equal_the_exact_winding_number(dtype):
    rng = np.random.default_rng(1)
    spot = pathlib.Path(__file__).resolve().parents[2] / "data" / "spot.obj"  # shipped, closed
    spot_v, spot_f = bvhkit.load_mesh(str(spot))
    spot_v = spot_v.astype(np.float64)
    for v, f in (box(), sphere(), (spot_v, spot_f), box((3, -2, 1), (0.5, 2, 0.01))):
        lo, hi = v.min(0), v.max(0)
        p = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), (4000, 3))
        mesh, got = judge(v, f, p, dtype)
        assert mesh.is_closed
        assert 0.05 < got.mean() < 0.95


def test_box_inside_is_analytic_on_grids_along_its_edges():
    v, f = box(half=(1, 1, 1))
    mesh = bvhkit.TriangleMesh(v, f)
    g = np.linspace(-1.5, 1.5, 31)  # runs through the box's faces, edges and corners
    p = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    inside = np.all(np.abs(p) < 1 - 1e-12, axis=1)
    on = np.all(np.abs(p) <= 1 + 1e-12, axis=1) & ~inside
    got = mesh.contains(p)
    np.testing.assert_array_equal(got[~on], inside[~on])
    # Rays from the grid's points on a face run along no face, but from an edge they can meet
    # the box's corners: those fall back, and still answer.
    assert mesh.is_closed


def test_overlapping_nested_and_inward_shells():
    rng = np.random.default_rng(2)
    p = rng.uniform(-2.5, 2.5, (20000, 3))
    # Two overlapping spheres as separate shells: the lens between them has winding number 2.
    a, b = sphere((-0.5, 0, 0)), sphere((0.5, 0, 0))
    mesh, got = judge(*union(a, b), p)
    assert mesh.is_closed
    r = np.linalg.norm(p - [-0.5, 0, 0], axis=1), np.linalg.norm(p - [0.5, 0, 0], axis=1)
    lens = (r[0] < 0.9) & (r[1] < 0.9)
    assert lens.sum() > 50 and got[lens].all()
    # A hollow ball: the inner shell faces inward, so the cavity has winding number 0.
    outer, inner = sphere(radius=2.0), sphere(radius=1.0)
    inner = (inner[0], inner[1][:, [0, 2, 1]])
    mesh, got = judge(*union(outer, inner), p)
    radius = np.linalg.norm(p, axis=1)
    assert not got[radius < 0.95].any() and got[(radius > 1.05) & (radius < 1.9)].all()
    # A sphere facing inward: winding number -1 inside, so nothing is contained.
    v, f = sphere()
    mesh, got = judge(v, f[:, [0, 2, 1]], p)
    assert mesh.is_closed and not got.any()


def test_open_split_and_fast_meshes():
    rng = np.random.default_rng(3)
    v, f = sphere()
    p = rng.uniform(-1.3, 1.3, (3000, 3))
    # A hole: not closed; the fast winding number decides, as before.
    mesh = bvhkit.TriangleMesh(v, f[1:])
    assert not mesh.is_closed
    np.testing.assert_array_equal(mesh.contains(p), mesh.winding_number(p) > 0.5)
    # Every triangle with vertices of its own (seams everywhere): welded, still closed.
    split_v, split_f = v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3)
    mesh, _ = judge(split_v, split_f, p)
    assert mesh.is_closed
    # The fast ray test is not watertight: no crossings.
    assert not bvhkit.TriangleMesh(v, f, ray_test="fast").is_closed
    # A face left out for a NaN corner opens the surface.
    nan_v = v.copy()
    nan_v[f[0, 0]] = np.nan
    assert not bvhkit.TriangleMesh(nan_v, f).is_closed


@pytest.mark.parametrize("scale, offset", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (1e-3, 1e5)])
def test_far_tiny_and_huge(scale, offset):
    rng = np.random.default_rng(4)
    v, f = sphere()
    v = v * scale + offset
    p = offset + scale * rng.uniform(-1.3, 1.3, (3000, 3))
    r = np.linalg.norm((p - offset) / scale, axis=1)
    mesh = bvhkit.TriangleMesh(v, f, dtype=np.float64)  # float32 would round 1e6 to 1/16
    got = mesh.contains(p)
    # Inside the inscribed sphere of the polyhedron and outside the circumscribed one.
    assert mesh.is_closed
    assert got[r < 0.97].all() and not got[r > 1.0 + 1e-9].any()


def test_non_finite_points_and_refit():
    v, f = box()
    mesh = bvhkit.TriangleMesh(v, f)
    p = np.array([[np.nan, 0, 0], [np.inf, 0, 0], [0, 0, 0], [5, 0, 0]])
    np.testing.assert_array_equal(mesh.contains(p), [False, False, True, False])
    mesh.refit(v + [5, 0, 0])
    assert mesh.is_closed
    np.testing.assert_array_equal(mesh.contains(p), [False, False, False, True])
