// `bvhkit closest`: the closest point on the user's mesh to each of the user's points, in the
// docs/workloads.md formats (points: 3 float32 each; result, format 2: float32 x y z, uint32
// triangle index, float64 distance per point; format 1, the earlier one: float32 x y z, float32
// squared distance, uint32 triangle index).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "args.hpp"
#include "bvhkit/io/file_access.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"
#include "commands.hpp"

namespace bvhkit::tools {
namespace {

constexpr const char* kClosestHelp =
    R"(usage: bvhkit closest MESH --points FILE --out FILE [--format 1|2] [--builder NAME]
                       [--threads N]

For every point of FILE (3 float32 each, little-endian, no header) finds the closest point on MESH
and writes, per point, little-endian and without a header:
  --format 2 (the default), 24 bytes: float32 x y z of that point, uint32 triangle index (the
    triangle's position in the mesh file, polygons split into fans in file order), float64
    distance (not squared: finite for every finite point);
  --format 1, 20 bytes, the earlier record: float32 x y z, float32 squared distance (+inf beyond
    1.8e19 and 0 below 1e-23, where float32 cannot hold the square), uint32 triangle index.
0xFFFFFFFF and +inf where there is no closest point (an empty mesh, a point with a NaN or an
infinite coordinate). --threads 0 (the default) uses every core when bvhkit has oneTBB; the output
is the same for any number of threads.
)";

std::vector<Vec3f> read_points(const std::string& path) {
    const auto bytes = file_detail::read_regular_file<std::vector<char>>(path, "points file");
    if (bytes.size() % 12 != 0)
        throw Error("points file '" + path + "' has " + std::to_string(bytes.size()) +
                    " bytes, not a multiple of 12 (3 float32 per point)");
    std::vector<Vec3f> points(bytes.size() / 12);
    for (std::size_t i = 0; i < points.size(); ++i)
        std::memcpy(&points[i][0], bytes.data() + 12 * i, 12);
    return points;
}

}  // namespace

int closest_command(int argc, char** argv) {
    const Args args(argc, argv, {"--points", "--out", "--format", "--builder", "--threads"}, {});
    if (args.help()) {
        std::fputs(kClosestHelp, stdout);
        return 0;
    }
    if (args.positional().size() != 1) throw Error("closest takes one mesh (see --help)");
    if (!args.has("--points") || !args.has("--out"))
        throw Error("closest needs --points FILE and --out FILE");
    const auto threads = unsigned(args.threads());
    const auto format = int(args.integer("--format", 2, 1, 2));
    const TriangleMesh mesh = load_mesh(args.positional()[0]);
    const std::vector<Vec3f> points = read_points(args.value("--points"));
    BuildOptions options = parse_builder(args.value("--builder", "binned-sah"));
    options.threads = threads;
    const auto t0 = std::chrono::steady_clock::now();
    const ClosestPointMesh<float> tree(mesh, options);
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<MeshPoint<float>> found(points.size());
    tree.closest_points(points, found, threads);
    const auto t2 = std::chrono::steady_clock::now();
    const std::size_t record = format == 1 ? 20 : 24;
    std::vector<char> out(points.size() * record);
    for (std::size_t i = 0; i < found.size(); ++i) {
        char* o = out.data() + record * i;
        const MeshPoint<float>& f = found[i];
        std::memcpy(o, &f.point[0], 12);
        if (format == 1) {
            std::memcpy(o + 12, &f.distance_squared, 4);
            std::memcpy(o + 16, &f.triangle, 4);
            continue;
        }
        // The distance in double, from the triangle measured again there: float's would be inf
        // for a point 3e38 from the mesh's far side, and its square is past float's range from
        // 1.8e19 on.
        double distance = std::numeric_limits<double>::infinity();
        if (f) {
            const auto& t = mesh.triangles[f.triangle];
            const Triangle<float> tri{mesh.vertices[t[0]], mesh.vertices[t[1]],
                                      mesh.vertices[t[2]]};
            distance = double(std::sqrt(closest_point_accurate(tri, points[i]).distance_squared));
        }
        std::memcpy(o + 12, &f.triangle, 4);
        std::memcpy(o + 16, &distance, 8);
    }
    const std::string out_path = args.value("--out");
    file_detail::write_file_bytes_of(out_path, out, "output file");
    const auto ms = [](auto a, auto b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    std::fprintf(stderr, "closest: %zu triangles, %zu points; build %.1f ms, queries %.1f ms\n",
                 mesh.triangles.size(), points.size(), ms(t0, t1), ms(t1, t2));
    return 0;
}

}  // namespace bvhkit::tools
