// `bvhkit bsp`: the statistics of the BSP of a mesh, and clear errors for bad options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "run_cli.hpp"

#include "bvhkit/io/ray_files.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "ray_sets.hpp"
#include "test_support.hpp"

namespace {

using Result = bvhkit::test::CliOutcome;

using bvhkit::test::run_cli;

Result run_bsp(const std::string& args) {
    return run_cli("bsp " + args);
}

TEST(BspCommand, PrintsTheStatistics) {
    const Result r = run_bsp("torus:u=24,v=12 --split-weight 0.5");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("576 triangles"), std::string::npos) << r.output;
    for (const char* column : {"build_ms", "nodes", "depth", "splits", "polygons", "solid"})
        EXPECT_NE(r.output.find(column), std::string::npos) << column << "\n" << r.output;
    EXPECT_NE(r.output.find("yes"), std::string::npos) << r.output;
}

TEST(BspCommand, HaltingOptionsReachTheTree) {
    const Result r =
        run_bsp("sphere:subdiv=2 --leaf-size 8 --max-depth 6 --candidates axis --json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"solid\": \"no\""), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"depth\": 6"), std::string::npos) << r.output;
}

TEST(BspCommand, BadOptionsAreOneErrorLine) {
    for (const char* args :
         {"sphere --split-weight 1.5", "sphere --split-weight x", "sphere --leaf-size -1",
          "sphere --candidates diagonal", "", "no_such_mesh.obj"}) {
        const Result r = run_bsp(args);
        EXPECT_NE(r.status, 0) << args;
        EXPECT_NE(r.output.find("error"), std::string::npos) << args << ": " << r.output;
        EXPECT_EQ(r.output.find("nodes"), std::string::npos) << args << ": " << r.output;
    }
}

// `trace --structure bsp` writes the hits the BVH's trace writes (R1 and R2 rays on spot): the same
// hit or miss and t within float rounding. The BSP runs in double and the BVH's watertight test in
// float, so a ray grazing an edge may fall either way: at most one in a thousand may differ.
TEST(BspCommand, TraceThroughTheBspEqualsTheBvh) {
    using namespace bvhkit;
    BVHKIT_REQUIRE_MESH(path, "spot.obj");
    const TriangleMesh mesh = read_mesh(path);
    std::vector<Ray3f> rays = camera_rays(mesh.bounds(), 48, 48);
    const auto r2 = random_rays(mesh.bounds(), 48 * 48, 3);
    rays.insert(rays.end(), r2.begin(), r2.end());
    const test::ScratchFile ray_file("bsp_test", "rays.bin"), bvh_file("bsp_test", "bvh.bin"),
        bsp_file("bsp_test", "bsp.bin");
    write_rays(ray_file, rays);
    const std::string common = "trace " + path.string() + " --rays " + ray_file.string();
    const Result a = run_cli(common + " --out " + bvh_file.string());
    ASSERT_EQ(a.status, 0) << a.output;
    const Result b = run_cli(common + " --out " + bsp_file.string() + " --structure bsp");
    ASSERT_EQ(b.status, 0) << b.output;
    EXPECT_NE(b.output.find("BSP"), std::string::npos) << b.output;
    const auto want = read_hits(bvh_file), got = read_hits(bsp_file);
    ASSERT_EQ(want.size(), rays.size());
    ASSERT_EQ(got.size(), rays.size());
    std::size_t differ = 0, hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const bool w = want[i].primitive != invalid_index, g = got[i].primitive != invalid_index;
        hits += w;
        if (w != g ||
            (w && std::fabs(got[i].t - want[i].t) > 1e-5f * std::max(1.0f, std::fabs(want[i].t)))) {
            ++differ;
            continue;
        }
        if (w && got[i].primitive != want[i].primitive) {
            // A tie at a shared edge: both triangles are hit at about the same t.
            EXPECT_NEAR(got[i].t, want[i].t, 1e-5f * std::max(1.0f, want[i].t)) << "ray " << i;
        }
    }
    EXPECT_GT(hits, rays.size() / 10);
    EXPECT_LE(differ, rays.size() / 1000) << differ << " of " << rays.size() << " rays differ";
    EXPECT_NE(run_cli(common + " --out /dev/null --structure kd").status, 0);
    EXPECT_NE(run_cli(common + " --out /dev/null --structure bsp --builder lbvh").status, 0);
}

// `render --structure bsp` draws through the BSP (where the build has libpng; else it says so).
TEST(BspCommand, RenderThroughTheBsp) {
    const bvhkit::test::ScratchFile png("bsp_test", "render.png");
    const Result r =
        run_cli("render torus:u=24,v=12 --structure bsp --size 64x64 --out " + png.string());
    if (r.status != 0 && r.output.find("libpng") != std::string::npos)
        GTEST_SKIP() << "built without libpng";
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("BSP of"), std::string::npos) << r.output;
    EXPECT_GT(std::filesystem::file_size(png.path()), 100u);
    EXPECT_NE(run_cli("render torus --structure octree --out " + png.string()).status, 0);
    EXPECT_NE(run_cli("render torus --structure bsp --builder lbvh --out " + png.string()).status,
              0);
}

}  // namespace
