// `bvhkit bench dynamic`: workloads D1, D2, D3 (the dynamic tree against Box2D's and Bullet's
// broadphases); see bench/workloads/dynamic_bench.hpp.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "bvhkit/error.hpp"
#include "commands.hpp"
#include "dynamic_bench.hpp"

namespace bvhkit::tools {

namespace {

int parse_positive(const char* option, const char* text) {
    char* end = nullptr;
    const long v = std::strtol(text, &end, 10);
    if (!text[0] || *end || v <= 0 || v > 100000000)
        throw Error(std::string(option) + ": '" + text + "' is not a positive integer");
    return int(v);
}

void usage(std::FILE* out) {
    std::fprintf(
        out,
        "usage: bvhkit bench dynamic [--json] [--n N] [--steps S] [--reps R] [--only D1|D2|D3]\n"
        "  D1 2D crowd (vs Box2D b2BroadPhase), D2 3D crowd (vs Bullet btDbvtBroadphase),\n"
        "  D3 churn. Defaults: --n 100000 --steps 40 --reps 3 (bvhkit-greedy: 1 rep).\n"
        "  step_ms: ms per step (D3: per round of 1,000 ops); speedup: that row's step_ms over\n"
        "  bvhkit's; pairs: pairs found over all steps; agree: same pairs as bvhkit every step.\n");
}

}  // namespace

int bench_dynamic_command(int argc, char** argv) {
    bench::DynamicBenchConfig c;
    bool json = false;
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        const auto value = [&]() -> const char* {
            if (i + 1 >= argc) throw Error(std::string(a) + " needs a value");
            return argv[++i];
        };
        if (a == "--help" || a == "-h") {
            usage(stdout);
            return 0;
        } else if (a == "--json") {
            json = true;
        } else if (a == "--n") {
            c.n = parse_positive("--n", value());
        } else if (a == "--steps") {
            c.steps = parse_positive("--steps", value());
        } else if (a == "--reps") {
            c.reps = parse_positive("--reps", value());
        } else if (a == "--only") {
            const std::string_view w = value();
            c.d1 = w == "D1", c.d2 = w == "D2", c.d3 = w == "D3";
            if (!c.d1 && !c.d2 && !c.d3)
                throw Error("--only: '" + std::string(w) + "' is not D1, D2 or D3");
        } else {
            std::fprintf(stderr, "bvhkit bench dynamic: unknown option '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    const auto rows = bench::run_dynamic_bench(c, stderr);
    if (json) {
        bench::print_json(stdout, rows);
    } else {
        bench::print_table(stdout, rows);
    }
    return 0;
}

}  // namespace bvhkit::tools
