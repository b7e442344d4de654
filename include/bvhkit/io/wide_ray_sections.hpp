#pragma once
// The wide ray layout's sections of a TriangleBvh file (version 2, docs/serialization.md): a
// 24-byte header (width 0, 4 or 8; a reserved u32; node and group counts), then, for a width
// other than 0, zero bytes up to a 64-byte boundary of the file, the RayNode records and the
// TriangleGroup records, each byte for byte as in memory (little-endian), so that a mapped file's
// sections are the walk's arrays. check_wide_structure() is what a walk needs of them whatever
// their boxes hold; same_wide_layout() the bit-for-bit comparison with a derived layout that a
// validating load runs instead of a geometric check.
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bvhkit/bvh/bvh.hpp"
#include "bvhkit/io/byte_codec.hpp"
#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/query/ray_wide_layout.hpp"

namespace bvhkit::serial_detail {

/// The wide sections start at a multiple of this many bytes from the file's start: a mapping
/// starts on a page, so its records lie aligned for RayNode (a cache line).
inline constexpr std::size_t wide_section_alignment = 64;
inline constexpr std::uint64_t wide_header_bytes = 24;

template <int W>
inline constexpr std::uint64_t ray_node_record_bytes = 32 * W;  // 6 W floats, 2 W u32
template <int W>
inline constexpr std::uint64_t ray_group_record_bytes =
    40 * RayGroup<W>::lanes;  // 9 L floats, L u32

// The records hold no padding, so comparing and mapping them byte for byte is sound.
static_assert(sizeof(RayNode<4>) == ray_node_record_bytes<4> &&
              sizeof(RayNode<8>) == ray_node_record_bytes<8>);
static_assert(sizeof(RayGroup<4>) == ray_group_record_bytes<4> &&
              sizeof(RayGroup<8>) == ray_group_record_bytes<8>);

/// The lane order a stored layout was written with (the wide header's second field): 0, the
/// collapse's own order (files written before the order for occlusion rays); 1, each node's
/// lanes ordered for occlusion rays (query/ray_wide_occlusion_order.hpp), as layouts are now made.
/// The answers do not depend on it; a load derives or checks the layout of the order it states.
inline constexpr std::uint32_t wide_lane_order_collapse = 0;
inline constexpr std::uint32_t wide_lane_order_occlusion = 1;

struct WideSectionHeader {
    int width = 0;  // 0: no wide layout stored
    std::uint32_t lane_order = wide_lane_order_occlusion;
    std::uint64_t nodes = 0, groups = 0;
};

/// Zero bytes until the file offset (payload offset + header) is a multiple of
/// wide_section_alignment.
inline std::size_t wide_padding(std::size_t payload_offset) {
    const std::size_t at = (tree_file_header_size + payload_offset) % wide_section_alignment;
    return at == 0 ? 0 : wide_section_alignment - at;
}

template <int W>
void put_wide_layout(ByteWriter& w, WideRayView<W> wide) {
    w.u32(wide.empty() ? 0 : std::uint32_t(W));
    w.u32(wide.empty() ? 0 : wide_lane_order_occlusion);
    w.u64(wide.nodes.size());
    w.u64(wide.groups.size());
    if (wide.empty()) return;
    for (std::size_t pad = wide_padding(w.size()); pad > 0; --pad) w.u8(0);
    for (const RayNode<W>& n : wide.nodes) {
        for (const auto& row : n.lo)
            for (const float x : row) w.scalar(x);
        for (const std::uint32_t c : n.child) w.u32(c);
        for (const std::uint32_t g : n.groups) w.u32(g);
    }
    for (const auto& g : wide.groups) {
        for (const auto& row : g.corner)
            for (const float x : row) w.scalar(x);
        for (const std::uint32_t s : g.slot) w.u32(s);
    }
}

/// The header, with the counts checked against the bytes left: the records must fill them exactly.
inline WideSectionHeader get_wide_header(ByteReader& r) {
    const auto fail = [&](const std::string& m) { r.fail("wide ray layout: " + m); };
    WideSectionHeader h;
    const std::uint32_t width = r.u32();
    if (width != 0 && width != 4 && width != 8) fail("width " + std::to_string(width));
    h.lane_order = r.u32();
    if (h.lane_order > wide_lane_order_occlusion || (width == 0 && h.lane_order != 0))
        fail("lane order " + std::to_string(h.lane_order));
    h.width = int(width);
    h.nodes = r.u64();
    h.groups = r.u64();
    if (width == 0) {
        if (h.nodes != 0 || h.groups != 0) fail("counts without a layout");
        if (r.remaining() != 0) fail("bytes after the last section");
        return h;
    }
    const std::uint64_t left = r.remaining(), pad = wide_padding(r.position());
    const std::uint64_t node_bytes =
        width == 8 ? ray_node_record_bytes<8> : ray_node_record_bytes<4>;
    const std::uint64_t group_bytes =
        width == 8 ? ray_group_record_bytes<8> : ray_group_record_bytes<4>;
    // By division first, so that no count can overflow the sum.
    if (h.nodes == 0 || pad > left || h.nodes > (left - pad) / node_bytes ||
        h.groups > (left - pad - h.nodes * node_bytes) / group_bytes ||
        pad + h.nodes * node_bytes + h.groups * group_bytes != left)
        fail(std::to_string(h.nodes) + " nodes and " + std::to_string(h.groups) +
             " groups do not fill the " + std::to_string(left) + " bytes left");
    if (h.nodes > 0xffffffffu || h.groups > 0xffffffffu) fail("more than 2^32 - 1 nodes or groups");
    for (std::uint64_t i = 0; i < pad; ++i)
        if (r.u8() != 0) fail("non-zero padding byte");
    return h;
}

/// The records, copied.
template <int W>
void get_wide_layout(ByteReader& r, const WideSectionHeader& h, WideRayBvh<W>& out) {
    out.nodes.resize(std::size_t(h.nodes));
    out.groups.resize(std::size_t(h.groups));
    if constexpr (std::endian::native == std::endian::little) {
        // The file's records are the memory's (no padding, little-endian): copied whole.
        const std::size_t node_bytes = out.nodes.size() * sizeof(RayNode<W>);
        const std::size_t group_bytes = out.groups.size() * sizeof(RayGroup<W>);
        if (node_bytes > 0) std::memcpy(out.nodes.data(), r.take(node_bytes).data(), node_bytes);
        if (group_bytes > 0)
            std::memcpy(out.groups.data(), r.take(group_bytes).data(), group_bytes);
        return;
    }
    for (RayNode<W>& n : out.nodes) {
        for (auto& row : n.lo)
            for (float& x : row) x = r.scalar<float>();
        for (std::uint32_t& c : n.child) c = r.u32();
        for (std::uint32_t& g : n.groups) g = r.u32();
    }
    for (auto& g : out.groups) {
        for (auto& row : g.corner)
            for (float& x : row) x = r.scalar<float>();
        for (std::uint32_t& s : g.slot) s = r.u32();
    }
}

/// The records where they lie when this machine's records are the file's (little-endian) and the
/// bytes are aligned for them, else copied into `copy`; either way the view to check and walk.
template <int W>
WideRayView<W> read_wide_layout(ByteReader& r, const WideSectionHeader& h, WideRayBvh<W>& copy) {
    if (std::endian::native == std::endian::little && r.aligned_in_memory(alignof(RayNode<W>))) {
        WideRayView<W> view;
        view.nodes = r.records_in_place<RayNode<W>>(std::size_t(h.nodes), 8);
        view.groups = r.records_in_place<RayGroup<W>>(std::size_t(h.groups), 8);
        return view;
    }
    get_wide_layout(r, h, copy);
    return copy.view();
}

/// `stored` in the lane order layouts are made in now: itself, or, when `reorder` (it was written
/// in the collapse's own order), a copy in `held` (not the storage `stored` views) with the order
/// for occlusion rays applied. Only for a layout check_wide_structure accepted (children after
/// their parents, runs of groups inside the groups).
template <int W>
WideRayView<W> ordered_as_now(WideRayView<W> stored, bool reorder, WideRayBvh<W>& held) {
    if (!reorder || stored.empty()) return stored;
    held.nodes.assign(stored.nodes.begin(), stored.nodes.end());
    held.groups.assign(stored.groups.begin(), stored.groups.end());
    order_for_occlusion(held);
    return held.view();
}

/// What a walk needs, whatever the boxes hold: an empty lane (child invalid_index, groups 0) has
/// the inverted box (+inf, -inf), which every ray misses, so no walk follows it; an inner lane
/// names a node after its own, and every node but the root has exactly one parent (a tree, so no
/// walk loops) at depth below max_bvh_depth (the walks' stacks hold (W - 1) entries a level); a
/// leaf lane's run of groups lies inside the groups; every group lane names a triangle below
/// `triangle_count` or is padding (invalid_index).
template <int W>
void check_wide_structure(WideRayView<W> wide, std::uint64_t triangle_count, const char* what) {
    const auto fail = [&](const std::string& m) {
        throw Error(std::string(what) + ": wide ray layout: " + m);
    };
    const std::size_t n = wide.nodes.size();
    constexpr std::uint8_t unreached = 0xff;
    std::vector<std::uint8_t> depth(n, unreached);
    if (n > 0) depth[0] = 0;
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        if (depth[i] == unreached) fail("node " + std::to_string(i) + " is unreachable");
        const RayNode<W>& node = wide.nodes[i];
        for (int c = 0; c < W; ++c) {
            const std::uint32_t child = node.child[c], groups = node.groups[c];
            const std::string lane = "node " + std::to_string(i) + " lane " + std::to_string(c);
            if (groups == 0 && child == invalid_index) {
                for (int a = 0; a < 3; ++a)
                    if (!(node.lo[a][c] == inf && node.lo[3 + a][c] == -inf))
                        fail(lane + " is empty but its box is not (+inf, -inf)");
            } else if (groups == 0) {
                if (child <= i || child >= n)
                    fail(lane + " names node " + std::to_string(child) +
                         ", out of range or out of order");
                if (depth[child] != unreached)
                    fail("node " + std::to_string(child) + " has two parents");
                if (depth[i] + 1 >= int(max_bvh_depth))
                    fail(lane + " is deeper than " + std::to_string(max_bvh_depth - 1));
                depth[child] = std::uint8_t(depth[i] + 1);
            } else if (child == invalid_index ||
                       std::uint64_t(child) + groups > wide.groups.size()) {
                fail(lane + ": leaf run of groups [" + std::to_string(child) + ", +" +
                     std::to_string(groups) + ") out of range");
            }
        }
    }
    for (std::size_t g = 0; g < wide.groups.size(); ++g)
        for (const std::uint32_t s : wide.groups[g].slot)
            if (s != invalid_index && s >= triangle_count)
                fail("group " + std::to_string(g) + " names triangle " + std::to_string(s) +
                     " of " + std::to_string(triangle_count));
}

/// Whether two layouts hold the same bytes.
template <int W>
bool same_wide_layout(WideRayView<W> a, WideRayView<W> b) {
    return a.nodes.size() == b.nodes.size() && a.groups.size() == b.groups.size() &&
           (a.nodes.empty() ||
            std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size_bytes()) == 0) &&
           (a.groups.empty() ||
            std::memcmp(a.groups.data(), b.groups.data(), a.groups.size_bytes()) == 0);
}

}  // namespace bvhkit::serial_detail
