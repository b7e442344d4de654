// `bvhkit collide MESH_A MESH_B --poses FILE --out FILE [--volume ...]`.
// Poses and results use the binary formats of docs/workloads.md: a pose is 12 float32 (a
// row-major rotation, then a translation) placing B in A's frame; a collision result is 5 packed
// bytes per pose (uint8 collided, uint32 number of intersecting triangle pairs, little-endian).
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "args.hpp"
#include "bvhkit/exec/executor.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "commands.hpp"
#include "pose_file.hpp"
#include "volume_choice.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kCollideHelp =
    R"(usage: bvhkit collide MESH_A MESH_B --poses FILE --out FILE
                      [--volume aabb|obb|rss|obbrss|sphere|kdop18|hull]
                      [--rule larger|a|b|simultaneous|by-overlap] [--threads N]

For each pose (12 float32: row-major rotation R, translation t; B placed at x' = R x + t in A's
frame) writes 5 packed bytes: uint8 collided, uint32 number of intersecting triangle pairs
(little-endian). Touching counts as intersecting; see docs/collision.md for the rules.
--volume picks the trees' bounding volume (default aabb; --bv is its earlier name). --threads 0
(the default) uses every core when bvhkit has oneTBB, 1 one thread; the output is the same for any
number of threads.
)";

template <class V>
void collide_all(const TriangleMesh& ma, const TriangleMesh& mb,
                 const std::vector<Transform<float>>& poses, DescentRule rule, unsigned threads,
                 std::vector<unsigned char>& out) {
    const CollisionModel<V> a(ma), b(mb);
    CollideOptions o;
    o.rule = rule;
    o.segments = false;
    out.assign(5 * poses.size(), 0);
    // Each pose's record has its own place in `out`, so the file is the same for any thread count.
    Executor(threads).parallel_for(poses.size(), 16, [&](std::size_t begin, std::size_t end) {
        CollideResult<float> result;
        for (std::size_t i = begin; i < end; ++i) {
            collide(a, b, poses[i], o, result);
            const auto n = std::uint32_t(result.contacts.size());
            unsigned char* record = out.data() + 5 * i;
            record[0] = result.colliding ? 1 : 0;
            for (int k = 0; k < 4; ++k) record[1 + k] = static_cast<unsigned char>(n >> (8 * k));
        }
    });
}

DescentRule parse_rule(const std::string& s) {
    for (DescentRule r : {DescentRule::Larger, DescentRule::A, DescentRule::B,
                          DescentRule::Simultaneous, DescentRule::ByOverlap})
        if (s == to_string(r)) return r;
    throw Error("--rule: unknown descent rule '" + s +
                "' (larger, a, b, simultaneous, by-overlap)");
}

}  // namespace

int collide_command(int argc, char** argv) {
    const Args args(argc, argv, {"--poses", "--out", "--volume", "--rule", "--threads"}, {});
    if (args.help()) {
        std::fputs(kCollideHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 2)
        return usage_error(
            "collide",
            "takes two meshes MESH_A MESH_B, got " + std::to_string(args.positional().size()),
            kCollideHelp);
    if (!args.has("--poses") || !args.has("--out"))
        return usage_error("collide", "--poses FILE and --out FILE are required", kCollideHelp);
    const TriangleMesh ma = load_mesh(args.positional()[0]);
    const TriangleMesh mb = load_mesh(args.positional()[1]);
    const auto poses = read_pose_file(args.value("--poses"));
    const DescentRule rule = parse_rule(args.value("--rule", "larger"));
    const unsigned threads = args.threads();
    const std::string bv = args.value("--volume", "aabb");
    std::vector<unsigned char> out;
    with_volume(bv, [&](auto tag) {
        collide_all<typename decltype(tag)::type>(ma, mb, poses, rule, threads, out);
    });
    write_bytes(args.value("--out"), out);
    std::size_t colliding = 0, pairs = 0;
    for (std::size_t i = 0; i + 5 <= out.size(); i += 5) {
        colliding += out[i];
        std::uint32_t n = 0;
        for (int k = 0; k < 4; ++k) n |= std::uint32_t(out[i + 1 + k]) << (8 * k);
        pairs += n;
    }
    std::fprintf(
        stderr, "collide: %zu poses (%s), %zu colliding, %zu intersecting pairs in all; wrote %s\n",
        poses.size(), bv.c_str(), colliding, pairs, args.value("--out").c_str());
    return 0;
}

}  // namespace bvhkit::tools
