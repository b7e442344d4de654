#pragma once
// Special files for the tests of readers and writers: a scratch folder removed with everything in
// it, a FIFO in it, and a way to call a reader on the FIFO that cannot hang the test (a reader that
// blocks is released by opening the FIFO's other end, and the test fails instead of waiting).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <filesystem>
#include <functional>
#include <future>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace bvhkit::test {

/// A fresh folder in the temporary directory, removed with its contents when the object goes.
class ScratchDir {
  public:
    explicit ScratchDir(const std::string& name) {
        static int counter = 0;
        path_ =
            std::filesystem::temp_directory_path() /
            ("bvhkit_" + name + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    ~ScratchDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
    /// The names of the files in the folder, sorted (to see that nothing was left behind).
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const auto& e : std::filesystem::directory_iterator(path_))
            out.push_back(e.path().filename().string());
        std::sort(out.begin(), out.end());
        return out;
    }

  private:
    std::filesystem::path path_;
};

/// A FIFO at `path`; false if the system cannot make one.
inline bool make_fifo(const std::filesystem::path& path) {
    return ::mkfifo(path.c_str(), 0600) == 0;
}

/// Runs `body` (which reads the FIFO at `fifo`) and waits up to `seconds`. If it has not returned
/// by then, a writer opens and closes the FIFO so the blocked read sees the end and returns, and
/// the answer is false. The exception `body` threw, if any, is stored in `thrown`.
inline bool returns_without_blocking(const std::function<void()>& body,
                                     const std::filesystem::path& fifo, std::exception_ptr& thrown,
                                     double seconds = 10) {
    auto done = std::async(std::launch::async, [&] {
        try {
            body();
        } catch (...) {
            thrown = std::current_exception();
        }
    });
    if (done.wait_for(std::chrono::duration<double>(seconds)) == std::future_status::ready)
        return true;
    for (int i = 0; i < 100; ++i) {  // the reader may still be opening: retry until it is there
        const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) {
            ::close(fd);
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    done.wait();
    return false;
}

}  // namespace bvhkit::test
