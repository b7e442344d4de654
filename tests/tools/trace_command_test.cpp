// End to end: `bvhkit trace` on ray files in the docs/workloads.md format must write the
// brute-force hits (closest hit over every triangle) for workload R1 and R2 rays on every shared
// mesh; and the command's errors must be clear.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "brute_force.hpp"
#include "bvhkit/io/ray_files.hpp"
#include "bvhkit/io/read_mesh.hpp"
#include "bvhkit/mesh/load_mesh.hpp"
#include "ray_sets.hpp"
#include "run_cli.hpp"
#include "test_support.hpp"

using namespace bvhkit;

namespace {

test::ScratchFile temp_path(const std::string& name) {
    return test::ScratchFile("trace_test", name);
}

int run(const std::string& args, const std::filesystem::path& log) {
    const std::string command =
        std::string(BVHKIT_CLI) + " " + args + " > " + log.string() + " 2>&1";
    return std::system(command.c_str());
}

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

class TraceCommand : public ::testing::TestWithParam<const char*> {};

TEST_P(TraceCommand, HitsEqualBruteForceForR1AndR2Rays) {
    BVHKIT_REQUIRE_MESH(path, GetParam());
    const TriangleMesh mesh = read_mesh(path);
    const std::vector<Triangle<float>> tris = mesh_triangles(mesh);
    // The brute force costs rays x triangles; a camera of 48 x 48 and as many random rays.
    const std::uint32_t side = test::full_scale() ? 256 : 48;
    std::vector<Ray3f> rays = camera_rays(mesh.bounds(), side, side);
    const auto r2 = random_rays(mesh.bounds(), std::size_t(side) * side, 1);
    rays.insert(rays.end(), r2.begin(), r2.end());
    const auto ray_file = temp_path("rays.bin"), hit_file = temp_path("hits.bin"),
               log = temp_path("log.txt");
    write_rays(ray_file, rays);
    ASSERT_EQ(run("trace " + path.string() + " --rays " + ray_file.string() + " --out " +
                      hit_file.string(),
                  log),
              0)
        << read_text(log);
    const std::vector<FileHit> hits = read_hits(hit_file);
    ASSERT_EQ(hits.size(), rays.size());
    const test::BruteForce<float> reference(tris, rays);
    std::size_t hit_count = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const Hit<float>& want = reference.closest(i);
        if (!want) {
            ASSERT_EQ(hits[i].primitive, invalid_index) << "ray " << i;
            ASSERT_TRUE(std::isinf(hits[i].t) && hits[i].t > 0) << "ray " << i;
            continue;
        }
        ++hit_count;
        ASSERT_EQ(hits[i].t, want.t) << "ray " << i;
        if (hits[i].primitive != want.primitive) {  // only a tie at the same t is allowed
            const auto other = reference.intersect(hits[i].primitive, rays[i]);
            ASSERT_TRUE(other && other->t == want.t) << "ray " << i;
        }
    }
    EXPECT_GT(hit_count, rays.size() / 20);
}

INSTANTIATE_TEST_SUITE_P(Meshes, TraceCommand,
                         ::testing::Values("suzanne.obj", "teapot.obj", "spot.obj", "fandisk.obj",
                                           "dragon-lowres.ply", "stanford-bunny.obj", "igea.ply"),
                         test::MeshFileName{});

TEST(TraceCommandErrors, BadInputGivesAClearErrorAndNonZeroExit) {
    const auto log = temp_path("err.txt"), bad_rays = temp_path("bad.bin");
    std::ofstream(bad_rays.path(), std::ios::binary) << "0123456789";  // not a multiple of 32 bytes
    EXPECT_NE(run("trace sphere --rays " + bad_rays.string() + " --out /dev/null", log), 0);
    EXPECT_NE(read_text(log).find("not a whole number of ray records"), std::string::npos)
        << read_text(log);
    EXPECT_NE(run("trace no-such-mesh.obj --rays " + bad_rays.string() + " --out /dev/null", log),
              0);
    EXPECT_NE(read_text(log).find("no-such-mesh.obj"), std::string::npos) << read_text(log);
    EXPECT_NE(run("trace sphere --out /dev/null", log), 0);
    EXPECT_NE(read_text(log).find("--rays"), std::string::npos) << read_text(log);
    EXPECT_NE(run("trace sphere --rays x --out y --bogus", log), 0);
    EXPECT_NE(read_text(log).find("--bogus"), std::string::npos) << read_text(log);
    EXPECT_EQ(run("trace --help", log), 0);
    EXPECT_EQ(run("render --help", log), 0);
    EXPECT_EQ(run("info --help", log), 0);
}

// --threads: one thread and several write the same file, byte for byte, for closest and any hit.
TEST(TraceCommandThreads, SameFileForEveryThreadCount) {
    const TriangleMesh mesh = load_mesh("sphere:subdiv=5");
    const auto rays = random_rays(mesh.bounds(), test::scaled(40000, 4), 3);
    const auto ray_file = temp_path("threads_rays.bin"), log = temp_path("threads_log.txt");
    write_rays(ray_file, rays);
    for (const std::string mode : {"", " --any-hit"}) {
        std::string bytes[2];
        for (int k = 0; k < 2; ++k) {
            const auto out = temp_path("threads_hits" + std::to_string(k) + ".bin");
            ASSERT_EQ(run("trace sphere:subdiv=5 --rays " + ray_file.string() + " --out " +
                              out.string() + mode + (k == 0 ? " --threads 1" : " --threads 2"),
                          log),
                      0)
                << read_text(log);
            std::ifstream in(out.path(), std::ios::binary);
            bytes[k].assign(std::istreambuf_iterator<char>(in), {});
        }
        EXPECT_EQ(bytes[0].size(), rays.size() * 8) << mode;
        EXPECT_TRUE(bytes[0] == bytes[1]) << mode;
    }
    EXPECT_NE(run("trace sphere:subdiv=2 --rays " + ray_file.string() + " --out " +
                      temp_path("x.bin").string() + " --threads -1",
                  log),
              0);
    EXPECT_NE(read_text(log).find("--threads"), std::string::npos) << read_text(log);
}
