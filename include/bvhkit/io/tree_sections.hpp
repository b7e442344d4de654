#pragma once
// The sections a static triangle tree file is made of (docs/serialization.md), shared by the
// TriangleBvh and ClosestPointMesh files: nodes, u32 arrays (slot indices, skipped triangles),
// triangle corners, each padded to 8 bytes; the check of the header's counts against the payload,
// and the checks on the loaded arrays.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/bvh/validate.hpp"
#include "bvhkit/io/byte_codec.hpp"
#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/primitives/triangle.hpp"

namespace bvhkit::serial_detail {

template <class T>
inline constexpr std::uint64_t node_record_bytes = 6 * sizeof(T) + 8;

template <class T>
void put_vec(ByteWriter& w, const Vec<T, 3>& v) {
    for (std::size_t a = 0; a < 3; ++a) w.scalar(v[a]);
}
template <class T>
Vec<T, 3> get_vec(ByteReader& r) {
    Vec<T, 3> v;
    for (std::size_t a = 0; a < 3; ++a) v[a] = r.scalar<T>();
    return v;
}

template <class T>
void put_nodes(ByteWriter& w, const AabbBvh<T, 3>& bvh) {
    for (const auto& n : bvh.nodes) {
        put_vec(w, n.bounds.min);
        put_vec(w, n.bounds.max);
        w.u32(n.first);
        w.u32(n.count);
    }
    w.pad(8);
}
template <class T>
void get_nodes(ByteReader& r, AabbBvh<T, 3>& bvh, std::uint64_t count) {
    bvh.nodes.resize(std::size_t(count));
    for (auto& n : bvh.nodes) {
        n.bounds.min = get_vec<T>(r);
        n.bounds.max = get_vec<T>(r);
        n.first = r.u32();
        n.count = r.u32();
    }
    r.skip_padding(8);
}

inline void put_u32s(ByteWriter& w, std::span<const std::uint32_t> values) {
    for (const std::uint32_t v : values) w.u32(v);
    w.pad(8);
}
inline void get_u32s(ByteReader& r, std::vector<std::uint32_t>& out, std::uint64_t count) {
    out.resize(std::size_t(count));
    for (std::uint32_t& v : out) v = r.u32();
    r.skip_padding(8);
}

template <class T>
void put_corners(ByteWriter& w, std::span<const Triangle<T>> tris) {
    for (const auto& t : tris) put_vec(w, t.p0), put_vec(w, t.p1), put_vec(w, t.p2);
    w.pad(8);
}
template <class T>
void get_corners(ByteReader& r, std::vector<Triangle<T>>& out, std::uint64_t count) {
    out.resize(std::size_t(count));
    for (auto& t : out) t.p0 = get_vec<T>(r), t.p1 = get_vec<T>(r), t.p2 = get_vec<T>(r);
    r.skip_padding(8);
}

template <class T>
void check_scalar_and_volume(const TreeFileHeader& h, const char* what) {
    if (h.scalar != scalar_code<T>())
        throw Error(std::string(what) + ": the file holds a " +
                    scalar_name(std::uint8_t(h.scalar)) + " tree, loaded as " +
                    scalar_name(std::uint8_t(scalar_code<T>())));
    if (h.volume != VolumeCode::Aabb3)
        throw Error(std::string(what) + ": unknown bounding volume " +
                    std::to_string(int(h.volume)));
}

/// counts = {nodes, slots, skipped, triangles}: each against the payload before any allocation,
/// then the sections' total (`triangle_record` bytes per slot, `extra` bytes after the skipped
/// list) against the payload size (equal, or for `exact` false at most: more sections follow,
/// checked by their reader), the u32 range, and triangles = slots + skipped.
inline void check_tree_counts(const TreeFileHeader& h, std::uint64_t node_record,
                              std::uint64_t triangle_record, std::uint64_t extra, const char* what,
                              bool exact = true) {
    const auto [nodes, slots, skipped, triangles] = h.counts;
    const std::uint64_t limit = h.payload_size;
    const std::uint64_t expected = section_bytes(nodes, node_record, limit, what, "node") +
                                   section_bytes(slots, 4, limit, what, "slot") +
                                   section_bytes(slots, triangle_record, limit, what, "triangle") +
                                   section_bytes(skipped, 4, limit, what, "skipped") + extra;
    const auto fail = [&](const std::string& m) { throw Error(std::string(what) + ": " + m); };
    if (exact ? expected != h.payload_size : expected > h.payload_size)
        fail("the counts need " + std::to_string(expected) + " payload bytes, the file has " +
             std::to_string(h.payload_size));
    if (nodes > 0xffffffffu || slots > 0xffffffffu) fail("more than 2^32 - 1 nodes or slots");
    if (triangles != slots + skipped)
        fail("triangle count " + std::to_string(triangles) + " is not slots (" +
             std::to_string(slots) + ") + skipped (" + std::to_string(skipped) + ")");
}

/// Skipped triangles: in range and strictly ascending (so each once).
inline void check_skipped(std::span<const std::uint32_t> skipped, std::uint64_t triangle_count,
                          const char* what) {
    for (std::size_t i = 0; i < skipped.size(); ++i)
        if (skipped[i] >= triangle_count || (i && skipped[i] <= skipped[i - 1]))
            throw Error(std::string(what) + ": skipped triangles out of range or not ascending");
}

/// validate() against a box per triangle: slot_box(slot, leaf) gives the box of the triangle in
/// a slot; triangles absent from the tree get the empty box (allowed absent). The tree must have
/// passed check_tree_structure.
template <class T, class SlotBox>
void validate_loaded(BvhView<Aabb<T, 3>> bvh, std::size_t triangle_count,
                     std::span<const std::uint32_t> skipped, SlotBox slot_box, const char* what) {
    std::vector<Aabb<T, 3>> boxes(triangle_count);
    for (const auto& n : bvh.nodes)
        if (n.is_leaf())
            for (std::uint32_t s = n.first; s < n.first + n.count; ++s)
                boxes[bvh.primitive_indices[s]] = slot_box(s, n);
    try {
        validate(bvh, std::span<const Aabb<T, 3>>(boxes), skipped);
    } catch (const Error& e) {
        throw Error(std::string(what) + ": " + e.what());
    }
}

}  // namespace bvhkit::serial_detail
