#pragma once
// The envelope of every bvhkit binary file (docs/serialization.md): a 72-byte header (magic,
// format version, what the file holds, scalar type, layout, four section counts, payload size,
// checksum) and the payload. open_tree_file() checks everything the envelope can check before a
// single count is used: the size the header claims against the bytes there are, and the checksum
// over header and payload, so a truncated or corrupted file is an Error before any allocation.
#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/error.hpp"
#include "bvhkit/io/byte_codec.hpp"
#include "bvhkit/io/file_access.hpp"

namespace bvhkit {

/// The format version this library writes for every kind but TriangleBvh; it reads this version
/// only.
inline constexpr std::uint32_t tree_file_version = 1;
/// The TriangleBvh file's version: 2 adds the wide ray layout's sections (docs/serialization.md).
/// Files of version 1 still load.
inline constexpr std::uint32_t triangle_bvh_file_version = 2;

struct LoadOptions {
    /// Run validate() on the loaded tree (each node encloses its children and its triangles, each
    /// triangle once, finite boxes, skipped triangles absent). When false, the loader still checks
    /// the tree's shape and every index, so queries stay in range: only the geometry is trusted.
    bool validate = true;
};

namespace serial_detail {

// PNG's trick: a 0x1A and a '\n' catch a file mangled by a text-mode transfer.
inline constexpr std::array<std::uint8_t, 8> tree_file_magic = {'B', 'V', 'H',  'K',
                                                                'I', 'T', 0x1A, '\n'};
inline constexpr std::size_t tree_file_header_size = 72;
inline constexpr std::size_t checksum_offset = 64;  // the checksum covers every byte but its own

enum class FileKind : std::uint32_t {
    TriangleBvh = 1,
    ClosestPointMesh = 2,
    SignedDistanceMesh = 3,
    WindingNumberMesh = 4,
    DynamicTree = 5,
    CollisionModel = 6,
    Scene = 7
};
enum class ScalarCode : std::uint8_t { Float32 = 1, Float64 = 2 };
enum class VolumeCode : std::uint8_t {
    Aabb3 = 1,
    Aabb2 = 2,
    Sphere = 3,
    Obb = 4,
    Rss = 5,
    ObbRss = 6,
    Kdop14 = 7,
    Kdop18 = 8,
    Kdop26 = 9,
    ConvexHull16 = 10
};

template <class T>
constexpr ScalarCode scalar_code() {
    static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>);
    return std::is_same_v<T, float> ? ScalarCode::Float32 : ScalarCode::Float64;
}
inline const char* scalar_name(std::uint8_t code) {
    return code == std::uint8_t(ScalarCode::Float32)   ? "float"
           : code == std::uint8_t(ScalarCode::Float64) ? "double"
                                                       : "unknown";
}

struct TreeFileHeader {
    std::uint32_t version = tree_file_version;
    FileKind kind = FileKind::TriangleBvh;
    ScalarCode scalar = ScalarCode::Float32;
    VolumeCode volume = VolumeCode::Aabb3;
    std::uint8_t layout = 0;                // kind-specific
    std::array<std::uint64_t, 4> counts{};  // kind-specific section counts
    std::uint64_t payload_size = 0;
};

/// The whole file: header (with the checksum of header and payload), then the payload.
inline std::vector<std::uint8_t> seal_tree_file(const TreeFileHeader& h,
                                                std::span<const std::uint8_t> payload) {
    ByteWriter w;
    w.reserve(tree_file_header_size + payload.size());
    for (const std::uint8_t b : tree_file_magic) w.u8(b);
    w.u32(h.version);
    w.u32(std::uint32_t(h.kind));
    w.u8(std::uint8_t(h.scalar));
    w.u8(std::uint8_t(h.volume));
    w.u8(h.layout);
    w.u8(0);   // reserved
    w.u32(0);  // reserved
    for (const std::uint64_t c : h.counts) w.u64(c);
    w.u64(payload.size());
    std::vector<std::uint8_t>& out = w.bytes();
    const std::uint64_t sum = fnv1a64(payload, fnv1a64(out));
    w.u64(sum);
    out.insert(out.end(), payload.begin(), payload.end());
    return out;
}

/// Recomputes the checksum of a file in place: for tests and fuzzing, which alter a file on
/// purpose and want the loader's other checks to see it. Needs at least the header's bytes.
inline void reseal_tree_file(std::span<std::uint8_t> file) {
    if (file.size() < tree_file_header_size) return;
    const std::uint64_t sum =
        fnv1a64(file.subspan(tree_file_header_size), fnv1a64(file.first(checksum_offset)));
    for (int i = 0; i < 8; ++i) file[checksum_offset + i] = std::uint8_t(sum >> (8 * i));
}

struct OpenedTreeFile {
    TreeFileHeader header;
    std::span<const std::uint8_t> payload;
};

/// Checks the envelope: size, magic, version (1 to `newest`), kind, reserved bytes, payload size,
/// checksum.
inline OpenedTreeFile open_tree_file(std::span<const std::uint8_t> file, FileKind expected,
                                     const char* what, std::uint32_t newest = tree_file_version) {
    ByteReader r(file, what);
    if (file.size() < tree_file_header_size)
        r.fail("truncated: " + std::to_string(file.size()) + " bytes, shorter than the " +
               std::to_string(tree_file_header_size) + "-byte header");
    for (const std::uint8_t b : tree_file_magic)
        if (r.u8() != b) r.fail("not a bvhkit tree file (bad magic)");
    OpenedTreeFile f;
    TreeFileHeader& h = f.header;
    h.version = r.u32();
    h.kind = FileKind(r.u32());
    // The kind first: each kind has versions of its own, so another kind's file may carry a
    // version this kind never had.
    if (h.kind != expected)
        r.fail("the file holds structure kind " + std::to_string(std::uint32_t(h.kind)) +
               ", expected " + std::to_string(std::uint32_t(expected)));
    if (h.version < 1 || h.version > newest)
        r.fail("format version " + std::to_string(h.version) + ", this library reads version " +
               (newest == 1 ? std::string("1") : "1 to " + std::to_string(newest)) +
               " of this kind");
    h.scalar = ScalarCode(r.u8());
    h.volume = VolumeCode(r.u8());
    h.layout = r.u8();
    if (r.u8() != 0 || r.u32() != 0) r.fail("reserved header bytes are not zero");
    for (std::uint64_t& c : h.counts) c = r.u64();
    h.payload_size = r.u64();
    const std::uint64_t stored = r.u64();
    const std::size_t actual = file.size() - tree_file_header_size;
    if (h.payload_size != actual)
        r.fail("the header says " + std::to_string(h.payload_size) +
               " payload bytes, the file has " + std::to_string(actual) +
               (h.payload_size > actual ? " (truncated)" : ""));
    f.payload = file.subspan(tree_file_header_size);
    if (fnv1a64(f.payload, fnv1a64(file.first(checksum_offset))) != stored)
        r.fail("checksum mismatch: the file is corrupted");
    return f;
}

/// `count` records of `record_bytes` each, plus padding to 8 bytes, or an Error if that exceeds
/// `limit` (the payload size): checked by division, so a huge count cannot overflow.
inline std::uint64_t section_bytes(std::uint64_t count, std::uint64_t record_bytes,
                                   std::uint64_t limit, const char* what, const char* section) {
    if (count > limit / record_bytes)
        throw Error(std::string(what) + ": " + section + " count " + std::to_string(count) +
                    " claims more than the file's " + std::to_string(limit) + " payload bytes");
    return (count * record_bytes + 7) / 8 * 8;
}

inline std::vector<std::uint8_t> read_file_bytes(const std::filesystem::path& path) {
    return file_detail::read_regular_file<std::vector<std::uint8_t>>(path, "tree file");
}

/// The structure from_bytes(bytes) makes of the file at `path`; an Error names the file.
template <class FromBytes>
auto load_file(const std::filesystem::path& path, FromBytes&& from_bytes) {
    const std::vector<std::uint8_t> bytes = read_file_bytes(path);
    try {
        return from_bytes(std::span<const std::uint8_t>(bytes));
    } catch (const Error& e) {
        throw Error(path.string() + ": " + e.what());
    }
}

/// Writes a new file next to `path` and renames it over `path` (file_access.hpp): the old file is
/// never rewritten in place, so a process that has it mapped (map_triangle_bvh) keeps reading the
/// bytes it checked, and a failed write leaves the old file whole and no partial file.
inline void write_file_bytes(const std::filesystem::path& path,
                             std::span<const std::uint8_t> bytes) {
    file_detail::write_file(path, bytes, "tree file");
}

}  // namespace serial_detail
}  // namespace bvhkit
