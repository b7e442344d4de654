#pragma once
// Deterministic random geometry for tests: soups of triangles, rays through a box.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "bvhkit/math/ray.hpp"
#include "bvhkit/primitives/triangle.hpp"
#include "bvhkit/primitives/triangle_mesh.hpp"

namespace bvhkit::test {

/// Uniform in [lo, hi) from raw 32-bit draws (std::uniform_real_distribution differs across
/// libraries).
class Random {
  public:
    explicit Random(std::uint64_t seed) : engine_(static_cast<std::mt19937::result_type>(seed)) {}
    double uniform(double lo = 0.0, double hi = 1.0) {
        return lo + (hi - lo) * (engine_() * (1.0 / 4294967296.0));
    }
    std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>(uniform() * n) % n; }
    template <class T>
    Vec<T, 3> point_in(const Aabb<T, 3>& box) {
        return {T(uniform(box.min[0], box.max[0])), T(uniform(box.min[1], box.max[1])),
                T(uniform(box.min[2], box.max[2]))};
    }
    template <class T>
    Vec<T, 3> unit_vector() {
        while (true) {
            const Vec<double, 3> v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
            const double l = length(v);
            if (l > 1e-3 && l <= 1.0) return Vec<T, 3>(v / l);
        }
    }

  private:
    std::mt19937 engine_;
};

/// `count` triangles with corners near random centres in the unit cube, sizes from tiny to ~0.2.
template <class T>
std::vector<Triangle<T>> random_soup(std::size_t count, std::uint64_t seed) {
    Random rng(seed);
    std::vector<Triangle<T>> out(count);
    for (auto& tri : out) {
        const Vec<T, 3> c = rng.point_in(Aabb<T, 3>({0, 0, 0}, {1, 1, 1}));
        const T size = T(0.2 * std::pow(rng.uniform(), 3.0));
        const Aabb<T, 3> around(c - Vec<T, 3>(size), c + Vec<T, 3>(size));
        tri = {rng.point_in(around), rng.point_in(around), rng.point_in(around)};
    }
    return out;
}

/// `count` needles in [-1, 1]^3: a long edge and a third corner 1e-6 to 1e-2 off its middle, a
/// duplicate after every tenth; with `degenerate`, also a collinear (zero-area) triangle after
/// every fifteenth and a point after every twentieth.
inline std::vector<Triangle<float>> random_needles(int count, std::uint64_t seed,
                                                   bool degenerate = false) {
    Random rng(seed);
    std::vector<Triangle<float>> out;
    for (int i = 0; i < count; ++i) {
        Vec<float, 3> a, d, s;
        for (int k = 0; k < 3; ++k) {
            a[k] = float(rng.uniform(-1, 1));
            d[k] = float(rng.uniform(-1, 1));
            s[k] = float(rng.uniform(-1, 1));
        }
        const float width = float(std::pow(10.0, rng.uniform(-6, -2)));
        out.push_back({a, a + d, a + d * 0.5f + s * width});
        if (i % 10 == 0) out.push_back(out.back());
        if (degenerate && i % 15 == 0) out.push_back({a, a + d, a + d * 2.0f});
        if (degenerate && i % 20 == 0) out.push_back({a, a, a});
    }
    return out;
}

/// Rays with origins uniform in `box` and directions uniform on the sphere (workload R2's rule).
template <class T>
std::vector<Ray<T, 3>> random_rays(std::size_t count, const Aabb<T, 3>& box, std::uint64_t seed) {
    Random rng(seed);
    std::vector<Ray<T, 3>> out(count);
    for (auto& r : out) r = Ray<T, 3>(rng.point_in(box), rng.unit_vector<T>());
    return out;
}

/// The mesh's triangles scaled by `scale` and moved by `offset` (in double), then rounded to T.
template <class T>
std::vector<Triangle<T>> placed(const TriangleMesh& mesh, double scale, double offset) {
    std::vector<Triangle<T>> out;
    const auto at = [&](std::uint32_t v) {
        Vec<T, 3> p;
        for (int k = 0; k < 3; ++k) p[k] = T(double(mesh.vertices[v][k]) * scale + offset);
        return p;
    };
    for (const auto& t : mesh.triangles) out.push_back({at(t[0]), at(t[1]), at(t[2])});
    return out;
}

/// Rays through the triangles' bounding box: from outside and inside, some aimed exactly at a
/// vertex or along an axis, some with direction components +0, -0 or subnormal.
inline std::vector<Ray<float, 3>> rays_through_box(const std::vector<Triangle<float>>& tris,
                                                   std::size_t n, std::uint64_t seed) {
    Aabb<float, 3> box;
    for (const auto& t : tris) box.grow(t.bounds());
    const Vec<double, 3> lo{box.min[0], box.min[1], box.min[2]};
    const Vec<double, 3> ext{double(box.max[0]) - lo[0], double(box.max[1]) - lo[1],
                             double(box.max[2]) - lo[2]};
    Random rng(seed);
    std::vector<Ray<float, 3>> rays;
    for (std::size_t i = 0; i < n; ++i) {
        Vec<double, 3> o, target;
        const double spread = i % 5 == 0 ? 0.5 : 3.0;  // one in five starts inside the box
        for (int k = 0; k < 3; ++k) {
            o[k] = lo[k] + ext[k] * (0.5 + spread * rng.uniform(-0.5, 0.5));
            target[k] = lo[k] + ext[k] * rng.uniform(0, 1);
        }
        if (i % 7 == 0) {
            const auto& t = tris[rng.below(std::uint32_t(tris.size()))];
            target = {t.p0[0], t.p0[1], t.p0[2]};
        }
        Ray<float, 3> ray;
        for (int k = 0; k < 3; ++k) {
            ray.origin[k] = float(o[k]);
            ray.direction[k] = float(target[k] - double(ray.origin[k]));
        }
        if (i % 4 == 1) ray.direction[i % 3] = (i / 4) % 2 ? 0.0f : -0.0f;
        if (i % 11 == 3) ray.direction[(i + 1) % 3] = (i / 11) % 2 ? 1e-40f : -1e-41f;
        if (i % 13 == 5) ray.tmax = float(rng.uniform(0, 1));  // short rays
        rays.push_back(ray);
    }
    return rays;
}

}  // namespace bvhkit::test
