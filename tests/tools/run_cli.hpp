#pragma once
// Runs the bvhkit command (BVHKIT_CLI, set by tests/CMakeLists.txt) with arguments, for the tests
// of tests/tools: its exit status and everything it printed.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace bvhkit::test {

struct CliOutcome {
    int status;          // the exit status; -1 when it did not exit normally
    std::string output;  // stdout and stderr together
};

inline CliOutcome run_cli(const std::string& args) {
    static int counter = 0;
    const auto log =
        std::filesystem::temp_directory_path() / ("bvhkit_cli_test_" + std::to_string(::getpid()) +
                                                  "_" + std::to_string(counter++) + ".txt");
    const std::string command =
        std::string(BVHKIT_CLI) + " " + args + " > " + log.string() + " 2>&1";
    const int raw = std::system(command.c_str());
    std::ifstream in(log);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::filesystem::remove(log);
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text};
}

}  // namespace bvhkit::test
