// `bvhkit-bench dynamic`: workloads D1-D4 (the dynamic tree against Box2D's and Bullet's
// broadphases and Box2D's tree ray cast); see bench/workloads/dynamic_bench.hpp.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "args.hpp"
#include "bench_commands.hpp"
#include "bvhkit/error.hpp"
#include "dynamic_bench.hpp"
#include "output.hpp"

namespace bvhkit::tools {

namespace {

void bench_dynamic_usage(std::FILE* out) {
    std::fprintf(
        out,
        "usage: bvhkit-bench dynamic [--json] [--boxes N] [--steps S] [--reps R] [--only "
        "D1|D2|D3|D4]\n"
        "  D1 2D crowd (vs Box2D b2BroadPhase), D2 3D crowd (vs Bullet btDbvtBroadphase),\n"
        "  D3 churn, D4 closest-hit ray casts (vs Box2D b2DynamicTree). Defaults: --boxes 100000 "
        "--steps 40 --reps 3 (bvhkit-exact, bvhkit-greedy: 1 rep).\n"
        "  step_ms: ms per step (D3: per round of 1,000 ops); speedup: that row's step_ms over\n"
        "  bvhkit's; pairs: pairs found over all steps; agree: same pairs as bvhkit every step.\n");
}

}  // namespace

int bench_dynamic(int argc, char** argv) {
    const Args args(argc, argv, {"--boxes", "--steps", "--reps", "--only"}, {"--json"});
    if (args.help()) {
        bench_dynamic_usage(stdout);
        return 0;
    }
    if (!args.positional().empty())
        throw Error("unexpected argument '" + args.positional()[0] + "'");
    bench::DynamicBenchConfig c;
    c.n = int(args.integer("--boxes", c.n, 1, 100000000));
    c.steps = int(args.integer("--steps", c.steps, 1, 100000000));
    c.reps = int(args.integer("--reps", c.reps, 1, 100000000));
    if (args.has("--only")) {
        const std::string w = args.value("--only");
        c.d1 = w == "D1", c.d2 = w == "D2", c.d3 = w == "D3", c.d4 = w == "D4";
        if (!c.d1 && !c.d2 && !c.d3 && !c.d4)
            throw Error("--only: '" + w + "' is not D1, D2, D3 or D4");
    }
    print_rows(bench::run_dynamic_bench(c, stderr), args.flag("--json"));
    return 0;
}

}  // namespace bvhkit::tools
