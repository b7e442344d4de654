#pragma once
// Runs the bvhkit command (BVHKIT_CLI, set by tests/CMakeLists.txt) or the bvhkit-bench program
// (BVHKIT_BENCH_CLI) with arguments, for the tests of tests/tools: its exit status and everything
// it printed.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <utility>

namespace bvhkit::test {

struct CliOutcome {
    int status;          // the exit status; -1 when it did not exit normally
    std::string output;  // stdout and stderr together
};

/// A path in the temporary directory, unique to this process ("bvhkit_<kind>_<pid>_<name>"), whose
/// file is removed when the object goes (also when a failed assertion leaves the test early): the
/// tools' tests leave nothing behind.
class ScratchFile {
  public:
    ScratchFile(const std::string& kind, const std::string& name)
        : path_(std::filesystem::temp_directory_path() /
                ("bvhkit_" + kind + "_" + std::to_string(::getpid()) + "_" + name)) {}
    ScratchFile(ScratchFile&& other) noexcept : path_(std::move(other.path_)) {
        other.path_.clear();
    }
    ScratchFile(const ScratchFile&) = delete;
    ScratchFile& operator=(const ScratchFile&) = delete;
    ScratchFile& operator=(ScratchFile&&) = delete;
    ~ScratchFile() {
        std::error_code ignored;
        if (!path_.empty()) std::filesystem::remove(path_, ignored);
    }

    const std::filesystem::path& path() const { return path_; }
    operator const std::filesystem::path&() const { return path_; }  // NOLINT: a path to pass on
    std::string string() const { return path_.string(); }

  private:
    std::filesystem::path path_;
};

/// Runs `program` (a path) with `args`; `shell_prefix` goes before it in the same shell
/// ("ulimit -f 8;", "timeout 20").
inline CliOutcome run_program(const std::string& program, const std::string& args,
                              const std::string& shell_prefix = "") {
    static int counter = 0;
    const ScratchFile log("cli_log", std::to_string(counter++) + ".txt");
    const std::string command =
        shell_prefix + " " + program + " " + args + " > " + log.string() + " 2>&1";
    const int raw = std::system(command.c_str());
    std::ifstream in(log.path());
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text};
}

/// The bvhkit command.
inline CliOutcome run_cli(const std::string& args, const std::string& shell_prefix = "") {
    return run_program(BVHKIT_CLI, args, shell_prefix);
}

/// The bvhkit-bench program.
inline CliOutcome run_bench_cli(const std::string& args) {
    return run_program(BVHKIT_BENCH_CLI, args);
}

}  // namespace bvhkit::test
