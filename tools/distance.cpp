// `bvhkit distance MESH_A MESH_B --poses FILE --out FILE [--volume ...]`: for each pose (12
// float32, B placed in A's frame) the float32 distance between the models, or -1 where they collide
// (docs/workloads.md).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>

#include "args.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/distance.hpp"
#include "commands.hpp"
#include "pose_file.hpp"
#include "volume_choice.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kDistanceHelp =
    R"(usage: bvhkit distance MESH_A MESH_B --poses FILE --out FILE
                       [--volume rss|obbrss|obb|aabb|sphere|kdop18|hull] [--threads N]

For each pose (12 float32: row-major rotation R, translation t; B placed at x' = R x + t in A's
frame) writes the float32 minimum distance between the two meshes, or -1 where they touch or
intersect. Exact (no tolerance). --volume picks the trees' bounding volume (default rss, the
fastest for distance: its bound is the exact distance between the volumes; --bv is its earlier
name). --threads 0 (the default) uses every core when bvhkit has oneTBB, 1 one thread; the output
is the same for any number of threads.
)";

template <class V>
void distance_all(const TriangleMesh& ma, const TriangleMesh& mb,
                  const std::vector<Transform<float>>& poses, unsigned threads,
                  std::vector<unsigned char>& out) {
    const CollisionModel<V> a(ma), b(mb);
    out.assign(4 * poses.size(), 0);
    // Each pose's record has its own place in `out`, so the file is the same for any thread count.
    Executor(threads).parallel_for(poses.size(), 16, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
            const float d = distance(a, b, poses[i]).distance;
            const float v = d > 0.0f ? d : -1.0f;
            std::memcpy(out.data() + 4 * i, &v, 4);
        }
    });
}

}  // namespace

int distance_command(int argc, char** argv) {
    const Args args(argc, argv, {"--poses", "--out", "--volume", "--threads"}, {});
    if (args.help()) {
        std::fputs(kDistanceHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 2)
        return usage_error(
            "distance",
            "takes two meshes MESH_A MESH_B, got " + std::to_string(args.positional().size()),
            kDistanceHelp);
    if (!args.has("--poses") || !args.has("--out"))
        return usage_error("distance", "--poses FILE and --out FILE are required", kDistanceHelp);
    const TriangleMesh ma = load_mesh(args.positional()[0]);
    const TriangleMesh mb = load_mesh(args.positional()[1]);
    const auto poses = read_pose_file(args.value("--poses"));
    const unsigned threads = args.threads();
    const std::string bv = args.value("--volume", "rss");
    std::vector<unsigned char> out;
    with_volume(bv, [&](auto tag) {
        distance_all<typename decltype(tag)::type>(ma, mb, poses, threads, out);
    });
    write_bytes(args.value("--out"), out);
    std::size_t colliding = 0;
    float nearest = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i + 4 <= out.size(); i += 4) {
        float d;
        std::memcpy(&d, out.data() + i, 4);
        if (d < 0)
            ++colliding;
        else
            nearest = std::min(nearest, d);
    }
    std::fprintf(
        stderr,
        "distance: %zu poses (%s), %zu colliding, smallest distance of the rest %g; wrote %s\n",
        poses.size(), bv.c_str(), colliding, nearest, args.value("--out").c_str());
    return 0;
}

}  // namespace bvhkit::tools
