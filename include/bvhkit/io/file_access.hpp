#pragma once
// Reading and writing whole files, for every bvhkit reader and writer (mesh files, tree files, the
// command's ray, point, pose and result files).
//
// Reading: only regular files. A character device (/dev/zero) never ends and a FIFO may never
// deliver, so reading one could take unbounded memory or block for ever; such a file is an Error
// before a byte is read (the FIFO is opened without blocking to find out). A regular file is read
// to the size it had when opened, so memory is bounded by what is on disk. A file that does not
// exist is a FileNotFoundError, which callers can tell from a damaged file.
//
// Writing: a regular target (or one that does not exist yet) is written to a new file beside it,
// which is renamed over it once every write, the fsync and the close have succeeded. A failure at
// any step removes the new file and throws an Error naming the target, so the target is either
// the old file, whole, or the new one, whole; never a truncated or empty file reported as written.
// fsync before the rename: without it a crash soon after can leave the renamed file empty on some
// file systems, and it is where some (NFS, quotas) first report that the data did not fit. A
// target that is not a regular file (/dev/stdout, a FIFO, a terminal, /dev/full) cannot be
// replaced: it is written in place, every write and the close checked. So is any target that
// resolves into /dev or /proc (/dev/stdout is a link to the caller's descriptor, which may be a
// file: replacing that file would cut the caller's own output off from the path).
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "bvhkit/error.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#define BVHKIT_POSIX_FILES 1
#else
#include <fstream>
#define BVHKIT_POSIX_FILES 0
#endif

namespace bvhkit::file_detail {

/// "mesh file 'a.obj'" or "'a.obj'" for messages; `what` may be empty.
inline std::string describe(std::string_view what, const std::filesystem::path& path) {
    std::string s(what);
    if (!s.empty()) s += ' ';
    return s + "'" + path.string() + "'";
}

#if BVHKIT_POSIX_FILES

/// Closes a descriptor once (the destructor for paths that leave by an exception).
class Descriptor {
  public:
    explicit Descriptor(int fd) : fd_(fd) {}
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    ~Descriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    int get() const { return fd_; }
    /// Closes now; the close's own result (errno set when it fails).
    int close() {
        const int r = ::close(fd_);
        fd_ = -1;
        return r;
    }

  private:
    int fd_;
};

/// Writes all `size` bytes, retrying short writes and interruptions; false with errno on failure.
inline bool write_all(int fd, const unsigned char* data, std::size_t size) {
    while (size > 0) {
        const ::ssize_t n = ::write(fd, data, size);
        if (n < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        if (n == 0) {  // no progress and no error: treat as a full device rather than spin
            errno = ENOSPC;
            return false;
        }
        data += n;
        size -= std::size_t(n);
    }
    return true;
}

#endif

/// The bytes of the regular file at `path` as a `Bytes` (std::string, std::vector<char> or
/// std::vector<std::uint8_t>). Errors name the file with `what` ("mesh file", "ray file", ...).
template <class Bytes>
Bytes read_regular_file(const std::filesystem::path& path, std::string_view what) {
    const auto fail = [&](const std::string& why) -> void {
        throw Error("cannot read " + describe(what, path) + ": " + why);
    };
#if BVHKIT_POSIX_FILES
    // O_NONBLOCK: opening a FIFO would otherwise wait for a writer before the type check below.
    Descriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK));
    if (fd.get() < 0) {
        const int err = errno;
        if (err == ENOENT)
            throw FileNotFoundError("cannot read " + describe(what, path) +
                                    ": no such file or directory");
        fail(std::strerror(err));
    }
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) fail(std::strerror(errno));
    if (S_ISDIR(st.st_mode)) fail("it is a directory");
    if (!S_ISREG(st.st_mode))
        fail("not a regular file (a device, FIFO or socket may never end or never deliver)");
    if (std::uintmax_t(st.st_size) > std::uintmax_t(Bytes().max_size()))
        fail("too large for this address space");
    const int flags = ::fcntl(fd.get(), F_GETFL);
    if (flags >= 0) ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);
    Bytes bytes(std::size_t(st.st_size), typename Bytes::value_type{});
    std::size_t got = 0;
    while (got < bytes.size()) {
        const ::ssize_t n = ::read(fd.get(), bytes.data() + got, bytes.size() - got);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail(std::strerror(errno));
        }
        if (n == 0) fail("the file became shorter while it was read");
        got += std::size_t(n);
    }
    return bytes;
#else
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (status.type() == std::filesystem::file_type::not_found)
        throw FileNotFoundError("cannot read " + describe(what, path) +
                                ": no such file or directory");
    if (std::filesystem::is_directory(status)) fail("it is a directory");
    if (!std::filesystem::is_regular_file(status)) fail("not a regular file");
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) fail("cannot open it");
    const std::streamoff size = in.tellg();
    if (size < 0) fail("size unknown");
    Bytes bytes(std::size_t(size), typename Bytes::value_type{});
    in.seekg(0);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) fail("read failed");
    return bytes;
#endif
}

/// Writes `bytes` to `path` as the header comment says (beside and renamed for a regular target,
/// in place for a special file); an Error naming `path` when any step fails, leaving no new file.
inline void write_file(const std::filesystem::path& path, std::span<const unsigned char> bytes,
                       std::string_view what = {}) {
    const auto fail = [&](const std::string& why) -> void {
        throw Error("cannot write " + describe(what, path) + ": " + why);
    };
#if BVHKIT_POSIX_FILES
    std::error_code ec;
    struct stat st {};
    const bool exists = ::stat(path.c_str(), &st) == 0;  // follows links
    if (exists && S_ISDIR(st.st_mode)) fail("it is a directory");
    std::filesystem::path target = path;
    bool in_place = exists && !S_ISREG(st.st_mode);
    if (exists && !in_place) {
        // Through a link, the file the link names is replaced, not the link.
        const std::filesystem::path resolved = std::filesystem::canonical(path, ec);
        if (!ec) target = resolved;
        const std::string t = target.string();
        if (t.rfind("/dev/", 0) == 0 || t.rfind("/proc/", 0) == 0) in_place = true;
    }
    if (in_place) {
        Descriptor fd(::open(path.c_str(), O_WRONLY | O_CLOEXEC));
        if (fd.get() < 0) fail(std::strerror(errno));
        if (!write_all(fd.get(), bytes.data(), bytes.size())) fail(std::strerror(errno));
        if (fd.close() != 0) fail(std::strerror(errno));
        return;
    }
    static std::atomic<std::uint64_t> counter{0};
    std::filesystem::path temp = target;
    temp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    Descriptor fd(::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666));
    if (fd.get() < 0) fail(std::string("cannot create a file beside it: ") + std::strerror(errno));
    const auto give_up = [&](int err) -> void {
        if (fd.get() >= 0) fd.close();
        ::unlink(temp.c_str());
        fail(std::strerror(err));
    };
    // The replacement keeps the permissions of the file it replaces.
    if (exists && ::fchmod(fd.get(), st.st_mode & 07777) != 0) give_up(errno);
    if (!write_all(fd.get(), bytes.data(), bytes.size())) give_up(errno);
    if (::fsync(fd.get()) != 0) give_up(errno);
    if (fd.close() != 0) give_up(errno);
    if (::rename(temp.c_str(), target.c_str()) != 0) give_up(errno);
#else
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) fail("it is a directory");
    std::filesystem::path temp = path;
    temp += ".tmp";
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) fail("cannot create a file beside it");
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        out.close();
        if (!out) {
            std::filesystem::remove(temp, ec);
            fail("write failed");
        }
    }
    std::filesystem::rename(temp, path, ec);
    if (ec) {
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        fail(ec.message());
    }
#endif
}

/// write_file for any contiguous bytes (std::string, std::vector of char or bytes).
template <class Bytes>
void write_file_bytes_of(const std::filesystem::path& path, const Bytes& bytes,
                         std::string_view what = {}) {
    write_file(path,
               std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(bytes.data()),
                                              bytes.size() * sizeof(bytes[0])),
               what);
}

}  // namespace bvhkit::file_detail
