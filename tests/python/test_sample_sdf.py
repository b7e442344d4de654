"""python -m bvhkit sample-sdf: the same bytes for any number of workers, signs from the winding
number, a broken mesh reported without stopping the others, reruns skipping finished meshes and
refusing outputs of other parameters or meshes, write failures reported with no partial file."""

import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

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
    args = [str(mesh_dir), "--out", str(out), "--points", str(POINTS), "--seed", "5"]
    assert sample_sdf.main(args) == 1
    first = files(out)
    before = {p: os.stat(out / p).st_mtime_ns for p in first}
    os.remove(out / "torus.npz")
    r = run(mesh_dir, out)
    assert r.returncode == 1, r.stderr
    assert r.stdout.count("exists") == 2 and "torus.obj: 3000 samples" in r.stdout
    for p in ("sphere.npz", "terrain.npz"):
        assert os.stat(out / p).st_mtime_ns == before[p]
    assert files(out) == first  # the redone mesh is the same bytes
    other = tmp_path / "seed1"
    sample_sdf.main(args[:1] + ["--out", str(other), "--points", str(POINTS), "--seed", "1"])
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


def record(path):
    with np.load(path) as z:
        return json.loads(str(z["meta"]))


def meshes_copy(mesh_dir, tmp_path):
    d = tmp_path / "meshes"
    d.mkdir()
    for name in MESHES:
        shutil.copy(mesh_dir / f"{name}.obj", d)
    return d


def test_outputs_record_the_parameters_and_the_mesh(mesh_dir, tmp_path):
    assert sample_sdf.main([str(mesh_dir), "--out", str(tmp_path), "--points", "101",
                            "--near-surface", "0.02", "--seed", "7"]) == 1
    for name in MESHES:
        digest = hashlib.sha256((mesh_dir / f"{name}.obj").read_bytes()).hexdigest()
        m = record(tmp_path / f"{name}.npz")
        assert (m["points"], m["near_surface"], m["seed"]) == (101, 0.02, 7)
        assert (m["mesh"], m["mesh_sha256"]) == (f"{name}.obj", digest)


@pytest.mark.parametrize("change", [["--points", "200"], ["--seed", "6"],
                                    ["--near-surface", "0.05"], "mesh", "old file"])
def test_outputs_of_other_parameters_or_meshes_are_refused(mesh_dir, tmp_path, capsys, change):
    meshes, out = meshes_copy(mesh_dir, tmp_path), tmp_path / "out"
    args = [str(meshes), "--out", str(out), "--points", "100", "--seed", "5"]
    assert sample_sdf.main(args) == 0
    extra = change if isinstance(change, list) else []
    if change == "mesh":  # the same faces, one vertex moved
        v, f = bvhkit.load_mesh(str(meshes / "sphere.obj"))
        v[0] *= 1.1
        write_obj(meshes / "sphere.obj", v, f)
    if change == "old file":  # an output without a record, as an older bvhkit wrote them
        with np.load(out / "torus.npz") as z:
            sample_sdf.write_npz(str(out / "torus.npz"), {"points": z["points"], "sdf": z["sdf"]})
    before = files(out)
    capsys.readouterr()
    assert sample_sdf.main(args + extra) == 1
    err = capsys.readouterr().err
    assert "--overwrite" in err and "nothing written" in err
    expected = {"mesh": ["sphere.npz"], "old file": ["torus.npz"]}.get(str(change), sorted(before))
    assert sorted(re.findall(r"REFUSED (\w+\.npz)", err)) == expected
    assert files(out) == before  # nothing written, nothing removed
    # --overwrite redoes those, and they are what a fresh folder gets.
    assert sample_sdf.main(args + extra + ["--overwrite"]) == 0
    fresh = tmp_path / "fresh"
    assert sample_sdf.main([str(meshes), "--out", str(fresh), "--points", "100", "--seed", "5",
                            *extra]) == 0
    assert files(out) == files(fresh)


def test_a_killed_run_resumes_with_the_same_bytes(mesh_dir, tmp_path):
    meshes, out = meshes_copy(mesh_dir, tmp_path), tmp_path / "out"
    cmd = [sys.executable, "-m", "bvhkit", "sample-sdf", str(meshes), "--out", str(out),
           "--points", "30000"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while proc.poll() is None and time.monotonic() < deadline:
        if os.path.isdir(out) and any(p.endswith(".npz") for p in os.listdir(out)):
            break
        time.sleep(0.01)
    proc.kill()
    assert proc.wait() == -signal.SIGKILL  # killed with meshes left to do
    (out / "torus.npz.tmp999999").write_bytes(b"a killed run's half-written file")
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    fresh = tmp_path / "fresh"
    assert sample_sdf.main([str(meshes), "--out", str(fresh), "--points", "30000"]) == 0
    done = files(out)
    assert {p: b for p, b in done.items() if ".tmp" not in p} == files(fresh)


def no_temporaries(d):
    return [p for p in os.listdir(d) if ".tmp" in p] == []


@pytest.mark.parametrize("scheduler", [None, "local:1"])
def test_a_full_file_system_stops_the_run_and_leaves_no_partial_file(mesh_dir, tmp_path,
                                                                     scheduler):
    # Files beyond 16 KB are refused (EFBIG), as a full disk refuses them, for root too.
    if scheduler:
        pytest.importorskip("distributed")
    resource = pytest.importorskip("resource")

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (16384, resource.getrlimit(
            resource.RLIMIT_FSIZE)[1]))

    cmd = [sys.executable, "-m", "bvhkit", "sample-sdf", str(mesh_dir), "--out",
           str(tmp_path), "--points", str(POINTS)]
    cmd += ["--scheduler", scheduler] if scheduler else []
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, preexec_fn=limit)
    assert r.returncode == 1, r.stderr
    assert "meshes written" in r.stdout, r.stderr  # ran to its end, no uncaught OSError
    assert re.search(r"FAILED \w+\.obj: cannot write \w+\.npz", r.stderr), r.stderr
    assert "stopped" in r.stderr
    assert os.listdir(tmp_path) == []  # no .npz, no temporary


def test_a_mesh_that_cannot_be_written_is_reported_and_the_others_go_on(mesh_dir, tmp_path,
                                                                        monkeypatch, capsys):
    replace = os.replace

    def fails_for_torus(src, dst):
        if str(dst).endswith("torus.npz"):
            raise IsADirectoryError(21, "Is a directory", str(dst))
        replace(src, dst)

    monkeypatch.setattr(sample_sdf.os, "replace", fails_for_torus)
    assert sample_sdf.main([str(mesh_dir), "--out", str(tmp_path), "--points", "50"]) == 1
    err = capsys.readouterr().err
    assert "FAILED torus.obj: cannot write torus.npz" in err
    assert sorted(os.listdir(tmp_path)) == ["sphere.npz", "terrain.npz"]


def test_an_output_folder_that_cannot_be_written(mesh_dir, tmp_path, capsys):
    (tmp_path / "file").write_text("")
    for out in (tmp_path / "file", tmp_path / "file" / "out"):
        with pytest.raises(SystemExit) as e:
            sample_sdf.main([str(mesh_dir), "--out", str(out), "--points", "10"])
        assert e.value.code == 2
        assert "--out" in capsys.readouterr().err
    if os.geteuid() != 0:  # root writes into read-only folders
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o555)
        with pytest.raises(SystemExit) as e:
            sample_sdf.main([str(mesh_dir), "--out", str(ro), "--points", "10"])
        assert e.value.code == 2 and os.listdir(ro) == []


@pytest.mark.parametrize("extra", [
    ["--near-surface", "1e300"], ["--near-surface", "inf"], ["--near-surface", "nan"],
    ["--near-surface", "2"], ["--near-surface", "x"], ["--seed", "-1"], ["--seed", "1.5"],
    ["--points", "1e3"], ["--scheduler", "local:\u00b2"]])
def test_numeric_options_are_checked_when_parsed(mesh_dir, tmp_path, capsys, extra):
    with pytest.raises(SystemExit) as e:
        sample_sdf.main([str(mesh_dir), "--out", str(tmp_path / "out"), "--points", "10",
                         *extra])
    assert e.value.code == 2
    assert f"argument {extra[0]}" in capsys.readouterr().err
    assert not os.path.exists(tmp_path / "out")


def test_a_scheduler_that_cannot_be_reached(mesh_dir, tmp_path, capsys):
    pytest.importorskip("distributed")
    import dask

    for address in ("tcp://127.0.0.1:9", "no-port"):
        with dask.config.set({"distributed.comm.timeouts.connect": "0.2s"}):
            with pytest.raises(SystemExit) as e:
                sample_sdf.main([str(mesh_dir), "--out", str(tmp_path), "--points", "10",
                                 "--scheduler", address])
        assert e.value.code == 2
        assert "argument --scheduler: cannot connect" in capsys.readouterr().err
        assert os.listdir(tmp_path) == []
    # The failed clients leave no scheduler behind for the process's later dask work.
    import bvhkit.dask

    assert bvhkit.dask._active_client() is None
    assert dask.config.get("scheduler", None) != "dask.distributed"


def test_samples_beyond_float32_are_refused(tmp_path, capsys):
    # A sphere of radius 1e38: the box grown by 5% still fits float32, but noise of 0.9
    # diagonal does not, and its distances square past float32's range.
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    v, f = bvhkit.load_mesh("sphere:subdiv=1")
    write_obj(meshes / "huge.obj", v.astype(np.float64) * 1e38, f)
    out = tmp_path / "out"
    for sigma in ("0.9", "0.01"):
        status = sample_sdf.main([str(meshes), "--out", str(out / sigma), "--points", "200",
                                  "--near-surface", sigma])
        written = os.listdir(out / sigma)
        assert status == 1 or sigma != "0.9"
        if status == 1:
            assert "FAILED huge.obj" in capsys.readouterr().err and written == []
        else:
            with np.load(out / sigma / "huge.npz") as z:
                assert np.isfinite(z["points"]).all() and np.isfinite(z["sdf"]).all()
