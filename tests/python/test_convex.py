"""Convex shapes, convex_distance and convex_signed_distance: analytic answers, the separation
property of the depth, batches against one-at-a-time calls, threads, pickling and bad input."""

import pickle

import numpy as np
import pytest

import bvhkit
from reference import box_mesh, random_rotations

I3 = np.eye(3)
CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)


def one(f, a, b, t, r=I3):
    """The answers of one pose as scalars and (3,) rows."""
    return [x[0] for x in f(a, b, r, np.asarray(t, float))]


def signed(a, b, t, r=I3):
    return one(bvhkit.convex_signed_distance, a, b, t, r)


def dist(a, b, t, r=I3):
    return one(bvhkit.convex_distance, a, b, t, r)


def check_consistent(s, pa, pb, n, tol=1e-12):
    assert np.linalg.norm(n) == pytest.approx(1, abs=1e-12)
    np.testing.assert_allclose(pb - pa, s * n, atol=tol)


# ---------------------------------------------------------------- analytic answers


def test_spheres_apart_touching_overlapping():
    a, b = bvhkit.Sphere(1.0), bvhkit.Sphere(0.5)
    d, pa, pb, n = dist(a, b, [3, 0, 0])
    assert d == pytest.approx(1.5, abs=1e-14)
    np.testing.assert_allclose([pa, pb, n], [[1, 0, 0], [2.5, 0, 0], [1, 0, 0]], atol=1e-14)
    s, pa, pb, n, ok = signed(a, b, [0, 3, 0])
    assert s == pytest.approx(1.5, abs=1e-14) and ok
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-14)
    # touching: no distance, no depth
    assert dist(a, b, [0, 0, 1.5])[0] == 0
    assert signed(a, b, [0, 0, 1.5])[0] == pytest.approx(0, abs=1e-14)
    # overlapping by 0.5 along x
    d, pa, pb, n = dist(a, b, [1, 0, 0])
    assert d == 0 and not n.any()
    s, pa, pb, n, ok = signed(a, b, [1, 0, 0])
    assert s == pytest.approx(-0.5, abs=1e-14) and ok
    np.testing.assert_allclose([pa, pb, n], [[1, 0, 0], [0.5, 0, 0], [1, 0, 0]], atol=1e-14)


def test_axis_aligned_boxes_depth_is_the_smallest_overlap():
    rng = np.random.default_rng(3)
    for _ in range(50):
        ha, hb = rng.uniform(0.2, 2, 3), rng.uniform(0.2, 2, 3)
        t = rng.uniform(-1, 1, 3) * (ha + hb)
        over = np.minimum(ha - (t - hb), (t + hb) + ha)  # per axis: push b up, or down
        axis = int(np.argmin(over))
        s, pa, pb, n, ok = signed(bvhkit.Box(ha), bvhkit.Box(hb), t)
        assert ok
        assert s == pytest.approx(-over[axis], abs=1e-12)
        sign = 1 if ha[axis] - (t[axis] - hb[axis]) <= t[axis] + hb[axis] + ha[axis] else -1
        np.testing.assert_allclose(n, sign * I3[axis], atol=1e-12)
        check_consistent(s, pa, pb, n)


def test_capsules():
    a = bvhkit.Capsule(0.5, 1.0)  # axis z
    b = bvhkit.Capsule(0.25, 2.0)
    to_x = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], float)  # b's axis along x
    d, pa, pb, n = dist(a, b, [0, 1, 0.3], to_x)
    assert d == pytest.approx(0.25, abs=1e-14)
    np.testing.assert_allclose([pa, pb, n], [[0, 0.5, 0.3], [0, 0.75, 0.3], [0, 1, 0]], atol=1e-14)
    s, pa, pb, n, ok = signed(a, b, [0, 0.5, 0.3], to_x)
    assert s == pytest.approx(-0.25, abs=1e-14) and ok
    np.testing.assert_allclose(n, [0, 1, 0], atol=1e-14)
    # end to end along the common axis
    assert dist(a, b, [0, 0, 4])[0] == pytest.approx(0.25, abs=1e-14)
    assert signed(a, b, [0, 0, -3.5])[0] == pytest.approx(-0.25, abs=1e-14)


def test_sphere_against_a_box_in_each_region():
    box, ball = bvhkit.Box([1, 2, 3]), bvhkit.Sphere(0.5)
    cases = [  # centre of the ball, closest point of the box
        ([2, 0, 0], [1, 0, 0]),  # face
        ([2, 3, 0], [1, 2, 0]),  # edge
        ([2, 3, 4], [1, 2, 3]),  # vertex
        ([-0.3, -2.8, 1], [-0.3, -2, 1]),  # another face
    ]
    for centre, near in cases:
        centre, near = np.array(centre, float), np.array(near, float)
        gap = np.linalg.norm(centre - near)
        d, pa, pb, n = dist(box, ball, centre)
        assert d == pytest.approx(gap - 0.5, abs=1e-12)
        np.testing.assert_allclose(pa, near, atol=1e-12)
        np.testing.assert_allclose(n, (centre - near) / gap, atol=1e-12)
        assert signed(box, ball, centre)[0] == pytest.approx(gap - 0.5, abs=1e-12)
    # the centre inside: the nearest face (x = 1, 0.2 away) plus the radius
    s, pa, pb, n, ok = signed(box, ball, [0.8, 0.1, -0.4])
    assert s == pytest.approx(-0.7, abs=1e-12) and ok
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pa, [1, 0.1, -0.4], atol=1e-12)


def test_cone_apex():
    cone, ball = bvhkit.Cone(1.0, 2.0), bvhkit.Sphere(0.5)  # apex at (0, 0, 1)
    d, pa, pb, n = dist(cone, ball, [0, 0, 3])
    assert d == pytest.approx(1.5, abs=1e-12)
    np.testing.assert_allclose(pa, [0, 0, 1], atol=1e-12)
    # within the apex's normal cone (side normal 63.4 degrees from z): still the apex
    centre = np.array([0.5, 0, 3])
    d, pa, pb, n = dist(cone, ball, centre)
    assert d == pytest.approx(np.hypot(0.5, 2) - 0.5, abs=1e-9)
    np.testing.assert_allclose(pa, [0, 0, 1], atol=1e-9)
    # a cylinder and a cone stacked: the cone's apex on the cylinder's top face
    cyl = bvhkit.Cylinder(1.0, 0.5)
    flipped = np.diag([1.0, -1, -1])  # apex down; the cylinder's top face is z = 0.5
    s, *_ = signed(cyl, cone, [0, 0, 1.4], flipped)  # apex at z = 0.4: 0.1 deep
    assert s == pytest.approx(-0.1, abs=1e-9)
    assert dist(cyl, cone, [0, 0, 1.7], flipped)[0] == pytest.approx(0.2, abs=1e-9)


def test_a_hull_of_a_cubes_corners_is_that_box():
    rng = np.random.default_rng(5)
    half = np.array([1.0, 0.5, 2.0])
    hull, box = bvhkit.ConvexHull(CUBE * half), bvhkit.Box(half)
    assert len(hull.vertices) == 8
    others = [bvhkit.Sphere(0.3), bvhkit.Box([0.4, 0.7, 0.2]), bvhkit.Capsule(0.2, 0.6)]
    k = 200
    r, t = random_rotations(rng, k), rng.uniform(-3, 3, (k, 3))
    for other in others:
        for f, tol in ((bvhkit.convex_distance, 1e-10), (bvhkit.convex_signed_distance, 1e-9)):
            x, y = f(hull, other, r, t)[0], f(box, other, r, t)[0]
            np.testing.assert_allclose(x, y, atol=tol)
            x, y = f(other, hull, r, t)[0], f(other, box, r, t)[0]
            np.testing.assert_allclose(x, y, atol=tol)


def test_far_from_the_origin():
    c = np.full(3, 1e6)
    near = bvhkit.ConvexHull(CUBE)
    far = bvhkit.ConvexHull(CUBE + c)
    ball = bvhkit.Sphere(0.5)
    cases = [([2, 0, 0], 0.5), ([1.2, 0.3, 0], -0.3), ([0, 1.9, 1.9], np.hypot(0.9, 0.9) - 0.5)]
    for offset, want in cases:
        got = signed(far, ball, c + offset)[0]
        assert got == pytest.approx(want, abs=1e-8)
        assert signed(near, ball, offset)[0] == pytest.approx(want, abs=1e-12)
        assert dist(far, ball, c + offset)[0] == pytest.approx(max(want, 0), abs=1e-8)
    # two hulls both far out, b's frame placed back on a's: the same as near the origin
    s_far = signed(far, bvhkit.ConvexHull(CUBE * 0.5 + c), [1.3, 0.2, 0])[0]
    s_near = signed(near, bvhkit.ConvexHull(CUBE * 0.5), [1.3, 0.2, 0])[0]
    assert s_far == pytest.approx(s_near, abs=1e-8) and s_near == pytest.approx(-0.2, abs=1e-12)


# ---------------------------------------------------------------- the separation property


def shape_zoo(rng):
    pts = rng.normal(size=(12, 3)) * rng.uniform(0.3, 1, 3)
    return [
        bvhkit.Sphere(0.7), bvhkit.Box([0.5, 0.8, 0.3]), bvhkit.Capsule(0.3, 0.6),
        bvhkit.Cylinder(0.5, 0.4), bvhkit.Cone(0.6, 1.0), bvhkit.ConvexHull(pts),
    ]


def test_moving_b_by_the_depth_separates_it():
    rng = np.random.default_rng(7)
    zoo = shape_zoo(rng)
    k = 40
    checked = 0
    for a in zoo:
        for b in zoo:
            r, t = random_rotations(rng, k), rng.uniform(-0.6, 0.6, (k, 3))
            s, pa, pb, n, ok = bvhkit.convex_signed_distance(a, b, r, t)
            inside = s < -1e-3
            depth = -s[inside, None]
            moved = t[inside] + (1 + 1e-6) * depth * n[inside]
            beyond = bvhkit.convex_distance(a, b, r[inside], moved)
            assert (beyond.distance > 0).all(), (a, b)
            short = inside & ok
            depth = -s[short, None]
            moved = t[short] + (1 - 1e-3) * depth * n[short]
            within = bvhkit.convex_distance(a, b, r[short], moved)
            assert (within.distance == 0).all(), (a, b)
            np.testing.assert_allclose(pb - pa, s[:, None] * n, atol=1e-9)
            checked += inside.sum()
    assert checked > 500


# ---------------------------------------------------------------- batches and threads


@pytest.mark.parametrize("f", [bvhkit.convex_distance, bvhkit.convex_signed_distance])
def test_a_batch_equals_one_pose_at_a_time_bit_for_bit(f):
    rng = np.random.default_rng(11)
    zoo = shape_zoo(rng)
    k = 30
    r, t = random_rotations(rng, k), rng.uniform(-1.5, 1.5, (k, 3))
    for a, b in zip(zoo, zoo[::-1]):
        batch = f(a, b, r, t)
        for i in range(k):
            single = f(a, b, r[i], t[i])
            for x, y in zip(batch, single):
                np.testing.assert_array_equal(x[i : i + 1], y)


@pytest.mark.parametrize("f", [bvhkit.convex_distance, bvhkit.convex_signed_distance])
def test_threads_give_the_same_answers(f):
    rng = np.random.default_rng(13)
    k = 5000
    r, t = random_rotations(rng, k), rng.uniform(-1.5, 1.5, (k, 3))
    a, b = bvhkit.Cylinder(0.5, 0.4), bvhkit.ConvexHull(rng.normal(size=(30, 3)) * 0.5)
    x, y = f(a, b, r, t, threads=1), f(a, b, r, t, threads=0)
    for u, v in zip(x, y):
        np.testing.assert_array_equal(u, v)


def test_pose_forms():
    a, b = bvhkit.Box([1, 1, 1]), bvhkit.Sphere(0.5)
    t = np.array([[2.0, 0, 0], [0, 3.0, 0]])
    want = bvhkit.convex_distance(a, b, np.stack([I3, I3]), t).distance
    np.testing.assert_array_equal(bvhkit.convex_distance(a, b, None, t).distance, want)
    np.testing.assert_array_equal(bvhkit.convex_distance(a, b, None, t.tolist()).distance, want)
    got = bvhkit.convex_distance(a, b, np.stack([I3, I3]).astype(np.float32), t.astype(np.float32))
    np.testing.assert_array_equal(got.distance, want)
    single = bvhkit.convex_signed_distance(a, b, I3, [2.0, 0, 0])
    assert single.signed_distance.shape == (1,) and single.normal.shape == (1, 3)
    assert single.converged.dtype == np.bool_
    empty = bvhkit.convex_signed_distance(a, b, np.empty((0, 3, 3)), np.empty((0, 3)))
    assert empty.signed_distance.shape == (0,) and empty.point_a.shape == (0, 3)


# ---------------------------------------------------------------- shapes: pickling, repr


def test_shapes_pickle_and_repr():
    rng = np.random.default_rng(17)
    shapes = shape_zoo(rng)
    shapes.append(bvhkit.ConvexHull(np.vstack([CUBE, CUBE * 0.5, [[1, 0, 0], [0, 1, 1]]])))
    r, t = random_rotations(rng, 50), rng.uniform(-1.5, 1.5, (50, 3))
    for s in shapes:
        copy = pickle.loads(pickle.dumps(s))
        assert type(copy) is type(s) and repr(copy) == repr(s)
        for other in shapes[:3]:
            for x, y in zip(bvhkit.convex_signed_distance(s, other, r, t),
                            bvhkit.convex_signed_distance(copy, other, r, t)):
                np.testing.assert_array_equal(x, y)
    assert repr(bvhkit.Sphere(0.5)) == "Sphere(0.5)"
    assert repr(bvhkit.Box([1, 2, 3])) == "Box((1.0, 2.0, 3.0))"
    assert repr(bvhkit.Capsule(1, 2)) == "Capsule(1.0, 2.0)"
    assert repr(shapes[-1]) == "ConvexHull(<8 vertices>)"
    cone = bvhkit.Cone(1, 3)
    assert (cone.radius, cone.height) == (1.0, 3.0)
    assert cone.bounding_radius == pytest.approx(np.hypot(1, 1.5))
    with pytest.raises(AttributeError):
        cone.radius = 2.0
    assert not shapes[-1].vertices.flags.writeable


def test_degenerate_shapes_are_valid():
    point, dot = bvhkit.ConvexHull([[0, 0, 0]]), bvhkit.Sphere(0)
    assert dist(point, dot, [3, 4, 0])[0] == pytest.approx(5, abs=1e-14)
    square = bvhkit.ConvexHull(CUBE[:4] * [0, 1, 1])  # flat, in x = 0
    s, pa, pb, n, ok = signed(square, bvhkit.Sphere(1), [0.25, 0, 0])
    assert s == pytest.approx(-0.75, abs=1e-12)  # out along +x: 1 - 0.25
    np.testing.assert_allclose(n, [1, 0, 0], atol=1e-12)


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("make, message", [
    (lambda: bvhkit.Sphere(-1), "radius"),
    (lambda: bvhkit.Sphere(float("nan")), "radius"),
    (lambda: bvhkit.Capsule(1, float("inf")), "half_length"),
    (lambda: bvhkit.Cylinder(1, -0.5), "half_height"),
    (lambda: bvhkit.Cone(-1, 1), "radius"),
    (lambda: bvhkit.Cone(1, float("nan")), "height"),
    (lambda: bvhkit.Box([1, -1, 1]), "half_extents"),
    (lambda: bvhkit.Box([1, float("nan"), 1]), "half_extents"),
    (lambda: bvhkit.Box([1, 1]), "half_extents"),
    (lambda: bvhkit.ConvexHull(np.empty((0, 3))), "points"),
    (lambda: bvhkit.ConvexHull([]), "points"),
    (lambda: bvhkit.ConvexHull([[0, 0, 0], [1, np.nan, 0]]), "points: row 1"),
    (lambda: bvhkit.ConvexHull(np.ones((4, 2))), "points"),
])
def test_bad_shapes_raise_value_error_naming_the_argument(make, message):
    with pytest.raises(ValueError, match=message):
        make()


@pytest.mark.parametrize("make, message", [
    (lambda: bvhkit.Sphere("1"), "radius"),
    (lambda: bvhkit.Sphere(None), "radius"),
    (lambda: bvhkit.Capsule(1, True), "half_length"),
    (lambda: bvhkit.Box("abc"), "half_extents"),
    (lambda: bvhkit.Box([True, False, True]), "half_extents"),
    (lambda: bvhkit.ConvexHull([["a", "b", "c"]]), "points"),
    (lambda: bvhkit.ConvexShape(), "ConvexShape"),
])
def test_wrong_types_raise_type_error_naming_the_argument(make, message):
    with pytest.raises(TypeError, match=message):
        make()


@pytest.mark.parametrize("f", [bvhkit.convex_distance, bvhkit.convex_signed_distance])
def test_bad_poses_and_arguments(f):
    a, b = bvhkit.Sphere(1), bvhkit.Box([1, 1, 1])
    t = np.zeros((2, 3))
    r = np.stack([I3, I3])
    with pytest.raises(TypeError, match="a: must be a ConvexShape"):
        f("sphere", b, r, t)
    with pytest.raises(TypeError, match="b: must be a ConvexShape"):
        f(a, None, r, t)
    with pytest.raises(ValueError, match="translations: row 1"):
        f(a, b, r, [[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(ValueError, match="rotations: rotation 1 has a NaN"):
        f(a, b, np.stack([I3, I3 * np.nan]), t)
    with pytest.raises(ValueError, match="rotations: rotation 0 is not a rotation"):
        f(a, b, np.stack([I3 * 2, I3]), t)
    with pytest.raises(ValueError, match="rotations: rotation 1 is not a rotation"):
        f(a, b, np.stack([I3, np.diag([1.0, 1, -1])]), t)  # a mirror
    with pytest.raises(ValueError, match="rotations: shape"):
        f(a, b, np.eye(4), t)
    with pytest.raises(ValueError, match="translations: shape"):
        f(a, b, r, np.zeros((2, 2)))
    with pytest.raises(ValueError, match="translations: 2 rows, rotations has 3"):
        f(a, b, np.stack([I3, I3, I3]), t)
    with pytest.raises(TypeError, match="threads"):
        f(a, b, r, t, threads=1.5)
    with pytest.raises(ValueError, match="threads"):
        f(a, b, r, t, threads=-1)
    # bad values reported in the documented order: the translation first
    with pytest.raises(ValueError, match="translations"):
        f(a, b, np.stack([I3 * 2, I3]), [[0, 0, 0], [np.inf, 0, 0]])


def test_convex_against_a_mesh_matches_the_analytic_box_distance():
    """A sphere and a capsule against a closed box mesh [-1, 1]^3 (OBB and AABB trees): the
    distance is the analytic distance from the centre (from the segment, found by dense sampling
    and checked within its spacing) to the box, less the radius, and 0 where they meet."""
    v, f = box_mesh([-1, -1, -1], [1, 1, 1])
    rng = np.random.default_rng(5)
    k = 400
    centres = rng.uniform(-1.8, 1.8, (k, 3))
    rotations = random_rotations(rng, k)

    def box_distance(p):
        return np.linalg.norm(np.maximum(np.abs(p) - 1, 0), axis=-1)

    for volume in ("obb", "aabb", "rss"):
        mesh = bvhkit.CollisionModel(v, f, volume=volume, dtype=np.float64)
        d = bvhkit.convex_mesh_distance(bvhkit.Sphere(0.5), mesh, rotations, centres)
        # The surface distance: outside the box it is the box distance; inside, the distance to
        # the nearest face (the mesh is a surface: a sphere inside the box meets it only if it
        # reaches a face).
        inside = np.all(np.abs(centres) < 1, axis=1)
        surface = np.where(inside, 1 - np.abs(centres).max(axis=1), box_distance(centres))
        np.testing.assert_allclose(d.distance, np.maximum(surface - 0.5, 0), atol=1e-9)
        np.testing.assert_array_equal(d.overlap, surface <= 0.5)
        gap = np.linalg.norm(d.point_mesh - d.point_shape, axis=1)
        np.testing.assert_allclose(gap, d.distance, atol=1e-9)
        assert np.all(np.abs(d.point_mesh).max(axis=1) > 1 - 1e-9)  # on the box's surface
        assert ((0 <= d.face) & (d.face < len(f))).all()
        clear = np.abs(surface - 0.5) > 1e-6
        np.testing.assert_array_equal(
            bvhkit.convex_mesh_collides(bvhkit.Sphere(0.5), mesh, rotations, centres)[clear],
            d.overlap[clear])
        assert 50 < d.overlap.sum() < k - 50
        # A capsule: its segment's distance to the surface by sampling the segment densely.
        cap = bvhkit.convex_mesh_distance(bvhkit.Capsule(0.2, 0.5), mesh, rotations, centres)
        s = np.linspace(-0.5, 0.5, 2001)
        axis = rotations[:, :, 2]
        pts = centres[:, None, :] + s[None, :, None] * axis[:, None, :]
        inside = np.all(np.abs(pts) < 1, axis=2)
        surf = np.where(inside, 1 - np.abs(pts).max(axis=2), box_distance(pts))
        crosses = inside.any(axis=1) & (~inside).any(axis=1)
        sampled = np.where(crosses, 0, surf.min(axis=1))
        np.testing.assert_allclose(cap.distance, np.maximum(sampled - 0.2, 0), atol=1e-3)
        assert np.all(cap.distance <= np.maximum(sampled - 0.2, 0) + 1e-9)  # samples: upper bounds


def test_convex_against_a_mesh_bad_arguments():
    v, f = box_mesh([-1, -1, -1], [1, 1, 1])
    mesh64 = bvhkit.CollisionModel(v, f, dtype=np.float64)
    mesh32 = bvhkit.CollisionModel(v, f)
    with pytest.raises(TypeError, match="mesh"):
        bvhkit.convex_mesh_distance(bvhkit.Sphere(1), mesh32, None, [0, 0, 0])
    with pytest.raises(TypeError, match="mesh"):
        bvhkit.convex_mesh_collides(bvhkit.Sphere(1), "mesh", None, [0, 0, 0])
    with pytest.raises(TypeError, match="shape"):
        bvhkit.convex_mesh_distance(mesh64, mesh64, None, [0, 0, 0])
    with pytest.raises(ValueError, match="translations"):
        bvhkit.convex_mesh_distance(bvhkit.Sphere(1), mesh64, None, [0, np.nan, 0])
    with pytest.raises(ValueError, match="rotations"):
        bvhkit.convex_mesh_collides(bvhkit.Sphere(1), mesh64, np.eye(3) * 2, [0, 0, 0])
    one = bvhkit.convex_mesh_distance(bvhkit.Box([0.5, 0.5, 0.5]), mesh64, None, [3, 0, 0])
    assert one.distance.shape == (1,) and one.distance[0] == pytest.approx(1.5, abs=1e-12)
