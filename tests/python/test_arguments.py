"""Every public function checks each scalar argument's kind and range and names the argument:
thread counts, numbers, flags, option names, limits (None = no limit) and paths; the package's
namespace holds its API alone, and its annotations are the types the checks enforce."""

import importlib.util
import subprocess
import sys
import textwrap
import typing

import numpy as np
import numpy.typing as npt
import pytest

import bvhkit
from bvhkit import _arrays

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
F = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
P = np.array([[0.2, 0.2, 0.2], [2.0, 2.0, 2.0]])
O, D = np.array([[0.2, 0.2, -1.0]]), np.array([[0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def scene():
    return bvhkit.TriangleMesh(V, F)


@pytest.fixture(scope="module")
def model():
    return bvhkit.CollisionModel(V, F)


POSE = (np.eye(3)[None], np.zeros((1, 3)))

# Every public call that takes threads=, as f(threads) on the fixtures.
THREADED = {
    "TriangleMesh": lambda s, m, n: bvhkit.TriangleMesh(V, F, threads=n),
    "intersect": lambda s, m, n: s.intersect(O, D, threads=n),
    "occluded": lambda s, m, n: s.occluded(O, D, threads=n),
    "count_intersections": lambda s, m, n: s.count_intersections(O, D, threads=n),
    "closest_point": lambda s, m, n: s.closest_point(P, threads=n),
    "signed_distance": lambda s, m, n: s.signed_distance(P, threads=n),
    "winding_number": lambda s, m, n: s.winding_number(P, threads=n),
    "contains": lambda s, m, n: s.contains(P, threads=n),
    "from_bytes": lambda s, m, n: bvhkit.TriangleMesh.from_bytes(s.to_bytes(), threads=n),
    "CollisionModel": lambda s, m, n: bvhkit.CollisionModel(V, F, threads=n),
    "collide": lambda s, m, n: bvhkit.collide(m, m, *POSE, threads=n),
    "collide contacts": lambda s, m, n: bvhkit.collide(m, m, *POSE, contacts=True, threads=n),
    "distance": lambda s, m, n: bvhkit.distance(m, m, *POSE, threads=n),
    "DynamicTree.query": lambda s, m, n: bvhkit.DynamicTree3D().query(P, P, threads=n),
    "DynamicTree.ray_cast": lambda s, m, n: bvhkit.DynamicTree3D().ray_cast(O, D, threads=n),
}


@pytest.mark.parametrize("call", THREADED.values(), ids=THREADED.keys())
@pytest.mark.parametrize(
    "threads,error",
    [(2**32, ValueError), (2**64, ValueError), (-1, ValueError), ("2", TypeError),
     (2.0, TypeError), (True, TypeError), (None, TypeError)],
)
def test_threads_out_of_range_or_not_an_int_name_threads(scene, model, call, threads, error):
    with pytest.raises(error, match="threads"):
        call(scene, model, threads)


@pytest.mark.parametrize("call", THREADED.values(), ids=THREADED.keys())
def test_every_thread_count_up_to_the_limit_is_accepted(scene, model, call):
    for n in (0, 1, np.int64(3), 2**32 - 1):
        call(scene, model, n)


# (call, error, the argument's name): a str where a number belongs, a truthy stand-in for a bool,
# an option that is not a str, a path that is not one.
BAD = [
    (lambda s, m: s.intersect(O, D, tmin="0"), TypeError, "tmin"),
    (lambda s, m: s.intersect(O, D, tmax="1"), TypeError, "tmax"),
    (lambda s, m: s.occluded(O, D, tmax=["a"]), TypeError, "tmax"),
    (lambda s, m: s.count_intersections(O, D, tmin=None), TypeError, "tmin"),
    (lambda s, m: s.intersect(O, D, tmax=True), TypeError, "tmax"),
    (lambda s, m: s.intersect(O, D, tmin=np.array([False])), TypeError, "tmin"),
    (lambda s, m: s.closest_point(P, max_distance="1"), TypeError, "max_distance"),
    (lambda s, m: s.closest_point(P, max_distance=[1.0]), TypeError, "max_distance"),
    (lambda s, m: s.closest_point(P, max_distance=10**400), ValueError, "max_distance"),
    (lambda s, m: s.winding_number(P, exact="no"), TypeError, "exact"),
    (lambda s, m: s.winding_number(P, exact=1), TypeError, "exact"),
    (lambda s, m: s.winding_number(P, exact=None), TypeError, "exact"),
    (lambda s, m: s.winding_number(P, beta="2"), TypeError, "beta"),
    (lambda s, m: s.winding_number(P, beta=np.inf), ValueError, "beta"),
    (lambda s, m: s.signed_distance(P, sign=1), TypeError, "sign"),
    (lambda s, m: s.signed_distance(P, sign=np.array(["pseudonormal"])), TypeError, "sign"),
    (lambda s, m: bvhkit.TriangleMesh(V, F, builder=1), TypeError, "builder"),
    (lambda s, m: bvhkit.TriangleMesh(V, F, builder="nope"), ValueError, "builder"),
    (lambda s, m: bvhkit.TriangleMesh(V, F, ray_test=None), TypeError, "ray_test"),
    (lambda s, m: bvhkit.TriangleMesh(V, F, spatial_splits="yes"), TypeError, "spatial_splits"),
    (lambda s, m: bvhkit.TriangleMesh(V, F, spatial_splits=0), TypeError, "spatial_splits"),
    (lambda s, m: s.save(3), TypeError, "path"),
    (lambda s, m: bvhkit.TriangleMesh.load(None), TypeError, "path"),
    (lambda s, m: bvhkit.CollisionModel(V, F, volume=1), TypeError, "volume"),
    (lambda s, m: bvhkit.CollisionModel(V, F, volume="box"), ValueError, "volume"),
    (lambda s, m: m.save(3.5), TypeError, "path"),
    (lambda s, m: bvhkit.CollisionModel.load(3), TypeError, "path"),
    (lambda s, m: bvhkit.collide(m, m, *POSE, contacts="no"), TypeError, "contacts"),
    (lambda s, m: bvhkit.collide(m, m, *POSE, contacts=0), TypeError, "contacts"),
    (lambda s, m: bvhkit.distance(m, m, *POSE, absolute_tolerance="0"), TypeError,
     "absolute_tolerance"),
    (lambda s, m: bvhkit.distance(m, m, *POSE, relative_tolerance=None), TypeError,
     "relative_tolerance"),
    (lambda s, m: bvhkit.DynamicTree3D(margin="0.1"), TypeError, "margin"),
    (lambda s, m: bvhkit.DynamicTree2D(margin_relative=None), TypeError, "margin_relative"),
    (lambda s, m: bvhkit.DynamicTree3D(displacement_multiplier=True), TypeError,
     "displacement_multiplier"),
    (lambda s, m: bvhkit.DynamicTree3D().ray_cast(O, D, max_fraction="1"), TypeError,
     "max_fraction"),
    (lambda s, m: bvhkit.DynamicTree3D().ray_cast(O, D, max_fraction=None), TypeError,
     "max_fraction"),
    (lambda s, m: bvhkit.load_mesh(None), TypeError, "path_or_spec"),
]


@pytest.mark.parametrize("call,error,name", BAD)
def test_bad_scalar_arguments_name_the_argument(scene, model, call, error, name):
    with pytest.raises(error, match=name):
        call(scene, model)


def test_none_means_no_limit_for_tmax_and_max_distance(scene):
    o = np.array([[0.2, 0.2, -1.0], [5, 5, -1.0], [0.2, 0.2, -1e6]])
    d = np.tile([0.0, 0.0, 1.0], (3, 1))
    want = scene.intersect(o, d)
    assert want.face[0] >= 0 and want.face[2] >= 0  # hits, also from far away
    for got in (scene.intersect(o, d, tmax=None), scene.intersect(o, d, 0.0, None)):
        np.testing.assert_array_equal(got.t, want.t)
        np.testing.assert_array_equal(got.face, want.face)
    np.testing.assert_array_equal(scene.occluded(o, d, tmax=None), [True, False, True])
    np.testing.assert_array_equal(scene.count_intersections(o, d, tmax=None), [2, 0, 2])
    far = np.array([[1e20, 0, 0]])
    assert scene.closest_point(far, max_distance=None).face[0] >= 0
    np.testing.assert_array_equal(scene.closest_point(P, max_distance=None).distance,
                                  scene.closest_point(P).distance)


def test_real_bools_and_numbers_of_every_kind_are_accepted(scene, model):
    w = scene.winding_number(P, exact=True)
    np.testing.assert_array_equal(scene.winding_number(P, exact=np.bool_(True)), w)
    np.testing.assert_array_equal(scene.winding_number(P, exact=True, beta=np.float32(2)), w)
    for md in (1, 1.0, np.float32(1), np.int64(1), np.array(1.0)):
        np.testing.assert_array_equal(scene.closest_point(P, max_distance=md).face,
                                      scene.closest_point(P, max_distance=1.0).face)
    for t in (2, np.float64(2.0), np.array(2.0), np.array([2.0])):
        np.testing.assert_array_equal(scene.intersect(O, D, tmax=t).t, scene.intersect(O, D).t)
    assert bvhkit.collide(model, model, *POSE, contacts=np.bool_(False)).dtype == np.bool_
    bvhkit.distance(model, model, *POSE, absolute_tolerance=np.float32(0), relative_tolerance=0)
    bvhkit.DynamicTree2D(margin=np.float64(0.5), margin_relative=0, displacement_multiplier=2)


def test_dask_functions_check_as_the_scene_does(scene):
    pytest.importorskip("dask")
    import bvhkit.dask as bd

    with pytest.raises(TypeError, match="exact"):
        bd.winding_number(scene, P, exact="no")
    with pytest.raises(TypeError, match="beta"):
        bd.winding_number(scene, P, beta="2")
    with pytest.raises(TypeError, match="max_distance"):
        bd.closest_point(scene, P, max_distance="1")
    with pytest.raises(TypeError, match="tmin"):
        bd.intersect(scene, O, D, tmin="0")
    with pytest.raises(TypeError, match="sign"):
        bd.signed_distance(scene, P, sign=3)
    with pytest.raises(ValueError, match="threads"):
        bd.occluded(scene, O, D, threads=2**32)
    got = bd.intersect(scene, O, D, tmax=None)[0].compute()
    np.testing.assert_array_equal(got, scene.intersect(O, D).t)
    got = bd.closest_point(scene, P, max_distance=None).distance.compute()
    np.testing.assert_array_equal(got, scene.closest_point(P).distance)


# ---------------------------------------------------------------- the namespace and the types


def test_the_namespace_holds_the_api_alone():
    for name in ("np", "Any", "NamedTuple", "annotations", "typing", "os", "numbers"):
        assert not hasattr(bvhkit, name), name
    for name in dir(bvhkit):
        if name.startswith("_"):
            continue
        value = getattr(bvhkit, name)
        is_submodule = getattr(value, "__name__", "").startswith("bvhkit.") and isinstance(
            value, type(bvhkit)
        )
        assert name in bvhkit.__all__ or is_submodule, name
    for name in bvhkit.__all__:
        assert hasattr(bvhkit, name), name


def public_callables():
    for name in bvhkit.__all__:
        obj = getattr(bvhkit, name)
        if isinstance(obj, type):
            yield name, obj.__init__
            for attr, member in vars(obj).items():
                member = getattr(member, "__func__", member)
                if callable(member) and not attr.startswith("_"):
                    yield f"{name}.{attr}", member
        else:
            yield name, obj


def test_every_annotation_resolves():
    for name, f in public_callables():
        typing.get_type_hints(f)  # a NameError here: an annotation naming what is not imported


def test_options_are_literals_that_match_the_checks():
    hints = typing.get_type_hints(bvhkit.TriangleMesh.__init__)
    assert typing.get_args(hints["ray_test"]) == _arrays.RAY_TESTS == ("watertight", "fast")
    builders = typing.get_args(hints["builder"])
    assert hints["vertices"] == npt.ArrayLike and hints["faces"] == npt.ArrayLike
    sign = typing.get_type_hints(bvhkit.TriangleMesh.signed_distance)["sign"]
    assert typing.get_args(sign) == _arrays.SIGNS == ("pseudonormal", "winding_number")
    volume = typing.get_type_hints(bvhkit.CollisionModel.__init__)["volume"]
    assert set(typing.get_args(volume)) == {"obb", "rss", "obbrss", "aabb", "sphere", "kdop18",
                                            "hull"}
    for name in ("origins", "directions", "tmin"):
        assert typing.get_type_hints(bvhkit.TriangleMesh.intersect)[name] == npt.ArrayLike
    # The builders the C++ library parses (its error lists them), spelt with underscores, are
    # the Literal's names, and each builds.
    with pytest.raises(ValueError) as e:
        bvhkit.TriangleMesh(V, F, builder="nope")
    listed = str(e.value).split("valid: ")[1].replace("top-down[+opt]", "top-down, top-down+opt")
    assert {b.strip().replace("-", "_") for b in listed.split(",")} == set(builders)
    for b in builders:
        assert bvhkit.TriangleMesh(V, F, builder=b).intersect(O, D).face[0] >= 0, b


@pytest.mark.skipif(not hasattr(typing, "get_overloads"), reason="typing.get_overloads: 3.11+")
def test_collide_is_overloaded_on_contacts():
    overloads = typing.get_overloads(bvhkit.collide)
    returns = {}
    for f in overloads:
        h = typing.get_type_hints(f)
        returns[h["contacts"]] = h["return"]
    assert returns[typing.Literal[False]] == np.ndarray
    assert returns[typing.Literal[True]] == typing.List[np.ndarray]


MYPY_SNIPPET = """\
    import numpy as np
    import bvhkit

    m = bvhkit.CollisionModel(np.zeros((3, 3)), [[0, 1, 2]], volume="rss")
    hit: np.ndarray = bvhkit.collide(m, m, None, np.zeros((1, 3)))
    pairs: list[np.ndarray] = bvhkit.collide(m, m, None, [[0.0, 0, 0]], contacts=True)
    s = bvhkit.TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], ray_test="fast")
    s.signed_distance([[0.0, 0, 0]], sign="winding_number")
    s.intersect([[0.0, 0, 0]], [[0.0, 0, 1]], tmax=None)
    bvhkit.TriangleMesh(np.zeros((3, 3)), [[0, 1, 2]], ray_test="slow")  # line 10: an error
    wrong: np.ndarray = bvhkit.collide(m, m, None, np.zeros((1, 3)), contacts=True)  # line 11
    bvhkit.np  # line 12: an error
"""


@pytest.mark.skipif(importlib.util.find_spec("mypy") is None, reason="mypy is not installed")
def test_mypy_reads_the_annotations(tmp_path, pytestconfig):
    src = tmp_path / "use.py"
    src.write_text(textwrap.dedent(MYPY_SNIPPET))
    cache = pytestconfig.cache.mkdir("bvhkit-mypy")  # numpy's stubs read once, not every run
    r = subprocess.run(
        [sys.executable, "-m", "mypy", "--no-error-summary", "--cache-dir", cache,
         str(src)],
        capture_output=True, text=True, cwd=tmp_path,
    )
    lines = {int(line.split(":")[1]) for line in r.stdout.splitlines() if ": error:" in line}
    assert lines == {10, 11, 12}, r.stdout + r.stderr
