"""Scene.signed_distance and Scene.contains against references that share none of the code's
arithmetic: unions of posed cubes, whose signed distance is analytic (the box's distance
function in each instance's frame, in long double), near and far from the origin, tiny and huge;
an open box (no top) against the exact winding number summed in long double; the arguments."""

import numpy as np
import pytest

import bvhkit
from reference import box_mesh, random_rotations

LD = np.longdouble


def box_distance(q, h):
    """Signed distance from the rows of q to the box [-h, h]^3 (analytic)."""
    e = np.abs(q) - h
    outside = np.sqrt((np.maximum(e, 0) ** 2).sum(axis=1))
    inside = np.minimum(e.max(axis=1), 0)
    return np.where(outside > 0, outside, inside)


def local(scene, id, p):
    """The rows of p in the instance's frame, R^T (p - t), in long double (the stored pose)."""
    r, t = scene.pose(id)
    return (p.astype(LD) - t.astype(LD)) @ r.astype(LD)


def union_reference(d, tol):
    """|distance|, inside, and whether the sign is sure beyond tol, from (instances, k) d."""
    dist = np.abs(d).min(axis=0)
    inside = (d < 0).any(axis=0)
    sure = (d < -tol).any(axis=0) | ~(np.abs(d) <= tol).any(axis=0)
    return dist, inside, sure


@pytest.mark.parametrize("dtype,scale,offset", [
    (np.float64, 1.0, 0.0), (np.float32, 1.0, 0.0), (np.float64, 1e-6, 0.0),
    (np.float32, 1e4, 0.0), (np.float64, 1.0, 1e6), (np.float32, 1.0, 1e5),
    (np.float64, 1e-3, 1e6),
])
def test_cubes_are_analytic(dtype, scale, offset):
    rng = np.random.default_rng(7)
    h = scale
    s = bvhkit.Scene(dtype=dtype)
    g = s.add_mesh(*box_mesh([-h] * 3, [h] * 3))
    ids = [s.add_instance(g, None, [offset] * 3),
           s.add_instance(g, None, [offset + 2 * h, offset, offset]),  # shares a face
           s.add_instance(g, None, [offset, offset - 3 * h, offset], margin=0.5 * h)]
    ids += list(s.add_instances(g, random_rotations(rng, 7),
                                offset + scale * rng.uniform(-3, 3, (7, 3))))
    p = (offset + scale * rng.uniform(-4.5, 4.5, (2000, 3))).astype(dtype)
    d = np.stack([box_distance(local(s, i, p), LD(h)) for i in ids])
    eps = LD(np.finfo(dtype).eps)
    tol = 64 * eps * 6 * LD(scale)
    dist, inside, sure = union_reference(d, tol)
    for sign in ("pseudonormal", "winding_number"):
        r = s.signed_distance(p, sign=sign)
        assert r.distance.dtype == dtype and r.point.shape == (len(p), 3)
        assert np.all(np.abs(np.abs(r.distance).astype(LD) - dist) <= tol)
        assert np.array_equal(np.signbit(r.distance)[sure], inside[sure])
        assert np.array_equal(np.abs(r.distance), s.closest_point(p).distance)
        assert set(np.unique(r.instance)) <= set(ids)
    assert np.array_equal(s.contains(p)[sure], inside[sure])
    assert inside[sure].sum() > 100 and (~inside[sure]).sum() > 100


def winding_reference(v, f, p):
    """The exact winding number of mesh (v, f) at the rows of p, in long double."""
    a, b, c = (v[f[:, k]].astype(LD)[None] - p.astype(LD)[:, None] for k in range(3))
    la, lb, lc = (np.sqrt((x * x).sum(-1)) for x in (a, b, c))
    num = (a * np.cross(b, c)).sum(-1)
    den = (la * lb * lc + (a * b).sum(-1) * lc + (b * c).sum(-1) * la + (c * a).sum(-1) * lb)
    return (2 * np.arctan2(num.astype(float), den.astype(float))).sum(-1) / (4 * np.pi)


def test_open_meshes_by_the_winding_number():
    rng = np.random.default_rng(3)
    v, f = box_mesh([-1] * 3, [1] * 3)
    f = f[[not np.all(v[t][:, 2] == 1) for t in f]]  # the top (+z) removed
    assert len(f) == 10
    s = bvhkit.Scene(dtype=np.float64)
    g = s.add_mesh(v, f)
    r = random_rotations(rng, 4)
    t = rng.uniform(-2, 2, (4, 3))
    s.add_instances(g, r, t)
    p = rng.uniform(-3.5, 3.5, (1500, 3))
    w = np.stack([winding_reference(v @ r[i].T + t[i], f, p) for i in range(4)])
    inside = (w > 0.55).any(axis=0)
    sure = inside | ~(np.abs(w - 0.5) <= 0.05).any(axis=0)
    assert np.array_equal(s.contains(p)[sure], inside[sure])
    sd = s.signed_distance(p, sign="winding_number").distance
    assert np.array_equal(np.signbit(sd)[sure], inside[sure])
    assert inside.sum() > 50


def test_threads_empty_scenes_and_bad_points():
    rng = np.random.default_rng(5)
    s = bvhkit.Scene()
    assert np.isinf(s.signed_distance([[0, 0, 0]]).distance[0])
    assert not s.contains([[0, 0, 0]])[0]
    assert s.signed_distance(np.zeros((0, 3))).distance.shape == (0,)
    assert s.contains(np.zeros((0, 3))).shape == (0,)
    v, f = bvhkit.load_mesh("sphere:subdiv=2")
    g = s.add_mesh(v, f)
    s.add_instances(g, random_rotations(rng, 40), rng.uniform(-6, 6, (40, 3)))
    p = rng.uniform(-7, 7, (5000, 3)).astype(np.float32)
    for sign in ("pseudonormal", "winding_number"):
        one = s.signed_distance(p, sign=sign, threads=1)
        for x, y in zip(one, s.signed_distance(p, sign=sign, threads=0)):
            assert np.array_equal(x, y, equal_nan=True)
    assert np.array_equal(s.contains(p, threads=1), s.contains(p, threads=3))
    # Pseudonormal and winding number agree on closed spheres away from the surface.
    a = s.signed_distance(p).distance
    b = s.signed_distance(p, sign="winding_number").distance
    far = np.abs(a) > 1e-3
    assert np.array_equal(np.signbit(a[far]), np.signbit(b[far]))
    r = s.signed_distance([[np.nan, 0, 0], [np.inf, 0, 0]])
    assert np.all(np.isinf(r.distance)) and np.all(r.instance == -1)
    assert not s.contains([[np.nan, 0, 0]]).any()


def test_bad_arguments_are_named():
    s = bvhkit.Scene()
    s.add_instance(s.add_mesh(*box_mesh([0, 0, 0], [1, 1, 1])))
    cases = [
        (lambda: s.signed_distance([[0, 0, 0]], sign="normal"), ValueError, "sign"),
        (lambda: s.signed_distance([[0, 0, 0]], sign=1), TypeError, "sign"),
        (lambda: s.signed_distance([[0, 0]]), ValueError, "points"),
        (lambda: s.signed_distance([["a", 0, 0]]), TypeError, "points"),
        (lambda: s.signed_distance([[0, 0, 0]], threads=-1), ValueError, "threads"),
        (lambda: s.contains([[0, 0]]), ValueError, "points"),
        (lambda: s.contains([[0, 0, 0]], threads=1.5), TypeError, "threads"),
    ]
    for call, kind, match in cases:
        with pytest.raises(kind, match=match):
            call()


def test_docs_example_runs_as_written():
    import contextlib
    import io
    import pathlib

    doc = pathlib.Path(__file__).resolve().parents[2] / "docs" / "scenes.md"
    section = doc.read_text(encoding="utf-8").split("\n## Signed distance and contains\n")[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(code, {})
    assert "[-0.5 -0.5  2.5]\nTrue [ True]" in out.getvalue()
