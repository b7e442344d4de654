#pragma once
// Saving and loading a TriangleBvh (format: docs/serialization.md). The file holds exactly what the
// tree holds: nodes, slot -> triangle indices, the triangles in slot order in the layout of the
// tree's triangle test (corners for the watertight test, p0/edges/normal for the fast one), the
// skipped triangles, and the ray layout it was built with (RayLayout, in the layout byte's high
// half). Nothing is rebuilt on load but the wide ray layout, derived from the loaded tree by the
// code a build uses (storing it does not pay: docs/serialization.md), so a loaded tree answers bit
// for bit as the saved one (on a CPU of the same kind: RayLayout::Auto picks by AVX2), and saving
// it again gives the same bytes.
//
// Loading trusts nothing: the envelope (size, checksum) is checked first, every count against the
// bytes there are before anything is allocated, then the tree's shape and every index
// (check_tree_structure), always; then validate() unless LoadOptions::validate is false. Any
// failure is a bvhkit::Error.
//
// Thread safety: saving reads the tree only (const queries may run at the same time); loading
// touches only its input and the tree it returns.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "bvhkit/io/tree_file.hpp"
#include "bvhkit/io/tree_sections.hpp"
#include "bvhkit/io/tree_structure.hpp"
#include "bvhkit/triangle_bvh.hpp"

namespace bvhkit {

namespace serial_detail {

// Layout byte of a TriangleBvh file: the low half says which triangle records the payload holds,
// the high half the tree's RayLayout (0 Auto, 1 Wide8, 2 Wide4, 3 Binary), so that a tree built
// to trace with another layout than the default traces (and breaks ties) with it after a load.
enum class TriangleLayout : std::uint8_t { Corners = 1, Precomputed = 2 };

struct TriangleBvhAccess {
    static constexpr const char* what = "TriangleBvh file";

    template <class T>
    static std::vector<std::uint8_t> save(const TriangleBvh<T>& tree) {
        const auto& bvh = tree.bvh_;
        const bool fast = tree.triangle_test_ == TriangleTest::Fast;
        ByteWriter w;
        w.reserve(bvh.nodes.size() * node_record_bytes<T> +
                  bvh.primitive_indices.size() * (4 + 12 * sizeof(T)) + 32);
        put_nodes(w, bvh);
        put_u32s(w, bvh.primitive_indices);
        if (fast) {
            for (const auto& t : tree.fast_)
                put_vec(w, t.p0), put_vec(w, t.e1), put_vec(w, t.e2), put_vec(w, t.n);
            w.pad(8);
        } else {
            put_corners<T>(w, tree.exact_);
        }
        put_u32s(w, tree.report_.skipped);
        TreeFileHeader h;
        h.kind = FileKind::TriangleBvh;
        h.scalar = scalar_code<T>();
        h.volume = VolumeCode::Aabb3;
        h.layout = std::uint8_t(
            std::uint8_t(fast ? TriangleLayout::Precomputed : TriangleLayout::Corners) |
            std::uint8_t(std::uint8_t(tree.ray_layout_) << 4));
        h.counts = {bvh.nodes.size(), bvh.primitive_indices.size(), tree.report_.skipped.size(),
                    tree.triangle_count_};
        return seal_tree_file(h, w.bytes());
    }

    template <class T>
    static TriangleBvh<T> load(std::span<const std::uint8_t> file, const LoadOptions& options) {
        const OpenedTreeFile f = open_tree_file(file, FileKind::TriangleBvh, what);
        const TreeFileHeader& h = f.header;
        check_scalar_and_volume<T>(h, what);
        const auto layout = TriangleLayout(h.layout & 0x0f);
        const int ray_layout = h.layout >> 4;
        if ((layout != TriangleLayout::Corners && layout != TriangleLayout::Precomputed) ||
            ray_layout > int(RayLayout::Binary))
            throw Error(std::string(what) + ": unknown triangle layout " +
                        std::to_string(int(h.layout)));
        const bool fast = layout == TriangleLayout::Precomputed;
        check_tree_counts(h, node_record_bytes<T>, (fast ? 12 : 9) * sizeof(T), 0, what);
        const auto [node_count, slot_count, skipped_count, triangle_count] = h.counts;

        ByteReader r(f.payload, what);
        TriangleBvh<T> tree;
        tree.triangle_test_ = fast ? TriangleTest::Fast : TriangleTest::Watertight;
        tree.ray_layout_ = RayLayout(ray_layout);
        tree.triangle_count_ = std::size_t(triangle_count);
        auto& bvh = tree.bvh_;
        get_nodes(r, bvh, node_count);
        get_u32s(r, bvh.primitive_indices, slot_count);
        if (fast) {
            tree.fast_.resize(std::size_t(slot_count));
            for (auto& t : tree.fast_)
                t.p0 = get_vec<T>(r), t.e1 = get_vec<T>(r), t.e2 = get_vec<T>(r),
                t.n = get_vec<T>(r);
            r.skip_padding(8);
        } else {
            get_corners(r, tree.exact_, slot_count);
        }
        auto& skipped = tree.report_.skipped;
        get_u32s(r, skipped, skipped_count);

        check_tree_structure(bvh, triangle_count, what);
        check_skipped(skipped, triangle_count, what);
        // The fast layout keeps no corners (p0 - e1 need not round back to p1): there a
        // triangle's box is its leaf's, and a leaf's enclosure of its triangles goes unchecked.
        if (options.validate)
            validate_loaded(
                bvh, tree.triangle_count_, skipped,
                [&](std::uint32_t s, const auto& leaf) {
                    return fast ? leaf.bounds : tree.exact_[s].bounds();
                },
                what);
        tree.make_ray_layout();  // derived, not stored: the structure was checked above
        return tree;
    }
};

}  // namespace serial_detail

/// The tree as a file's bytes (to write elsewhere, or to pickle).
template <class T>
std::vector<std::uint8_t> to_bytes(const TriangleBvh<T>& tree) {
    return serial_detail::TriangleBvhAccess::save(tree);
}

template <class T>
void save(const TriangleBvh<T>& tree, const std::filesystem::path& path) {
    serial_detail::write_file_bytes(path, to_bytes(tree));
}

/// A tree from bytes written by to_bytes / save; the scalar type must match the file's.
template <class T>
TriangleBvh<T> triangle_bvh_from_bytes(std::span<const std::uint8_t> bytes,
                                       const LoadOptions& options = {}) {
    return serial_detail::TriangleBvhAccess::load<T>(bytes, options);
}

template <class T>
TriangleBvh<T> load_triangle_bvh(const std::filesystem::path& path,
                                 const LoadOptions& options = {}) {
    return serial_detail::load_file(path, [&](std::span<const std::uint8_t> bytes) {
        return triangle_bvh_from_bytes<T>(bytes, options);
    });
}

}  // namespace bvhkit
