"""The README's Python example, run as written (the text is read from README.md, so an edit that
breaks it fails here), and its answers checked against the geometry it sets up."""

import contextlib
import io
import math
import pathlib
import re

import numpy as np

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def readme_example():
    text = README.read_text(encoding="utf-8")
    section = text.split("\n## Python\n", 1)
    assert len(section) == 2, "README.md has no '## Python' section"
    blocks = re.findall(r"```python\n(.*?)```", section[1], flags=re.S)
    assert blocks, "README.md's Python section has no python code block"
    return blocks[0]


def test_readme_example_runs_as_written():
    namespace = {}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(readme_example(), str(README), "exec"), namespace)
    assert out.getvalue().strip(), "the example prints its answers"

    # A unit icosphere (vertices on the unit sphere, every face inside it): the ray from z = -5
    # along +z enters between t = 4 and t = 4 + (1 - inradius), the inradius of a 5,120-face
    # icosphere being above 0.995.
    t = namespace["t"]  # (`face` is reused by the example for the closest points' faces)
    assert t.shape == (1,) and 4.0 - 1e-6 <= t[0] <= 4.005
    face, n_faces = namespace["face"], len(namespace["faces"])
    assert face.shape == (100_000,) and np.all((face >= 0) & (face < n_faces))

    # Points uniform in [-2, 2]^3: the nearest surface point of one outside the sphere is about
    # |p| - 1 away, and the share of points inside is about the volume ratio (4/3 pi) / 64.
    points, dist = namespace["points"], namespace["dist"]
    radius = np.linalg.norm(points, axis=1)
    outside = radius > 1.01
    assert np.all(np.abs(dist[outside] - (radius[outside] - 1.0)) <= 5e-3)
    inside_share = float((namespace["sdf"] < 0).mean())
    expected = (4.0 / 3.0 * math.pi) / 64.0
    assert abs(inside_share - expected) < 0.005
    # Inside the inscribed sphere is inside the mesh; outside the unit sphere is outside it.
    inside = namespace["sdf"] < 0
    assert np.all(inside[radius < 0.995]) and not np.any(inside[radius > 1.0])

    # Two unit spheres 1.5 apart overlap.
    assert namespace["hits"].tolist() == [True]
