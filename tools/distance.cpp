// `bvhkit distance MESH_A MESH_B --poses FILE --out FILE`: for each pose (12 float32, B placed in
// A's frame) the float32 distance between the models, or -1 where they collide
// (../shared/BENCHMARKS.md).
#include <cstdio>
#include <cstring>

#include "args.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/distance.hpp"
#include "bvhkit/volumes/obb.hpp"
#include "commands.hpp"
#include "pose_file.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kHelp =
    R"(usage: bvhkit distance MESH_A MESH_B --poses FILE --out FILE

For each pose (12 float32: row-major rotation R, translation t; B placed at x' = R x + t in A's
frame) writes the float32 minimum distance between the two meshes, or -1 where they touch or
intersect. Exact (no tolerance); OBB trees.
)";

}  // namespace

int distance_command(int argc, char** argv) {
    const Args args(argc, argv, {"--poses", "--out"}, {});
    if (args.help()) {
        std::fputs(kHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 2 || !args.has("--poses") || !args.has("--out")) {
        std::fputs(kHelp, stderr);
        return 2;
    }
    const CollisionModel<Obb<float>> a(load_mesh(args.positional()[0]));
    const CollisionModel<Obb<float>> b(load_mesh(args.positional()[1]));
    std::vector<unsigned char> out;
    for (const auto& p : read_pose_file(args.value("--poses"))) {
        const float d = distance(a, b, p).distance;
        const float v = d > 0.0f ? d : -1.0f;
        unsigned char bytes[4];
        std::memcpy(bytes, &v, 4);
        out.insert(out.end(), bytes, bytes + 4);
    }
    write_bytes(args.value("--out"), out);
    return 0;
}

}  // namespace bvhkit::tools
