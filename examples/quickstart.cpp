// The README's tour, compiled so it cannot rot: load a mesh (or generate one), build a BVH, shoot
// rays.
#include <bvhkit/bvhkit.hpp>
#include <bvhkit/mesh/load_mesh.hpp>
#include <cstdio>

int main(int argc, char** argv) {
    // A file (OBJ, PLY, STL) or a generator spec such as "sphere:subdiv=6".
    const bvhkit::TriangleMesh mesh = bvhkit::load_mesh(argc > 1 ? argv[1] : "sphere:subdiv=6");

    // Binned SAH by default; BuildOptions picks another builder or other parameters.
    const bvhkit::TriangleBvh<float> bvh(mesh);

    // Closest hit: t, the triangle's index in the mesh, barycentrics.
    const bvhkit::Ray3f ray({0, 0, -5}, {0, 0, 1});
    if (const bvhkit::Hit<float> hit = bvh.closest_hit(ray))
        std::printf("hit triangle %u at t = %.3f (u %.2f, v %.2f)\n", hit.primitive, hit.t, hit.u,
                    hit.v);

    // Occlusion within [tmin, tmax], and the statistics that make tree quality measurable.
    bvhkit::TraversalStats stats;
    const bool blocked = bvh.any_hit(bvhkit::Ray3f({0, 0, -5}, {0, 0, 1}, 0.0f, 3.0f), stats);
    std::printf("blocked before t = 3: %s (%llu boxes tested)\n", blocked ? "yes" : "no",
                static_cast<unsigned long long>(stats.nodes_visited));

    // The tree itself: flat nodes plus primitive indices, with statistics and a validator.
    const bvhkit::BvhStatistics s = bvhkit::statistics(bvh.bvh());
    std::printf("%zu nodes, depth %u, SAH cost %.2f\n", s.node_count, s.depth, s.sah_cost);
    return 0;
}
