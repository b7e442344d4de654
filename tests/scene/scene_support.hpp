#pragma once
// The references of the scene tests: random scenes, and the same scene as one world-space mesh
// built here (each instance's vertices moved by its pose in long double, then rounded to T), with
// brute-force long double ray and point queries over every triangle of it. Nothing here calls the
// scene's own transforms or the library's triangle tests.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "bvhkit/scene/scene.hpp"

namespace bvhkit::scene_test {

using LD = long double;
using V3 = Vec<LD, 3>;

/// The icosphere of `subdivisions` at radius `scale`, in T.
template <class T>
BasicTriangleMesh<T> sphere_mesh(std::uint32_t subdivisions, double scale) {
    const TriangleMesh m = make_sphere(subdivisions);
    BasicTriangleMesh<T> out;
    for (const auto& v : m.vertices)
        out.vertices.push_back(Vec<T, 3>(T(v[0] * scale), T(v[1] * scale), T(v[2] * scale)));
    out.triangles = m.triangles;
    return out;
}

template <class T>
V3 wide(const Vec<T, 3>& v) {
    return {LD(v[0]), LD(v[1]), LD(v[2])};
}
inline LD dot3(const V3& a, const V3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline V3 cross3(const V3& a, const V3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline LD norm3(const V3& a) {
    return std::sqrt(dot3(a, a));
}

/// A rotation from a random unit quaternion, rounded to T.
template <class T>
Mat3<T> random_rotation(SplitMix64& rng) {
    LD q[4], n = 0;
    do {
        n = 0;
        for (LD& c : q) c = LD(rng.uniform(-1.0, 1.0)), n += c * c;
    } while (n < 0.01L || n > 1);
    for (LD& c : q) c /= std::sqrt(n);
    const Mat3<LD> r = rotation_from_quaternion<LD>(q[0], q[1], q[2], q[3]);
    return Mat3<T>(r);
}

/// R x + t in long double, rounded to T: the test's own world vertex.
template <class T>
Vec<T, 3> world_vertex(const Transform<T>& pose, const Vec<T, 3>& x) {
    Vec<T, 3> r;
    for (std::size_t i = 0; i < 3; ++i)
        r[i] = T(LD(pose.rotation[i][0]) * LD(x[0]) + LD(pose.rotation[i][1]) * LD(x[1]) +
                 LD(pose.rotation[i][2]) * LD(x[2]) + LD(pose.translation[i]));
    return r;
}

/// One triangle of the concatenated world mesh and where it came from.
template <class T>
struct WorldTriangle {
    Vec<T, 3> p[3];
    InstanceId instance;
    std::uint32_t face;
};

/// The scene as one world-space triangle list, and the largest |coordinate| in it.
template <class T>
struct WorldMesh {
    std::vector<WorldTriangle<T>> triangles;
    LD largest = 0;

    explicit WorldMesh(const Scene<T>& scene) {
        scene.for_each_instance([&](InstanceId id) {
            const SceneInstance<T>& r = scene.instance(id);
            const BasicTriangleMesh<T>& m = scene.geometry(r.geometry).mesh();
            for (std::uint32_t f = 0; f < m.triangles.size(); ++f) {
                WorldTriangle<T> w;
                w.instance = id;
                w.face = f;
                bool finite = true;
                for (int k = 0; k < 3; ++k) {
                    w.p[k] = world_vertex(r.pose, m.vertices[m.triangles[f][k]]);
                    finite = finite && is_finite(w.p[k]);
                    for (int a = 0; a < 3; ++a)
                        largest = std::max(largest, std::fabs(LD(w.p[k][a])));
                }
                if (finite) triangles.push_back(w);
            }
        });
    }
    const WorldTriangle<T>* find(InstanceId id, std::uint32_t face) const {
        for (const auto& t : triangles)
            if (t.instance == id && t.face == face) return &t;
        return nullptr;
    }
};

/// Distance from p to segment [a, b] in long double.
inline LD segment_distance(const V3& p, const V3& a, const V3& b) {
    const V3 e = b - a;
    const LD ee = dot3(e, e);
    LD s = ee > 0 ? dot3(p - a, e) / ee : 0;
    s = std::clamp(s, LD(0), LD(1));
    return norm3(p - (a + e * s));
}

/// Distance from p to the triangle in long double: to its plane when p's foot falls inside (the
/// three edge functions agree in sign), else to the nearest edge.
template <class T>
LD point_triangle_distance(const V3& p, const WorldTriangle<T>& t) {
    const V3 a = wide(t.p[0]), b = wide(t.p[1]), c = wide(t.p[2]);
    const V3 n = cross3(b - a, c - a);
    const LD nn = dot3(n, n);
    if (nn > 0) {
        const LD e0 = dot3(n, cross3(b - a, p - a)), e1 = dot3(n, cross3(c - b, p - b)),
                 e2 = dot3(n, cross3(a - c, p - c));
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) return std::fabs(dot3(n, p - a)) / std::sqrt(nn);
    }
    return std::min(
        {segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

enum class Crossing { Hit, Miss, Unsure };

struct RayCrossing {
    Crossing kind = Crossing::Miss;
    LD t = 0;
    LD t_tolerance = 0;
};

/// Whether the ray o + t d, t in [tmin, tmax], crosses the triangle, with a band of doubt: the
/// scene traces a copy of the triangle and ray that differ from these by `wobble` (a length) in
/// each point. Barycentrics by Cramer's rule in long double; a shift of the plane by wobble moves
/// the crossing by wobble / |cos| along the ray, and a barycentric by at most that over the
/// triangle's least height (2 area / longest edge), so within that band either answer is right.
template <class T>
RayCrossing cross(const Ray<T, 3>& ray, const WorldTriangle<T>& tri, LD wobble) {
    RayCrossing out;
    const V3 o = wide(ray.origin), d = wide(ray.direction);
    const V3 a = wide(tri.p[0]), b = wide(tri.p[1]), c = wide(tri.p[2]);
    const V3 e1 = b - a, e2 = c - a, n = cross3(e1, e2);
    const LD area2 = norm3(n), dn = dot3(d, n);
    const LD longest = std::max({norm3(e1), norm3(e2), norm3(c - b)});
    if (area2 == 0) return out;  // never hit (a zero-area triangle)
    const LD cosine = std::fabs(dn) / (area2 * norm3(d));
    const LD along = cosine > 0 ? wobble / cosine : std::numeric_limits<LD>::infinity();
    const LD band = (along + wobble) * longest / area2;  // a barycentric's doubt
    out.t_tolerance = along / norm3(d) + 1e-12L;
    if (dn == 0) {  // parallel: unsure when the ray runs within the wobble of the plane
        if (std::fabs(dot3(a - o, n)) / area2 <= wobble) {
            out.kind = Crossing::Unsure;
            out.t_tolerance = std::numeric_limits<LD>::infinity();
        }
        return out;
    }
    out.t = dot3(a - o, n) / dn;
    const V3 x = o + d * out.t;
    const LD u = dot3(cross3(x - a, e2), n) / (area2 * area2);
    const LD v = dot3(cross3(e1, x - a), n) / (area2 * area2);
    const LD w = 1 - u - v;
    const LD least = std::min({u, v, w});
    const LD slack_t = out.t_tolerance;
    const bool in_range = out.t >= LD(ray.tmin) - slack_t && out.t <= LD(ray.tmax) + slack_t;
    const bool surely_in_range = out.t > LD(ray.tmin) + slack_t && out.t < LD(ray.tmax) - slack_t;
    if (least < -band || !in_range)
        out.kind = Crossing::Miss;
    else if (least > band && surely_in_range)
        out.kind = Crossing::Hit;
    else
        out.kind = Crossing::Unsure;
    return out;
}

}  // namespace bvhkit::scene_test
