// The command's files at the edges of the file system: an output that cannot be written (a full
// device, a full disk) is a non-zero exit and a message naming the file, never exit 0 with an empty
// or truncated file, and a regular output is replaced whole or not at all; inputs that never end
// (/dev/zero) or never deliver (a FIFO) are refused at once instead of growing or blocking.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "run_cli.hpp"
#include "special_files.hpp"

namespace {

using bvhkit::test::run_cli;
using bvhkit::test::ScratchDir;

void write_floats(const std::filesystem::path& p, const std::vector<float>& f) {
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(f.data()), std::streamsize(f.size() * sizeof(float)));
}

std::string output_text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Inputs for every command with an --out: `n` points, `n` rays and two poses.
struct CommandInputs {
    explicit CommandInputs(const ScratchDir& dir, std::size_t n)
        : points(dir / "points.bin"), rays(dir / "rays.bin"), poses(dir / "poses.bin") {
        std::vector<float> p, r;
        for (std::size_t i = 0; i < n; ++i) {
            const float x = float(i % 97) / 97.0f - 0.5f, y = float(i % 89) / 89.0f - 0.5f;
            p.insert(p.end(), {x, y, 2.0f});
            r.insert(r.end(), {x, y, -3.0f, 0, 0, 1, 0, 1e30f});
        }
        write_floats(points, p);
        write_floats(rays, r);
        write_floats(poses,
                     {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 3, 0, 0});
    }
    // The four commands that write --out, each up to (not including) its --out argument.
    std::vector<std::string> commands() const {
        const std::string mesh = "sphere:subdiv=2";
        return {"closest " + mesh + " --points " + points.string(),
                "trace " + mesh + " --rays " + rays.string(),
                "collide " + mesh + " " + mesh + " --poses " + poses.string(),
                "distance " + mesh + " " + mesh + " --poses " + poses.string()};
    }
    std::filesystem::path points, rays, poses;
};

}  // namespace

TEST(OutputFiles, FullDeviceIsANonZeroExitNamingIt) {
    const ScratchDir dir("cli_full");
    const CommandInputs in(dir, 64);
    for (const std::string& command : in.commands()) {
        const auto o = run_cli(command + " --out /dev/full");
        EXPECT_NE(o.status, 0) << command << "\n" << o.output;
        EXPECT_NE(o.output.find("/dev/full"), std::string::npos) << command << "\n" << o.output;
    }
}

// A disk that fills up mid-file (a file size limit, with the signal it raises ignored so the write
// fails instead): the old output stays, whole, and no partial file is left beside it.
TEST(OutputFiles, FullDiskLeavesTheOldOutputWholeAndNothingBeside) {
    const ScratchDir dir("cli_full_disk");
    const CommandInputs in(dir, 20000);  // results of 160 kB (trace) to 400 kB (closest)
    const auto out = dir / "out.bin";
    for (const std::string& command : {in.commands()[0], in.commands()[1]}) {
        std::ofstream(out) << "the old output";
        const auto o = run_cli(command + " --out " + out.string(), "trap '' XFSZ; ulimit -f 64;");
        EXPECT_NE(o.status, 0) << command << "\n" << o.output;
        EXPECT_NE(o.output.find(out.string()), std::string::npos) << command << "\n" << o.output;
        EXPECT_TRUE(output_text(out) == "the old output") << command;  // not printed: binary
        EXPECT_EQ(dir.names(),
                  (std::vector<std::string>{"out.bin", "points.bin", "poses.bin", "rays.bin"}))
            << command;
    }
}

TEST(OutputFiles, SpecialTargetsAreWrittenInPlace) {
    const ScratchDir dir("cli_stdout");
    const CommandInputs in(dir, 64);
    const auto o = run_cli(in.commands()[0] + " --out /dev/stdout");
    EXPECT_EQ(o.status, 0) << o.output;
    EXPECT_GE(o.output.size(), 64u * 20u);  // the results went to the log
}

TEST(InputFiles, EndlessAndBlockingInputsAreRefused) {
    const ScratchDir dir("cli_inputs");
    const CommandInputs in(dir, 8);
    const auto fifo = dir / "fifo.bin";
    ASSERT_TRUE(bvhkit::test::make_fifo(fifo));
    const std::string mesh = "sphere:subdiv=1", out = (dir / "out.bin").string();
    for (const std::string& source : {std::string("/dev/zero"), fifo.string()}) {
        for (const std::string& command :
             {"closest " + mesh + " --points " + source, "trace " + mesh + " --rays " + source,
              "collide " + mesh + " " + mesh + " --poses " + source,
              "distance " + mesh + " " + mesh + " --poses " + source}) {
            // The time limit only keeps a regression from hanging the test.
            const auto o = run_cli(command + " --out " + out, "timeout 30");
            EXPECT_NE(o.status, 0) << command << "\n" << o.output;
            EXPECT_NE(o.status, 124) << command << ": still reading after 30 s";
            EXPECT_NE(o.output.find("regular file"), std::string::npos) << command << "\n"
                                                                        << o.output;
        }
    }
}
