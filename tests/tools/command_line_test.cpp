// The command line as a new user meets it: every mistake gets one clear error line and a non-zero
// exit, nothing else is printed after an error, and every command says what it did.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "run_cli.hpp"

namespace {

using Outcome = test::CliOutcome;

Outcome run(const std::string& args) {
    return test::run_cli(args);
}

std::filesystem::path temp_file(const std::string& name) {
    return std::filesystem::temp_directory_path() /
           ("bvhkit_cli_test_" + std::to_string(::getpid()) + "_" + name);
}

// Identity and a far-away pose, 12 float32 each.
std::filesystem::path write_poses() {
    const float poses[2][12] = {{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0},
                                {1, 0, 0, 0, 1, 0, 0, 0, 1, 10, 0, 0}};
    const auto p = temp_file("poses.bin");
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(poses), sizeof poses);
    return p;
}

TEST(CommandLine, VersionFlag) {
    const Outcome o = run("--version");
    EXPECT_EQ(o.status, 0) << o.output;
    EXPECT_NE(o.output.find("bvhkit "), std::string::npos) << o.output;
}

TEST(CommandLine, BenchHelpListsEveryWorkload) {
    const Outcome o = run("bench --help");
    EXPECT_EQ(o.status, 0);
    for (const char* w : {"rays", "dynamic", "nearest", "collide"})
        EXPECT_NE(o.output.find(w), std::string::npos) << w << " missing from: " << o.output;
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

TEST(CommandLine, RenderSizeIsCheckedNotWrapped) {
    for (const char* size : {"4294967312x16", "16384x16384", "15x16", "x16", "16x", "-16x16"}) {
        const Outcome o = run(std::string("render sphere:subdiv=1 --size ") + size + " -o " +
                              temp_file("r.png").string());
        EXPECT_EQ(o.status, 1) << size << ": " << o.output;
        EXPECT_NE(o.output.find("--size"), std::string::npos) << size << ": " << o.output;
    }
}

}  // namespace
