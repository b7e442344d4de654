// The command line as a new user meets it: every mistake gets one clear error line and a non-zero
// exit, nothing else is printed after an error, and every command says what it did.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "run_cli.hpp"

namespace {

using Outcome = bvhkit::test::CliOutcome;

Outcome run(const std::string& args) {
    return bvhkit::test::run_cli(args);
}

bvhkit::test::ScratchFile temp_file(const std::string& name) {
    return bvhkit::test::ScratchFile("cli_test", name);
}

// Identity and a far-away pose, 12 float32 each.
bvhkit::test::ScratchFile write_poses() {
    const float poses[2][12] = {{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0},
                                {1, 0, 0, 0, 1, 0, 0, 0, 1, 10, 0, 0}};
    auto p = temp_file("poses.bin");
    std::ofstream(p.path(), std::ios::binary)
        .write(reinterpret_cast<const char*>(poses), sizeof poses);
    return p;
}

TEST(CommandLine, VersionFlag) {
    const Outcome o = run("--version");
    EXPECT_EQ(o.status, 0) << o.output;
    EXPECT_NE(o.output.find("bvhkit "), std::string::npos) << o.output;
}

TEST(CommandLine, BenchHelpListsEveryWorkload) {
    const Outcome o = bvhkit::test::run_bench_cli("--help");
    EXPECT_EQ(o.status, 0);
    for (const char* w : {"rays", "instances", "dynamic", "nearest", "collide", "scene", "files"})
        EXPECT_NE(o.output.find(w), std::string::npos) << w << " missing from: " << o.output;
}

// The saved-tree benchmark on a small mesh: every operation gets a row, and the mapped tree and
// the trees in memory hit the same rays.
TEST(CommandLine, BenchFilesMeasuresEveryOperation) {
    const Outcome o =
        bvhkit::test::run_bench_cli("files sphere:subdiv=3 --reps 1 --rays 2000 --json");
    ASSERT_EQ(o.status, 0) << o.output;
    for (const char* op : {"\"build\"", "\"save\"", "\"load\"", "\"map\"", "\"map-novalidate\"",
                           "\"R2-mapped\"", "\"R2-memory-binary\"", "\"R2-memory-default\""})
        EXPECT_NE(o.output.find(op), std::string::npos) << op << " missing from: " << o.output;
    // Three R2 rows with one hit count between them.
    const auto first = o.output.find("\"hits\"");
    ASSERT_NE(first, std::string::npos) << o.output;
    const std::string hits = o.output.substr(first, o.output.find_first_of(",}", first) - first);
    std::size_t count = 0;
    for (auto at = o.output.find(hits); at != std::string::npos; at = o.output.find(hits, at + 1))
        ++count;
    EXPECT_EQ(count, 3u) << hits << " in: " << o.output;
}

TEST(CommandLine, CollideWithOneMeshSaysWhatIsWrong) {
    const auto poses = write_poses();
    const Outcome o = run("collide sphere:subdiv=1 --poses " + poses.string() + " --out /dev/null");
    EXPECT_EQ(o.status, 2);
    EXPECT_NE(o.output.find("error: takes two meshes"), std::string::npos) << o.output;
    const Outcome d =
        run("distance sphere:subdiv=1 --poses " + poses.string() + " --out /dev/null");
    EXPECT_EQ(d.status, 2);
    EXPECT_NE(d.output.find("error: takes two meshes"), std::string::npos) << d.output;
}

TEST(CommandLine, CollideAndDistanceSayWhatTheyDid) {
    const auto poses = write_poses();
    const Outcome c = run("collide sphere:subdiv=1 sphere:subdiv=1 --poses " + poses.string() +
                          " --out " + temp_file("c.bin").string());
    EXPECT_EQ(c.status, 0) << c.output;
    EXPECT_NE(c.output.find("2 poses"), std::string::npos) << c.output;
    EXPECT_NE(c.output.find("1 colliding"), std::string::npos) << c.output;
    const Outcome d = run("distance sphere:subdiv=1 sphere:subdiv=1 --poses " + poses.string() +
                          " --out " + temp_file("d.bin").string());
    EXPECT_EQ(d.status, 0) << d.output;
    EXPECT_NE(d.output.find("1 colliding"), std::string::npos) << d.output;
}

std::string read_all(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every volume --volume names gives the same answers (the AABB's) on a pose list where some poses
// touch, and an unknown name is an error that lists the names.
TEST(CommandLine, EveryVolumeAnswersAlike) {
    const float poses[3][12] = {{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0},
                                {0, -1, 0, 1, 0, 0, 0, 0, 1, 1.5f, 0.3f, 0},
                                {1, 0, 0, 0, 1, 0, 0, 0, 1, 2.5f, 0, 0}};
    const auto p = temp_file("poses3.bin");
    std::ofstream(p.path(), std::ios::binary)
        .write(reinterpret_cast<const char*>(poses), sizeof poses);
    const std::string meshes = "torus sphere:subdiv=2 --poses " + p.string();
    std::string first_c, first_d;
    for (const char* bv : {"aabb", "obb", "rss", "obbrss", "sphere", "kdop18", "hull"}) {
        const auto c = temp_file(std::string("c_") + bv), d = temp_file(std::string("d_") + bv);
        const Outcome oc = run("collide " + meshes + " --out " + c.string() + " --volume " + bv);
        const Outcome od = run("distance " + meshes + " --out " + d.string() + " --volume " + bv);
        ASSERT_EQ(oc.status, 0) << bv << ": " << oc.output;
        ASSERT_EQ(od.status, 0) << bv << ": " << od.output;
        if (first_c.empty()) {
            first_c = read_all(c);
            first_d = read_all(d);
            EXPECT_EQ(first_c.size(), 15u);
            EXPECT_EQ(first_d.size(), 12u);
            ASSERT_EQ(first_c.size(), 15u);
            // Both outcomes occur, so the comparison means something.
            EXPECT_EQ(first_c[0] + first_c[5] + first_c[10], 2) << "colliding flags";
        }
        EXPECT_EQ(read_all(c), first_c) << bv;
        const std::string dd = read_all(d);
        ASSERT_EQ(dd.size(), first_d.size()) << bv;
        for (std::size_t k = 0; k < 3; ++k) {
            float x, y;
            std::memcpy(&x, dd.data() + 4 * k, 4);
            std::memcpy(&y, first_d.data() + 4 * k, 4);
            EXPECT_NEAR(x, y, 1e-5f * (1 + std::fabs(y))) << bv << " pose " << k;
        }
    }
    const Outcome bad = run("collide " + meshes + " --out /dev/null --volume cone");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("hull"), std::string::npos) << bad.output;
}

TEST(CommandLine, DirectoryAsMeshSaysSo) {
    const Outcome o = run("info " + std::filesystem::temp_directory_path().string());
    EXPECT_EQ(o.status, 1);
    EXPECT_NE(o.output.find("is a directory"), std::string::npos) << o.output;
}

TEST(CommandLine, UnknownBuilderPrintsOnlyTheError) {
    const Outcome o = run("info sphere:subdiv=1 --builder nope");
    EXPECT_EQ(o.status, 1);
    EXPECT_NE(o.output.find("error"), std::string::npos) << o.output;
    EXPECT_EQ(o.output.find("triangles"), std::string::npos) << "summary printed after an error:\n"
                                                             << o.output;
}

TEST(CommandLine, InfoReportsTheSpatialSplitBuild) {
    // A room: walls of two triangles each among small objects, where spatial splits pay.
    const Outcome o = run("info room:objects=20 --spatial-splits");
    EXPECT_EQ(o.status, 0) << o.output;
    const auto row = o.output.find("spatial-splits");
    ASSERT_NE(row, std::string::npos) << o.output;
    EXPECT_NE(o.output.find("binned-sah"), std::string::npos) << o.output;
    EXPECT_NE(o.output.find("references"), std::string::npos) << "no reference count:\n"
                                                              << o.output;
}

TEST(CommandLine, RenderSizeIsCheckedNotWrapped) {
    for (const char* size : {"4294967312x16", "16384x16384", "15x16", "x16", "16x", "-16x16"}) {
        const Outcome o = run(std::string("render sphere:subdiv=1 --size ") + size + " --out " +
                              temp_file("r.png").string());
        EXPECT_EQ(o.status, 1) << size << ": " << o.output;
        EXPECT_NE(o.output.find("--size"), std::string::npos) << size << ": " << o.output;
    }
}

}  // namespace
