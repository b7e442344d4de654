"""python -m bvhkit sample-sdf: the same bytes for any number of workers, signs from the winding
number, a broken mesh reported without stopping the others, reruns skipping finished meshes."""

import os
import subprocess
import sys

import numpy as np
import pytest

import bvhkit
from bvhkit import sample_sdf

MESHES = {"sphere": "sphere:subdiv=3", "torus": "torus:u=24,v=12", "terrain": "terrain:n=16"}
POINTS = 3000


def write_obj(path, v, f):
    with open(path, "w") as out:
        out.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in v.tolist())
        out.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f.tolist())


@pytest.fixture(scope="module")
def mesh_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("meshes")
    for name, spec in MESHES.items():
        write_obj(d / f"{name}.obj", *bvhkit.load_mesh(spec))
    (d / "broken.obj").write_text("v 0 0 0\nv 1 0\nf 1 2 3\n")
    (d / "notes.txt").write_text("not a mesh")
    return d


def run(mesh_dir, out, *extra):
    cmd = [sys.executable, "-m", "bvhkit", "sample-sdf", str(mesh_dir), "--out", str(out)]
    cmd += ["--points", str(POINTS), "--seed", "5", *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


def files(d):
    return {p: (d / p).read_bytes() for p in sorted(os.listdir(d))}


def test_workers_write_the_same_bytes_and_broken_meshes_are_reported(mesh_dir, tmp_path):
    pytest.importorskip("distributed")
    outs = {}
    for scheduler in ("local:1", "local:2"):
        r = run(mesh_dir, tmp_path / scheduler, "--scheduler", scheduler)
        assert r.returncode == 1, r.stderr
        assert "FAILED broken.obj" in r.stderr
        assert "3 of 4 meshes written" in r.stdout
        outs[scheduler] = files(tmp_path / scheduler)
    assert list(outs["local:1"]) == ["sphere.npz", "terrain.npz", "torus.npz"]
    assert outs["local:1"] == outs["local:2"]
    # And this process, without Dask, writes them too.
    assert sample_sdf.main([str(mesh_dir), "--out", str(tmp_path / "here"), "--points",
                            str(POINTS), "--seed", "5"]) == 1
    assert files(tmp_path / "here") == outs["local:1"]


def test_samples_are_signed_by_the_winding_number(mesh_dir, tmp_path):
    assert sample_sdf.main([str(mesh_dir), "--out", str(tmp_path), "--points", str(POINTS)]) == 1
    for name in MESHES:
        with np.load(tmp_path / f"{name}.npz") as z:
            p, sdf = z["points"], z["sdf"]
        assert p.dtype == np.float32 and p.shape == (POINTS, 3)
        assert sdf.dtype == np.float32 and sdf.shape == (POINTS,)
        scene = bvhkit.TriangleMesh(*bvhkit.load_mesh(str(mesh_dir / f"{name}.obj")))
        uniform = p[: POINTS // 2]
        np.testing.assert_array_equal(
            np.signbit(sdf[: POINTS // 2]), scene.winding_number(uniform) > 0.5
        )
        np.testing.assert_array_equal(np.abs(sdf), scene.closest_point(p).distance)
        # The near half is near: noise of 0.01 diagonal, so well within 0.05 diagonal.
        lo, hi = uniform.min(axis=0), uniform.max(axis=0)
        assert np.all(np.abs(sdf[POINTS // 2 :]) < 0.05 * np.linalg.norm(hi - lo))
    sphere = np.load(tmp_path / "sphere.npz")["sdf"][: POINTS // 2]
    assert 0.1 < np.mean(sphere < 0) < 0.9  # both signs occur


def test_rerun_skips_finished_meshes_and_seeds_matter(mesh_dir, tmp_path):
    out = tmp_path / "out"
    args = [str(mesh_dir), "--out", str(out), "--points", "100"]
    assert sample_sdf.main(args) == 1
    before = {p: os.stat(out / p).st_mtime_ns for p in os.listdir(out)}
    os.remove(out / "torus.npz")
    r = run(mesh_dir, out)
    assert r.stdout.count("exists") == 2 and "torus.obj: 3000 samples" in r.stdout
    for p in ("sphere.npz", "terrain.npz"):
        assert os.stat(out / p).st_mtime_ns == before[p]
    other = tmp_path / "seed1"
    sample_sdf.main(args[:1] + ["--out", str(other), "--points", "100", "--seed", "1"])
    assert files(other)["sphere.npz"] != files(out)["sphere.npz"]


def test_bad_arguments(mesh_dir, tmp_path, capsys):
    for extra in (["--points", "0"], ["--points", "10", "--scheduler", "local:0"],
                  ["--points", "10", "--near-surface", "-1"]):
        with pytest.raises(SystemExit) as e:
            sample_sdf.main([str(mesh_dir), "--out", str(tmp_path), *extra])
        assert e.value.code == 2
    with pytest.raises(SystemExit):
        sample_sdf.main([str(tmp_path / "absent"), "--out", str(tmp_path), "--points", "10"])
    assert "MESH_DIR" in capsys.readouterr().err
    r = subprocess.run([sys.executable, "-m", "bvhkit", "frobnicate"], capture_output=True,
                       text=True)
    assert r.returncode == 2 and "unknown command" in r.stderr


def test_two_files_with_one_name_are_reported(tmp_path, capsys):
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    write_obj(meshes / "x.obj", *bvhkit.load_mesh("sphere:subdiv=1"))
    (meshes / "x.ply").write_text("not read")
    assert sample_sdf.main([str(meshes), "--out", str(tmp_path / "out"), "--points", "10"]) == 1
    assert "FAILED x.ply: writes x.npz as x.obj does" in capsys.readouterr().err
    assert os.listdir(tmp_path / "out") == ["x.npz"]
