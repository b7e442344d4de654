"""Brute-force references in float64 numpy, written independently of the library's arithmetic.

Rays: Moller-Trumbore (Moller and Trumbore 1997) against every triangle, with a robustness margin
so that tests can leave out rays that graze an edge. Closest point: the projection onto the
triangle's plane when it falls inside (solved from the 2x2 normal equations), else the best of the
three edge segments (a different formulation from the library's region tests).
"""

from __future__ import annotations

import numpy as np


def triangles(vertices, faces):
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces)
    return v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]


def ray_hits(vertices, faces, origins, directions, tmin=0.0, tmax=np.inf):
    """Per ray and triangle: t (inf where missed) and the robustness margin (smallest of the
    barycentric coordinates' distances from 0, relative; small = grazing an edge)."""
    a, b, c = triangles(vertices, faces)
    o = np.asarray(origins, np.float64)[:, None, :]
    d = np.asarray(directions, np.float64)[:, None, :]
    e1, e2 = (b - a)[None], (c - a)[None]
    p = np.cross(d, e2)
    det = np.einsum("rti,rti->rt", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - a[None]
        u = np.einsum("rti,rti->rt", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("rti,rti->rt", d, q) * inv
        t = np.einsum("rti,rti->rt", e2, q) * inv
    w = 1 - u - v
    t0 = np.broadcast_to(np.asarray(tmin, np.float64), (o.shape[0],))[:, None]
    t1 = np.broadcast_to(np.asarray(tmax, np.float64), (o.shape[0],))[:, None]
    hit = (det != 0) & (u >= 0) & (v >= 0) & (w >= 0) & (t >= t0) & (t <= t1)
    scale = np.maximum(np.abs(t), 1.0)
    margin = np.minimum(np.minimum(np.abs(u), np.abs(v)), np.abs(w))
    margin = np.minimum(margin, np.minimum(np.abs(t - t0), np.abs(t1 - t)) / scale)
    margin = np.where(np.isfinite(margin), margin, 0.0)
    return np.where(hit, t, np.inf), margin


def _segment_closest(p, a, b):
    ab = b - a
    denom = np.einsum("...i,...i->...", ab, ab)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.einsum("...i,...i->...", p - a, ab) / denom
    s = np.clip(np.where(denom > 0, s, 0.0), 0.0, 1.0)
    return a + s[..., None] * ab


def point_triangle_pairs(p, a, b, c):
    """Distance from points p to triangles abc, elementwise (broadcasting), and the points."""
    e1, e2 = b - a, c - a
    r = p - a
    # Normal equations for p ~ a + s e1 + t e2.
    g11 = np.einsum("...i,...i->...", e1, e1)
    g12 = np.einsum("...i,...i->...", e1, e2)
    g22 = np.einsum("...i,...i->...", e2, e2)
    r1 = np.einsum("...i,...i->...", r, e1)
    r2 = np.einsum("...i,...i->...", r, e2)
    det = g11 * g22 - g12 * g12
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (g22 * r1 - g12 * r2) / det
        t = (g11 * r2 - g12 * r1) / det
    inside = (det > 1e-24 * g11 * g22) & (s >= 0) & (t >= 0) & (s + t <= 1)
    s, t = np.where(inside, s, 0), np.where(inside, t, 0)
    proj = a + s[..., None] * e1 + t[..., None] * e2
    shape = np.broadcast_shapes(p.shape, a.shape, b.shape, c.shape)
    best = np.where(inside[..., None], proj, np.nan)
    bestd = np.where(inside, np.linalg.norm(p - proj, axis=-1), np.inf)
    A, B, C, P = (np.broadcast_to(x, shape) for x in (a, b, c, p))
    for x, y in ((A, B), (B, C), (C, A)):
        q = _segment_closest(P, x, y)
        d = np.linalg.norm(P - q, axis=-1)
        better = d < bestd
        bestd = np.where(better, d, bestd)
        best = np.where(better[..., None], q, best)
    return bestd, best


def point_triangle(points, vertices, faces):
    """Distance (k, m) from every point to every triangle, and the closest points (k, m, 3)."""
    a, b, c = triangles(vertices, faces)
    p = np.asarray(points, np.float64)[:, None, :]
    return point_triangle_pairs(p, a[None], b[None], c[None])


def segment_segment_distance(p1, q1, p2, q2):
    """Distance between segments, broadcasting over leading axes (clamped closed form, with the
    parallel case handled by also trying every endpoint against the other segment)."""
    cands = [
        np.linalg.norm(p1 - _segment_closest(p1, p2, q2), axis=-1),
        np.linalg.norm(q1 - _segment_closest(q1, p2, q2), axis=-1),
        np.linalg.norm(p2 - _segment_closest(p2, p1, q1), axis=-1),
        np.linalg.norm(q2 - _segment_closest(q2, p1, q1), axis=-1),
    ]
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...i,...i->...", d1, d1)
    e = np.einsum("...i,...i->...", d2, d2)
    b = np.einsum("...i,...i->...", d1, d2)
    c = np.einsum("...i,...i->...", d1, r)
    f = np.einsum("...i,...i->...", d2, r)
    den = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (b * f - c * e) / den
        t = (a * f - b * c) / den
    ok = (den > 1e-12 * a * e) & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
    x = p1 + np.where(ok, s, 0)[..., None] * d1
    y = p2 + np.where(ok, t, 0)[..., None] * d2
    cands.append(np.where(ok, np.linalg.norm(x - y, axis=-1), np.inf))
    return np.min(cands, axis=0)


def triangle_distance(ta, tb):
    """Distance between triangles ta, tb (each (..., 3, 3)) that do not intersect: the least of
    vertex-triangle and edge-edge distances."""
    out = np.full(np.broadcast_shapes(ta.shape[:-2], tb.shape[:-2]), np.inf)
    for x, y in ((ta, tb), (tb, ta)):
        for k in range(3):
            d, _ = point_triangle_pairs(x[..., k, :], y[..., 0, :], y[..., 1, :], y[..., 2, :])
            out = np.minimum(out, d)
    for i in range(3):
        for j in range(3):
            out = np.minimum(out, segment_segment_distance(
                ta[..., i, :], ta[..., (i + 1) % 3, :], tb[..., j, :], tb[..., (j + 1) % 3, :]))
    return out


def segment_crosses_triangle(p, q, a, b, c):
    """Whether segment pq crosses triangle abc, and the margin (how far from grazing)."""
    d = q - p
    e1, e2 = b - a, c - a
    h = np.cross(d, e2)
    det = np.einsum("...i,...i->...", e1, h)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = p - a
        u = np.einsum("...i,...i->...", s, h) * inv
        qq = np.cross(s, e1)
        v = np.einsum("...i,...i->...", d, qq) * inv
        t = np.einsum("...i,...i->...", e2, qq) * inv
    w = 1 - u - v
    hit = (det != 0) & (u >= 0) & (v >= 0) & (w >= 0) & (t >= 0) & (t <= 1)
    margin = np.min([np.abs(u), np.abs(v), np.abs(w), np.abs(t), np.abs(1 - t)], axis=0)
    return hit, np.where(np.isfinite(margin), margin, 0.0)


def triangles_intersect(ta, tb):
    """Whether triangles intersect (an edge of one crosses the other) and the least margin over
    the edge tests; exact for pairs in general position (margin well above 0)."""
    shape = np.broadcast_shapes(ta.shape[:-2], tb.shape[:-2])
    hit = np.zeros(shape, bool)
    margin = np.full(shape, np.inf)
    for x, y in ((ta, tb), (tb, ta)):
        for k in range(3):
            h, m = segment_crosses_triangle(x[..., k, :], x[..., (k + 1) % 3, :],
                                            y[..., 0, :], y[..., 1, :], y[..., 2, :])
            hit |= h
            margin = np.minimum(margin, m)
    return hit, margin


def random_soup(rng, count, spread=1.0, size=0.4, offset=0.0, scale=1.0):
    """`count` random triangles (separate vertices) in a cube of side 2*spread."""
    centres = rng.uniform(-spread, spread, (count, 1, 3))
    v = (centres + rng.uniform(-size, size, (count, 3, 3))).reshape(-1, 3)
    return v * scale + offset, np.arange(3 * count).reshape(-1, 3)


def box_mesh(lo, hi):
    """A closed, outward-oriented box: 8 vertices, 12 faces."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                  for z in (lo[2], hi[2])])
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return v, f


def random_rotations(rng, k):
    """k rotation matrices from uniformly random unit quaternions."""
    q = rng.normal(size=(k, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)
