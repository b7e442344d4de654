#pragma once
// MappedFile: a whole file's bytes, read-only, mapped into memory (mmap on POSIX systems) rather
// than read: its pages come from the page cache as they are touched and are shared by every
// process that maps the same file, so N worker processes hold one copy of a large tree. Where
// there is no mmap, or where mmap refuses the file (some special file systems), the file is read
// into an 8-byte-aligned buffer instead (same interface).
//
// The mapping is private and read-only. The file must not be truncated or rewritten in place while
// it is mapped: a private mapping is no snapshot, so a page not yet read would show the new bytes,
// which no check has seen, and a page past a shorter file ends the process (SIGBUS). bvhkit's
// save() never does that (it writes a new file and renames it over the old one); other writers
// must do the same. Move-only; the bytes stay at the same address when it is moved.
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>
#include <utility>

#include "bvhkit/error.hpp"

#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#define BVHKIT_HAS_MMAP 1
#else
#define BVHKIT_HAS_MMAP 0
#endif

namespace bvhkit {

class MappedFile {
  public:
    MappedFile() = default;
    explicit MappedFile(const std::filesystem::path& path) {
#if BVHKIT_HAS_MMAP
        const auto fail = [&](const char* what) {
            throw Error(std::string(what) + " " + path.string() + ": " + std::strerror(errno));
        };
        // O_NONBLOCK: opening a FIFO would otherwise wait for a writer (the type check below then
        // refuses it); it changes nothing for a regular file.
        const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
        if (fd < 0) fail("cannot open");
        struct stat st {};
        if (::fstat(fd, &st) != 0) {
            ::close(fd);
            fail("cannot read");
        }
        if (!S_ISREG(st.st_mode)) {
            ::close(fd);
            throw Error("cannot map " + path.string() + ": not a regular file");
        }
        if (std::uintmax_t(st.st_size) > std::uintmax_t(SIZE_MAX)) {
            ::close(fd);
            throw Error("cannot map " + path.string() + ": too large for this address space");
        }
        size_ = std::size_t(st.st_size);
        if (size_ > 0) {  // mmap refuses length 0; an empty file is an empty span
            void* at = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
            if (at != MAP_FAILED) data_ = static_cast<const std::uint8_t*>(at);
        }
        ::close(fd);  // the mapping keeps the file
        if (size_ > 0 && !data_) read_into_buffer(path);
#else
        read_into_buffer(path);
#endif
    }

    MappedFile(MappedFile&& other) noexcept {
        swap(other);
    }
    MappedFile& operator=(MappedFile&& other) noexcept {
        MappedFile(std::move(other)).swap(*this);
        return *this;
    }
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile() {
#if BVHKIT_HAS_MMAP
        if (mapped()) ::munmap(const_cast<std::uint8_t*>(data_), size_);
#endif
    }

    /// The file's bytes; the first is page-aligned (8-byte-aligned when read into a buffer).
    std::span<const std::uint8_t> bytes() const {
        return {data_, size_};
    }
    /// True when the bytes are mapped, false when they were read into a buffer (or are none).
    bool mapped() const {
        return data_ && !buffer_;
    }

  private:
    void read_into_buffer(const std::filesystem::path& path) {
        std::ifstream in(path, std::ios::binary | std::ios::ate);
        if (!in) throw Error("cannot open " + path.string());
        const std::streamoff size = in.tellg();
        if (size < 0) throw Error("cannot read " + path.string());
        size_ = std::size_t(size);
        buffer_ = std::make_unique<std::uint64_t[]>((size_ + 7) / 8);
        in.seekg(0);
        if (size_ && !in.read(reinterpret_cast<char*>(buffer_.get()), std::streamsize(size_)))
            throw Error("cannot read " + path.string());
        data_ = reinterpret_cast<const std::uint8_t*>(buffer_.get());
    }
    void swap(MappedFile& other) noexcept {
        std::swap(data_, other.data_);
        std::swap(size_, other.size_);
        std::swap(buffer_, other.buffer_);
    }

    const std::uint8_t* data_ = nullptr;
    std::size_t size_ = 0;
    std::unique_ptr<std::uint64_t[]> buffer_;  // only when the file was read, not mapped
};

}  // namespace bvhkit
