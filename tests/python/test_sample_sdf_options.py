"""python -m bvhkit sample-sdf's options for occupancy networks and DeepSDF: several noise levels
with their shares, the uniform share, occupancy labels, closest points and normals, and the
normalisation to the unit sphere or cube. Judged on a box, whose signed distance, closest points
and normals are known in closed form, and by the counts and spreads the options ask for."""

import json

import numpy as np
import pytest

from bvhkit import sample_sdf

CENTRE = np.array([10.0, -20.0, 30.0])
HALF = np.array([1.0, 0.5, 0.25])  # a box of sides 2, 1 and 1/2, off the origin


def box_mesh():
    """The box's 8 corners and 12 outward-wound triangles."""
    s = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    v = CENTRE + s * HALF
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = []
    for a, b, c, d in quads:
        f += [(a, b, c), (a, c, d)]
    # Outward: each triangle's normal points away from the centre.
    for i, (a, b, c) in enumerate(f):
        n = np.cross(v[b] - v[a], v[c] - v[a])
        if np.dot(n, (v[a] + v[b] + v[c]) / 3 - CENTRE) < 0:
            f[i] = (a, c, b)
    return v, np.array(f)


def box_sdf(p, centre, half):
    """The exact signed distance to an axis-aligned box (negative inside)."""
    q = np.abs(p - centre) - half
    outside = np.linalg.norm(np.maximum(q, 0), axis=1)
    inside = np.minimum(q.max(axis=1), 0)
    return outside + inside


@pytest.fixture(scope="module")
def box_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("box")
    v, f = box_mesh()
    with open(d / "box.obj", "w") as out:
        out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in v.tolist())
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f.tolist())
    return d


def sample(box_dir, out, *extra, points=4000):
    status = sample_sdf.main([str(box_dir), "--out", str(out), "--points", str(points),
                              "--seed", "2", *extra])
    assert status == 0
    with np.load(out / "box.npz") as z:
        return {k: z[k] for k in z.files}


def test_default_options_record_only_the_original_keys(box_dir, tmp_path):
    z = sample(box_dir, tmp_path / "a")
    meta = json.loads(str(z["meta"]))
    assert set(meta) == {"format", "mesh", "mesh_sha256", "points", "near_surface", "seed"}
    assert set(z) == {"points", "sdf", "meta"}
    # The same recipe spelled out in full writes the same bytes.
    sample(box_dir, tmp_path / "b", "--near-surface", "0.01:0.5", "--uniform", "0.5")
    assert (tmp_path / "a" / "box.npz").read_bytes() == (tmp_path / "b" / "box.npz").read_bytes()


def test_levels_get_their_shares_and_spreads(box_dir, tmp_path):
    n = 20000
    z = sample(box_dir, tmp_path, "--near-surface", "0.001:0.3,0.05:0.2", points=n)
    meta = json.loads(str(z["meta"]))
    assert meta["near_surface"] == [[0.001, 0.3], [0.05, 0.2]] and meta["uniform"] == 0.5
    diagonal = 2 * np.linalg.norm(HALF)
    truth = box_sdf(z["points"].astype(np.float64), CENTRE, HALF)
    uniform, first, second = truth[: n // 2], truth[n // 2 : n // 2 + 6000], truth[n // 2 + 6000 :]
    assert len(second) == 4000
    # Gaussian noise of deviation s off a flat face: the distance is half-normal, median 0.674 s;
    # near edges and corners a little less.
    for d, sigma in ((first, 0.001), (second, 0.05)):
        ratio = np.median(np.abs(d)) / (sigma * diagonal)
        assert 0.45 < ratio < 0.8, ratio
    # The uniform part lies in the box grown by 5% of its size on every side, and fills it.
    offsets = np.abs(z["points"][: n // 2].astype(np.float64) - CENTRE)
    assert np.all(offsets <= 1.1 * HALF * (1 + 1e-6))
    assert np.all(offsets.max(axis=0) > 1.05 * HALF)
    assert 0.2 < np.mean(uniform < 0) < 0.9  # the box is 75% of the grown one's volume


def test_occupancy_closest_points_and_normals_match_the_box(box_dir, tmp_path):
    z = sample(box_dir, tmp_path, "--outputs", "normals,occupancy,closest", points=6000)
    p = z["points"].astype(np.float64)
    truth = box_sdf(p, CENTRE, HALF)
    assert json.loads(str(z["meta"]))["outputs"] == ["occupancy", "normals", "closest"]
    assert z["occupancy"].dtype == np.uint8 and z["closest"].dtype == np.float32
    clear = np.abs(truth) > 1e-5
    assert np.array_equal(z["occupancy"][clear], (truth[clear] < 0).astype(np.uint8))
    # Outside, the closest point of a box is the point clamped to it.
    out = truth > 1e-5
    clamped = np.clip(p[out], CENTRE - HALF, CENTRE + HALF)
    assert np.abs(z["closest"][out] - clamped).max() < 1e-5
    # Outside a face (one coordinate beyond the box, the others clear of its edges), the normal
    # is that face's axis.
    offset = np.abs(p - CENTRE)
    beyond = offset > HALF + 1e-4
    face_region = out & (beyond.sum(axis=1) == 1) & ((beyond | (offset < HALF - 1e-4)).all(axis=1))
    axis = np.argmax(beyond[face_region], axis=1)
    expected = np.zeros((face_region.sum(), 3))
    expected[np.arange(len(axis)), axis] = np.sign((p[face_region] - CENTRE)[np.arange(len(axis)),
                                                                               axis])
    assert face_region.sum() > 100
    assert np.abs(z["normals"][face_region] - expected).max() < 1e-6
    assert np.allclose(np.linalg.norm(z["normals"], axis=1), 1, atol=1e-6)


@pytest.mark.parametrize("how", ["sphere", "cube"])
def test_normalized_outputs_are_in_the_unit_frame(box_dir, tmp_path, how):
    z = sample(box_dir, tmp_path, "--normalize", how, "--outputs", "closest")
    scale = 1 / np.linalg.norm(HALF) if how == "sphere" else 1 / (2 * HALF.max())
    assert np.allclose(z["offset"], CENTRE, rtol=0, atol=1e-12)
    assert abs(float(z["scale"]) - scale) < 1e-12 * scale
    meta = json.loads(str(z["meta"]))
    assert meta["normalize"] == how and abs(meta["scale"] - scale) < 1e-12 * scale
    # The sdf is the normalized box's: centred at the origin, half sides times the scale.
    truth = box_sdf(z["points"].astype(np.float64), np.zeros(3), HALF * scale)
    assert np.abs(z["sdf"] - truth).max() < 1e-5
    # Mapping back gives the mesh's own coordinates.
    world = z["closest"].astype(np.float64) / z["scale"] + z["offset"]
    assert np.all(np.abs(world - CENTRE) <= HALF + 1e-5)


def test_rerun_with_other_options_is_refused(box_dir, tmp_path, capsys):
    sample(box_dir, tmp_path, "--outputs", "occupancy")
    assert sample_sdf.main([str(box_dir), "--out", str(tmp_path), "--points", "4000",
                            "--seed", "2"]) == 1
    assert "--outputs" in capsys.readouterr().err
    assert sample_sdf.main([str(box_dir), "--out", str(tmp_path), "--points", "4000",
                            "--seed", "2", "--outputs", "occupancy"]) == 0


@pytest.mark.parametrize("extra, message", [
    (["--near-surface", "0.01:0.3,0.02"], "every level or to none"),
    (["--near-surface", "0.01:0.3", "--uniform", "0.5"], "must sum to 1"),
    (["--near-surface", "0.01:0.7,0.02:0.7"], "must sum to 1"),
    (["--near-surface", "0.01:x"], "share must be a number"),
    (["--outputs", "colour"], "unknown output"),
    (["--uniform", "1.5"], "from 0 to 1"),
    (["--normalize", "ball"], "invalid choice"),
])
def test_bad_options_are_named(box_dir, tmp_path, capsys, extra, message):
    with pytest.raises(SystemExit) as e:
        sample_sdf.main([str(box_dir), "--out", str(tmp_path), "--points", "10", *extra])
    assert e.value.code == 2
    assert message in capsys.readouterr().err
