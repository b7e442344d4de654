#pragma once
// What the main() of bvhkit and of bvhkit-bench share: a table of subcommands, and running the one
// a command line names with an error reported as one line that names the program and the
// subcommand.
#include <cstdio>
#include <exception>
#include <span>
#include <string_view>

#include "bvhkit/error.hpp"

namespace bvhkit::tools {

struct Subcommand {
    const char* name;
    const char* summary;
    int (*run)(int argc, char** argv);  // argv[0] is the subcommand's name
};

/// One line per subcommand: its name, then what it does.
inline void print_subcommands(std::FILE* out, std::span<const Subcommand> table) {
    for (const Subcommand& s : table) std::fprintf(out, "  %-12s %s\n", s.name, s.summary);
}

/// Runs the subcommand of `table` named `name` with argv[0] its name and returns its exit code; a
/// bvhkit::Error (or any exception) it throws is one line on stderr and exit code 1; a name not in
/// the table is exit code 2, after `usage`.
inline int run_subcommand(const char* program, std::string_view name,
                          std::span<const Subcommand> table, int argc, char** argv,
                          void (*usage)(std::FILE*)) {
    for (const Subcommand& s : table) {
        if (name != s.name) continue;
        try {
            return s.run(argc, argv);
        } catch (const bvhkit::Error& e) {
            std::fprintf(stderr, "%s %s: error: %s\n", program, s.name, e.what());
            return 1;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s %s: unexpected error: %s\n", program, s.name, e.what());
            return 1;
        }
    }
    std::fprintf(stderr, "%s: unknown subcommand '%.*s'\n\n", program, int(name.size()),
                 name.data());
    usage(stderr);
    return 2;
}

}  // namespace bvhkit::tools
