#include "ray_sets.hpp"

#include <cmath>

#include "bvhkit/math/random.hpp"

namespace bvhkit {

std::vector<Ray3f> camera_rays(const Aabb3f& bounds, std::uint32_t width, std::uint32_t height) {
    const Vec3d lo(bounds.min), hi(bounds.max);
    const Vec3d centre = (lo + hi) * 0.5;
    const double radius = std::max(0.5 * length(hi - lo), 1e-6);
    const double half_fov = 30.0 * 3.14159265358979323846 / 180.0;
    const Vec3d back = normalize(Vec3d(0.5, 0.35, 1.0));
    const Vec3d eye = centre + back * (radius / std::sin(half_fov));
    const Vec3d forward = -back;
    const Vec3d right = normalize(cross(forward, Vec3d(0, 1, 0)));
    const Vec3d up = cross(right, forward);
    const double half_h = std::tan(half_fov);
    const double half_w = half_h * double(width) / double(std::max(height, 1u));
    std::vector<Ray3f> rays;
    rays.reserve(std::size_t(width) * height);
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const double sx = (2.0 * (x + 0.5) / width - 1.0) * half_w;
            const double sy = (1.0 - 2.0 * (y + 0.5) / height) * half_h;
            rays.emplace_back(Vec3f(eye), Vec3f(normalize(forward + right * sx + up * sy)));
        }
    return rays;
}

std::vector<Ray3f> random_rays(const Aabb3f& bounds, std::size_t count, std::uint64_t seed) {
    SplitMix64 rng(seed);
    std::vector<Ray3f> rays;
    rays.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        Vec3f o;
        for (int k = 0; k < 3; ++k) o[k] = float(rng.uniform(bounds.min[k], bounds.max[k]));
        rays.emplace_back(o, Vec3f(rng.unit_vector()));
    }
    return rays;
}

}  // namespace bvhkit
