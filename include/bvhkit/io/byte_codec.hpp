#pragma once
// Little-endian bytes for the binary tree files (docs/serialization.md): a writer, a reader that
// checks every read against the bytes left, and FNV-1a 64, the files' checksum. A big-endian
// machine assembles values byte by byte with shifts, so files are the same on either byte order.
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bvhkit/error.hpp"

namespace bvhkit::serial_detail {

inline constexpr std::uint64_t fnv1a64_offset = 14695981039346656037ull;

/// FNV-1a 64, continuing from `h`. Each step is a bijection of the state, so any change to a
/// single byte changes the result: a one-byte corruption is always detected.
inline std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes,
                             std::uint64_t h = fnv1a64_offset) {
    for (const std::uint8_t b : bytes) {
        h ^= b;
        h *= 1099511628211ull;
    }
    return h;
}

class ByteWriter {
  public:
    void u8(std::uint8_t v) { bytes_.push_back(v); }
    void u32(std::uint32_t v) { put(v); }
    void u64(std::uint64_t v) { put(v); }
    template <class T>
    void scalar(T v) {
        static_assert(sizeof(T) == 4 || sizeof(T) == 8);
        if constexpr (sizeof(T) == 4)
            u32(std::bit_cast<std::uint32_t>(v));
        else
            u64(std::bit_cast<std::uint64_t>(v));
    }
    /// Zero bytes up to the next multiple of `alignment`, so every section starts aligned.
    void pad(std::size_t alignment) {
        while (bytes_.size() % alignment) bytes_.push_back(0);
    }
    void reserve(std::size_t n) { bytes_.reserve(n); }
    std::size_t size() const { return bytes_.size(); }
    std::vector<std::uint8_t>& bytes() { return bytes_; }

  private:
    template <class U>
    void put(U v) {
        const std::size_t at = bytes_.size();
        bytes_.resize(at + sizeof(U));
        if constexpr (std::endian::native == std::endian::little) {
            std::memcpy(bytes_.data() + at, &v, sizeof(U));  // the same bytes, faster
        } else {
            for (std::size_t i = 0; i < sizeof(U); ++i) bytes_[at + i] = std::uint8_t(v >> (8 * i));
        }
    }

    std::vector<std::uint8_t> bytes_;
};

/// Reads from a span it does not own; every read past the end, and every padding byte that is not
/// zero, throws bvhkit::Error naming `what` and the offset.
class ByteReader {
  public:
    ByteReader(std::span<const std::uint8_t> bytes, std::string_view what)
        : bytes_(bytes), what_(what) {}

    std::size_t position() const { return pos_; }
    std::size_t remaining() const { return bytes_.size() - pos_; }

    std::uint8_t u8() {
        need(1);
        return bytes_[pos_++];
    }
    std::uint32_t u32() { return get<std::uint32_t>(); }
    std::uint64_t u64() { return get<std::uint64_t>(); }
    template <class T>
    T scalar() {
        static_assert(sizeof(T) == 4 || sizeof(T) == 8);
        if constexpr (sizeof(T) == 4)
            return std::bit_cast<T>(u32());
        else
            return std::bit_cast<T>(u64());
    }
    void skip_padding(std::size_t alignment) {
        while (pos_ % alignment)
            if (u8() != 0) fail("non-zero padding byte");
    }
    /// `count` records of U where they lie, without a copy (a mapped load), then the padding to
    /// `alignment`. U must be a little-endian record laid out as the file's; the bytes must be
    /// aligned for U (an Error otherwise). The caller checks the machine is little-endian. U is
    /// trivially copyable and only read, the case C++23's std::start_lifetime_as_array makes
    /// formal; GCC and Clang read such bytes as the records they hold.
    template <class U>
    std::span<const U> records_in_place(std::size_t count, std::size_t alignment) {
        if (count > remaining() / sizeof(U)) fail("unexpected end of data");
        const std::uint8_t* at = bytes_.data() + pos_;
        if (reinterpret_cast<std::uintptr_t>(at) % alignof(U))
            fail("section not aligned to " + std::to_string(alignof(U)) + " bytes in memory");
        pos_ += count * sizeof(U);
        skip_padding(alignment);
        return {reinterpret_cast<const U*>(at), count};
    }
    /// The next `n` bytes as they lie, then past them (a little-endian machine copies records
    /// with them whole).
    std::span<const std::uint8_t> take(std::size_t n) {
        need(n);
        const std::span<const std::uint8_t> out = bytes_.subspan(pos_, n);
        pos_ += n;
        return out;
    }
    /// Whether the next byte lies at an address that is a multiple of `alignment`.
    bool aligned_in_memory(std::size_t alignment) const {
        return reinterpret_cast<std::uintptr_t>(bytes_.data() + pos_) % alignment == 0;
    }
    [[noreturn]] void fail(const std::string& message) const {
        throw Error(std::string(what_) + ": " + message + " (at byte " + std::to_string(pos_) +
                    ")");
    }

  private:
    void need(std::size_t n) const {
        if (n > remaining()) fail("unexpected end of data");
    }
    template <class U>
    U get() {
        need(sizeof(U));
        U v = 0;
        if constexpr (std::endian::native == std::endian::little) {
            std::memcpy(&v, bytes_.data() + pos_, sizeof(U));
        } else {
            for (std::size_t i = 0; i < sizeof(U); ++i) v |= U(bytes_[pos_ + i]) << (8 * i);
        }
        pos_ += sizeof(U);
        return v;
    }

    std::span<const std::uint8_t> bytes_;
    std::string_view what_;
    std::size_t pos_ = 0;
};

}  // namespace bvhkit::serial_detail
