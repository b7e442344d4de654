// `bvhkit-bench collide`: workloads C1 and C2 (bench/workloads/collide_bench.hpp).
#include <cstdio>
#include <string>

#include "args.hpp"
#include "bench_commands.hpp"
#include "collide_bench.hpp"
#include "output.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kBenchHelp =
    R"(usage: bvhkit-bench collide [MESH ...] [--json] [--reps N] [--poses N] [--distance-poses N]
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

int bench_collide(int argc, char** argv) {
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
