#pragma once
// Independent references for the BSP tests, in long double and written apart from the library's
// code: ray against triangle by barycentric coordinates (Cramer's rule), point in a convex polygon
// by edge distances, and the winding number as a sum of solid angles.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "bvhkit/bsp/bsp.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/procedural.hpp"
#include "test_support.hpp"

namespace bvhkit::test {

using LD = long double;
using VL = Vec<LD, 3>;

inline VL to_ld(const Vec<double, 3>& v) {
    return VL(v);
}
inline VL to_ld(const Vec<float, 3>& v) {
    return VL(v);
}

struct LdTriangle {
    VL p[3];
};

inline std::vector<LdTriangle> ld_triangles(const TriangleMesh& mesh) {
    std::vector<LdTriangle> out;
    for (const auto& t : mesh.triangles)
        out.push_back(
            {{to_ld(mesh.vertices[t[0]]), to_ld(mesh.vertices[t[1]]), to_ld(mesh.vertices[t[2]])}});
    return out;
}

inline LD ld_area(const LdTriangle& t) {
    return length(cross(t.p[1] - t.p[0], t.p[2] - t.p[0])) / 2;
}

/// Barycentric (u, v) and t of the ray's meeting with the triangle's plane; false when parallel.
inline bool ld_ray_plane(const VL& o, const VL& d, const LdTriangle& tri, LD& t, LD& u, LD& v) {
    const VL e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0], s = o - tri.p[0];
    // Solve o + t d = p0 + u e1 + v e2 by Cramer's rule on [-d e1 e2].
    const LD det = dot(-d, cross(e1, e2));
    if (det == 0) return false;
    t = dot(s, cross(e1, e2)) / det;
    u = dot(-d, cross(s, e2)) / det;
    v = dot(-d, cross(e1, s)) / det;
    return true;
}

/// The closest t over triangles the ray meets with every barycentric >= -delta ("grown") and with
/// every barycentric >= delta ("shrunk"): a correct answer for the real triangles lies between.
struct RayReference {
    LD t_grown = std::numeric_limits<LD>::infinity();
    LD t_shrunk = std::numeric_limits<LD>::infinity();
};

inline RayReference ld_closest(const VL& o, const VL& d, const std::vector<LdTriangle>& tris,
                               LD delta) {
    RayReference r;
    for (const auto& tri : tris) {
        LD t, u, v;
        if (!ld_ray_plane(o, d, tri, t, u, v) || t < 0) continue;
        const LD w = 1 - u - v;
        const LD m = std::min({u, v, w});
        if (m >= -delta) r.t_grown = std::min(r.t_grown, t);
        if (m >= delta) r.t_shrunk = std::min(r.t_shrunk, t);
    }
    return r;
}

/// Least signed distance from p (in the polygon's plane, normal n) to the polygon's edge lines,
/// positive inside: > 0 strictly inside a convex polygon that runs counter-clockwise about n.
inline LD ld_inside_margin(std::span<const Vec<double, 3>> poly, const VL& n, const VL& p) {
    LD m = std::numeric_limits<LD>::infinity();
    for (std::size_t k = 0; k < poly.size(); ++k) {
        const VL a = to_ld(poly[k]), b = to_ld(poly[(k + 1) % poly.size()]);
        const VL e = b - a;
        m = std::min(m, dot(cross(e, p - a), n) / length(e));
    }
    return m;
}

/// The winding number of the closed mesh at q: the sum of the triangles' solid angles
/// (Van Oosterom and Strackee 1983) over 4 pi.
inline LD ld_winding(const std::vector<LdTriangle>& tris, const VL& q) {
    LD sum = 0;
    for (const auto& t : tris) {
        const VL a = t.p[0] - q, b = t.p[1] - q, c = t.p[2] - q;
        const LD la = length(a), lb = length(b), lc = length(c);
        const LD num = dot(a, cross(b, c));
        const LD den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2 * std::atan2(num, den);
    }
    return sum / (4 * std::numbers::pi_v<LD>);
}

/// The meshes the BSP tests run on: two procedural ones and the shipped spot.obj.
inline std::vector<std::pair<std::string, TriangleMesh>> bsp_test_meshes() {
    std::vector<std::pair<std::string, TriangleMesh>> out;
    out.emplace_back("sphere", make_sphere(3));
    out.emplace_back("torus", make_torus(48, 24));
    const auto spot = shared_mesh("spot.obj");
    if (!spot.empty()) out.emplace_back("spot", read_mesh(spot));
    return out;
}

}  // namespace bvhkit::test
