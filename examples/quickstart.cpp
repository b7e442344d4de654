// The README's tour, compiled so it cannot rot. It reads the shipped data/spot.obj (found from any
// folder: the build records where the repository's data/ is) or the mesh file or generator spec
// given as its argument.
#include <bvhkit/bvhkit.hpp>
#include <cstdio>
#include <vector>

#ifndef BVHKIT_EXAMPLE_MESH
#define BVHKIT_EXAMPLE_MESH "data/spot.obj"
#endif

namespace {

int tour(const char* mesh_spec) {
    // A file (OBJ, PLY, STL) or a generator spec such as "sphere:subdiv=6".
    const bvhkit::TriangleMesh mesh = bvhkit::load_mesh(mesh_spec);
    const bvhkit::Aabb3f box = mesh.bounds();
    const bvhkit::Vec3f centre = box.centroid();
    const float diagonal = bvhkit::length(box.extent());

    // Rays: binned SAH by default; BuildOptions picks another builder or other parameters.
    const bvhkit::TriangleBvh<float> bvh(mesh);
    const bvhkit::Ray3f ray(centre - bvhkit::Vec3f(0, 0, 2 * diagonal), {0, 0, 1});
    if (const bvhkit::Hit<float> hit = bvh.closest_hit(ray))
        std::printf("ray hits triangle %u at t = %.4f (u %.3f, v %.3f)\n", hit.primitive, hit.t,
                    hit.u, hit.v);
    else
        std::printf("ray misses\n");

    // Occlusion: is anything between the origin and a light beyond the mesh (t in [0, tmax])?
    // With the statistics that make tree quality measurable.
    bvhkit::TraversalStats stats;
    const bvhkit::Ray3f shadow(ray.origin, ray.direction, 0.0f, 4 * diagonal);
    const bool blocked = bvh.any_hit(shadow, stats);
    std::printf("light blocked: %s (%llu boxes tested)\n", blocked ? "yes" : "no",
                static_cast<unsigned long long>(stats.nodes_visited));

    // Proximity: the closest point on the mesh to a point above it.
    const bvhkit::ClosestPointMesh<float> surface(mesh);
    const bvhkit::Vec3f p = centre + bvhkit::Vec3f(0, box.max[1] - centre[1] + 0.1f * diagonal, 0);
    if (const bvhkit::MeshPoint<float> q = surface.closest_point(p))
        std::printf("closest point to (%.2f %.2f %.2f): (%.3f %.3f %.3f) on triangle %u\n", p[0],
                    p[1], p[2], q.point[0], q.point[1], q.point[2], q.triangle);

    // The tree itself: flat nodes plus primitive indices, with statistics and a validator.
    const bvhkit::BvhStatistics s = bvhkit::statistics(bvh.bvh());
    std::printf("%zu triangles, %zu nodes, depth %u, SAH cost %.2f\n", mesh.triangle_count(),
                s.node_count, s.depth, s.sah_cost);

    // A scene: the mesh added once, placed five times along x (each a quarter turn further),
    // for rays, closest points and collision over all of them.
    bvhkit::Scene<float> scene;
    const bvhkit::GeometryId shape = scene.add_mesh(mesh);
    for (int i = 0; i < 5; ++i) {
        bvhkit::Transform<float> pose;
        pose.rotation = bvhkit::rotation_about(bvhkit::Vec3f(0, 1, 0), 1.5708f * float(i));
        pose.translation = bvhkit::Vec3f(0.4f * diagonal * float(i), 0, 0);
        scene.add_instance(shape, pose, {.user_data = std::uint64_t(i)});
    }
    const bvhkit::Ray3f along(centre - bvhkit::Vec3f(diagonal, 0, 0), {1, 0, 0});
    if (const bvhkit::SceneHit<float> hit = bvhkit::closest_hit(scene, along))
        std::printf("scene ray hits copy %llu, triangle %u at t = %.4f\n",
                    static_cast<unsigned long long>(scene.user_data(hit.instance)), hit.face,
                    hit.t);
    std::vector<bvhkit::InstancePair> touching;
    bvhkit::colliding_pairs(scene, touching);
    std::printf("%zu instances, %zu colliding pairs\n", scene.instance_count(), touching.size());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const char* mesh_spec = argc > 1 ? argv[1] : BVHKIT_EXAMPLE_MESH;
    // bvhkit reports bad input (a missing or malformed file, say) as bvhkit::Error.
    try {
        return tour(mesh_spec);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bvhkit_example_quickstart: %s\n", e.what());
        return 1;
    }
}
