// `bvhkit-bench rays|instances|nearest|scene|files ...`: the same-run comparisons against the peers
// (dynamic and collide have their own files).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "args.hpp"
#include "bench_commands.hpp"
#include "bvhkit/error.hpp"
#include "bvhkit/mesh/data_files.hpp"
#include "collide_bench.hpp"
#include "file_bench.hpp"
#include "instance_bench.hpp"
#include "nearest_bench.hpp"
#include "output.hpp"
#include "ray_bench.hpp"
#include "scene_bench.hpp"

namespace bvhkit::tools {

std::vector<std::string> default_bench_meshes(const char* fallback) {
    std::vector<std::string> meshes;
    for (const char* m : {"stanford-bunny.obj", "igea.ply"})
        if (const auto p = find_data_file(m, data_dirs()); !p.empty()) meshes.push_back(p.string());
    if (meshes.empty()) meshes.push_back(fallback);
    return meshes;
}

namespace {

constexpr const char* kRaysHelp =
    R"(usage: bvhkit-bench rays [MESH ...] [--json] [--reps N] [--rays N]
                        [--size N] [--builder NAME] [--high-quality]

Workload R of docs/workloads.md for bvhkit and Embree 3 (when installed), in this process, one thread
each: build, R1 (camera rays, SIZE x SIZE), R2 (random rays), R3 (R2 as occlusion queries).
Times are medians of N repetitions; speedup = Embree ms / bvhkit ms (> 1: bvhkit is faster).
Rows bvhkit-auto: TriangleBvhOptions::auto_spatial_splits (spatial splits where the tree's overlap
says they pay; the bvhkit tree elsewhere), against Embree's default build.
MESH is a file (OBJ, PLY, STL) or a generator spec such as sphere:subdiv=7; the default is the
shared bunny and igea meshes when present (else a procedural sphere), then scenes that are not
scans: room:objects=200, city:blocks=8 and soup:n=100000.

  --json          print a JSON array of rows instead of a table
  --reps N        repetitions per figure (default 5)
  --rays N        rays in R2 and R3 (default 1000000)
  --size N        R1 image side (default 1024)
  --builder NAME  bvhkit builder (default binned-sah)
  --high-quality  also bvhkit with spatial splits (bvhkit-sbvh) against Embree's high-quality
                  build (embree3-high); bvhkit-sbvh's speedup is over embree3-high
)";

}  // namespace

int bench_rays(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--rays", "--size", "--builder"},
                    {"--json", "--high-quality"});
    if (args.help()) {
        std::fputs(kRaysHelp, stdout);
        return 0;
    }
    bench::RayBenchOptions o;
    o.meshes = args.positional();
    if (o.meshes.empty()) {
        // The scans, then architecture-like scenes, whose trees differ (walls and floors that
        // overlap many boxes, sizes over orders of magnitude, unconnected triangles).
        o.meshes = default_bench_meshes();
        for (const char* scene : {"room:objects=200", "city:blocks=8", "soup:n=100000"})
            o.meshes.emplace_back(scene);
    }
    o.repetitions = int(args.integer("--reps", 5, 1, 1000));
    o.random_rays = std::size_t(args.integer("--rays", 1000000, 1, 100000000));
    o.camera_size = std::uint32_t(args.integer("--size", 1024, 1, 16384));
    o.builder = args.value("--builder", "binned-sah");
    o.high_quality = args.flag("--high-quality");
    if (!bench::have_embree())
        std::fprintf(stderr,
                     "Embree 3 was not found at build time (apt-get install libembree-dev): "
                     "only bvhkit is measured\n");
    const auto rows = bench::run_ray_bench(o, args.flag("--json") ? nullptr : stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

namespace {

constexpr const char* kInstancesHelp =
    R"(usage: bvhkit-bench instances [MESH] [--json] [--reps N] [--rays N] [--size N]
                             [--counts N,N,...] [--density D] [--seed S]

Workload S3 (issue 40) for bvhkit's Scene and Embree 3's instances (RTC_GEOMETRY_TYPE_INSTANCE, when
installed), in this process, one thread each: a crowd of instances of one mesh at random rigid poses,
then closest and any hit for camera rays framing the crowd (S3-R1, SIZE x SIZE) and random rays from
inside the crowd's box (S3-R2). Build and ray times are medians of N interleaved repetitions;
speedup = Embree ms / bvhkit ms (> 1: bvhkit is faster). disagree: rays whose answers differ (hit or
miss, instance, t beyond a relative 1e-4); ties: of those, two instances hit at the same t; bvhkit_right
and embree_right: of the rest, which answer a brute-force referee in double confirms. MESH is a
file or a generator spec; the default is the shared bunny when present, else a procedural sphere.

  --json          print a JSON array of rows instead of a table
  --reps N        repetitions per figure (default 5)
  --rays N        rays in S3-R2 (default 1000000)
  --size N        S3-R1 image side (default 1024)
  --counts LIST   instances per scene, comma separated (default 100,10000)
  --density D     fraction of the crowd's cube the instances' bounding spheres fill (default 0.3)
  --seed S        poses and random rays (default 1)
)";

}  // namespace

int bench_instances(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--rays", "--size", "--counts", "--density", "--seed"},
                    {"--json"});
    if (args.help()) {
        std::fputs(kInstancesHelp, stdout);
        return 0;
    }
    bench::InstanceBenchOptions o;
    const auto meshes = args.positional();
    if (meshes.size() > 1) throw Error("bench instances: one mesh at most");
    o.mesh = meshes.empty() ? default_bench_meshes().front() : meshes.front();
    o.repetitions = int(args.integer("--reps", 5, 1, 1000));
    o.random_rays = std::size_t(args.integer("--rays", 1000000, 1, 100000000));
    o.camera_size = std::uint32_t(args.integer("--size", 1024, 1, 16384));
    o.counts.clear();
    const std::string counts = args.value("--counts", "100,10000");
    for (std::size_t b = 0; b <= counts.size();) {
        const std::size_t e = std::min(counts.find(',', b), counts.size());
        const std::string item = counts.substr(b, e - b);
        char* end = nullptr;
        const unsigned long long n = std::strtoull(item.c_str(), &end, 10);
        if (item.empty() || *end != 0 || n < 1 || n > 10000000)
            throw Error("--counts: '" + item + "' is not a count of instances in [1, 10000000]");
        o.counts.push_back(std::size_t(n));
        b = e + 1;
    }
    if (args.has("--density")) {
        const std::string v = args.value("--density");
        char* end = nullptr;
        o.density = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != 0 || !(o.density > 0 && o.density <= 1))
            throw Error("option --density: '" + v + "' is not a number in (0, 1]");
    }
    o.seed = std::uint64_t(args.integer("--seed", 1, 0, 1000000000));
    if (!bench::have_embree())
        std::fprintf(stderr,
                     "Embree 3 was not found at build time (apt-get install libembree-dev): "
                     "only bvhkit is measured\n");
    const auto rows = bench::run_instance_bench(o, args.flag("--json") ? nullptr : stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

namespace {

constexpr const char* kNearestHelp =
    R"(usage: bvhkit-bench nearest [MESH ...] [--json] [--reps N] [--points N] [--builder NAME]
                           [--scaling]

Workload N1 of docs/workloads.md for bvhkit and CGAL 5.5's AABB_tree (when installed), in this process,
one thread each: closest point, squared distance and triangle for N points uniform in the mesh's
box grown by 10%. Query times are medians of N interleaved repetitions (bvhkit, CGAL, bvhkit, ...);
speedup = bvhkit queries/s over CGAL's. Default meshes: the shared bunny and igea when present.

  --json          print a JSON array of rows instead of a table
  --reps N        repetitions per figure (default 5)
  --points N      query points (default 100000)
  --builder NAME  bvhkit builder (default binned-sah)
  --scaling       also bvhkit on one thread against all threads (oneTBB): batched N1 queries,
                  bottom-up and LBVH builds (interleaved medians)
)";

}  // namespace

int bench_nearest(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--points", "--builder"}, {"--json", "--scaling"});
    if (args.help()) {
        std::fputs(kNearestHelp, stdout);
        return 0;
    }
    bench::NearestBenchOptions o;
    o.meshes = args.positional();
    if (o.meshes.empty()) o.meshes = default_bench_meshes();
    o.repetitions = int(args.integer("--reps", 5, 1, 1000));
    o.points = std::size_t(args.integer("--points", 100000, 1, 100000000));
    o.builder = args.value("--builder", "binned-sah");
    o.scaling = args.flag("--scaling");
    if (!bench::have_cgal())
        std::fprintf(stderr,
                     "CGAL was not found at build time (apt-get install libcgal-dev): only "
                     "bvhkit is measured\n");
    const auto rows = bench::run_nearest_bench(o, args.flag("--json") ? nullptr : stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

namespace {

constexpr const char* kFilesHelp =
    R"(usage: bvhkit-bench files [MESH ...] [--json] [--reps N] [--rays N]

Saved trees (docs/serialization.md): for a TriangleBvh<float> over each mesh, the median times of
build, save, load (copied into memory) and map (read in place), with and without validation; what
one load and one map add to the process's resident memory (anon_mb: its own; file_mb: file pages,
shared with the page cache), measured on Linux; and R (random) rays through the mapped tree, the
same tree in memory walked binary, and the default tree (wide) in memory. Default meshes: the
shared bunny and igea when present.

  --json          print a JSON array of rows instead of a table
  --reps N        repetitions per figure (default 5)
  --rays N        random rays (default 200000)
)";

}  // namespace

int bench_files(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--rays"}, {"--json"});
    if (args.help()) {
        std::fputs(kFilesHelp, stdout);
        return 0;
    }
    bench::FileBenchOptions o;
    o.meshes = args.positional();
    if (o.meshes.empty()) o.meshes = default_bench_meshes();
    o.repetitions = int(args.integer("--reps", 5, 1, 1000));
    o.random_rays = std::size_t(args.integer("--rays", 200000, 1, 100000000));
    const auto rows = bench::run_file_bench(o, args.flag("--json") ? nullptr : stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

namespace {

constexpr const char* kSceneHelp =
    R"(usage: bvhkit-bench scene [MESH ...] [--json] [--reps N] [--configurations N]
                         [--extent S] [--threads N] [--seed N]

Workload S1 of docs/workloads.md, a collision manager called per robot configuration: a six-link
arm of capsules (960 triangles each) and a gripper among an environment of MESH files, each scaled
to S across and placed around the arm's base; for N random configurations, whether the arm touches
the environment or itself (links not next to each other), and the smallest distance when it does
not. bvhkit's Scene<double> (set_poses per configuration; and const queries, on one thread and
batched on all threads) against FCL 0.7's DynamicAABBTreeCollisionManager over BVHModel<OBBRSS>
(when installed), medians of N interleaved repetitions; vs_fcl = FCL's time / bvhkit's. The
answers are compared on every configuration (colliding flags, distances). Default meshes: the
shared bunny, dragon-lowres, teapot and suzanne (99,605 triangles).

  --json              print a JSON array of rows instead of a table
  --reps N            repetitions per figure (default 3)
  --configurations N  robot configurations (default 10000)
  --extent S          each environment mesh's largest extent (default 0.7; the arm reaches 1.8;
                      --size is its earlier name)
  --threads N         threads of the batched rows (default 0: every core)
  --seed N            the configurations' seed (default 2026)
)";

}  // namespace

int bench_scene(int argc, char** argv) {
    const Args args(argc, argv, {"--reps", "--configurations", "--extent", "--threads", "--seed"},
                    {"--json"});
    if (args.help()) {
        std::fputs(kSceneHelp, stdout);
        return 0;
    }
    bench::SceneBenchOptions o;
    o.meshes = args.positional();
    if (o.meshes.empty())
        for (const std::string& name : bench::scene_bench_default_meshes())
            if (const auto p = find_data_file(name, data_dirs()); !p.empty())
                o.meshes.push_back(p.string());
    if (o.meshes.empty()) o.meshes = {"sphere:subdiv=6", "torus", "spot.obj", "teapot.obj"};
    o.repetitions = int(args.integer("--reps", 3, 1, 1000));
    o.configurations = std::size_t(args.integer("--configurations", 10000, 1, 100000000));
    if (args.has("--extent")) {
        const std::string v = args.value("--extent");
        char* end = nullptr;
        o.object_size = std::strtod(v.c_str(), &end);
        if (v.empty() || *end != '\0' || !(o.object_size > 0 && o.object_size < 1e6))
            throw Error("option --extent: '" + v + "' is not a number in (0, 1e6)");
    }
    o.threads = args.threads();
    o.seed = std::uint64_t(args.integer("--seed", 2026, 0, std::numeric_limits<long long>::max()));
    if (!bench::have_fcl())
        std::fprintf(stderr,
                     "FCL was not found at build time (apt-get install libfcl-dev): only bvhkit is "
                     "measured\n");
    const auto rows = bench::run_scene_bench(o, args.flag("--json") ? nullptr : stderr);
    print_rows(rows, args.flag("--json"));
    return 0;
}

}  // namespace bvhkit::tools
