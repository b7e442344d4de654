// bvhkit's timed query loop of workload N1, alone in its file, as a user's would be in its own:
// nearest_bench.cpp also compiles CGAL's AABB tree, and GCC's inlining budget is per file (see
// ray_timed_calls.cpp for what that cost the ray loop). CGAL's code is compiled where it always
// is, in the file that includes it.
#include "bvhkit/query/closest_point_mesh.hpp"
#include "nearest_bench.hpp"

namespace bvhkit::bench {

void closest_points_one_thread(const ClosestPointMesh<float>& mesh, std::span<const Vec3f> points,
                               std::span<MeshPoint<float>> out) {
    NearestScratch<float> scratch;
    for (std::size_t i = 0; i < points.size(); ++i) out[i] = mesh.closest_point(points[i], scratch);
}

}  // namespace bvhkit::bench
