// K3 of issue 41: signed_distance_between (query/mesh_penetration.hpp) on the C1 poses of the
// shared closed meshes against a copy of themselves, beside C2's distance() on the same models
// (the poses where the copies are apart), one thread, medians of interleaved repetitions.
// Built with the benchmarks: build/release/bench/bvhkit_bench_k3.
// --dense N: also the least depth over N directions spread on the sphere (a Fibonacci lattice,
// each bisected on the exact test), against which the local optimum is compared.
//   usage: mesh_penetration_k3 [--poses N] [--reps N] [--dense N] MESH...
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/query/mesh_penetration.hpp"
#include "bvhkit/volumes/rss.hpp"
#include "random_rigid_poses.hpp"

using namespace bvhkit;

namespace {

/// This thread's CPU time in microseconds: the machine is shared, and wall time counts the other
/// processes' turns.
double cpu_us() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) * 1e6 + double(ts.tv_nsec) * 1e-3;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    std::size_t poses_n = 200;
    int reps = 3;
    int dense = 0;
    std::vector<std::string> meshes;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--poses") && i + 1 < argc)
            poses_n = std::size_t(std::atol(argv[++i]));
        else if (!std::strcmp(argv[i], "--dense") && i + 1 < argc)
            dense = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc)
            reps = std::atoi(argv[++i]);
        else
            meshes.push_back(argv[i]);
    }
    std::printf("%-20s %7s %6s %6s %12s %12s %12s %10s %8s\n", "mesh", "faces", "apart", "over",
                "C2 dist us", "K3 apart us", "K3 depth us", "tests/q", "unverif");
    for (const std::string& name : meshes) {
        const TriangleMesh mesh = read_mesh(name);
        const SolidModel<Rss<float>> solid(mesh);
        const auto poses = random_rigid_poses(mesh.bounds(), poses_n, 2026);
        std::vector<Transform<float>> apart, over;
        double tests = 0;
        int unverified = 0;
        for (const auto& p : poses) {
            const auto r = signed_distance_between(solid, solid, p);
            if (r.signed_distance > 0) {
                apart.push_back(p);
            } else {
                over.push_back(p);
                tests += r.overlap_tests;
                unverified += !r.verified;
            }
        }
        std::vector<double> c2, k3a, k3d;
        volatile float sink = 0;
        for (int rep = 0; rep < reps; ++rep) {
            auto t0 = cpu_us();
            for (const auto& p : apart)
                sink = sink + distance(solid.collision(), solid.collision(), p).distance;
            auto t1 = cpu_us();
            for (const auto& p : apart)
                sink = sink + signed_distance_between(solid, solid, p).signed_distance;
            auto t2 = cpu_us();
            for (const auto& p : over)
                sink = sink + signed_distance_between(solid, solid, p).signed_distance;
            auto t3 = cpu_us();
            const auto us = [](auto a, auto b, std::size_t n) {
                return (b - a) / double(std::max<std::size_t>(n, 1));
            };
            c2.push_back(us(t0, t1, apart.size()));
            k3a.push_back(us(t1, t2, apart.size()));
            k3d.push_back(us(t2, t3, over.size()));
        }
        const std::string base = name.substr(name.find_last_of('/') + 1);
        if (dense > 0) {
            // Local optimum over the best of `dense` directions: the ratio per pose.
            std::vector<double> ratio;
            int better_or_equal = 0;
            for (const auto& p : over) {
                const float local = -signed_distance_between(solid, solid, p).signed_distance;
                float best = std::numeric_limits<float>::infinity();
                for (int k = 0; k < dense; ++k) {
                    const double z = 1 - (2 * k + 1) / double(dense);
                    const double rho = std::sqrt(1 - z * z), phi = k * 2.399963229728653;
                    const Vec<float, 3> d{float(rho * std::cos(phi)), float(rho * std::sin(phi)),
                                          float(z)};
                    penetration_detail::DepthSearch<Rss<float>> s(solid, solid, p, {});
                    s.start(d);
                    best = std::min(best, s.depth());
                }
                ratio.push_back(double(local) / double(best));
                better_or_equal += local <= best * (1 + 1e-3f);
            }
            std::sort(ratio.begin(), ratio.end());
            if (!ratio.empty())
                std::printf(
                    "%s: local / best of %d directions over %zu poses: median %.4f, "
                    "max %.4f, min %.4f; local within 0.1%% of it or below at %d\n",
                    base.c_str(), dense, ratio.size(), ratio[ratio.size() / 2], ratio.back(),
                    ratio.front(), better_or_equal);
        }
        std::printf("%-20s %7zu %6zu %6zu %12.1f %12.1f %12.1f %10.0f %8d\n", base.c_str(),
                    mesh.triangles.size(), apart.size(), over.size(), median(c2), median(k3a),
                    median(k3d), over.empty() ? 0.0 : tests / double(over.size()), unverified);
    }
    return 0;
}
