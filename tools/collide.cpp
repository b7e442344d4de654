// `bvhkit collide MESH_A MESH_B --poses FILE --out FILE [--bv ...]` and `bvhkit bench collide`.
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
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/pairs_model.hpp"
#include "collide_bench.hpp"
#include "commands.hpp"
#include "output.hpp"
#include "pose_file.hpp"
#include "volume_choice.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kCollideHelp =
    R"(usage: bvhkit collide MESH_A MESH_B --poses FILE --out FILE [--bv aabb|obb|rss|obbrss|sphere|kdop18|hull]
                      [--rule larger|a|b|simultaneous|by-overlap]

For each pose (12 float32: row-major rotation R, translation t; B placed at x' = R x + t in A's
frame) writes 5 packed bytes: uint8 collided, uint32 number of intersecting triangle pairs
(little-endian). Touching counts as intersecting; see docs/collision.md for the rules.
)";

template <class V>
void collide_all(const TriangleMesh& ma, const TriangleMesh& mb,
                 const std::vector<Transform<float>>& poses, DescentRule rule,
                 std::vector<unsigned char>& out) {
    const CollisionModel<V> a(ma), b(mb);
    CollideResult<float> result;
    CollideOptions o;
    o.rule = rule;
    o.segments = false;
    for (const auto& p : poses) {
        collide(a, b, p, o, result);
        const auto n = std::uint32_t(result.contacts.size());
        out.push_back(result.colliding ? 1 : 0);
        for (int k = 0; k < 4; ++k) out.push_back(static_cast<unsigned char>(n >> (8 * k)));
    }
}

DescentRule parse_rule(const std::string& s) {
    for (DescentRule r : {DescentRule::Larger, DescentRule::A, DescentRule::B,
                          DescentRule::Simultaneous, DescentRule::ByOverlap})
        if (s == to_string(r)) return r;
    throw Error("--rule: unknown descent rule '" + s +
                "' (larger, a, b, simultaneous, by-overlap)");
}

constexpr const char* kBenchHelp =
    R"(usage: bvhkit bench collide [MESH ...] [--json] [--reps N] [--poses N] [--distance-poses N]
                             [--seed N]

Workloads C1 and C2 of docs/workloads.md: the mesh against a copy of itself under N random rigid
poses (C1: yes/no and all-pairs collision) and the distance at the poses where they do not
collide (C2), for bvhkit with each volume type (aabb, obb, rss, obbrss, sphere, kdop18, hull) and FCL 0.7
(BVHModel<OBBRSS> and <OBB>; FCL has no OBB distance) in this process, one thread each. Times
are medians of N repetitions interleaved round-robin across the libraries; vs_fcl_best = bvhkit
queries/s over FCL's best volume type. The agreement of the answers is printed to stderr.
Default meshes: the shared bunny and igea when present.

  --json               print a JSON array of rows instead of a table
  --reps N             repetitions per figure (default 3)
  --poses N            C1 poses (default 1000)
  --distance-poses N   C2: at most N of the non-colliding poses (default: all)
  --seed N             pose seed (default 2026)
)";

}  // namespace

int collide_command(int argc, char** argv) {
    const Args args(argc, argv, {"--poses", "--out", "--bv", "--rule"}, {});
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
    const std::string bv = args.value("--bv", "aabb");
    std::vector<unsigned char> out;
    with_volume(
        bv, [&](auto tag) { collide_all<typename decltype(tag)::type>(ma, mb, poses, rule, out); });
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

int bench_collide_command(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--poses", "--distance-poses", "--seed"}, {"--json"});
    if (args.help()) {
        std::fputs(kBenchHelp, stdout);
        return 0;
    }
    bench::CollideBenchOptions o;
    o.meshes = args.positional();
    if (o.meshes.empty()) o.meshes = default_bench_meshes("sphere:subdiv=6");
    o.repetitions = int(args.integer("--reps", 3, 1, 1000));
    o.poses = std::size_t(args.integer("--poses", 1000, 1, 10000000));
    o.distance_poses = std::size_t(args.integer("--distance-poses", 0, 0, 10000000));
    o.seed = std::uint64_t(args.integer("--seed", 2026, 0, 1LL << 62));
    if (!bench::have_fcl())
        std::fprintf(stderr,
                     "FCL was not found at build time (apt-get install libfcl-dev): only bvhkit "
                     "is measured\n");
    const auto rows = bench::run_collide_bench(o, stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

}  // namespace bvhkit::tools
