"""docs/figures/contact_manifold.py draws the contact manifold picture of docs/collision.md from
bvhkit's own contacts: it must keep running, and what it draws must be the analytic answer."""

import importlib.util
import pathlib
import xml.etree.ElementTree as ET

import numpy as np

FIGURES = pathlib.Path(__file__).resolve().parents[2] / "docs" / "figures"


def load_script():
    spec = importlib.util.spec_from_file_location("contact_manifold_figure",
                                                  FIGURES / "contact_manifold.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_contact_manifold_figure(tmp_path):
    figure = load_script()
    out = tmp_path / "manifold.svg"
    every, kept = figure.draw(out)
    root = ET.parse(out).getroot()  # well-formed SVG
    assert root.tag.endswith("svg")
    # Two regions of at most four kept points, one per sphere, each led by its deepest point: the
    # sphere's lowest vertex, (0, 0, -1) * r + c exactly, inside the slab whose top is z = 0 and
    # whose bottom is z = -1, so its depth is c_z - r and the way out is straight up (normal -z:
    # from b into a).
    assert sorted(set(kept.regions.tolist())) == [0, 1]
    for region, (x, y, depth) in enumerate([(-0.9, 0.0, 0.25), (1.1, 0.3, 0.1)]):
        mine = kept.regions == region
        assert 1 <= mine.sum() <= 4
        first = np.flatnonzero(mine)[0]
        assert abs(kept.depths[first] - depth) < 1e-15
        np.testing.assert_allclose(kept.points[first], [x, y, -depth], atol=1e-15)
        np.testing.assert_array_equal(kept.normals[first], [0.0, 0.0, -1.0])
        assert kept.kinds[first] == 2  # a vertex of b inside a
        assert (kept.depths[mine] <= kept.depths[first]).all()
    # Every contact lies on or inside the slab, within its sphere; curve points on the top face.
    assert len(every.points) > len(kept.points)
    assert (every.points[:, 2] <= 1e-12).all() and (every.points[:, 2] >= -0.25 - 1e-12).all()
    curve = every.kinds == 0
    np.testing.assert_allclose(every.points[curve, 2], 0.0, atol=1e-12)
    assert (every.depths[curve] == 0).all()
    # The figure shows each kept point once in each of its two views.
    circles = [c for c in root.iter() if c.tag.endswith("circle") and c.get("r") == "4.5"]
    assert len(circles) == 2 * len(kept.points)


def test_committed_figure_is_current(tmp_path):
    # The committed picture shows the same kept contacts the script finds now (regenerate with
    # `python docs/figures/contact_manifold.py` when contacts change on purpose).
    figure = load_script()
    committed = (FIGURES / "contact_manifold.svg").read_text()
    _, kept = figure.draw(tmp_path / "now.svg")
    for p, d in zip(kept.points, kept.depths):
        assert f"point ({p[0]:+.3f}, {p[1]:+.3f}, {p[2]:+.3f})" in committed
        assert f"depth {d:.4f}" in committed
