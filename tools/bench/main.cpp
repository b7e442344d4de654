// bvhkit-bench: the same-run comparisons against the peer libraries, `bvhkit-bench WORKLOAD
// [ARGS...]`. Apart from the bvhkit command so that the command a user installs links no peer.
#include <cstdio>
#include <exception>
#include <string_view>

#include "bench_commands.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/version.hpp"

namespace {

struct Workload {
    const char* name;
    const char* summary;
    int (*run)(int argc, char** argv);  // argv[0] is the workload's name
};

const Workload kWorkloads[] = {
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
    for (const auto& w : kWorkloads) std::fprintf(out, "  %-10s %s\n", w.name, w.summary);
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
    for (const auto& w : kWorkloads) {
        if (first != w.name) continue;
        try {
            return w.run(argc - 1, argv + 1);
        } catch (const bvhkit::Error& e) {
            std::fprintf(stderr, "bvhkit-bench %s: error: %s\n", w.name, e.what());
            return 1;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "bvhkit-bench %s: unexpected error: %s\n", w.name, e.what());
            return 1;
        }
    }
    std::fprintf(stderr, "bvhkit-bench: unknown workload '%s'\n\n", argv[1]);
    print_usage(stderr);
    return 2;
}
