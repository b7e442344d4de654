// Writes the seed corpus of fuzz_tree_file into the folder given: small saved TriangleBvh files
// (float and double, both triangle layouts, one with skipped triangles, an empty tree),
// ClosestPointMesh, SignedDistanceMesh, WindingNumberMesh, DynamicTree and CollisionModel files
// (one per volume type), each a few KB so the fuzzer's mutations land on every section.
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/io/closest_point_mesh_file.hpp"
#include "bvhkit/io/collision_model_file.hpp"
#include "bvhkit/io/dynamic_tree_file.hpp"
#include "bvhkit/io/signed_distance_mesh_file.hpp"
#include "bvhkit/io/triangle_bvh_file.hpp"
#include "bvhkit/io/winding_number_mesh_file.hpp"
#include "bvhkit/scene/scene_file.hpp"

namespace {

// A small grid of triangles in the unit square, slightly tilted so boxes are not flat.
template <class T>
std::vector<bvhkit::Triangle<T>> grid(int n) {
    std::vector<bvhkit::Triangle<T>> out;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const T x = T(i) / T(n), y = T(j) / T(n), s = T(1) / T(n), z = T(0.1) * x;
            out.push_back({{x, y, z}, {x + s, y, z}, {x, y + s, z + s}});
            out.push_back({{x + s, y, z}, {x + s, y + s, z + s}, {x, y + s, z}});
        }
    return out;
}

// The triangles as an indexed mesh, three vertices each (what a CollisionModel builds from).
template <class T>
bvhkit::BasicTriangleMesh<T> indexed(const std::vector<bvhkit::Triangle<T>>& tris) {
    bvhkit::BasicTriangleMesh<T> mesh;
    for (const auto& t : tris) {
        const auto i = std::uint32_t(mesh.vertices.size());
        mesh.vertices.insert(mesh.vertices.end(), {t.p0, t.p1, t.p2});
        mesh.triangles.push_back({i, i + 1, i + 2});
    }
    return mesh;
}

template <class T>
void write(const std::filesystem::path& dir, const std::string& name,
           const std::vector<bvhkit::Triangle<T>>& tris, bvhkit::TriangleTest test) {
    bvhkit::TriangleBvhOptions options;
    options.triangle_test = test;
    options.max_leaf_size = 2;
    bvhkit::save(bvhkit::TriangleBvh<T>(tris, options), dir / name);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    using bvhkit::TriangleTest;
    write(dir, "float_watertight.bvh", grid<float>(4), TriangleTest::Watertight);
    write(dir, "float_fast.bvh", grid<float>(3), TriangleTest::Fast);
    write(dir, "double_watertight.bvh", grid<double>(3), TriangleTest::Watertight);
    auto holes = grid<float>(3);
    holes[1].p0[0] = std::numeric_limits<float>::quiet_NaN();
    holes[4].p2[1] = std::numeric_limits<float>::infinity();
    write(dir, "float_skipped.bvh", holes, TriangleTest::Watertight);
    write(dir, "empty.bvh", std::vector<bvhkit::Triangle<float>>{}, TriangleTest::Watertight);
    bvhkit::save(bvhkit::ClosestPointMesh<float>(grid<float>(3)), dir / "closest_float.bvh");
    bvhkit::save(bvhkit::ClosestPointMesh<float>(holes), dir / "closest_skipped.bvh");
    bvhkit::save(bvhkit::ClosestPointMesh<double>(grid<double>(2)), dir / "closest_double.bvh");
    // A closed octahedron, for the signed distance.
    bvhkit::TriangleMesh octahedron;
    octahedron.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    octahedron.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                            {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    bvhkit::save(bvhkit::SignedDistanceMesh<float>(octahedron), dir / "signed_float.bvh");
    bvhkit::save(bvhkit::SignedDistanceMesh<double>(octahedron), dir / "signed_double.bvh");
    bvhkit::save(bvhkit::WindingNumberMesh<float>(octahedron), dir / "winding_float.bvh");
    bvhkit::save(bvhkit::WindingNumberMesh<double>(octahedron), dir / "winding_double.bvh");
    // Dynamic trees: a few boxes, one destroyed, one moved, a pair step, one more move pending.
    bvhkit::DynamicTree<float, 2> flat;
    for (int i = 0; i < 12; ++i)
        flat.create(bvhkit::Aabb<float, 2>({float(i), 0}, {float(i) + 1.5f, 1}), std::uint64_t(i));
    flat.destroy(bvhkit::ProxyId(3, 0));  // a fresh tree: slot i, generation 0
    flat.update_pairs([](bvhkit::ProxyId, bvhkit::ProxyId) {},
                      [](bvhkit::ProxyId, bvhkit::ProxyId) {});
    flat.move(bvhkit::ProxyId(5, 0), bvhkit::Aabb<float, 2>({20, 0}, {21, 1}));
    bvhkit::save(flat, dir / "dynamic_2d_float.bvh");
    bvhkit::DynamicTree<double, 3> solid;
    for (int i = 0; i < 10; ++i)
        solid.create(bvhkit::Aabb<double, 3>({0, double(i), 0}, {1, double(i) + 1.5, 1}));
    solid.enlarge(bvhkit::ProxyId(2, 0), bvhkit::Aabb<double, 3>({5, 5, 5}, {6, 6, 6}));
    bvhkit::save(solid, dir / "dynamic_3d_double.bvh");
    // Scenes: two meshes, instances with margins and filters, one removed (a later generation).
    for (const bool wide : {false, true}) {
        const auto build = [&](auto scalar) {
            using T = decltype(scalar);
            bvhkit::Scene<T> scene;
            const bvhkit::GeometryId g = scene.add_mesh(octahedron);
            bvhkit::Transform<T> pose;
            std::vector<bvhkit::InstanceId> ids;
            for (int i = 0; i < 5; ++i) {
                pose.translation = bvhkit::Vec<T, 3>(T(1.5 * i), T(0), T(0));
                bvhkit::InstanceOptions<T> o;
                o.margin = T(0.1 * (i % 2));
                o.group = 1u << (i % 2);
                ids.push_back(scene.add_instance(g, pose, o));
            }
            scene.remove(ids[2]);
            (void)scene.add_instance(g, pose);
            bvhkit::save(scene, dir / (wide ? "scene_double.bvh" : "scene_float.bvh"));
        };
        if (wide)
            build(0.0);
        else
            build(0.0f);
    }
    // Collision models: every volume type over the octahedron, one over a grid with skipped
    // triangles, one in double.
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Aabb<float, 3>>(octahedron),
                 dir / "collision_aabb.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Sphere<float>>(octahedron),
                 dir / "collision_sphere.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Obb<float>>(octahedron), dir / "collision_obb.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Rss<float>>(octahedron), dir / "collision_rss.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::ObbRss<float>>(octahedron),
                 dir / "collision_obbrss.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Kdop<float, 14>>(octahedron),
                 dir / "collision_kdop14.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Kdop<float, 18>>(octahedron),
                 dir / "collision_kdop18.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Kdop<float, 26>>(octahedron),
                 dir / "collision_kdop26.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::ConvexHull<float>>(octahedron),
                 dir / "collision_hull.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Obb<float>>(indexed(holes)),
                 dir / "collision_skipped.bvh");
    bvhkit::save(bvhkit::CollisionModel<bvhkit::Obb<double>>(indexed(grid<double>(2))),
                 dir / "collision_obb_double.bvh");
    return 0;
}
