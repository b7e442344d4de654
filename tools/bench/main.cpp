// bvhkit-bench: the same-run comparisons against the peer libraries, `bvhkit-bench WORKLOAD
// [ARGS...]`. Apart from the bvhkit command so that the command a user installs links no peer.
#include <cstdio>
#include <string_view>

#include "bench_commands.hpp"
#include "bvhkit/version.hpp"
#include "dispatch.hpp"

namespace {

using bvhkit::tools::Subcommand;

const Subcommand kWorkloads[] = {
    {"rays", "workload R against Embree 3", bvhkit::tools::bench_rays},
    {"instances", "workload S3 (instanced rays) against Embree 3", bvhkit::tools::bench_instances},
    {"dynamic", "workloads D1-D4 against Box2D and Bullet", bvhkit::tools::bench_dynamic},
    {"nearest", "workload N1 against CGAL's AABB tree", bvhkit::tools::bench_nearest},
    {"collide", "workloads C1, C2 against FCL", bvhkit::tools::bench_collide},
    {"scene", "workload S1 (a robot arm's configurations) against FCL", bvhkit::tools::bench_scene},
    {"files", "saved trees: save, load, map and rays through them", bvhkit::tools::bench_files},
};

void print_usage(std::FILE* out) {
    std::fprintf(out,
                 "usage: bvhkit-bench WORKLOAD [ARGS...]   (bvhkit-bench WORKLOAD --help for "
                 "details)\n"
                 "       bvhkit-bench --version\n\n");
    bvhkit::tools::print_subcommands(out, kWorkloads);
}

}  // namespace

int main(int argc, char** argv) {
    const std::string_view first = argc > 1 ? argv[1] : "";
    if (argc < 2 || first == "help" || first == "--help" || first == "-h") {
        print_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (first == "--version" || first == "-V") {
        std::printf("bvhkit-bench %s\n", bvhkit::version_string);
        return 0;
    }
    return bvhkit::tools::run_subcommand("bvhkit-bench", first, kWorkloads, argc - 1, argv + 1,
                                         print_usage);
}
