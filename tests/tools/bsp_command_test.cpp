// `bvhkit bsp`: the statistics of the BSP of a mesh, and clear errors for bad options.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

struct Result {
    int status;
    std::string output;  // stdout and stderr together
};

Result run_bsp(const std::string& args) {
    static int counter = 0;
    const auto log =
        std::filesystem::temp_directory_path() / ("bvhkit_bsp_test_" + std::to_string(::getpid()) +
                                                  "_" + std::to_string(counter++) + ".txt");
    const std::string command =
        std::string(BVHKIT_CLI) + " bsp " + args + " > " + log.string() + " 2>&1";
    const int raw = std::system(command.c_str());
    std::ifstream in(log);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(log);
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text};
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

}  // namespace
