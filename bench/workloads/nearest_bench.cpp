#include "nearest_bench.hpp"

#include <cmath>

#include "bvhkit/exec/parallel.hpp"
#include "bvhkit/math/random.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "bvhkit/query/closest_point_mesh.hpp"

#if defined(BVHKIT_HAVE_CGAL)
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#endif

namespace bvhkit::bench {

bool have_cgal() {
#if defined(BVHKIT_HAVE_CGAL)
    return true;
#else
    return false;
#endif
}

namespace {

/// N1's points: uniform in the mesh's box grown by 10% (5% of its extent on every side).
std::vector<Vec3f> n1_points(const TriangleMesh& mesh, std::size_t count) {
    const Aabb3f box = mesh.bounds();
    const Vec3f grow = box.extent() * 0.05f;
    const Aabb3f g(box.min - grow, box.max + grow);
    SplitMix64 rng(1);
    std::vector<Vec3f> out(count);
    for (auto& p : out)
        for (int a = 0; a < 3; ++a) p[a] = float(rng.uniform(g.min[a], g.max[a]));
    return out;
}

#if defined(BVHKIT_HAVE_CGAL)
using CgalKernel = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<CgalKernel::Triangle_3>;
using CgalPrimitive = CGAL::AABB_triangle_primitive<CgalKernel, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<CgalKernel, CgalPrimitive>>;
#endif

}  // namespace

std::vector<Row> run_nearest_bench(const NearestBenchOptions& o, std::FILE* progress) {
    std::vector<Row> rows;
    const BuildOptions build = parse_builder(o.builder);
    for (const std::string& m : o.meshes) {
        const TriangleMesh mesh = load_mesh(m);
        const std::string name = mesh_label(m);
        if (progress)
            std::fprintf(progress, "%s: %zu triangles\n", name.c_str(), mesh.triangles.size());
        const std::vector<Vec3f> points = n1_points(mesh, o.points);
        const auto qps = [&](double ms) { return double(points.size()) / (ms / 1000.0); };

        // bvhkit, one thread: build and queries.
        BuildOptions serial = build;
        serial.threads = 1;
        ClosestPointMesh<float> ours;
        const double our_build =
            median_ms(o.repetitions, [&] { ours = ClosestPointMesh<float>(mesh, serial); });
        std::vector<MeshPoint<float>> our_out(points.size());
        // In its own file: see nearest_timed_calls.cpp.
        const auto run_ours = [&] { closest_points_one_thread(ours, points, our_out); };
        Row r;
        r.set("workload", "N1")
            .set("library", "bvhkit")
            .set("mesh", name)
            .set("build_ms", our_build);
#if defined(BVHKIT_HAVE_CGAL)
        CgalTriangles tris;
        tris.reserve(mesh.triangles.size());
        for (const auto& t : mesh.triangles) {
            const auto pt = [&](std::uint32_t k) {
                const Vec3f& v = mesh.vertices[k];
                return CgalKernel::Point_3(v[0], v[1], v[2]);
            };
            tris.emplace_back(pt(t[0]), pt(t[1]), pt(t[2]));
        }
        std::unique_ptr<CgalTree> cgal;
        const double cgal_build = median_ms(o.repetitions, [&] {
            cgal = std::make_unique<CgalTree>(tris.cbegin(), tris.cend());
            cgal->build();
            cgal->accelerate_distance_queries();
        });
        std::vector<std::pair<double, std::uint32_t>> cgal_out(points.size());
        const auto run_cgal = [&] {
            for (std::size_t i = 0; i < points.size(); ++i) {
                const CgalKernel::Point_3 q(points[i][0], points[i][1], points[i][2]);
                const auto [c, prim] = cgal->closest_point_and_primitive(q);
                cgal_out[i] = {CGAL::squared_distance(q, c), std::uint32_t(prim - tris.cbegin())};
            }
        };
        const auto [our_ms, cgal_ms] = median_ms_interleaved(o.repetitions, run_ours, run_cgal);
        // Agreement: the squared distances (CGAL in double, bvhkit in float).
        double worst = 0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const double a = our_out[i].distance_squared, b = cgal_out[i].first;
            worst = std::max(worst, std::fabs(a - b) / std::max(b, 1e-30));
        }
        r.set("queries_per_s", qps(our_ms))
            .set("speedup", cgal_ms / our_ms)
            .set("max_rel_diff_d2", worst);
        rows.push_back(r);
        Row c;
        c.set("workload", "N1")
            .set("library", "cgal-5.5")
            .set("mesh", name)
            .set("build_ms", cgal_build)
            .set("queries_per_s", qps(cgal_ms));
        rows.push_back(c);
#else
        const double our_ms = median_ms(o.repetitions, run_ours);
        r.set("queries_per_s", qps(our_ms));
        rows.push_back(r);
#endif
        if (!o.scaling) continue;
        // One thread against all of them (oneTBB), interleaved; the results are identical.
        std::vector<MeshPoint<float>> batch(points.size());
        const auto [one, all] = median_ms_interleaved(
            o.repetitions, [&] { ours.closest_points(points, batch, 1); },
            [&] { ours.closest_points(points, batch, 0); });
        Row s;
        s.set("workload", "N1-batch")
            .set("library", "bvhkit")
            .set("mesh", name)
            .set("ms_1_thread", one)
            .set("ms_all_threads", all)
            .set("scaling", one / all);
        rows.push_back(s);
        std::vector<Aabb3f> boxes;
        std::vector<Vec3f> centroids;
        for (const auto& t : mesh.triangles) {
            boxes.push_back(
                Aabb3f::of_points(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
            centroids.push_back(boxes.back().centroid());
        }
        for (const char* b : {"binned-sah", "bottom-up", "lbvh"}) {
            BuildOptions b1 = parse_builder(b), ball = b1;
            b1.threads = 1;
            ball.threads = 0;
            const auto [t1, tall] = median_ms_interleaved(
                o.repetitions, [&] { (void)build_bvh<float, 3>(boxes, centroids, b1); },
                [&] { (void)build_bvh<float, 3>(boxes, centroids, ball); });
            Row br;
            br.set("workload", std::string("build-") + b)
                .set("library", "bvhkit")
                .set("mesh", name)
                .set("ms_1_thread", t1)
                .set("ms_all_threads", tall)
                .set("scaling", t1 / tall);
            rows.push_back(br);
        }
    }
    return rows;
}

}  // namespace bvhkit::bench
