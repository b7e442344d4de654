// Builds a tree over a procedural sphere and checks a ray through its centre hits the near side.
#include <bvhkit/bvhkit.hpp>
#include <bvhkit/mesh/procedural.hpp>
#include <cmath>
#include <cstdio>

int main() {
    const bvhkit::TriangleMesh sphere = bvhkit::make_sphere(4);  // unit sphere
    const bvhkit::TriangleBvh<float> bvh(sphere);
    const bvhkit::Ray3f ray({0, 0, -5}, {0, 0, 1});
    const bvhkit::Hit<float> hit = bvh.closest_hit(ray);
    std::printf("consumer: bvhkit %s, %zu triangles, hit t = %.4f (triangle %u)\n",
                bvhkit::version_string, sphere.triangle_count(), hit.t, hit.primitive);
    // The sphere is inscribed-ish in the unit ball: the hit is at t just above 4.
    return hit && std::fabs(hit.t - 4.0f) < 0.02f ? 0 : 1;
}
