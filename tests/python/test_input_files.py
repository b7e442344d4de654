"""Files that are not what a loader expects: a device that never ends (/dev/zero), a FIFO that never
delivers, a missing file. Each is a prompt, clear exception, never unbounded memory or a hang."""

import os
import threading

import pytest

import bvhkit


def _loaders():
    return {
        "TriangleMesh.load": bvhkit.TriangleMesh.load,
        "CollisionModel.load": bvhkit.CollisionModel.load,
        "load_mesh": bvhkit.load_mesh,
    }


@pytest.mark.parametrize("name", sorted(_loaders()))
def test_dev_zero_is_refused(name):
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero")
    with pytest.raises(ValueError, match="regular file"):
        _loaders()[name]("/dev/zero")


@pytest.mark.parametrize("name", sorted(_loaders()))
def test_fifo_is_refused_without_blocking(tmp_path, name):
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    fifo = tmp_path / "scene.obj"
    os.mkfifo(fifo)
    outcome = {}

    def load():
        try:
            _loaders()[name](fifo)
        except Exception as e:  # noqa: BLE001 - the test inspects whatever was raised
            outcome["error"] = e

    t = threading.Thread(target=load, daemon=True)
    t.start()
    t.join(10)
    if t.is_alive():
        # Release the blocked reader (a writer that opens and closes), then fail.
        fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
        t.join(10)
        pytest.fail(f"{name} blocked on a FIFO")
    assert isinstance(outcome.get("error"), ValueError), outcome
    assert "regular file" in str(outcome["error"])


@pytest.mark.parametrize("name", sorted(_loaders()))
def test_missing_file_is_file_not_found_and_value_error(tmp_path, name):
    path = tmp_path / "missing.obj"
    with pytest.raises(FileNotFoundError, match="missing.obj") as info:
        _loaders()[name](path)
    assert isinstance(info.value, ValueError)
