// The bvhkit command: `bvhkit SUBCOMMAND [ARGS...]`. Each subcommand lives in its own file and is
// listed in the table below; `bvhkit help` (or no argument) prints the list.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

#include "commands.hpp"
#include "dispatch.hpp"

namespace {

using bvhkit::tools::Subcommand;

const Subcommand kSubcommands[] = {
    {"bsp", "the BSP tree of a mesh and its statistics", bvhkit::tools::bsp_command},
    {"closest", "closest points on a mesh for a points file", bvhkit::tools::closest_command},
    {"collide", "collision of two meshes at the poses of a file", bvhkit::tools::collide_command},
    {"distance", "distance between two meshes at the poses of a file",
     bvhkit::tools::distance_command},
    {"draw-tree", "draw a 2D dynamic tree as SVG", bvhkit::tools::draw_tree_command},
    {"info", "a mesh and the trees each builder makes of it", bvhkit::tools::info_command},
    {"render", "a shaded picture or a traversal-cost heat map (PNG)",
     bvhkit::tools::render_command},
    {"trace", "trace a ray file through a mesh, write the hits", bvhkit::tools::trace_command},
    {"version", "print the library version", bvhkit::tools::version_command},
};

void print_usage(std::FILE* out) {
    std::fprintf(out,
                 "usage: bvhkit SUBCOMMAND [ARGS...]   (bvhkit SUBCOMMAND --help for details)\n"
                 "       bvhkit --version\n\n");
    bvhkit::tools::print_subcommands(out, kSubcommands);
    std::fprintf(out, "\nThe same-run benchmarks against the peer libraries are bvhkit-bench.\n");
}

// `bvhkit bench ...` from before the benchmarks were their own program: runs bvhkit-bench from this
// program's folder with the same arguments, so that this program links no peer library.
int run_bvhkit_bench(char** argv) {
    std::fprintf(stderr, "note: bvhkit bench moved to bvhkit-bench\n");
    std::error_code ec;
    std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) self = argv[0];
    const std::filesystem::path bench = self.parent_path() / "bvhkit-bench";
    std::string name = bench.string();
    argv[1] = name.data();
    ::execv(name.c_str(), argv + 1);
    std::fprintf(stderr,
                 "bvhkit bench: error: cannot run %s (%s); build the bvhkit_bench_cli target\n",
                 name.c_str(), std::strerror(errno));
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2 || std::string_view(argv[1]) == "help" || std::string_view(argv[1]) == "--help" ||
        std::string_view(argv[1]) == "-h") {
        print_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const std::string_view name =
        std::string_view(argv[1]) == "--version" || std::string_view(argv[1]) == "-V" ? "version"
                                                                                      : argv[1];
    if (name == "bench") return run_bvhkit_bench(argv);
    return bvhkit::tools::run_subcommand("bvhkit", name, kSubcommands, argc - 1, argv + 1,
                                         print_usage);
}
