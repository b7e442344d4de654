// One option vocabulary over both programs: the spellings of an earlier release are still read,
// each with one note naming the new option, and only by commands that have that option; the
// commands that run queries take --threads and write the same files for any thread count; and
// `bvhkit bench` runs bvhkit-bench, or says clearly that it cannot.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

#include "run_cli.hpp"
#include "special_files.hpp"

namespace {

using bvhkit::test::run_bench_cli;
using bvhkit::test::run_cli;
using bvhkit::test::ScratchDir;

std::string bytes_of_file(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// Poses where the torus and the sphere touch, overlap and stand apart (12 float32 each).
std::filesystem::path write_touching_poses(const ScratchDir& dir) {
    const float poses[4][12] = {{1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0},
                                {0, -1, 0, 1, 0, 0, 0, 0, 1, 1.5f, 0.3f, 0},
                                {1, 0, 0, 0, 1, 0, 0, 0, 1, 2.5f, 0, 0},
                                {1, 0, 0, 0, 0, -1, 0, 1, 0, 0.2f, 1.1f, -0.4f}};
    const auto p = dir / "poses.bin";
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(poses), sizeof poses);
    return p;
}

TEST(OptionVocabulary, OldSpellingsAreReadWithOneNoteEach) {
    const ScratchDir dir("cli_vocabulary_old");
    const auto old_svg = dir / "old.svg", new_svg = dir / "new.svg";
    const auto o = run_cli("draw-tree -o " + old_svg.string() + " --n 30 --seed 4");
    ASSERT_EQ(o.status, 0) << o.output;
    EXPECT_EQ(occurrences(o.output, "note: -o is now --out\n"), 1u) << o.output;
    EXPECT_EQ(occurrences(o.output, "note: --n is now --boxes\n"), 1u) << o.output;
    const auto n = run_cli("draw-tree --out " + new_svg.string() + " --boxes 30 --seed 4");
    ASSERT_EQ(n.status, 0) << n.output;
    EXPECT_EQ(n.output.find("note:"), std::string::npos) << n.output;
    EXPECT_FALSE(bytes_of_file(new_svg).empty());
    EXPECT_EQ(bytes_of_file(old_svg), bytes_of_file(new_svg));

    // bench scene's mesh size was --size, which is an image's size in render and bench rays.
    const auto scene = run_bench_cli("scene --size 0.5 --help");
    EXPECT_EQ(scene.status, 0) << scene.output;
    EXPECT_EQ(occurrences(scene.output, "note: --size is now --extent\n"), 1u) << scene.output;

    const auto poses = write_touching_poses(dir);
    const std::string meshes = "torus sphere:subdiv=2 --poses " + poses.string();
    for (const char* command : {"collide ", "distance "}) {
        const auto a = dir / "bv.bin", b = dir / "volume.bin";
        const auto ob = run_cli(command + meshes + " --bv obb --out " + a.string());
        const auto ov = run_cli(command + meshes + " --volume obb --out " + b.string());
        ASSERT_EQ(ob.status, 0) << command << ob.output;
        ASSERT_EQ(ov.status, 0) << command << ov.output;
        EXPECT_EQ(occurrences(ob.output, "note: --bv is now --volume\n"), 1u) << ob.output;
        EXPECT_EQ(ov.output.find("note:"), std::string::npos) << ov.output;
        EXPECT_FALSE(bytes_of_file(b).empty()) << command;
        EXPECT_EQ(bytes_of_file(a), bytes_of_file(b)) << command;
    }
}

// An old spelling means its new option only: a command without that option refuses it as it
// refuses any unknown option, and names it.
TEST(OptionVocabulary, OldSpellingIsUnknownWhereTheNewOptionIs) {
    const auto i = run_cli("info sphere:subdiv=1 -o /dev/null");
    EXPECT_NE(i.status, 0);
    EXPECT_NE(i.output.find("unknown option -o"), std::string::npos) << i.output;
    EXPECT_EQ(i.output.find("note:"), std::string::npos) << i.output;
    const auto b = run_bench_cli("rays sphere:subdiv=1 --n 10");
    EXPECT_NE(b.status, 0);
    EXPECT_NE(b.output.find("unknown option --n"), std::string::npos) << b.output;
}

// The commands that run the user's queries take --threads; the files they write do not depend on
// the thread count (each pose's record has its own place).
TEST(OptionVocabulary, ThreadsChangeNoOutput) {
    const ScratchDir dir("cli_vocabulary_threads");
    const auto poses = write_touching_poses(dir);
    const std::string meshes = "torus:u=40,v=20 sphere:subdiv=3 --poses " + poses.string();
    for (const char* command : {"collide ", "distance "}) {
        std::string first;
        for (const char* threads : {"1", "2", "0"}) {
            const auto out = dir / (std::string("t") + threads + ".bin");
            const auto o =
                run_cli(command + meshes + " --threads " + threads + " --out " + out.string());
            ASSERT_EQ(o.status, 0) << command << threads << ": " << o.output;
            if (first.empty()) first = bytes_of_file(out);
            EXPECT_EQ(bytes_of_file(out), first) << command << "--threads " << threads;
        }
        EXPECT_EQ(first.size(), std::string(command) == "collide " ? 20u : 16u) << command;
    }
    std::string first;
    for (const char* threads : {"1", "2"}) {
        const auto png = dir / (std::string("r") + threads + ".png");
        const auto o = run_cli("render torus --heatmap --size 64x48 --threads " +
                               std::string(threads) + " --out " + png.string());
        if (o.status != 0 && o.output.find("libpng") != std::string::npos)
            GTEST_SKIP() << "built without libpng";
        ASSERT_EQ(o.status, 0) << o.output;
        EXPECT_EQ(o.output.find("note:"), std::string::npos) << "--size is render's own:\n"
                                                             << o.output;
        if (first.empty()) first = bytes_of_file(png);
        EXPECT_EQ(bytes_of_file(png), first) << "--threads " << threads;
    }
    EXPECT_NE(run_cli("collide " + meshes + " --threads -1 --out /dev/null").status, 0);
}

// info's --threads is the builders': every tree and its ray costs are the same, only the build
// times may differ. 81,920 triangles: past the size where the builders split their work.
TEST(OptionVocabulary, InfoThreadsChangeNoTree) {
    for (const char* builder : {"binned-sah --spatial-splits", "bottom-up", "lbvh"}) {
        std::string first;
        for (const char* threads : {"1", "2", "0"}) {
            const auto o = run_cli("info sphere:subdiv=6 --json --builder " + std::string(builder) +
                                   " --threads " + threads);
            ASSERT_EQ(o.status, 0) << o.output;
            const std::string rows =
                std::regex_replace(o.output, std::regex("\"build_ms\": *[-0-9.eE+]+"), "");
            ASSERT_NE(rows.find("sah_cost"), std::string::npos) << o.output;
            if (first.empty()) first = rows;
            EXPECT_EQ(rows, first) << builder << ", --threads " << threads;
        }
    }
}

// `bvhkit bench WORKLOAD ...` still runs, through bvhkit-bench beside the command, with a note.
TEST(OptionVocabulary, BvhkitBenchRunsBvhkitBench) {
    const auto o = run_cli("bench files sphere:subdiv=2 --reps 1 --rays 500 --json");
    ASSERT_EQ(o.status, 0) << o.output;
    EXPECT_EQ(occurrences(o.output, "note: bvhkit bench moved to bvhkit-bench\n"), 1u) << o.output;
    EXPECT_NE(o.output.find("\"R2-mapped\""), std::string::npos) << o.output;
    const auto h = run_cli("bench --help");
    EXPECT_EQ(h.status, 0) << h.output;
    EXPECT_NE(h.output.find("usage: bvhkit-bench"), std::string::npos) << h.output;
}

// A bvhkit without bvhkit-bench beside it says what is missing, and exits non-zero.
TEST(OptionVocabulary, BvhkitBenchMissingIsAClearError) {
    const ScratchDir dir("cli_vocabulary_alone");
    const auto alone = dir / "bvhkit";
    std::filesystem::copy_file(BVHKIT_CLI, alone);
    const auto o = bvhkit::test::run_program(alone.string(), "bench rays --reps 1");
    EXPECT_EQ(o.status, 1) << o.output;
    EXPECT_NE(o.output.find("bvhkit bench moved to bvhkit-bench"), std::string::npos) << o.output;
    EXPECT_NE(o.output.find((dir / "bvhkit-bench").string()), std::string::npos) << o.output;
    EXPECT_NE(o.output.find("error"), std::string::npos) << o.output;
}

}  // namespace
