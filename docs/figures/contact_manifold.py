"""Draws docs/figures/contact_manifold.svg: the contact manifold of two sphere meshes pressed into a
slab mesh, from bvhkit's own `contacts`, seen from the side and from above.

    python docs/figures/contact_manifold.py [OUT.svg]

The picture is plain SVG written here (no plotting library), so it builds wherever bvhkit's Python
package does; tests/python/test_docs_figures.py runs this script.
"""

import sys
from pathlib import Path

import numpy as np

import bvhkit


def slab_mesh(n=8, size=2.0, thickness=1.0):
    """A closed box [-size, size]^2 x [-thickness, 0], outward facing, its top face an n x n grid so
    that the spheres meet faces of several sizes and the walk inside has vertices to reach."""
    xs = np.linspace(-size, size, n + 1)
    top = np.array([[x, y, 0.0] for y in xs for x in xs])
    bottom = top - np.array([0.0, 0.0, thickness])
    vertices = np.vstack([top, bottom])
    faces = []
    m = n + 1
    corner = lambda i, j: j * m + i  # noqa: E731
    for j in range(n):
        for i in range(n):
            a, b, c, d = corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)
            faces += [[a, b, c], [a, c, d]]  # top faces +z
            faces += [[m * m + a, m * m + c, m * m + b], [m * m + a, m * m + d, m * m + c]]
    rim = [corner(i, 0) for i in range(n)] + [corner(n, j) for j in range(n)]
    rim += [corner(i, n) for i in range(n, 0, -1)] + [corner(0, j) for j in range(n, 0, -1)]
    for k in range(len(rim)):  # the four sides, outward: the rim runs anticlockwise seen from +z
        p, q = rim[k], rim[(k + 1) % len(rim)]
        faces += [[p, m * m + p, m * m + q], [p, m * m + q, q]]
    return vertices, np.array(faces, dtype=np.int64)


def sphere_mesh(centre, radius, subdiv=2):
    v, f = bvhkit.load_mesh(f"sphere:subdiv={subdiv}")
    return v.astype(np.float64) * radius + np.asarray(centre, dtype=np.float64), f


def scene():
    """Model a: the slab; model b: two spheres, one pressed 0.25 deep, the other 0.1."""
    va, fa = slab_mesh()
    v1, f1 = sphere_mesh([-0.9, 0.0, 0.75], 1.0)
    v2, f2 = sphere_mesh([1.1, 0.3, 0.5], 0.6)
    vb = np.vstack([v1, v2])
    fb = np.vstack([f1, f2 + len(v1)])
    return (va, fa), (vb, fb)


class Panel:
    """One orthographic view: world (u, v) axes onto a rectangle of the picture."""

    def __init__(self, x0, y0, w, h, u_axis, v_axis, lo, hi, title):
        self.x0, self.y0, self.w, self.h = x0, y0, w, h
        self.u, self.v, self.title = u_axis, v_axis, title
        self.scale = min(w / (hi[0] - lo[0]), h / (hi[1] - lo[1]))
        self.lo, self.hi = lo, hi

    def at(self, p):
        x = self.x0 + (p[self.u] - self.lo[0]) * self.scale
        y = self.y0 + self.h - (p[self.v] - self.lo[1]) * self.scale
        return x, y


def svg_mesh_edges(panel, vertices, faces, colour, width):
    edges = set()
    for f in faces:
        for i in range(3):
            a, b = int(f[i]), int(f[(i + 1) % 3])
            edges.add((min(a, b), max(a, b)))
    parts = []
    for a, b in sorted(edges):
        (x1, y1), (x2, y2) = panel.at(vertices[a]), panel.at(vertices[b])
        parts.append(f"M{x1:.1f} {y1:.1f}L{x2:.1f} {y2:.1f}")
    return (f'<path d="{"".join(parts)}" stroke="{colour}" stroke-width="{width}" '
            f'fill="none" stroke-opacity="0.55"/>')


REGION_COLOURS = ["#c0392b", "#1f6fb2", "#1e8449", "#8e44ad"]
KIND_NAMES = ["on the intersection curve", "vertex of a inside b", "vertex of b inside a",
              "edge point of a inside b", "edge point of b inside a"]


def draw(out_path):
    (va, fa), (vb, fb) = scene()
    a = bvhkit.CollisionModel(va, fa, dtype=np.float64)
    b = bvhkit.CollisionModel(vb, fb, dtype=np.float64)
    identity = np.eye(3)[None]
    zero = np.zeros((1, 3))
    every = bvhkit.contacts(a, b, identity, zero, max_points=0)[0]
    kept = bvhkit.contacts(a, b, identity, zero, max_points=4)[0]
    assert len(kept.points) > 0, "the figure's meshes must overlap"

    width, height = 980, 670
    side = Panel(40, 70, 440, 330, 0, 2, (-2.2, -1.2), (2.2, 1.9), "side (x right, z up)")
    top = Panel(520, 70, 420, 420, 0, 1, (-2.2, -2.2), (2.2, 2.2), "from above (x right, y up)")
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="13">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           "<defs>" + "".join(
               f'<marker id="head{i}" markerWidth="8" markerHeight="8" refX="7" refY="4" markerUnits="userSpaceOnUse" '
               f'orient="auto"><path d="M0 0L8 4L0 8z" fill="{c}"/></marker>'
               for i, c in enumerate(REGION_COLOURS)) + "</defs>",
           '<text x="40" y="30" font-size="16" font-weight="bold">Contact manifold of a slab '
           '(model a) and two sphere meshes (model b) pressed into it</text>']
    arrow_scale = 2.0  # arrows are drawn at twice the depth, so that the shallow ones show
    for panel in (side, top):
        out.append(f'<text x="{panel.x0}" y="{panel.y0 - 12}" font-weight="bold">'
                   f'{panel.title}</text>')
        out.append(svg_mesh_edges(panel, va, fa, "#7f8c8d", 0.6))
        out.append(svg_mesh_edges(panel, vb, fb, "#d4ac0d", 0.4))
        for p in every.points:
            x, y = panel.at(p)
            out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="1.6" fill="#555"/>')
        for p, n, d, r in zip(kept.points, kept.normals, kept.depths, kept.regions):
            colour_index = int(r) % len(REGION_COLOURS)
            colour = REGION_COLOURS[colour_index]
            x, y = panel.at(p)
            x2, y2 = panel.at(p + n * max(d, 0.0) * arrow_scale)
            if abs(x2 - x) + abs(y2 - y) > 1.0:
                out.append(f'<line x1="{x:.1f}" y1="{y:.1f}" x2="{x2:.1f}" y2="{y2:.1f}" '
                           f'stroke="{colour}" stroke-width="2" marker-end="url(#head{colour_index})"/>')
            out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4.5" fill="{colour}" '
                       f'stroke="black" stroke-width="0.8"/>')

    kept_normals = kept.normals + 0.0  # prints -0 as 0
    lines = [f"{len(every.points)} contacts in all (small grey dots); kept: at most 4 a region "
             f"(max_points=4), coloured by region, the deepest first:"]
    for i, (p, n, d, r, k, f) in enumerate(zip(kept.points, kept_normals, kept.depths,
                                               kept.regions, kept.kinds, kept.faces)):
        lines.append(f"region {r}: point ({p[0]:+.3f}, {p[1]:+.3f}, {p[2]:+.3f})  normal "
                     f"({n[0]:+.2f}, {n[1]:+.2f}, {n[2]:+.2f})  depth {d:.4f}  faces "
                     f"({f[0]}, {f[1]})  {KIND_NAMES[int(k)]}")
    lines.append("Arrows: the normal (from b into a: moving a along it by the depth separates "
                 "that contact), drawn at twice the depth; curve points have depth 0.")
    y = 500
    for i, text in enumerate(lines):
        out.append(f'<text x="40" y="{y + 16 * i}" font-size="11">{text}</text>')
    out.append("</svg>")
    Path(out_path).write_text("\n".join(out) + "\n")
    return every, kept


if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else Path(__file__).with_suffix(".svg")
    every, kept = draw(target)
    print(f"{target}: {len(every.points)} contacts, {len(kept.points)} kept")
